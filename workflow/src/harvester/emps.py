"""EMPS: the Electro-Mechanical Positioning System benchmark, identified in closed loop.

The EMPS (Janot, Gautier and Brunot 2019; ``data/emps/SOURCE.md``) is a prismatic
joint driven by a DC motor through a ball screw: eq. (1) with a force input, no spring and no
base motion,

    M q'' + Fv q' + Fc sgn(q') + OF = F,        F = gtau vir,

i.e. our terms with k = 0, c_m = Fv, ``coulomb_friction`` (F_coulomb = Fc) and ``offset_force``
(F_offset = OF). The drive runs under digital position control at 1 kHz; from the recorded
qm, qg and vir the controller is (``check_controller``: 0.24 % RMS residual on DATA_EMPS)

    vir_k = kv (kp (qg_k - qm_k) - (qm_k - qm_{k-2}) / (2 dt)) + d_k,

with the force gtau vir_k held over the sample (zero-order hold). d_k is a voltage added to the
controller output: zero in DATA_EMPS; in DATA_EMPS_PULSES the pulses, pulses_N x 1.014 V
(the recorded vir exceeds the control law by 5.07 V while pulses_N = 5).

Why the closed loop is simulated. The plant integrates (k = 0): simulated open loop from the
recorded force, any force error integrates twice and the position drifts (published parameters:
6.8 mm RMS, 19 mm at worst over the 25 s record, against 1.7 um RMS in closed loop). The
controller holds the real drive on the reference; simulating the same controller around the
model keeps the model on it too, and what the parameters change is the tracking error qg - q
(hundreds of micrometres), which the encoder (0.05 um) resolves. So the likelihood is
the tool's "simulation error" formulation: the exogenous inputs are the reference qg and the
added voltage d, the model output is the position q, compared with the measured qm:
:class:`ClosedLoopProblem`, a :class:`~harvester.likelihood.Problem` whose simulation is
:func:`simulate_closed_loop`. The benchmark authors' own method, inverse dynamics with least
squares on a filtered, differentiated qm (IDIM-LS), is :func:`idim_ls`, reported beside it.

The simulation runs at the controller's 1 kHz (the digital loop, its two-sample velocity and
the zero-order hold matter at the micrometre level, so the input is not decimated); the
likelihood compares every ``stride``-th sample (10: 100 Hz, five times the closed loop's 19 Hz
natural frequency), which keeps the information below 50 Hz. The residual is still correlated
at that spacing (over tau ~ 16-21 strided samples), so eq. (10) is tempered by 1 / tau, tau
estimated once from the viscous baseline's least-squares residual (:func:`temper_from`), as
the diagnosis does: evidence differences and posterior widths then count independent
information once.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numba as nb
import numpy as np
import pandas as pd
from scipy import io as sio
from scipy import signal

from harvester.daq import sha256 as file_sha256
from harvester.errors import DataError
from harvester.likelihood import Problem
from harvester.physics import Layout, step_rates, term
from harvester.signals import time_base
from harvester.simulate import BLOW_UP, MAX_SUBSTEPS, RATE_H, Simulation, _rhs, rk4_step
from harvester.structures import ModelStructure

log = logging.getLogger("harvester.emps")

#: Published reference model (IDIM-LS by the benchmark's authors; SOURCE.md).
PUBLISHED: dict[str, float] = {"M": 95.1089, "Fv": 203.5034, "Fc": 20.3935, "offset": -3.1648}
#: EMPS parameter -> our parameter name.
PARAMETERS: dict[str, str] = {"M": "M", "Fv": "c_m", "Fc": "F_coulomb", "offset": "F_offset"}
#: Units of the EMPS parameters.
UNITS: dict[str, str] = {"M": "kg", "Fv": "N s/m", "Fc": "N", "offset": "N"}
#: Known base parameters of the EMPS: no spring, no base motion (m does not enter).
KNOWN: dict[str, float] = {"m": 0.0, "k": 0.0}
#: Base parameters identified: M and the viscous coefficient.
FREE_BASE: tuple[str, ...] = ("M", "c_m")
#: Viscous-only baseline: M q'' + Fv q' + OF = F.
BASELINE_TERMS: tuple[str, ...] = ("offset_force",)
#: Fewest RK4 sub-steps per 1 ms sample: one step is within 3 nm (max) of 16 steps on DATA_EMPS
#: (tests/test_emps.py), against a 1.7 um residual; stability is kept by RATE_H regardless.
MIN_SUBSTEPS = 1
#: Columns of results/emps/parameters.csv.
PARAMETER_COLUMNS = ["parameter", "mean", "sd", "q2.5", "q97.5", "published"]


# --------------------------------------------------------------------------- data


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
    instrument for the closed-loop FRF (:func:`harvester.frf_priors.fit_linear_frf`).
    """
    return pd.DataFrame({"time": record.time, "force": record.force, "rel_disp": record.qm,
                         "qg": record.qg, "vir": record.vir})


# --------------------------------------------------------------------------- closed-loop model


@nb.njit(cache=True, error_model="numpy")
def _closed_loop_one(qg, dist, dt, q0, gtau, kp, kv, p, codes, poff, soff, n_states, n_sub,
                     out_q, out_v, out_a, out_f):
    """One particle: digital controller at every sample, RK4 sub-steps with the force held."""
    s = np.zeros(n_states)
    s[0] = q0
    k1 = np.zeros(n_states)
    k2 = np.zeros(n_states)
    k3 = np.zeros(n_states)
    k4 = np.zeros(n_states)
    tmp = np.zeros(n_states)
    h = dt / n_sub
    n = qg.shape[0]
    q_1 = q0
    q_2 = q0
    for i in range(n):
        q = s[0]
        f = gtau * (kv * (kp * (qg[i] - q) - (q - q_2) / (2.0 * dt)) + dist[i])
        out_q[i] = q
        out_v[i] = s[1]
        out_f[i] = f
        out_a[i] = _rhs(s, f, p, codes, poff, soff, k1, True)
        q_2 = q_1
        q_1 = q
        if i == n - 1:
            break
        for _ in range(n_sub):
            rk4_step(s, f, 0.0, h, p, codes, poff, soff, k1, k2, k3, k4, tmp, True)
        for e in range(n_states):
            if not (abs(s[e]) < BLOW_UP):
                return False
    return True


@nb.njit(cache=True, parallel=True, error_model="numpy")
def _closed_loop_batch(qg, dist, dt, q0, gtau, kp, kv, params, codes, poff, soff, n_states,
                       n_sub, qq, vv, aa, ff, ok):
    for i in nb.prange(params.shape[0]):
        ok[i] = _closed_loop_one(qg, dist, dt, q0, gtau, kp, kv, params[i], codes, poff, soff,
                                 n_states, n_sub[i], qq[i], vv[i], aa[i], ff[i])


@dataclass
class ClosedLoopSimulation(Simulation):
    """A closed-loop simulation: position (rel_disp, to ground), velocity, acceleration, force."""

    force: np.ndarray = field(default=None)  # gtau vir_k applied over each sample (N)


def simulate_closed_loop(layout: Layout, params: np.ndarray, reference: np.ndarray,
                         disturbance: np.ndarray, loop: ServoLoop, dt: float, q0: float = 0.0,
                         n_substeps: int | np.ndarray | None = None,
                         min_substeps: int = MIN_SUBSTEPS) -> ClosedLoopSimulation:
    """The model of ``layout`` (force input, base fixed) inside the digital position loop.

    ``reference`` qg (m) and ``disturbance`` d (V) are sampled every ``dt`` s; the model
    starts at rest at q0 (m). ``params`` is (particles, layout parameters) or one vector.
    Sub-steps per sample: as :func:`harvester.simulate.substeps` (rate x h <= RATE_H, for
    stability) but at least ``min_substeps`` instead of 4, or ``n_substeps`` if given.
    """
    p = np.ascontiguousarray(np.atleast_2d(params), dtype=np.float64)
    if p.shape[1] != len(layout.parameter_names):
        raise ValueError(f"params has {p.shape[1]} columns, layout needs "
                         f"{len(layout.parameter_names)}: {layout.parameter_names}")
    qg = np.ascontiguousarray(reference, dtype=np.float64)
    dist = np.ascontiguousarray(disturbance, dtype=np.float64)
    if dist.shape != qg.shape:
        raise ValueError("reference and disturbance differ in length")
    n_part, n = p.shape[0], qg.shape[0]
    valid = np.all(np.isfinite(p), axis=1) & (p[:, 0] > 0)
    p = np.where(valid[:, None], p, 1.0)
    if n_substeps is None:
        steps = np.ceil(step_rates(layout, p) * dt / RATE_H)
        steps = np.where(np.isfinite(steps), steps, MAX_SUBSTEPS)
        n_sub = np.clip(steps, min_substeps, MAX_SUBSTEPS).astype(np.int64)
    else:
        n_sub = np.broadcast_to(np.asarray(n_substeps, dtype=np.int64), (n_part,)).copy()
    qq, vv, aa, ff = (np.empty((n_part, n)) for _ in range(4))
    ok = np.zeros(n_part, dtype=np.bool_)
    _closed_loop_batch(qg, dist, float(dt), float(q0), loop.gtau, loop.kp, loop.kv, p,
                       layout.codes, layout.param_offsets, layout.state_offsets, layout.n_states,
                       n_sub, qq, vv, aa, ff, ok)
    ok &= valid & np.all(np.isfinite(qq), axis=1)
    for a in (qq, vv, aa, ff):
        a[~ok] = np.nan
    return ClosedLoopSimulation(rel_acc=aa, rel_disp=qq, rel_vel=vv, ok=ok, substeps=n_sub,
                                force=ff)


@dataclass
class ClosedLoopProblem(Problem):
    """A :class:`Problem` whose model runs inside the EMPS position loop.

    ``input`` is the position reference qg (m), ``output`` the measured position qm (m,
    output kind ``rel_disp``, to ground); ``disturbance`` (V) is added to the controller
    output; the model starts at rest at qm[0]. Likelihood: eq. (10) on every ``stride``-th
    sample of the position in ``window``.
    """

    loop: ServoLoop | None = None
    disturbance: np.ndarray | None = None
    min_substeps: int = MIN_SUBSTEPS

    def _check_kinds(self) -> None:
        if self.input_kind != "position_reference" or self.output_kind != "rel_disp":
            raise ValueError("a ClosedLoopProblem has input_kind 'position_reference' and "
                             "output_kind 'rel_disp'")
        if self.loop is None:
            raise ValueError("a ClosedLoopProblem needs the servo loop (gains)")
        if self.disturbance is None:
            self.disturbance = np.zeros_like(self.input)
        self.disturbance = np.asarray(self.disturbance, dtype=float)

    def simulate(self, theta: np.ndarray, input: np.ndarray | None = None, *,
                 base_acc: np.ndarray | None = None) -> ClosedLoopSimulation:
        if input is not None or base_acc is not None:
            raise ValueError("simulate another record with problem.for_record(record)")
        return simulate_closed_loop(self.structure.layout, self.layout_params(theta),
                                    self.input, self.disturbance, self.loop, self.dt,
                                    q0=float(self.output[0]), min_substeps=self.min_substeps)

    def for_record(self, record: EmpsRecord, window: tuple[int, int] | None = None
                   ) -> "ClosedLoopProblem":
        """The same model and known values on another record (e.g. the validation file)."""
        return closed_loop_problem(record, self.structure, self.known, window, self.stride,
                                   temper=self.temper)


def closed_loop_problem(record: EmpsRecord, model: ModelStructure | Sequence[str],
                        known: Mapping[str, float] | None = None,
                        window: tuple[int, int] | None = None, stride: int = 10,
                        disturbance: np.ndarray | None = None,
                        temper: float = 1.0) -> ClosedLoopProblem:
    """The closed-loop identification problem of an EMPS record.

    ``model``: a structure, or the terms added to eq. (1) (names of ``physics.TERMS``), with
    M and c_m identified and k = 0, m = 0 known (:data:`KNOWN`) unless ``known`` says
    otherwise. ``disturbance`` defaults to :func:`disturbance_voltage` (the pulses);
    ``temper`` multiplies eq. (10) (1 / tau of the residual, :func:`temper_from`).
    """
    if not isinstance(model, ModelStructure):
        terms = tuple(model)
        model = ModelStructure(emps_model_name(terms), terms, FREE_BASE)
    known = {**KNOWN, **(known or {})}
    d = disturbance_voltage(record) if disturbance is None else disturbance
    return ClosedLoopProblem(model, record.qg, record.qm, record.dt, known, window,
                             input_kind="position_reference", output_kind="rel_disp",
                             stride=stride, temper=temper, loop=record.loop, disturbance=d)


def closed_loop_fit(problem: ClosedLoopProblem, start: Mapping[str, float]
                    ) -> tuple[dict[str, float], np.ndarray]:
    """Least-squares output-error fit of the physical parameters (sigma left out).

    Starts from ``start`` (e.g. the prior means); returns the fitted values and the residual
    qm - q on the whole record. Used to set the likelihood's temper (:func:`temper_from`).
    """
    from scipy import optimize
    names = problem.structure.free_parameters
    x0 = np.array([start[n] for n in names], dtype=float)
    scale = np.maximum(np.abs(x0), 1.0)

    def residual(x: np.ndarray) -> np.ndarray:
        pred = problem.predict(np.append(x * scale, 1.0)[None, :])[0]
        r = (pred - problem.output)[problem.samples]
        return np.where(np.isfinite(r), r, 1.0) / np.std(problem.observed)

    sol = optimize.least_squares(residual, x0 / scale, x_scale=1.0)
    values = dict(zip(names, map(float, sol.x * scale)))
    pred = problem.predict(np.append(sol.x * scale, 1.0)[None, :])[0]
    return values, problem.output - pred


def correlation_time(x: np.ndarray, c: float = 5.0) -> float:
    """Integrated autocorrelation time tau = 1 + 2 sum_k rho(k) (samples), Sokal's window.

    tau correlated samples are worth one independent one: eq. (10) on them counts each piece
    of information tau times, so the likelihood is tempered by 1 / tau.
    """
    x = np.asarray(x, dtype=float) - np.mean(x)
    f = np.fft.rfft(x, n=2 * x.size)
    acf = np.fft.irfft(f * np.conj(f))[: x.size]
    if acf[0] <= 0:
        return 1.0
    taus = 2.0 * np.cumsum(acf / acf[0]) - 1.0
    ok = np.arange(x.size) >= c * taus
    return float(max(taus[int(np.argmax(ok)) if ok.any() else -1], 1.0))


def temper_from(residual: np.ndarray, stride: int) -> tuple[float, float]:
    """(temper = 1 / tau, tau) of a residual sampled every ``stride`` samples."""
    tau = correlation_time(np.asarray(residual)[::stride])
    return 1.0 / tau, tau


def emps_model_name(terms: Sequence[str]) -> str:
    """'viscous' for the baseline terms, 'viscous+<extra terms>' otherwise."""
    extra = [t for t in terms if t not in BASELINE_TERMS]
    return "+".join(["viscous", *extra])


def model_terms(name: str) -> tuple[str, ...]:
    """Inverse of :func:`emps_model_name`: 'viscous+coulomb_friction' -> terms."""
    base, *extra = name.split("+")
    if base != "viscous":
        raise ValueError(f"EMPS model names start with 'viscous', got {name!r}")
    for t in extra:
        term(t)
    return BASELINE_TERMS + tuple(extra)


# --------------------------------------------------------------------------- IDIM-LS


@dataclass(frozen=True)
class IdimFit:
    """Inverse-dynamics least squares (the benchmark's method): values, standard errors."""

    values: dict[str, float]
    se: dict[str, float]
    rel_error: float  # ||F - X beta|| / ||F|| (%)


def idim_ls(record: EmpsRecord, cutoff_hz: float = 100.0, order: int = 4,
            decimate_to_hz: float = 40.0, border: int = 50) -> IdimFit:
    """M, Fv, Fc, offset by least squares on F = M q'' + Fv q' + Fc sgn(q') + OF.

    As the benchmark authors' script: qm low-passed (Butterworth, zero phase, ``cutoff_hz``),
    differentiated twice by central differences, ``border`` samples dropped at each end,
    columns and force decimated (``scipy.signal.decimate``, factor round(0.8 fs/2 /
    decimate_to_hz)).
    """
    fs = 1.0 / record.dt
    b, a = signal.butter(order, cutoff_hz / (fs / 2.0))
    q = signal.filtfilt(b, a, record.qm)
    dq = np.gradient(q, record.dt)
    ddq = np.gradient(dq, record.dt)
    s = slice(border, len(q) - border)
    x = np.column_stack([ddq, dq, np.sign(dq), np.ones_like(dq)])[s]
    y = record.force[s]
    factor = int(round(0.8 * fs / 2.0 / decimate_to_hz))
    xd = np.column_stack([signal.decimate(x[:, j], factor) for j in range(4)])
    yd = signal.decimate(y, factor)
    beta, *_ = np.linalg.lstsq(xd, yd, rcond=None)
    err = yd - xd @ beta
    se = np.std(err) * np.sqrt(np.diag(np.linalg.inv(xd.T @ xd)))
    names = ("M", "Fv", "Fc", "offset")
    return IdimFit(dict(zip(names, map(float, beta))), dict(zip(names, map(float, se))),
                   float(100 * np.linalg.norm(err) / np.linalg.norm(yd)))


# --------------------------------------------------------------------------- results


def parameters_table(idata, published: Mapping[str, float] = PUBLISHED) -> pd.DataFrame:
    """results/emps/parameters.csv: parameter (M, Fv, Fc, offset), mean, sd, q2.5, q97.5, published.

    Rows for the EMPS parameters the posterior holds, in the order of :data:`PARAMETERS`.
    """
    rows = []
    for emps_name, ours in PARAMETERS.items():
        if ours not in idata.posterior:
            continue
        x = idata.posterior[ours].values.reshape(-1)
        rows.append({"parameter": emps_name, "mean": x.mean(), "sd": x.std(ddof=1),
                     "q2.5": np.quantile(x, 0.025), "q97.5": np.quantile(x, 0.975),
                     "published": published[emps_name]})
    return pd.DataFrame(rows, columns=PARAMETER_COLUMNS)


@dataclass
class TrackingBand:
    """Posterior ensemble of the closed-loop position, shown as tracking error q - qg (m)."""

    time: np.ndarray
    tracking: np.ndarray  # (samples, time): q_s - qg
    measured: np.ndarray  # qm - qg
    sigma: np.ndarray  # (samples,) m
    force: np.ndarray  # (samples, time) N
    measured_force: np.ndarray  # gtau vir (N)


def tracking_band(problem: ClosedLoopProblem, theta: np.ndarray, record: EmpsRecord
                  ) -> TrackingBand:
    """Simulate every row of theta in the loop of ``record`` (its reference and pulses)."""
    p = problem if record.qg is problem.input else problem.for_record(record)
    sim = p.simulate(theta)
    keep = sim.ok
    if not keep.any():
        raise RuntimeError(f"no posterior sample could be simulated on {record.name}")
    return TrackingBand(record.time, sim.rel_disp[keep] - record.qg, record.qm - record.qg,
                        np.asarray(theta)[keep, -1], sim.force[keep], record.force)


def error_metrics(band: TrackingBand, stride: int = 1) -> dict[str, float]:
    """Error of the posterior-mean simulation on a record.

    rms_position_um: RMS(q_mean - qm) in micrometres; nrmse_tracking: that over the RMS
    tracking error qm - qg; rms_force_N: RMS of the simulated minus the recorded force;
    outside_3sigma: fraction of samples of qm outside mean +- 3 (parameter sd (+) sigma);
    mlpd: mean log predictive density per sample (nats) of the mixture over samples of
    N(q_s, sigma_s^2), on every ``stride``-th sample.
    """
    from scipy.special import logsumexp
    mean = band.tracking.mean(axis=0)
    err = mean - band.measured
    sd = np.sqrt(band.tracking.var(axis=0) + np.mean(band.sigma**2))
    r = (band.measured[None, ::stride] - band.tracking[:, ::stride]) / band.sigma[:, None]
    logp = -0.5 * np.log(2 * np.pi * band.sigma[:, None] ** 2) - 0.5 * r**2
    mlpd = float(np.mean(logsumexp(logp, axis=0) - np.log(len(band.sigma))))
    return {
        "rms_position_um": float(1e6 * np.sqrt(np.mean(err**2))),
        "nrmse_tracking": float(np.sqrt(np.mean(err**2)) / np.sqrt(np.mean(band.measured**2))),
        "rms_force_N": float(np.sqrt(np.mean((band.force.mean(axis=0) - band.measured_force)
                                             ** 2))),
        "outside_3sigma": float(np.mean(np.abs(err) > 3 * sd)),
        "mlpd": mlpd,
    }


# --------------------------------------------------------------------------- missing physics


#: Candidate terms tried on top of the baseline when the diagnosis module is not used.
CANDIDATES: tuple[str, ...] = ("coulomb_friction", "tanh_friction", "quadratic_damping")


#: Log evidence differences below this (nats) are a tie ("not worth more than a bare
#: mention", Kass and Raftery 1995): the model with fewer parameters is named.
TIE_NATS = 1.0


def evidence_table(runs: Mapping[str, object], tie_nats: float = TIE_NATS
                   ) -> tuple[pd.DataFrame, str]:
    """Evidence of the baseline and of each baseline + term (InferenceData by model name).

    Returns the table (model, added_term, n_parameters, log_evidence, sd_over_chains,
    log_evidence_gain, tied_with_best), best first, and the named missing physics: among the
    models within ``tie_nats`` of the best, the added term of the one with fewest parameters,
    if it beats the baseline by more than ``tie_nats``; else ''. (Stand-in for
    ``harvester.diagnosis``.)
    """
    from harvester.posterior import pooled_log_evidence
    from harvester.tmcmc import log_evidence
    rows = []
    for name, idata in runs.items():
        terms = model_terms(name)
        extra = [t for t in terms if t not in BASELINE_TERMS]
        n_par = len(FREE_BASE) + sum(len(term(t).parameters) for t in terms)
        ev = log_evidence(idata)
        rows.append({"model": name, "added_term": "+".join(extra), "n_parameters": n_par,
                     "log_evidence": pooled_log_evidence(ev),
                     "sd_over_chains": float(np.std(ev, ddof=1)) if len(ev) > 1 else np.nan})
    table = pd.DataFrame(rows)
    if not (table["added_term"] == "").any():
        raise ValueError("the runs must include the baseline 'viscous'")
    base = table.loc[table["added_term"] == "", "log_evidence"].iloc[0]
    table["log_evidence_gain"] = table["log_evidence"] - base
    table = table.sort_values("log_evidence", ascending=False, ignore_index=True)
    table["tied_with_best"] = table["log_evidence"] >= table["log_evidence"].iloc[0] - tie_nats
    tied = table[table["tied_with_best"]].sort_values(["n_parameters", "log_evidence"],
                                                      ascending=[True, False])
    best = tied.iloc[0]
    named = best["added_term"] if best["log_evidence_gain"] > tie_nats else ""
    return table, named


def compare_terms(identify_model: Callable[[tuple[str, ...]], object],
                  baseline: tuple[str, ...] = BASELINE_TERMS,
                  candidates: Sequence[str] = CANDIDATES) -> tuple[pd.DataFrame, str, dict]:
    """Identify the baseline and baseline + each candidate; :func:`evidence_table` of them.

    ``identify_model(terms) -> InferenceData`` runs TMCMC for one structure (e.g. on
    :func:`closed_loop_problem`). Returns (table, named term, InferenceData by model name).
    """
    runs = {}
    for extra in (None, *candidates):
        terms = baseline if extra is None else baseline + (extra,)
        runs[emps_model_name(terms)] = identify_model(terms)
    table, named = evidence_table(runs)
    return table, named, runs


# --------------------------------------------------------------------------- report tables

#: Columns of results/emps/validation.csv.
VALIDATION_COLUMNS = ["model", "record", "file", "rms_position_um", "nrmse_tracking",
                      "rms_force_N", "outside_3sigma", "mlpd", "samples"]


def comparison_table(parameters: pd.DataFrame, idim: Mapping[str, float],
                     tolerance: float = 0.05) -> pd.DataFrame:
    """Posterior means beside the published values and our IDIM-LS: % errors, within 5 %?"""
    t = parameters[["parameter", "mean", "sd", "q2.5", "q97.5", "published"]].copy()
    t["unit"] = [UNITS[p] for p in t["parameter"]]
    t["error_pct"] = 100.0 * (t["mean"] / t["published"] - 1.0)
    t["within_tolerance"] = t["error_pct"].abs() <= 100.0 * tolerance
    t["published_in_95ci"] = (t["published"] >= t["q2.5"]) & (t["published"] <= t["q97.5"])
    t["idim_ls"] = [idim.get(p, np.nan) for p in t["parameter"]]
    t["idim_ls_error_pct"] = 100.0 * (t["idim_ls"] / t["published"] - 1.0)
    return t


def headline_table(comparison: pd.DataFrame, evidence: pd.DataFrame, named: Mapping,
                   validation: pd.DataFrame, runtimes: Mapping[str, float], baseline: str,
                   extended: str) -> pd.DataFrame:
    """Rows (quantity, value, reference, note): the EMPS study's numbers."""
    rows = []
    for _, r in comparison.iterrows():
        rows.append({"quantity": f"{r['parameter']} ({r['unit']}), posterior mean",
                     "value": r["mean"], "reference": r["published"],
                     "note": f"error {r['error_pct']:+.2f} % of published; sd {r['sd']:.3g}; "
                             f"95 % [{r['q2.5']:.5g}, {r['q97.5']:.5g}]; IDIM-LS "
                             f"{r['idim_ls']:.5g}"})
    ev = evidence.set_index("model")
    rows.append({"quantity": "named missing physics", "value": np.nan,
                 "reference": np.nan, "note": f"{named['named_term']} (expected "
                 f"{named['expected']})"})
    gain = ev.loc[extended, "log_evidence_gain"]
    rows.append({"quantity": f"log evidence gain {extended} over {baseline} (nats)",
                 "value": gain, "reference": np.nan,
                 "note": f"sd over chains {ev.loc[extended, 'sd_over_chains']:.3g}"})
    v = validation.set_index(["model", "record"])
    for record in ("training", "validation"):
        for metric, what in (("rms_position_um", "RMS position error (um)"),
                             ("nrmse_tracking", "position error / RMS tracking error"),
                             ("mlpd", "mean log predictive density (nats/sample)")):
            rows.append({"quantity": f"{record}: {what}, {extended}",
                         "value": v.loc[(extended, record), metric],
                         "reference": v.loc[(baseline, record), metric],
                         "note": f"reference column: {baseline}"})
    for model, seconds in runtimes.items():
        rows.append({"quantity": f"TMCMC wall time {model} (s)", "value": seconds,
                     "reference": np.nan, "note": ""})
    return pd.DataFrame(rows, columns=["quantity", "value", "reference", "note"])
