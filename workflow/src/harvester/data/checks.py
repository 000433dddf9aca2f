"""Instrument-style checks of a recording: what cannot be right, and what only looks wrong.

A recording that passed the format's checks (``daq.read_recording``: header, numbers, uniform
time) is looked at as an instrument would look at its own channels before anyone trusts
them. What cannot be right raises :class:`~harvester.data.errors.DataError` naming the file,
the line or column, what was found and what was expected; what may be right but looks wrong
is returned as a :class:`CheckWarning` whose text carries the evidence.

========================= ===================================================== ==========
check                     evidence                                              outcome
========================= ===================================================== ==========
absurd magnitude          a value beyond any sensor of the kind (1e5 m/s^2,     error
                          1e8 N, 1e3 m), at its line
clock                     sampling rate below MIN_SAMPLING_HZ (a time column    error
                          in ms); the device's natural frequency sqrt(k/M)
                          beyond what the rate resolves                         warning
dead channel              input or output constant over the whole record        error
flat stretch              a run of equal values of an acceleration or force     warning
                          over FLAT_RUN_S (a dropout)
saturation                runs of equal extreme values (a clipped sensor or     error above
                          ADC): samples, share, level, longest run              SATURATED_
                                                                                SHARE, else
                                                                                warning
spike                     a sample SPIKE_ROBUST_SD robust sd from the median    warning
drift                     a base displacement's straight-line change over the   warning
                          record above DRIFT_SHARE of its RMS oscillation
fast displacement         a displacement whose derivative moves faster than     error with
                          MAX_VELOCITY_RMS (mm read as m)                       M or m given,
                                                                                else warning
unit slip                 the output/input gain above resonance (a force        error: median
                          input driven below it: below) against the bound M,    above
                          m, k allow (m/M for base_acc -> rel_acc): g against   UNIT_RATIO;
                          m/s^2, mm against m, kN or mN against N (friction     warning: 90th
                          lowers the gain, so heavy friction can hide a slip;   percentile
                          a low gain needs M, m known)                          below 1/(2 it)
========================= ===================================================== ==========

Reach of the unit check, measured (``tests/test_input_checks.py``; the ratio is the median
gain over the bound): the rig's tanh device 0.8 (base_acc in g: 7.9; rel_acc in g: 90th
percentile 0.10); a device with 30 N of friction under 8 m/s^2 0.33 (in g: 3.2, caught), under
4 m/s^2 0.20 (in g: 2.0, NOT caught); the bundled records 0.4-0.9 and the detection grid's
scenarios 0.3-1.0 raise nothing. The frame of Marino and Cicirello (``harvester.data.public``,
``tests/test_kinds.py``): as recorded (base_disp -> rel_disp) 1.5-1.6 above resonance; driven
by the force K y (its friction on the ground) only below resonance, 0.80-0.98 there (0.5-1 Hz),
its force in kN 796-979 (refused), in mN 0.00080-0.00098 (a warning). A narrow-band excitation
with fewer than MIN_LINES coherent lines above resonance (and, for a base input, any below it:
friction on the ground, written relative to the base, exceeds the bound there: the frame as
recorded, 0.5-1 Hz, medians 6.3 and 12.6) is not judged: a slow displacement in mm then
passes unless it moves faster than MAX_VELOCITY_RMS read as m (``fast_displacements``; the
frame's displacements in mm move at 6.3-10.3 m/s RMS, caught; the rig's tanh device under
three sines of 0.5 mm at 0.7-2.1 Hz, its rel_disp in mm at 0.86 m/s: NOT caught).

Gravity left in an acceleration and displacements beyond 5 m are
``recording.check_plausible``'s (called from here). Checks that rest on linear theory (the
linear FRF fit's m/M, ``harvester.initial.frf``) ask :func:`nonlinearity` first: on a visibly
nonlinear recording what they find is a warning with that evidence, not an error. The
sidecar (``RECORDING.yaml``) is checked by ``harvester.data.sidecar``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import signal

from harvester.data.errors import DataError
from harvester.data.input_noise import FLOOR_SPREAD, noise_floor
from harvester.data.recording import G, RecordingKinds, check_plausible
from harvester.data.units import SI, Units

#: Largest magnitude a column of each kind can hold (SI units): beyond any sensor's range.
MAX_MAGNITUDE: dict[str, float] = {"base_acc": 1.0e5, "rel_acc": 1.0e5, "force": 1.0e8,
                                   "rel_disp": 1.0e3, "base_disp": 1.0e3, "time": 1.0e9}
#: Columns that hold a displacement (may rest while friction holds the mass or the base).
DISPLACEMENTS = ("rel_disp", "base_disp")
#: Lowest sampling rate (Hz) of a vibration recording the method can use.
MIN_SAMPLING_HZ = 10.0
#: A run of equal values this long (s, and at least FLAT_RUN_SAMPLES) in an acceleration or a
#: force is reported as a dropout.
FLAT_RUN_S = 0.5
FLAT_RUN_SAMPLES = 32
#: Runs of at least this many equal samples at a channel's extreme count as saturated.
SATURATED_RUN = 3
#: Share of saturated samples above which an acceleration or force cannot be fitted.
SATURATED_SHARE = 0.01
#: A sample this many robust sd (1.4826 x MAD) from the median is reported as a spike.
SPIKE_ROBUST_SD = 100.0
#: Measured gain above resonance over the physical bound beyond which a unit slipped.
UNIT_RATIO = 3.0
#: FRF lines used by the unit check: coherence at least this, frequency at least
#: RESONANCE_MARGIN x the natural frequency.
MIN_COHERENCE = 0.5
RESONANCE_MARGIN = 3.0
#: The unit check needs Welch segments of at least MIN_SEGMENT_S (s, four of them) and
#: MIN_LINES such lines.
MIN_SEGMENT_S = 0.5
MIN_LINES = 8
#: Unit factors a ratio is compared with, and what each means.
UNIT_FACTORS: dict[float, str] = {G: "g (9.81)", 1000.0: "1000 (mm against m, kN against N, "
                                                       "ms against s)"}


@dataclass(frozen=True)
class CheckWarning:
    """Something that may be right but looks wrong, with its evidence."""

    source: str
    check: str
    message: str
    column: str | None = None
    line: int | None = None

    def __str__(self) -> str:
        where = self.source
        if self.line is not None:
            where += f", line {self.line}"
        if self.column is not None:
            where += f", column '{self.column}'"
        return f"{where}: {self.message}"


def _line(lines: Sequence[int] | None, i: int) -> int:
    """File line of row i (the header is line 1)."""
    return int(lines[i]) if lines is not None else i + 2


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """(start, length) of each run of True in ``mask``."""
    edges = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    starts, stops = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
    return list(zip(starts.tolist(), (stops - starts).tolist()))


def _equal_runs(x: np.ndarray) -> list[tuple[int, int]]:
    """(start, length) of each run of at least 2 equal consecutive values."""
    same = np.concatenate([[False], x[1:] == x[:-1]])
    return [(s - 1, n + 1) for s, n in _runs(same)]


# --------------------------------------------------------------------------- errors


def check_magnitudes(df: pd.DataFrame, kinds: RecordingKinds, source: str | Path,
                     lines: Sequence[int] | None = None) -> None:
    """DataError at the first value beyond :data:`MAX_MAGNITUDE` of its column's kind."""
    for name in ("time", kinds.input_kind, kinds.output_kind):
        x = df[name].to_numpy(dtype=float)
        bad = np.flatnonzero(np.abs(x) > MAX_MAGNITUDE[name])
        if bad.size:
            i = int(bad[0])
            unit = "s" if name == "time" else kinds.input_unit if name == kinds.input_kind \
                else kinds.output_unit
            raise DataError(source, f"{x[i]:.4g} {unit}: beyond any sensor's range "
                            f"(|{name}| <= {MAX_MAGNITUDE[name]:g} {unit}); a corrupted cell or "
                            f"another unit ({bad.size} such value(s))", line=_line(lines, i),
                            column=name)


def check_sampling_rate(dt: float, source: str | Path, line: int = 3) -> None:
    """DataError if the time step gives a rate below :data:`MIN_SAMPLING_HZ`."""
    fs = 1.0 / dt
    if fs >= MIN_SAMPLING_HZ:
        return
    hint = (f"; a time column in ms instead of s gives this (in s the rate would be "
            f"{1000.0 * fs:.6g} Hz)" if 1000.0 * fs >= MIN_SAMPLING_HZ else "")
    raise DataError(source, f"time step {dt:.6g} s, a sampling rate of {fs:.4g} Hz: below the "
                    f"{MIN_SAMPLING_HZ:g} Hz a vibration recording needs (time must be in s)"
                    f"{hint}", line=line, column="time")


def check_live_channels(df: pd.DataFrame, kinds: RecordingKinds, source: str | Path) -> None:
    """DataError if the input or the output is constant over the whole record (dead)."""
    for name, role in ((kinds.input_kind, "input"), (kinds.output_kind, "output")):
        x = df[name].to_numpy(dtype=float)
        if x.size and np.all(x == x[0]):
            raise DataError(source, f"the {role} is {x[0]:g} in all {x.size} samples: a dead "
                            "or disconnected channel; the device starts at rest, so a "
                            "constant channel leaves nothing to identify", column=name)


# --------------------------------------------------------------------------- warnings


def flat_stretches(df: pd.DataFrame, kinds: RecordingKinds, dt: float, source: str | Path,
                   lines: Sequence[int] | None = None) -> list[CheckWarning]:
    """Runs of equal values over FLAT_RUN_S in an acceleration or force (a displacement may
    rest while friction holds the mass), and constant extra columns."""
    out = []
    need = max(FLAT_RUN_SAMPLES, int(round(FLAT_RUN_S / dt)))
    for name in df.columns:
        if name == "time" or name in DISPLACEMENTS:
            continue
        x = df[name].to_numpy(dtype=float)
        if name not in (kinds.input_kind, kinds.output_kind):
            if x.size and np.all(x == x[0]):
                out.append(CheckWarning(str(source), "flat", f"constant ({x[0]:g}); the column "
                                        "is not used", column=name))
            continue
        long = [(s, n) for s, n in _equal_runs(x) if n >= need]
        if long:
            s, n = max(long, key=lambda r: r[1])
            out.append(CheckWarning(
                str(source), "flat", f"{n} equal values ({x[s]:g}, {n * dt:.3g} s) from line "
                f"{_line(lines, s)}; {len(long)} such stretch(es), "
                f"{sum(r[1] for r in long) / x.size:.1%} of the record: a dropout or a sensor "
                "that stopped", column=name, line=_line(lines, s)))
    return out


def saturation(df: pd.DataFrame, kinds: RecordingKinds, dt: float, source: str | Path,
               lines: Sequence[int] | None = None) -> list[CheckWarning]:
    """Runs of SATURATED_RUN or more equal samples at a channel's largest or smallest value.

    DataError when more than SATURATED_SHARE of an acceleration's or a force's samples are
    saturated (the model cannot reproduce a clipped signal); a warning otherwise (and for a
    displacement, which may rest at a turning point while friction holds it).
    """
    out = []
    for name in (kinds.input_kind, kinds.output_kind):
        x = df[name].to_numpy(dtype=float)
        runs = [(s, n) for level in (x.max(), x.min())
                for s, n in _runs(x == level) if n >= SATURATED_RUN]
        if not runs:
            continue
        count = sum(n for _, n in runs)
        first, longest = min(r[0] for r in runs), max(r[1] for r in runs)
        levels = sorted({float(x[s]) for s, _ in runs})
        what = (f"{count} samples ({count / x.size:.1%}) sit at the extreme value(s) "
                f"{', '.join(f'{v:g}' for v in levels)} in runs of up to {longest} samples "
                f"({longest * dt:.3g} s), first at line {_line(lines, first)}: a clipped "
                "sensor or an ADC at the end of its range")
        if name not in DISPLACEMENTS and count / x.size > SATURATED_SHARE:
            raise DataError(source, f"saturated: {what}; at most {SATURATED_SHARE:.0%} can be "
                            "tolerated: record again with a larger range", column=name)
        out.append(CheckWarning(str(source), "saturation", what, column=name,
                                line=_line(lines, first)))
    return out


def spikes(df: pd.DataFrame, kinds: RecordingKinds, source: str | Path,
           lines: Sequence[int] | None = None) -> list[CheckWarning]:
    """Samples more than SPIKE_ROBUST_SD robust sd from the channel's median."""
    out = []
    for name in (kinds.input_kind, kinds.output_kind):
        x = df[name].to_numpy(dtype=float)
        med = np.median(x)
        sd = 1.4826 * np.median(np.abs(x - med))
        if not sd > 0:
            continue
        far = np.flatnonzero(np.abs(x - med) > SPIKE_ROBUST_SD * sd)
        if far.size:
            i = int(far[np.argmax(np.abs(x[far] - med))])
            out.append(CheckWarning(
                str(source), "spike", f"{far.size} sample(s) more than {SPIKE_ROBUST_SD:g} "
                f"robust sd from the median ({med:.4g}, sd {sd:.4g}); the largest is "
                f"{x[i]:.4g} ({abs(x[i] - med) / sd:.0f} sd): a glitch or a corrupted cell",
                column=name, line=_line(lines, i)))
    return out


# --------------------------------------------------------------------------- physics


def _factor_named(ratio: float) -> str:
    """The unit factor a gain ratio is close to (within 2x), or ''."""
    r = max(ratio, 1.0 / ratio)
    for factor, what in UNIT_FACTORS.items():
        if factor / 2.0 < r < factor * 2.0:
            return f", close to a factor {what}"
    return ""


def _winsorised(x: np.ndarray) -> np.ndarray:
    """x with samples beyond SPIKE_ROBUST_SD robust sd of the median pulled to that bound
    (so that one glitch does not decide a spectrum)."""
    med = np.median(x)
    sd = 1.4826 * np.median(np.abs(x - med))
    return np.clip(x, med - SPIKE_ROBUST_SD * sd, med + SPIKE_ROBUST_SD * sd) if sd > 0 else x


def _frf(df: pd.DataFrame, kinds: RecordingKinds, dt: float) -> tuple[np.ndarray, ...] | None:
    """(f in Hz, coherence, |H| in accelerations, input power S_uu) of a recording (Welch,
    2 s segments, at least four and at least MIN_SEGMENT_S long), or None for too short a
    record. |H| is times w^2 for a displacement output and over w^2 for a displacement input
    (the kinds' ``order``, ``harvester.data.kinds``)."""
    from harvester.data.kinds import input_kind, output_kind
    inp, out = input_kind(kinds.input_kind), output_kind(kinds.output_kind)
    u, y = (_winsorised(df[c].to_numpy(float)) for c in (kinds.input_kind, kinds.output_kind))
    fs = 1.0 / dt
    nper = int(min(round(2.0 * fs), u.size // 4))
    if nper < MIN_SEGMENT_S * fs:
        return None
    kw = {"fs": fs, "nperseg": nper, "noverlap": nper // 2, "detrend": "linear"}
    f, s_uu = signal.welch(u, **kw)
    _, s_yy = signal.welch(y, **kw)
    _, s_uy = signal.csd(u, y, **kw)
    with np.errstate(divide="ignore", invalid="ignore"):
        coh = np.abs(s_uy) ** 2 / (s_uu * s_yy)
        w = 2 * np.pi * f
        gain = np.abs(s_uy) / s_uu * w ** (2 - out.order) / (
            1.0 if inp.force_input else w ** (2 - inp.order))
    return f, coh, gain, s_uu


#: The gain a base input's own sensor noise gives a relative output formed as a difference
#: with it (x - y from two lasers, x'' - y'' from two accelerometers): that noise is in both
#: channels, coherent, with gain 1 (with two equal sensors at coherence 0.5, the check's
#: threshold). It is allowed on lines where the input lies on its white noise floor
#: (``input_noise.noise_floor``, within its FLOOR_SPREAD; none where the input shows no
#: floor). On effect-free devices of the literature grid with two accelerometers: seed 5
#: (excitation up to 9 Hz, f_n 1.8 Hz, m/M 0.31) had 59 of its 66 coherent lines above
#: resonance on the base's noise and a median gain 3.4 x the device's bound; seed 36
#: (excitation 0.8-6.1 Hz at 1.04 m/s^2 peak, f_n 2.3 Hz, m/M 0.35) a median gain 1.075,
#: 3.1 x the bound, with the noise at 1.4e-3 of the strongest line. Both were refused as
#: unit slips, seed 36 still under the former rule (lines below 1e-3 of that line).
SHARED_NOISE_GAIN = 1.0


def _judged(f: np.ndarray, gain: np.ndarray, ok: np.ndarray, scale: float,
            f_n: float | None, side: str, noise_lines: np.ndarray | None = None) -> dict:
    """Median and 90th percentile of the gain over the lines ``ok`` against the bound
    scale w^2 / |w^2 - w_n^2| (scale alone without f_n); and the median against the most the
    device and its sensors give (``ratio_ceiling``): on ``noise_lines`` max(bound,
    SHARED_NOISE_GAIN), a gain the sensors' shared noise can raise, never lower."""
    w2 = (2 * np.pi * f[ok]) ** 2
    bound = scale * w2 / (np.abs(w2 - (2 * np.pi * f_n) ** 2) if f_n else w2)
    ratio = gain[ok] / bound
    ceiling = bound if noise_lines is None else np.where(
        noise_lines[ok], np.maximum(bound, SHARED_NOISE_GAIN), bound)
    return {"lines": int(ok.sum()), "band_hz": (float(f[ok][0]), float(f[ok][-1])),
            "gain": float(np.median(gain[ok])), "ratio": float(np.median(ratio)),
            "ratio_ceiling": float(np.median(gain[ok] / ceiling)),
            "ratio_p90": float(np.quantile(ratio, 0.9)), "scale": float(scale),
            "known": bool(f_n), "side": side}


def gain_above_resonance(df: pd.DataFrame, kinds: RecordingKinds, dt: float,
                         known: Mapping[str, float],
                         lowpass_hz: float | None = None) -> dict | None:
    """|output / input| away from resonance against what a passive device allows there.

    Measured (:func:`_frf`): the median over FRF lines (at least MIN_LINES) with coherence
    >= MIN_COHERENCE above RESONANCE_MARGIN x the natural frequency f_n = sqrt(k/M) / 2 pi
    (without M and k: the upper half of the coherent lines), below 0.4 x the rate and 0.8 x
    ``lowpass_hz`` (a low-pass of the output alone lowers the gain above it), and its 90th
    percentile over the lines. Bound: eq. (1) with any damping or friction, |z''/y''| <=
    (m/M) w^2 / (w^2 - w_n^2) for a base input (m/M <= 1 when not known: M = m + J (2 pi /
    l)^2), |z''/F| <= (1/M) w^2 / |w^2 - w_n^2| for a force input (None without M). A force
    input with fewer lines above resonance is judged below it (:func:`_below_resonance`).
    ``side`` says which. Returns None when nothing can be judged.
    """
    force = kinds.input_kind == "force"
    M, m, k = (known.get(p) for p in ("M", "m", "k"))
    if force and M is None:
        return None
    frf = _frf(df, kinds, dt)
    if frf is None:
        return None  # too short a record for a spectrum
    f, coh, gain, s_uu = frf
    scale = 1.0 / M if force else (m / M if M and m else 1.0)
    top = min(0.4 / dt, 0.8 * lowpass_hz) if lowpass_hz else 0.4 / dt
    coherent = (f > 0) & (f < top) & (coh >= MIN_COHERENCE)
    f_n = np.sqrt(k / M) / (2 * np.pi) if M and k else None
    ok = coherent & (f > RESONANCE_MARGIN * f_n) if f_n else (
        coherent & (f > np.median(f[coherent])) if coherent.any() else coherent)
    if ok.sum() >= MIN_LINES:
        quiet = _on_input_floor(df[kinds.input_kind].to_numpy(float), f, s_uu, 1.0 / dt, top)
        return _judged(f, gain, ok, scale, f_n, "above", None if force else quiet)
    if force and f_n:
        below = _below_resonance(f, coherent, s_uu, top, f_n)
        if below is not None:
            return _judged(f, gain, below, scale, f_n, "below")
    return {"lines": int(ok.sum()), "coherence": float(np.nanmax(coh[f > 0]))}


def _on_input_floor(u: np.ndarray, f: np.ndarray, s_uu: np.ndarray, fs: float,
                    top: float) -> np.ndarray:
    """The lines whose input PSD ``s_uu`` lies on the input's white noise floor below
    ``top`` Hz (``input_noise.noise_floor``), none where it shows no floor."""
    floor = noise_floor(u, fs, top)
    if floor is None:
        return np.zeros(f.shape, dtype=bool)
    return s_uu <= FLOOR_SPREAD * floor.level


#: Below resonance (force inputs): lines below f_n / RESONANCE_MARGIN, at least
#: MIN_LINES_BELOW of them, holding at least MIN_POWER_BELOW of the input's power in the band.
MIN_LINES_BELOW = 2
MIN_POWER_BELOW = 0.5


def _below_resonance(f: np.ndarray, coherent: np.ndarray, s_uu: np.ndarray, top: float,
                     f_n: float) -> np.ndarray | None:
    """The coherent lines below f_n / RESONANCE_MARGIN when they carry the excitation (a
    force below resonance, as a frame driven through its spring, K y: there |z / F| <=
    1 / |k - M w^2| whatever the damping, and friction, stiffening a stuck mass, lowers it),
    else None."""
    ok = coherent & (f < f_n / RESONANCE_MARGIN)
    band = (f > 0) & (f < top)
    power = float(np.sum(s_uu[ok]) / max(float(np.sum(s_uu[band])), 1e-300))
    return ok if ok.sum() >= MIN_LINES_BELOW and power >= MIN_POWER_BELOW else None


#: The unit slips that make the gain too high (an input too small, an output too large) and
#: too low, for each kind.
_SLIP_HIGH = {"base_acc": "base_acc in g", "force": "force in kN", "base_disp": None,
              "rel_acc": "rel_acc in mm/s^2", "rel_disp": "rel_disp in mm"}
_SLIP_LOW = {"base_acc": "base_acc in mm/s^2", "force": "force in mN",
             "base_disp": "base_disp in mm", "rel_acc": "rel_acc in g", "rel_disp": None}


def _slips(kinds: RecordingKinds, table: Mapping[str, str | None]) -> str:
    """The slips of ``table`` this recording's input and output can have, e.g. 'force in kN
    or rel_disp in mm'."""
    found = [table[k] for k in (kinds.input_kind, kinds.output_kind) if table[k]]
    return " or ".join(found)


def check_units_by_physics(df: pd.DataFrame, kinds: RecordingKinds, dt: float,
                           known: Mapping[str, float], source: str | Path,
                           known_from: str = "the sidecar",
                           lowpass_hz: float | None = None) -> list[CheckWarning]:
    """DataError when the gain away from resonance (:func:`gain_above_resonance`, its median
    over the lines) exceeds by UNIT_RATIO what a passive device allows and what a base
    sensor's noise gives an output formed as a difference with it (SHARED_NOISE_GAIN): a
    unit slipped, or the sidecar's M, m are wrong; a warning when it exceeds the device's
    bound alone by that much, or when, with M (and m) known, even its 90th percentile
    is below 1 / (2 UNIT_RATIO) of it (friction lowers the gain most at low frequencies), or
    when input and output do not cohere."""
    g = gain_above_resonance(df, kinds, dt, known, lowpass_hz)
    if g is None:
        return []
    pair = f"|{kinds.output_kind} / {kinds.input_kind}|"
    if "ratio" not in g:
        if g["coherence"] >= MIN_COHERENCE:
            return []  # no line above resonance: the clock check speaks
        return [CheckWarning(str(source), "unit", f"{kinds.output_kind} hardly follows "
                             f"{kinds.input_kind} (largest coherence {g['coherence']:.2f}): "
                             "friction holding the device, or unrelated or swapped channels")]
    force = kinds.input_kind == "force"
    name = "1/M" if force else "m/M"
    what = (f"{name} = {g['scale']:.4g}, from {known_from}" if "M" in known else
            f"{name} <= 1: M, m not known") + (", times w^2 / |w^2 - w_n^2|" if g["known"]
                                                 else "")
    evidence = (f"{g['side']} resonance ({g['band_hz'][0]:.3g}-{g['band_hz'][1]:.3g} Hz, "
                f"{g['lines']} FRF lines with coherence >= {MIN_COHERENCE}) the median {pair} "
                f"is {g['gain']:.4g}, {g['ratio']:.3g} times the most a passive device allows "
                f"there ({what})")
    if g["ratio_ceiling"] > UNIT_RATIO:
        shared = ("" if g["ratio_ceiling"] == g["ratio"] else
                  f"; {g['ratio_ceiling']:.3g} times it with the base sensor's noise allowed "
                  f"its gain {SHARED_NOISE_GAIN:g} where the input lies on its noise floor")
        factor = _factor_named(g["ratio"]) or _factor_named(g["ratio_ceiling"])
        raise DataError(source, f"{evidence}{shared}{factor}: "
                        f"a unit slipped "
                        f"({kinds.input_kind} must be in {kinds.input_unit}, "
                        f"{kinds.output_kind} in {kinds.output_unit}; e.g. "
                        f"{_slips(kinds, _SLIP_HIGH)}), or the M, m in {known_from} are wrong")
    if g["ratio"] > UNIT_RATIO:
        return [CheckWarning(str(source), "unit", f"{evidence}, but within {UNIT_RATIO:g} x "
                             f"the gain {SHARED_NOISE_GAIN:g} that the base sensor's own noise "
                             f"has in a {kinds.output_kind} formed as a difference with it "
                             "(lines where the input lies on its white noise floor, beyond "
                             "the excitation's band): if the excitation covers these lines, "
                             f"the M, m in {known_from} are wrong or a unit slipped "
                             f"({_slips(kinds, _SLIP_HIGH)})")]
    scale_known = "M" in known and ("m" in known or force)
    if scale_known and g["ratio_p90"] < 1.0 / (2.0 * UNIT_RATIO):
        return [CheckWarning(str(source), "unit", f"{evidence}; even its 90th percentile is "
                             f"{g['ratio_p90']:.3g} times it{_factor_named(g['ratio_p90'])}: "
                             "friction holding the mass, an output low-passed below these "
                             "frequencies (give filtered_at_hz), or a unit slip "
                             f"({_slips(kinds, _SLIP_LOW)})")]
    return []


def check_clock_against_device(dt: float, known: Mapping[str, float], source: str | Path,
                               known_from: str = "the sidecar") -> list[CheckWarning]:
    """A warning when the device's natural frequency sqrt(k/M) / 2 pi is above a quarter of
    the sampling rate (a clock off by 1000, or k and M wrong)."""
    M, k = known.get("M"), known.get("k")
    if not (M and k):
        return []
    f_n, fs = np.sqrt(k / M) / (2 * np.pi), 1.0 / dt
    if f_n <= 0.25 * fs:
        return []
    return [CheckWarning(str(source), "clock", f"the device's natural frequency sqrt(k/M) / "
                         f"2 pi = {f_n:.3g} Hz (k, M from {known_from}) is above a quarter of "
                         f"the {fs:.4g} Hz sampling rate: the clock does not match the device "
                         "(time in ms instead of s?)", column="time")]


#: Share of the output's in-band power coherent with the input below which a recording is
#: visibly nonlinear (or noisy) for the checks that rest on linear theory.
MIN_COHERENT_SHARE = 0.5
#: Weighted RMS log-FRF misfit (nepers) of the best linear eq. (1) above which the response is
#: not a linear device's. Measured: 0.04-0.06 on a sprung mass with 4 N of Coulomb friction
#: under 3 m/s^2 (also with a column in g), 0.2-0.43 with 20-40 N; 1.6-1.7 on the frame of
#: Marino and Cicirello (tests/test_kinds.py).
MAX_FRF_MISFIT = 0.5
#: Output level against input level over the record's quarters: a slope of log RMS off 1 by
#: more than this is an amplitude-dependent response, when the input's level varies by at
#: least AMPLITUDE_RANGE between quarters.
AMPLITUDE_SLOPE_TOL = 0.25
AMPLITUDE_RANGE = 1.5


@dataclass(frozen=True)
class Nonlinearity:
    """How far a recording departs from a linear, noise-free input-output relation.

    ``coherent_share``: the share of the output's power (0 Hz to 0.4 x the rate) that is
    coherent with the input, sum gamma^2 S_yy / sum S_yy (Welch, 2 s segments): 1 for a
    linear device without noise; friction's harmonics and sticking, or noise, lower it.
    ``slope``: d log RMS(output) / d log RMS(input) over the record's quarters (1 for a
    linear device), None when the input's level does not vary by AMPLITUDE_RANGE.
    ``frf_misfit``: the weighted RMS log misfit (nepers) of the best linear eq. (1) to the
    measured FRF, where one was fitted (``harvester.initial.frf``); a narrow-band excitation
    of a friction device leaves the first two near their linear values and shows here.
    """

    coherent_share: float
    slope: float | None
    input_range: float
    frf_misfit: float | None = None

    @property
    def visible(self) -> bool:
        return self.coherent_share < MIN_COHERENT_SHARE or (
            self.slope is not None and abs(self.slope - 1.0) > AMPLITUDE_SLOPE_TOL) or (
            self.frf_misfit is not None and self.frf_misfit > MAX_FRF_MISFIT)

    def evidence(self) -> str:
        amp = (f"the output's level grows as the input's to the power {self.slope:.2f} over "
               f"the record's quarters (1 if linear)" if self.slope is not None else
               f"the input's level varies by {self.input_range:.2f}x over the record's "
               "quarters (too little to see an amplitude dependence)")
        fit = ("" if self.frf_misfit is None else
               f"; the best linear model misses the measured FRF by {self.frf_misfit:.2f} "
               f"nepers RMS (a factor {np.exp(self.frf_misfit):.2g}; a linear device: below "
               f"{MAX_FRF_MISFIT:g})")
        return (f"{self.coherent_share:.0%} of the output's power is coherent with the input "
                f"(a linear device without noise: 100 %); {amp}{fit}")


def nonlinearity(u: np.ndarray, y: np.ndarray, fs: float,
                 top_hz: float | None = None) -> Nonlinearity:
    """:class:`Nonlinearity` of input ``u`` and output ``y`` sampled at ``fs`` Hz (the band
    ends at ``top_hz``, default 0.4 x the rate)."""
    u, y = _winsorised(np.asarray(u, float)), _winsorised(np.asarray(y, float))
    nper = int(max(16, min(round(2.0 * fs), u.size // 4)))
    kw = {"fs": fs, "nperseg": nper, "noverlap": nper // 2, "detrend": "linear"}
    f, s_uu = signal.welch(u, **kw)
    _, s_yy = signal.welch(y, **kw)
    _, s_uy = signal.csd(u, y, **kw)
    band = (f > 0) & (f <= (top_hz or 0.4 * fs))
    with np.errstate(divide="ignore", invalid="ignore"):
        coh = np.where(s_uu * s_yy > 0, np.abs(s_uy) ** 2 / (s_uu * s_yy), 0.0)
    total = float(np.sum(s_yy[band]))
    share = float(np.sum(np.clip(coh[band], 0, 1) * s_yy[band]) / total) if total > 0 else 0.0
    quarters = np.array_split(np.arange(u.size), 4)
    ru = np.array([np.std(signal.detrend(u[q])) for q in quarters])
    ry = np.array([np.std(signal.detrend(y[q])) for q in quarters])
    ok = (ru > 0) & (ry > 0)
    spread = float(ru[ok].max() / ru[ok].min()) if ok.sum() >= 2 else 1.0
    slope = float(np.polyfit(np.log(ru[ok]), np.log(ry[ok]), 1)[0]) \
        if spread >= AMPLITUDE_RANGE and ok.sum() >= 3 else None
    return Nonlinearity(share, slope, spread)


#: Largest RMS velocity (m/s) of a rig's displacement (its band-limited derivative): beyond
#: it the column is probably in mm (3 mm at 1 Hz read as m moves at 13 m/s RMS).
MAX_VELOCITY_RMS = 5.0


def fast_displacements(df: pd.DataFrame, kinds: RecordingKinds, dt: float,
                       source: str | Path, known: Mapping[str, float] | None = None,
                       known_from: str = "the sidecar", units: Units = SI
                       ) -> list[CheckWarning]:
    """A displacement column (rel_disp, base_disp) whose derivative
    (``harvester.data.kinds.derivative``, band-limited at the DAQ's edge) moves faster than
    MAX_VELOCITY_RMS: mm read as m. DataError for a mechanical device (its mass M or m known
    in kg, ``known``), which no rig moves that fast; a warning otherwise: a device known only
    through its recordings may be in other units (a circuit whose 'displacement' is a
    voltage). Nothing where the sidecar gives the displacement another unit (``units``)."""
    from harvester.data.kinds import derivative
    if units.displacement != "m":
        return []
    mechanical = bool({"M", "m"} & set(known or {}))
    out = []
    for name in (kinds.input_kind, kinds.output_kind):
        if name not in DISPLACEMENTS or len(df) < 8:
            continue
        v = derivative(df[name].to_numpy(dtype=float), dt, 1, None)
        rms = float(np.std(v))
        if rms > MAX_VELOCITY_RMS and mechanical:
            raise DataError(source, f"{name} moves at {rms:.3g} m/s RMS (its derivative), "
                            f"faster than the {MAX_VELOCITY_RMS:g} m/s a shaker or rig reaches "
                            f"(a device of {known_from}'s masses in kg): probably mm (in m it "
                            f"would move at {rms / 1000:.3g} m/s); {name} must be in m",
                            column=name)
        if rms > MAX_VELOCITY_RMS:
            out.append(CheckWarning(str(source), "unit", f"{name} moves at {rms:.3g} m/s RMS "
                                    f"(its derivative), faster than the {MAX_VELOCITY_RMS:g} "
                                    "m/s a shaker or rig reaches: in mm? (in m it would move "
                                    f"at {rms / 1000:.3g} m/s); {name} must be in m, unless "
                                    "the device is not mechanical (a circuit in volts)",
                                    column=name))
    return out


def drifting_base(df: pd.DataFrame, kinds: RecordingKinds, dt: float,
                  source: str | Path) -> list[CheckWarning]:
    """A warning when a base displacement drifts (``harvester.data.kinds.drift``): its
    straight-line change over the record is more than DRIFT_SHARE of its RMS oscillation.
    A straight line has no acceleration, so the model's base acceleration is unchanged; a
    curved drift (a sensor warming up) adds a slow acceleration below the analysed band."""
    from harvester.data.kinds import DRIFT_SHARE, drift
    if kinds.input_kind != "base_disp":
        return []
    d = drift(df["base_disp"].to_numpy(dtype=float), dt)
    if not d.drifting:
        return []
    return [CheckWarning(str(source), "drift", f"the base displacement drifts by "
                         f"{d.drift:.4g} m over {d.seconds:.3g} s (straight-line fit; mean "
                         f"{d.start:.4g} m over the first tenth, {d.end:.4g} m over the last), "
                         f"{d.share:.2g} times its RMS oscillation about that line "
                         f"({d.oscillation:.4g} m; more than {DRIFT_SHARE:g} is reported): a "
                         "drifting sensor (a laser or LVDT warming up, a mount that slipped) "
                         "or a base that moved; a straight drift leaves base_acc unchanged, a "
                         "curved one adds a slow acceleration", column="base_disp")]


# --------------------------------------------------------------------------- entry points


def check_recording(df: pd.DataFrame, kinds: RecordingKinds, dt: float, source: str | Path,
                    known: Mapping[str, float] | None = None,
                    lines: Sequence[int] | None = None,
                    known_from: str = "the sidecar",
                    lowpass_hz: float | None = None, units: Units = SI
                    ) -> list[CheckWarning]:
    """Every check of a recording whose format is valid; returns the warnings.

    ``dt``: its time step (s); ``known``: the device's M, m, k where known (the sidecar's,
    named by ``known_from``), for the physics checks; ``lines``: file line of each row;
    ``lowpass_hz``: a low-pass the output went through (the sidecar's filtered_at_hz);
    ``units``: the sidecar's (a displacement in volts is not judged as metres).
    Raises DataError for what cannot be right, in this order: absurd magnitudes, sampling
    rate, gravity left in or mm (``recording.check_plausible``), dead channels, saturation,
    a unit slip against the physics.
    """
    known = dict(known or {})
    check_magnitudes(df, kinds, source, lines)
    check_sampling_rate(dt, source, _line(lines, 1))
    check_plausible(df, kinds, source)
    check_live_channels(df, kinds, source)
    found = saturation(df, kinds, dt, source, lines)
    found += flat_stretches(df, kinds, dt, source, lines)
    found += spikes(df, kinds, source, lines)
    found += drifting_base(df, kinds, dt, source)
    found += fast_displacements(df, kinds, dt, source, known, known_from, units)
    found += check_clock_against_device(dt, known, source, known_from)
    found += check_units_by_physics(df, kinds, dt, known, source, known_from, lowpass_hz)
    return found


def check_frame(df: pd.DataFrame, source: str | Path, columns: Sequence[str]) -> float:
    """A recording held in memory: a table with ``columns``, finite numbers, a uniform time
    base; returns the time step (s). DataError naming the column and row (1 = header)."""
    from harvester.data.signals import uniform_step
    if not isinstance(df, pd.DataFrame):
        raise DataError(source, "expected a table with columns " + ", ".join(columns))
    for c in columns:
        if c not in df.columns:
            raise DataError(source, f"missing column (need {', '.join(columns)})", column=c)
    for c in columns:
        x = pd.to_numeric(df[c], errors="coerce").to_numpy(dtype=float)
        bad = np.flatnonzero(~np.isfinite(x))
        if bad.size:
            raise DataError(source, f"not a finite number at row {int(bad[0]) + 1}", column=c)
    return uniform_step(df["time"].to_numpy(dtype=float), source)


def check_duration(df: pd.DataFrame, dt: float, source: str | Path, lead_in_s: float,
                   analysed_s: float, holdout_fraction: float) -> None:
    """DataError unless the record holds the lead-in, ``analysed_s`` analysed seconds plus
    the held-out share, and 0.5 s of filter end effects."""
    t = df["time"].to_numpy(dtype=float)
    need = lead_in_s + analysed_s / (1.0 - holdout_fraction) + 0.5
    if t[-1] - t[0] + dt < need - 1e-9:
        held = f", {holdout_fraction:.0%} held out" if holdout_fraction > 0 else ""
        raise DataError(source, f"too short: {t[-1] - t[0] + dt:.2f} s; the diagnosis needs at "
                        f"least {need:.2f} s ({lead_in_s:g} s lead-in, {analysed_s:g} s "
                        f"analysed{held}, 0.5 s of filter end effects)")
