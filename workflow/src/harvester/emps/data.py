"""EMPS records: the .mat files, the position controller and its check against the
recorded voltage, the record in the recording format.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import io as sio

from harvester.data.daq import sha256 as file_sha256
from harvester.data.errors import DataError
from harvester.data.signals import time_base

#: Published reference model (IDIM-LS by the benchmark's authors; SOURCE.md).
PUBLISHED: dict[str, float] = {"M": 95.1089, "Fv": 203.5034, "Fc": 20.3935, "offset": -3.1648}
#: EMPS parameter -> our parameter name.
PARAMETERS: dict[str, str] = {"M": "M", "Fv": "c_m", "Fc": "F_coulomb", "offset": "F_offset"}
#: Units of the EMPS parameters.
UNITS: dict[str, str] = {"M": "kg", "Fv": "N s/m", "Fc": "N", "offset": "N"}


@dataclass(frozen=True)
class ServoLoop:
    """The digital position controller: gains and the voltage-to-force constant.

    vir_k = kv (kp (qg_k - q_k) - (q_k - q_{k-2}) / (2 dt)) + d_k (V); force gtau vir_k (N),
    held over [t_k, t_{k+1}).
    """

    gtau: float  # N/V
    kp: float  # 1/s
    kv: float  # V s/m

    def voltage(self, qg: np.ndarray, q: np.ndarray, dt: float) -> np.ndarray:
        """The control law applied to a position record q (m): vir without d (V)."""
        q = np.asarray(q, dtype=float)
        q2 = np.concatenate([np.full(2, q[0]), q[:-2]])
        return self.kv * (self.kp * (np.asarray(qg) - q) - (q - q2) / (2.0 * dt))

    @property
    def natural_frequency_hz(self) -> float:
        """Closed-loop natural frequency sqrt(gtau kv kp / M) / 2 pi for M = 95 kg (Hz)."""
        return float(np.sqrt(self.gtau * self.kv * self.kp / PUBLISHED["M"]) / (2 * np.pi))


@dataclass
class EmpsRecord:
    """One EMPS file: time (s), qm, qg (m), vir (V), the loop, and pulses_N if present."""

    name: str
    time: np.ndarray
    qm: np.ndarray
    qg: np.ndarray
    vir: np.ndarray
    loop: ServoLoop
    pulses: np.ndarray  # pulses_N as recorded (zeros if the file has none)

    @property
    def dt(self) -> float:
        return time_base(self.time)[0]

    @property
    def force(self) -> np.ndarray:
        """Applied force gtau vir (N)."""
        return self.loop.gtau * self.vir

    def __len__(self) -> int:
        return len(self.time)


def load_emps(path: str | Path, sha256: str | None = None) -> EmpsRecord:
    """Read an EMPS .mat file (scipy.io.loadmat), checking its SHA256 if given."""
    path = Path(path)
    if not path.is_file():
        raise DataError(path, "file not found")
    if sha256 is not None and file_sha256(path) != sha256.lower():
        raise DataError(path, f"SHA256 {file_sha256(path)} differs from the expected {sha256}")
    raw = sio.loadmat(str(path))
    get = {k: np.asarray(v, dtype=float).ravel() for k, v in raw.items() if not k.startswith("__")}
    missing = [k for k in ("t", "qm", "qg", "vir", "gtau", "kp", "kv") if k not in get]
    if missing:
        raise DataError(path, f"not an EMPS file: missing variables {missing}")
    loop = ServoLoop(float(get["gtau"][0]), float(get["kp"][0]), float(get["kv"][0]))
    n = get["t"].size
    return EmpsRecord(path.stem, get["t"], get["qm"], get["qg"], get["vir"], loop,
                      get.get("pulses_N", np.zeros(n)))


@dataclass(frozen=True)
class ControllerCheck:
    """How well the control law reproduces the recorded vir from the recorded qm and qg.

    rel_residual: RMS(vir - law - d) / RMS(vir); pulse_gain: volts added to vir per unit of
    pulses_N (least squares; NaN without pulses); gains_scale: least-squares factors on the
    kp and kv terms (1 if the file's gains are the ones used); rel_residual_one_step: the same
    law with a one-step velocity (q_k - q_{k-1}) / dt, for comparison.
    """

    rel_residual: float
    pulse_gain: float
    gains_scale: tuple[float, float]
    rel_residual_one_step: float

    def to_dict(self) -> dict:
        return {"rel_residual": self.rel_residual, "pulse_gain": self.pulse_gain,
                "gains_scale": list(self.gains_scale),
                "rel_residual_one_step": self.rel_residual_one_step}


def check_controller(record: EmpsRecord, edge: int = 100) -> ControllerCheck:
    """Verify the controller structure against the recorded vir (``edge`` samples left out)."""
    lp, dt = record.loop, record.dt
    q, qg, vir = record.qm, record.qg, record.vir
    s = slice(edge, len(record) - edge)
    q2 = np.concatenate([np.full(2, q[0]), q[:-2]])
    e_term = lp.kv * lp.kp * (qg - q)
    v_term = -lp.kv * (q - q2) / (2 * dt)
    has_pulses = bool(np.any(record.pulses != 0))
    cols = [e_term, v_term] + ([record.pulses] if has_pulses else [])
    a = np.column_stack(cols)[s]
    coef = np.linalg.lstsq(a, vir[s], rcond=None)[0]
    gain = float(coef[2]) if has_pulses else np.nan
    d = gain * record.pulses if has_pulses else 0.0
    law = lp.voltage(qg, q, dt)
    rms = float(np.sqrt(np.mean(vir[s] ** 2)))
    rel = float(np.sqrt(np.mean((vir - law - d)[s] ** 2)) / rms)
    q1 = np.concatenate([[q[0]], q[:-1]])
    law1 = lp.kv * (lp.kp * (qg - q) - (q - q1) / dt)
    rel1 = float(np.sqrt(np.mean((vir - law1 - d)[s] ** 2)) / rms)
    return ControllerCheck(rel, gain, (float(coef[0]), float(coef[1])), rel1)


def disturbance_voltage(record: EmpsRecord) -> np.ndarray:
    """Voltage d added to the controller output (V): the pulses, scaled by the measured gain."""
    if not np.any(record.pulses != 0):
        return np.zeros(len(record))
    return check_controller(record).pulse_gain * record.pulses


def to_recording(record: EmpsRecord) -> pd.DataFrame:
    """The record in the recording format: time, force (N), rel_disp (m, to ground), extras.

    ``qg`` (reference, m) and ``vir`` (V) ride along as extra columns; ``qg`` is the
    instrument for the closed-loop FRF (:func:`harvester.initial.frf.fit_linear_frf`).
    """
    return pd.DataFrame({"time": record.time, "force": record.force, "rel_disp": record.qm,
                         "qg": record.qg, "vir": record.vir})


