"""Loaded records as the electrical likelihood reads them.

A loaded record (``docs/virtual-rig-electrical.md``) is converted by rule ``convert`` to time,
base_acc, rel_acc and the two line voltages v_ab (``voltage``) and v_bc (``voltage_bc``), V;
its raw metadata gives the load per resistor of the star (``load.resistance_ohm``, null in open
circuit) and the generator's nameplate (lead, pole pairs). The likelihood compares

* the relative acceleration z'' low-passed as the paper's records are (zero-phase Butterworth,
  config ``preprocess``), and
* the space-vector magnitude of the two line voltages (``generator.space_vector_magnitude``),
  which does not depend on the rotor's angle: one line voltage alone is
  V sin(p (theta_0 + G z) + phi), whose phase turns by a radian per l / (2 pi p) = 0.8 mm of
  z, so that every error of the simulated z (0.02 mm from the base accelerometer's noise alone
  on the rig, more from any error of the mechanical model) and an unknown theta_0 per record
  would enter the fit of the generator (``docs/electrical.md``).
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from harvester.data.signals import lowpass
from harvester.electrical.generator import (
    conductance,
    screw_ratio,
    space_vector_magnitude,
)


@dataclass(frozen=True)
class LoadedRecord:
    """One record: input y'' (m/s^2), filtered z'' (m/s^2), voltage magnitude V (V), the
    load R_L (ohm, None: open circuit), the screw ratio G (rad/m), sample time dt (s) and the
    window [start, stop) of samples the likelihood uses."""

    name: str
    base_acc: np.ndarray
    rel_acc: np.ndarray
    voltage: np.ndarray
    load_ohm: float | None
    G: float
    dt: float
    window: tuple[int, int]

    @property
    def g(self) -> float:
        """Load conductance 1 / R_L (1/ohm), 0 in open circuit."""
        return conductance(self.load_ohm)

    @property
    def samples(self) -> slice:
        return slice(*self.window)

    @property
    def n_data(self) -> int:
        return self.window[1] - self.window[0]


def read_meta(path: str | Path) -> dict:
    """A raw record's JSON metadata."""
    return json.loads(Path(path).read_text(encoding="utf-8"))


def window_of(n: int, fs: float, lead_in_s: float, fit_s: float | None) -> tuple[int, int]:
    """Samples [lead-in, lead-in + fit) of a record of n samples at fs (Hz)."""
    start = int(round(lead_in_s * fs))
    stop = n if fit_s is None else min(n, start + int(round(fit_s * fs)))
    if not 0 <= start < stop:
        raise ValueError(f"lead-in {lead_in_s} s leaves no samples of a {n / fs:g} s record")
    return start, stop


def load_record(csv: str | Path, meta: Mapping, lowpass_hz: float, order: int,
                lead_in_s: float, fit_s: float | None, name: str | None = None,
                duration_s: float | None = None) -> LoadedRecord:
    """A converted loaded record with its raw metadata; ``duration_s`` keeps the first seconds
    (the simulation runs from the record's start, the likelihood over the window)."""
    df = pd.read_csv(csv)
    fs = float(meta["sampling_rate_hz"])
    if duration_s is not None:
        df = df.iloc[: int(round(duration_s * fs))]
    missing = {"base_acc", "rel_acc", "voltage", "voltage_bc"} - set(df.columns)
    if missing:
        raise ValueError(f"{csv}: a loaded record needs columns {sorted(missing)} (two line "
                         "voltages: the rig records v_ab and v_bc)")
    window = window_of(len(df), fs, lead_in_s, fit_s)
    return LoadedRecord(
        name=name or str(meta.get("record", Path(csv).stem)),
        base_acc=df["base_acc"].to_numpy(dtype=float),
        rel_acc=lowpass(df["rel_acc"].to_numpy(dtype=float), fs, lowpass_hz, order),
        voltage=space_vector_magnitude(df["voltage"], df["voltage_bc"]),
        load_ohm=meta["load"]["resistance_ohm"], G=screw_ratio(meta["generator"]["lead_m"]),
        dt=1.0 / fs, window=window)
