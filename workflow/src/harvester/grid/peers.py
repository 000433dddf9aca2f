"""The tools a user would otherwise reach for, run on the same records as the diagnosis and
scored against the same truth (issue 64).

A *record set* is a folder of recordings as the project reads them (``<name>.csv``, its
sidecar ``<name>.yaml`` with the known M, m, k) each with a truth file ``<name>.json`` as the
literature grid writes it (``grid.generators.make_scenario_files``): ``correct_names`` (the
library terms that name its effect; empty for an effect-free record or a form outside the
library), ``ratio`` (0 for an effect-free record; null where the strength is not known, as on
a real device), ``baseline`` and ``settings.lead_in_s``. A real recording's truth
(``grid.recorded``) also says ``"diagnose": "recording"``: the diagnosis is then the
command's own call on the file (``diagnosis.diagnose_recording``). Records of base
accelerations (``time, base_acc, rel_acc``: z and z' integrated), of base displacements
(``base_disp, rel_disp``) or of a force (``force, rel_disp``: M need not be known, its
inertia is then a free baseline column): z' and z'' differentiated (:func:`differentiate`).
A sidecar's ``friction_on: ground`` puts the friction candidates on the absolute velocity
z' + y' and displacement z + y (a contact fixed to the ground).

Every tool is scored on the same split: the diagnosis's analysis window and its held-out
tail (``diagnosis.prepare.analysis.analysis_window``, 25 % held out).

* :func:`sindy_names`: pysindy's STLSQ on the restoring force of eq. (1),
  f = -m y'' - M z'' = c z' + k z + F_c tanh(z'/v_t) + (missing), z and z' integrated from
  the record (:func:`integrate`); the baseline's terms (z, z', tanh with its width v_t the
  least-squares best, a constant) kept unpenalised by regressing them out of the force and
  of every candidate first (Frisch-Waugh-Lovell: the sparse fit of the residuals is the fit
  with those terms free), the candidates (:func:`library`, each a library term's physics)
  scaled to unit RMS so that a coefficient is the term's RMS force (N) and a threshold a
  share of the residual force's RMS. Named: the selected
  candidates' library names, largest force first. Held out: z'' predicted from the measured
  z, z' (an equation error, not a simulation).
* :func:`narx_free_run`: SysIdentPy's polynomial NARX (FROLS) from y'' to z'', simulated
  free on the held-out tail from its first measured lags. It names nothing.
* :func:`score_names`: right / wrong / missed / false alarm from a tool's ordered names, as
  ``grid.scoring.outcome`` scores the diagnosis's first name.

pysindy and sysidentpy are the optional ``[peers]`` dependency group; they are imported here
only when a tool runs.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from harvester.data.errors import DataError

#: STLSQ thresholds tried, as shares of the residual restoring force's RMS (a user's sweep).
THRESHOLDS = (0.02, 0.05, 0.1)
#: Held-out share of the analysed record (the diagnosis's ``holdout_fraction``).
HOLDOUT = 0.25
#: Velocity scales (shares of z' RMS) the search of the baseline's tanh width v_t starts
#: from (:func:`baseline_width`), and the Stribeck term's decay.
TANH_SHARES = np.geomspace(1e-3, 1.0, 25)
STRIBECK_SHARE = 0.3
#: The integrals' drift is cut at this share of the input's lowest frequency (its spectrum's
#: first bin within 1 % of its peak power).
DRIFT_SHARE = 0.5
#: Gaps of the dead-zone / contact candidates, as shares of max |z|.
GAPS = (0.6, 0.8)
#: NARX settings: lags (samples) of input and output, polynomial degree, terms kept.
NARX_LAGS = 4
NARX_DEGREE = 2
NARX_TERMS = 20
#: A free run whose held-out NRMSE exceeds this (or is not finite) counts as diverged.
DIVERGED_NRMSE = 10.0


@dataclass(frozen=True)
class Motion:
    """What the regression needs of a record: z (m), z' (m/s), z'' and y'' (m/s^2), the rate
    (Hz) and the drift cut (Hz) of the integrals (0: differentiated); ``w`` and ``x`` the
    friction's velocity and displacement (z', z; on the ground z' + y', z + y); ``force`` the
    drive of a force record (None: base-driven); ``drive`` and ``output`` the channels as
    recorded (the black-box model's input and output)."""

    z: np.ndarray
    v: np.ndarray
    a: np.ndarray
    base_acc: np.ndarray
    fs: float
    f_lo: float
    w: np.ndarray
    x: np.ndarray
    force: np.ndarray | None
    drive: np.ndarray
    output: np.ndarray


def _band_edge(x: np.ndarray, fs: float, share: float = 1e-2) -> float:
    """Lowest frequency (Hz) where the spectrum of ``x`` reaches ``share`` of its peak power."""
    p = np.abs(np.fft.rfft(x - x.mean())) ** 2
    f = np.fft.rfftfreq(x.size, 1.0 / fs)
    above = np.nonzero(p[1:] >= share * p[1:].max())[0]
    return float(f[1 + above[0]]) if above.size else float(f[1])


def integrate(a: np.ndarray, fs: float, f_lo: float) -> tuple[np.ndarray, np.ndarray]:
    """z' and z of an acceleration ``a`` (m/s^2 at ``fs`` Hz): trapezoidal integrals, each
    high-passed at ``f_lo`` Hz (zero phase, order 4) to remove its drift."""
    from scipy.integrate import cumulative_trapezoid
    from scipy.signal import butter, sosfiltfilt
    sos = butter(4, f_lo, btype="highpass", fs=fs, output="sos")
    v = sosfiltfilt(sos, cumulative_trapezoid(a - a.mean(), dx=1.0 / fs, initial=0.0))
    z = sosfiltfilt(sos, cumulative_trapezoid(v, dx=1.0 / fs, initial=0.0))
    return v, z


def differentiate(z: np.ndarray, fs: float) -> tuple[np.ndarray, np.ndarray]:
    """z' and z'' of a displacement ``z`` sampled at ``fs`` Hz, spectrally (i omega) on its
    even extension (z then its reverse: periodic and continuous, so no wrap-around jump):
    exact within the band, where central differences lose half the slope at 0.3 x the rate
    (the Silverbox's band edge); a kink of z' at the ends rings over a few samples there."""
    ext = np.concatenate([z - z.mean(), (z - z.mean())[::-1]])
    iw = 2j * np.pi * np.fft.rfftfreq(ext.size, 1.0 / fs)
    spec = np.fft.rfft(ext)
    v = np.fft.irfft(iw * spec, ext.size)[:z.size]
    a = np.fft.irfft(iw**2 * spec, ext.size)[:z.size]
    return v, a


RECORD_KINDS = {("base_acc", "rel_acc"): "acceleration", ("base_disp", "rel_disp"):
                "displacement", ("force", "rel_disp"): "force"}


def motion(rec: pd.DataFrame, source: str = "recording", friction_on: str | None = None
           ) -> Motion:
    """The record's motion (:class:`Motion`): an acceleration record integrated (the drift
    cut below the input's band, :data:`DRIFT_SHARE`), a displacement or force record
    differentiated; ``friction_on`` "ground": the friction's velocity the absolute one."""
    kind = RECORD_KINDS.get(tuple(rec.columns[1:3]))
    if rec.columns[0] != "time" or kind is None:
        raise DataError(source, f"columns {list(rec.columns)}: the peers read time and one of "
                        f"{[list(k) for k in RECORD_KINDS]}")
    t = rec["time"].to_numpy()
    fs = 1.0 / float(t[1] - t[0])
    drive, output = (rec[c].to_numpy(dtype=float) for c in rec.columns[1:3])
    force, y, vy = None, np.zeros_like(output), np.zeros_like(output)
    if kind == "acceleration":
        y2, a, f_lo = drive, output, DRIFT_SHARE * _band_edge(drive, fs)
        v, z = integrate(a, fs, f_lo)
    else:
        z, f_lo = output - output.mean(), 0.0
        v, a = differentiate(z, fs)
        if kind == "force":
            force, y2 = drive, np.zeros_like(z)
        else:
            y = drive - drive.mean()
            vy, y2 = differentiate(y, fs)
    ground = friction_on == "ground"
    if ground and kind == "acceleration":
        raise DataError(source, "friction_on: ground needs the base's displacement: an "
                        "acceleration record has only y''")
    return Motion(z, v, a, y2, fs, f_lo, v + vy if ground else v, z + y if ground else z,
                  force, drive, output)


def _dead_zone(z: np.ndarray, gap: float) -> np.ndarray:
    return np.sign(z) * np.maximum(np.abs(z) - gap, 0.0)


def library(m: Motion, vt: float) -> tuple[np.ndarray, list[tuple[str, str]]]:
    """The candidate columns and, per column, (its label, the library term it stands for);
    the friction's on its velocity w and displacement x (:class:`Motion`). No inertia-error
    column: z'' carries the record's noise, which is in the force too, so it would be
    selected on any record (errors in variables); nor a mode's (not a static force of z and
    z'); nor an offset force (the baseline's constant: z's mean is not in an acceleration
    record)."""
    w_rms, z_max = float(np.std(m.w)), float(np.max(np.abs(m.z)))
    ws = STRIBECK_SHARE * w_rms
    z, v, w, x = m.z, m.v, m.w, m.x
    cols = [
        ("sgn(w)", "coulomb_friction", np.sign(w)),
        ("sgn(w) exp(-(w/ws)^2)", "stribeck_friction", np.sign(w) * np.exp(-(w / ws) ** 2)),
        ("step(w)", "asymmetric_friction", 0.5 * (1.0 + np.tanh(w / vt))),
        ("v|v|", "quadratic_damping", v * np.abs(v)),
        ("z^3", "cubic_stiffness", z**3),
        *[(f"dead zone {g:g} z_max", "end_stop", _dead_zone(z, g * z_max)) for g in GAPS],
        ("x|w|", "hysteresis", x * np.abs(w)),
        ("|x| sgn(w)", "hysteresis", np.abs(x) * np.sign(w)),
    ]
    return np.column_stack([c[2] for c in cols]), [(c[0], c[1]) for c in cols]


def baseline_columns(m: Motion, vt: float | None, inertia: bool = False) -> np.ndarray:
    """The baseline's restoring-force terms: z, z', a constant (the static part of k z,
    which an acceleration record does not hold), tanh(w/v_t) for the tanh baseline (``vt``
    given) and z'' where the mass is not known (``inertia``: a force record without M)."""
    cols = [m.z, m.v, np.ones_like(m.z)]
    cols += [np.tanh(m.w / vt)] if vt is not None else []
    cols += [m.a] if inertia else []
    return np.column_stack(cols)


def baseline_width(m: Motion, f: np.ndarray, fit: slice, inertia: bool = False) -> float:
    """The tanh width v_t (m/s) whose baseline least-squares fit of ``f`` on ``fit`` leaves
    the least squared residual: the best of :data:`TANH_SHARES` x w RMS, refined by a
    bounded search between its neighbours (log scale)."""
    from scipy.optimize import minimize_scalar
    w_rms = float(np.std(m.w))

    def sse(log_vt: float) -> float:
        cols = baseline_columns(m, float(np.exp(log_vt)), inertia)[fit]
        return float(np.sum(_residualise(cols, f[fit, None]) ** 2))

    grid = np.log(TANH_SHARES * w_rms)
    i = int(np.argmin([sse(g) for g in grid]))
    lo, hi = grid[max(i - 1, 0)], grid[min(i + 1, grid.size - 1)]
    return float(np.exp(minimize_scalar(sse, bounds=(lo, hi), method="bounded",
                                        options={"xatol": 1e-3}).x))


def inertia_free(m: Motion, known: Mapping[str, float]) -> bool:
    """Whether z'' is a fitted baseline column: a force record whose M is not known."""
    return m.force is not None and "M" not in known


def driving_force(m: Motion, known: Mapping[str, float]) -> np.ndarray:
    """The drive on the right of eq. (1): -m y'' (N) for a base-driven record, the force
    itself for a force record."""
    return m.force if m.force is not None else -float(known["m"]) * m.base_acc


def restoring_force(m: Motion, known: Mapping[str, float]) -> np.ndarray:
    """f = drive - M z'' (N), eq. (1) with everything but the inertia on the right (the
    drive alone where M is not known: z'' is then a baseline column)."""
    f = driving_force(m, known)
    return f if inertia_free(m, known) else f - float(known["M"]) * m.a


@dataclass
class SindyFit:
    """One STLSQ fit: the named library terms (largest force first), each candidate's RMS
    force (N, 0 where dropped), and the held-out NRMSE of z'' from the measured motion."""

    threshold: float
    names: list[str]
    forces: dict[str, float]
    heldout_nrmse: float
    seconds: float


def _residualise(B: np.ndarray, X: np.ndarray) -> np.ndarray:
    """X with its least-squares projection on B's columns removed."""
    coef, *_ = np.linalg.lstsq(B, X, rcond=None)
    return X - B @ coef


#: Width of the one-sided step's tanh (a share of w's RMS) where the baseline has no v_t.
STEP_SHARE = 0.01


def sindy_names(m: Motion, known: Mapping[str, float], fit: slice, held: slice,
                thresholds: Sequence[float] = THRESHOLDS, baseline: str = "tanh"
                ) -> list[SindyFit]:
    """pysindy's STLSQ at each threshold (module docstring), fitted on ``fit`` samples, the
    ``baseline``'s terms kept ("tanh": with its width searched; "linear": without); each
    fit's seconds include the shared preparation (v_t's search, the library)."""
    import pysindy as ps
    start = time.perf_counter()
    f, inertia = restoring_force(m, known), inertia_free(m, known)
    vt = baseline_width(m, f, fit, inertia) if baseline == "tanh" else None
    X, labels = library(m, vt if vt is not None else STEP_SHARE * float(np.std(m.w)))
    B = baseline_columns(m, vt, inertia)
    Bf, Xf = B[fit], X[fit]
    scale = np.std(Xf, axis=0)
    scale[scale == 0] = 1.0
    Xr = _residualise(Bf, Xf / scale)
    fr = _residualise(Bf, f[fit, None])
    prepared = time.perf_counter() - start  # the baseline's width, the library
    out = []
    for thr in thresholds:
        clock = time.perf_counter() - prepared
        opt = ps.STLSQ(threshold=thr * float(np.std(fr)), alpha=1e-9)
        opt.fit(Xr, fr)
        coef = np.asarray(opt.coef_).ravel()
        out.append(_sindy_fit(thr, coef, scale, labels, X, B, f, m, known, fit, held,
                              time.perf_counter() - clock))
    return out


def _sindy_fit(thr, coef, scale, labels, X, B, f, m, known, fit, held, seconds) -> SindyFit:
    """Names, forces and the held-out z'' error of one STLSQ coefficient vector."""
    chosen = np.nonzero(coef)[0]
    order = chosen[np.argsort(-np.abs(coef[chosen]))]
    names = list(dict.fromkeys(labels[i][1] for i in order))
    # refit the baseline beside the kept candidates (unpenalised) for the prediction
    full = np.column_stack([B, X[:, chosen] / scale[chosen]]) if chosen.size else B
    beta, *_ = np.linalg.lstsq(full[fit], f[fit], rcond=None)
    if inertia_free(m, known):  # drive = M z'' + rest, z'' the baseline's last column
        mass, i_a = float(beta[B.shape[1] - 1]), B.shape[1] - 1
        rest = full @ beta - full[:, i_a] * beta[i_a]
        a_hat = (driving_force(m, known) - rest) / mass
    else:
        a_hat = (driving_force(m, known) - full @ beta) / float(known["M"])
    err = m.a[held] - a_hat[held]
    forces = {labels[i][0]: float(abs(coef[i])) for i in range(len(labels))}
    return SindyFit(thr, names, forces, float(np.sqrt(np.mean(err**2)) / np.std(m.a[held])),
                    seconds)


@dataclass
class NarxRun:
    """SysIdentPy's free run on the held-out tail: NRMSE of the recorded output (NaN:
    diverged) and terms."""

    heldout_nrmse: float
    diverged: bool
    terms: int
    seconds: float


def narx_free_run(m: Motion, fit: slice, held: slice, lags: int = NARX_LAGS,
                  degree: int = NARX_DEGREE, n_terms: int = NARX_TERMS) -> NarxRun:
    """A polynomial NARX (FROLS) from the recorded input to the recorded output (y'' to z''
    on an acceleration record, y to z or the force to z on the others) fitted on ``fit``,
    simulated free over ``held`` from the first ``lags`` measured outputs there
    (SysIdentPy's ``predict``)."""
    from sysidentpy.basis_function import Polynomial
    from sysidentpy.model_structure_selection import FROLS
    clock = time.perf_counter()
    x, y = m.drive[:, None], m.output[:, None]
    model = FROLS(xlag=lags, ylag=lags, basis_function=Polynomial(degree=degree),
                  n_terms=n_terms, order_selection=False)
    model.fit(X=x[fit], y=y[fit])
    xs, ys = x[held], y[held]
    with np.errstate(all="ignore"):
        yhat = np.asarray(model.predict(X=xs, y=ys[:model.max_lag])).ravel()
        k = model.max_lag
        err = ys.ravel()[k:] - yhat[k:]
        e = float(np.sqrt(np.mean(err**2)) / np.std(ys.ravel()[k:]))
    bad = not np.isfinite(e) or e > DIVERGED_NRMSE
    return NarxRun(float("nan") if bad else e, bad, int(len(model.final_model)),
                   time.perf_counter() - clock)


def score_names(names: Sequence[str], correct: set[str], effect_free: bool) -> str:
    """right | wrong | missed | false_alarm | quiet of a tool's names, most important first
    (the first name decides, as ``grid.scoring.outcome`` scores the diagnosis)."""
    if effect_free:
        return "false_alarm" if names else "quiet"
    if not names:
        return "missed"
    return "right" if names[0] in correct else "wrong"


@dataclass
class Record:
    """One record of a set: its path, the recording, the truth, the known M, m, k and where
    its friction acts (the sidecar's ``friction_on``)."""

    path: Path
    data: pd.DataFrame
    truth: dict[str, Any]
    known: dict[str, float] = field(default_factory=dict)
    friction_on: str | None = None

    @property
    def effect_free(self) -> bool:
        """A record without an effect: its truth's ratio 0 (null: strength not known)."""
        ratio = self.truth.get("ratio", 0.0)
        return ratio is not None and float(ratio) == 0.0

    @property
    def baseline(self) -> str:
        return str(self.truth.get("baseline") or "tanh")

    @property
    def correct(self) -> set[str]:
        return set(self.truth.get("correct_names") or [])


def read_set(directory: str | Path) -> list[Record]:
    """Every ``*.csv`` of ``directory`` with its sidecar and its truth ``<name>.json``
    (DataError naming the file when either is missing or lacks what is needed)."""
    from harvester.data.daq import read_recording
    from harvester.data.sidecar import read_sidecar
    directory = Path(directory)
    csvs = sorted(directory.glob("*.csv"))
    if not csvs:
        raise DataError(directory, "no recording (*.csv) in the folder")
    return [_read_record(csv, read_recording, read_sidecar) for csv in csvs]


def read_truth(path: Path, beside: str) -> dict[str, Any]:
    """A record's truth file (DataError naming it where it is missing or incomplete)."""
    if not path.is_file():
        raise DataError(path, f"no truth file beside {beside}: expected correct_names and "
                        "ratio (as the literature grid writes them)")
    truth = json.loads(path.read_text())
    for key in ("correct_names", "ratio"):
        if key not in truth:
            raise DataError(path, f"no '{key}' (expected the literature grid's truth)")
    return truth


def _read_record(csv: Path, read_recording, read_sidecar) -> Record:
    truth = read_truth(csv.with_suffix(".json"), csv.name)
    side = read_sidecar(csv)
    known = dict(side.known) or dict(truth.get("known") or {})
    data = read_recording(csv)
    need = set() if tuple(data.columns[1:3]) == ("force", "rel_disp") else {"M", "m"}
    if not need <= set(known):
        raise DataError(csv, f"known {sorted(known)}: the restoring force needs M and m "
                        "(sidecar or the truth's 'known')")
    return Record(csv, data, truth, known, side.friction_on)


def split(rec: Record) -> tuple[slice, slice]:
    """The fitted and the held-out samples, as the diagnosis cuts the record."""
    from harvester.diagnosis.prepare.analysis import analysis_window
    t = rec.data["time"].to_numpy()
    fs = 1.0 / float(t[1] - t[0])
    lead_in = float((rec.truth.get("settings") or {}).get("lead_in_s", 1.0))
    lead, hold, end = analysis_window(len(t), fs, lead_in, HOLDOUT)
    return slice(lead, hold), slice(hold, end)


def peer_rows(rec: Record, narx: bool = True) -> list[dict[str, Any]]:
    """pysindy at each threshold and (``narx``) the NARX free run, one row each."""
    fit, held = split(rec)
    clock = time.perf_counter()
    mo = motion(rec.data, str(rec.path), rec.friction_on)
    integrals = time.perf_counter() - clock
    rows = []
    for s in sindy_names(mo, rec.known, fit, held, baseline=rec.baseline):
        rows.append({"tool": f"pysindy STLSQ {s.threshold:g}", "names": s.names,
                     "outcome": score_names(s.names, rec.correct, rec.effect_free),
                     "heldout_nrmse": s.heldout_nrmse, "heldout_kind": "equation error",
                     "seconds": integrals + s.seconds})
    if narx:
        r = narx_free_run(mo, fit, held)
        rows.append({"tool": "SysIdentPy NARX", "names": [],
                     "outcome": "diverged" if r.diverged else "no names",
                     "heldout_nrmse": r.heldout_nrmse, "heldout_kind": "free run",
                     "seconds": r.seconds})
    return rows


def diagnosis_row(rec: Record, run: Callable[[Record], dict[str, Any]]) -> dict[str, Any]:
    """The diagnosis's row: ``run`` gives its diagnosis.json-like dict (with ``runtime_s``),
    scored by ``grid.scoring.score`` and mapped to right / wrong / missed / false alarm
    (a reported tie holding a correct name: "tied")."""
    from harvester.grid.scoring import score
    d = run(rec)
    truth = {"effect": rec.truth.get("effect", rec.path.stem), "seed": 0, **rec.truth}
    truth["ratio"] = float("nan") if truth["ratio"] is None else truth["ratio"]
    s = score(truth, d)
    outcome = {"named": "right", "tied": "tied"}.get(s["outcome"], s["outcome"])
    fit = ((d.get("fit") or {}).get("improved") or {})
    return {"tool": "harvester diagnose", "names": list(d.get("missing") or []),
            "outcome": outcome, "heldout_nrmse": fit.get("nrmse", d.get("unseen_nrmse")),
            "heldout_kind": "free run", "seconds": float(d.get("runtime_s", float("nan")))}


OUTCOMES = ("right", "tied", "wrong", "missed", "false_alarm", "quiet", "diverged")


def summary(rows: pd.DataFrame) -> pd.DataFrame:
    """Per tool: counts of each outcome, records whose names hold a correct one anywhere
    (``right_anywhere``; rows give ``names`` and ``correct`` as space-separated names),
    median held-out NRMSE, seconds per record."""
    out = []
    for tool, g in rows.groupby("tool", sort=False):
        counts = {o: int((g["outcome"] == o).sum()) for o in OUTCOMES}
        anywhere = sum(bool(set(str(n).split()) & set(str(c).split()))
                       for n, c in zip(g["names"].fillna(""), g["correct"].fillna("")))
        out.append({"tool": tool, "records": len(g), **counts, "right_anywhere": anywhere,
                    "heldout_nrmse_median": float(pd.to_numeric(g["heldout_nrmse"],
                                                                errors="coerce").median()),
                    "heldout_kind": g["heldout_kind"].iloc[0],
                    "seconds_per_record": float(g["seconds"].mean())})
    return pd.DataFrame(out)
