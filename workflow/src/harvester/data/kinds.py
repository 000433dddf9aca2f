"""What a kind of recording means to the model and to the diagnosis: one object per kind.

A recording declares by its columns what drives the device and what was measured
(``harvester.data.recording``). Everything that depends on that choice lives here, in one
:class:`InputKind` or :class:`OutputKind` per column name, so that detection, location,
signatures and priors ask the kind instead of branching on its name:

========== ====== ================== ========================================================
kind       unit   the model sees     what the kind supplies
========== ====== ================== ========================================================
base_acc   m/s^2  base_acc           drive gain m (eq. 1 driven by -m y''), power balance
base_disp  m      base_acc = y''     y'' by a band-limited second derivative
                                     (:func:`derivative`), a drift check (:func:`drift`)
force      N      force              drive gain -1 (eq. 1 driven by F), force_input
rel_acc    m/s^2  rel_acc            simulated z'', standstill where |z''| stays small
rel_disp   m      rel_disp           simulated z, standstill where |z'| stays small
========== ====== ================== ========================================================

Input kinds the model cannot take as they are (``base_disp``) are converted to one it can
by :func:`model_recording`; the recording passed in is never changed (a converted copy is
returned, the conversion stated in its notes). :func:`paper_case` reads any recording as the
paper's base_acc -> rel_acc case for the methods written for it (the FRF damping fit of the
priors); :func:`on_ground` rewrites a base-driven recording of a device whose friction acts
on the mass's own velocity (the sidecar's ``friction_on: ground``) in absolute coordinates,
and takes a force-driven one as it is (its base is the ground).

A displacement is differentiated in the frequency domain: the line joining its end points is
removed (a straight line has no acceleration), the record is extended by its odd reflection at
both ends (value and slope continuous, so the edges add no step), and multiplied by
(i 2 pi f)^order times the squared gain of a Butterworth low-pass at the recording's own
low-pass (a zero-phase filter, as ``signals.lowpass``), so that what the differentiation
amplifies above it, sensor noise, is removed as the recording's filter removed it from the
other channel. Without a known low-pass the cut-off is the measurement chain's
(``signals.chain_cutoff``: the DAQ's anti-alias edge). Measured on two sines (1.1 and 4.7 Hz,
250 Hz, 20 Hz cut-off; ``tests/test_kinds.py``): exact to 1e-8 of the RMS inside the record;
the reflection sets the acceleration to 0 at the first and last sample (an error of half the
RMS there), below 2 % from 0.08 s and 1e-3 from 0.25 s of the ends, inside the diagnosis's
lead-in and its last 0.5 s.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray
from scipy import signal

from harvester.data.signals import butterworth_sos, chain_cutoff

#: Order of the Butterworth low-pass a displacement's derivative goes through.
DERIVATIVE_FILTER_ORDER = 8
#: A base displacement whose straight-line drift over the record exceeds this share of its
#: RMS oscillation about that line is reported as drifting.
DRIFT_SHARE = 0.5


# --------------------------------------------------------------------------- signal steps


def derivative(x: ArrayLike, dt: float, order: int, cutoff_hz: float | None,
               filter_order: int = DERIVATIVE_FILTER_ORDER,
               low_hz: float = 0.1) -> NDArray[np.float64]:
    """The ``order``-th time derivative of ``x`` (sampled every ``dt`` s), band-limited at
    ``cutoff_hz`` (None: the measurement chain's cut-off) by the squared gain of an order
    ``filter_order`` Butterworth low-pass, zero phase (module docstring). A negative order
    integrates, over frequencies from ``low_hz`` up (a record's integral has no mean)."""
    x = np.asarray(x, dtype=float)
    n = x.size
    fs = 1.0 / dt
    cutoff = chain_cutoff(fs, cutoff_hz)
    pad = min(n - 1, max(32, int(round(8.0 * fs / cutoff))))
    if order >= 0:  # the end-to-end line removed, odd reflections: no step at the edges
        r = x - (x[0] + (x[-1] - x[0]) * np.arange(n) / max(n - 1, 1))
        ext = np.concatenate([-r[pad:0:-1], r, -r[-2:-pad - 2:-1]])
    else:  # an integral: about the mean, even reflections (no step in what is integrated)
        r = x - np.mean(x)
        ext = np.concatenate([r[pad:0:-1], r, r[-2:-pad - 2:-1]])
    f = np.fft.rfftfreq(ext.size, dt)
    sos = butterworth_sos(fs, cutoff, filter_order)
    gain = np.abs(signal.sosfreqz(sos, worN=f, fs=fs)[1]) ** 2
    with np.errstate(divide="ignore", invalid="ignore"):
        factor = np.where(f >= low_hz, (2j * np.pi * np.maximum(f, 1e-300)) ** order, 0.0) \
            if order < 0 else (2j * np.pi * f) ** order
    spectrum = np.fft.rfft(ext) * factor * gain
    out = np.fft.irfft(spectrum, n=ext.size)[pad:pad + n]
    if order == 1:
        out += (x[-1] - x[0]) / (dt * max(n - 1, 1))  # the removed line's slope
    return out


@dataclass(frozen=True)
class Drift:
    """A displacement's straight-line drift over the record against its oscillation."""

    drift: float        # change of the fitted line over the record (m)
    oscillation: float  # RMS about the line (m)
    seconds: float
    start: float        # mean of the first and of the last tenth of the record (m)
    end: float

    @property
    def share(self) -> float:
        return abs(self.drift) / self.oscillation if self.oscillation > 0 else float("inf")

    @property
    def drifting(self) -> bool:
        return self.share > DRIFT_SHARE


def drift(x: ArrayLike, dt: float) -> Drift:
    """Straight-line fit of a displacement over the record (least squares) and the RMS of
    what is left about it; a shaker's base returns to where it oscillates, a laser or LVDT
    that warms up or a mount that slips does not."""
    x = np.asarray(x, dtype=float)
    t = np.arange(x.size) * dt
    slope, icpt = np.polyfit(t, x, 1)
    rest = x - (slope * t + icpt)
    tenth = max(1, x.size // 10)
    return Drift(float(slope * (t[-1] - t[0])), float(np.sqrt(np.mean(rest**2))),
                 float(t[-1] - t[0]), float(np.mean(x[:tenth])), float(np.mean(x[-tenth:])))


# --------------------------------------------------------------------------- kinds


@dataclass(frozen=True)
class InputKind:
    """An input column: what drives eq. (1).

    ``order``: time derivatives of a displacement it holds (2: an acceleration, 0: a
    displacement; None: a force); ``model``: the kind the simulator is driven by
    (:func:`model_recording` converts to it); ``force_input``: the base is fixed and the
    input is a force on the mass (``simulate``'s ``force_input``); ``symbol`` names it in
    formulas, ``region_name`` and ``region`` (a format string of ``hi``, the quantile) the
    diagnosis's state region where the model's input is large.
    """

    name: str
    unit: str
    meaning: str
    order: int | None
    model: str
    force_input: bool
    symbol: str
    region_name: str
    region: str

    def drive_gain(self, known: Mapping[str, float]) -> float:
        """g with eq. (1) driven by -g u: the oscillating mass m (kg) for a base acceleration,
        -1 for a force on the mass (0 when m is not known)."""
        return -1.0 if self.force_input else float(known.get("m", 0.0))

    def dissipative_force(self, u: ArrayLike, rel_vel: ArrayLike,
                          known: Mapping[str, float]) -> float | None:
        """The damping the motion shows, as a force (N): c_eq sigma_v with c_eq = <F_d z'> /
        <z'^2>. Eq. (1) times z', averaged: the power dissipated equals the power the drive
        puts in, <F_d z'> = -g <u z'> (:meth:`drive_gain`), whatever the split between
        viscous damping and friction. ``u``: the model's input (this kind's :attr:`model`).
        None when the estimate is not positive (m unknown or 0, or no motion)."""
        v = np.asarray(rel_vel, dtype=float)
        power = -self.drive_gain(known) * float(np.mean(np.asarray(u, dtype=float) * v))
        sigma_v = float(np.sqrt(np.mean(v**2)))
        if not (power > 0.0 and sigma_v > 0.0 and np.isfinite(power)):
            return None
        return power / sigma_v

    def to_model(self, x: ArrayLike, dt: float, lowpass_hz: float | None) -> NDArray:
        """The column in the kind the model is driven by (:attr:`model`)."""
        x = np.asarray(x, dtype=float)
        if self.model == self.name:
            return x.copy()
        return derivative(x, dt, 2 - int(self.order), lowpass_hz)


@dataclass(frozen=True)
class OutputKind:
    """An output column: what was measured of the mass's motion.

    ``order``: time derivatives of the relative displacement z it holds (2: z'', 0: z);
    ``symbol``: its name in formulas; the simulated output of this kind is
    :meth:`simulated`; the measured motion's standstill is where :meth:`motion` stays small.
    """

    name: str
    unit: str
    meaning: str
    order: int
    symbol: str

    def simulated(self, sim) -> np.ndarray:
        """The simulated output of this kind (``harvester.model.simulate.Simulation``)."""
        return sim.rel_acc if self.order == 2 else sim.rel_disp

    def motion(self, x: np.ndarray, dt: float) -> np.ndarray:
        """What is zero while the mass moves with the base (sticking), from this kind's
        values along the last axis: z'' itself, or z' of a displacement."""
        if self.order == 2:
            return x
        return np.gradient(x, dt, axis=-1)

    @property
    def motion_symbol(self) -> str:
        return "z''" if self.order == 2 else "z'"

    @property
    def holds_slow_motion(self) -> bool:
        """Whether this kind fixes the slow part of z: a displacement does; from z'' a slow
        force trades against k z, its effect on z'' falling as (f / f_n)^2 below f_n."""
        return self.order == 0

    def velocity(self, x: ArrayLike, dt: float, lowpass_hz: float | None) -> NDArray:
        """z' from this kind's values (:func:`derivative`: a displacement differentiated, an
        acceleration integrated above 0.1 Hz, up to a slow drift: for levels and power
        balances, not for waveforms), band-limited at ``lowpass_hz``."""
        return derivative(np.asarray(x, dtype=float), dt, 1 - self.order, lowpass_hz)

    def to_acceleration(self, x: ArrayLike, dt: float, lowpass_hz: float | None) -> NDArray:
        """z'' from this kind's values (band-limited at ``lowpass_hz``, :func:`derivative`)."""
        x = np.asarray(x, dtype=float)
        return x.copy() if self.order == 2 else derivative(x, dt, 2 - self.order, lowpass_hz)


INPUTS: dict[str, InputKind] = {
    "base_acc": InputKind("base_acc", "m/s^2", "base acceleration y''", 2, "base_acc", False,
                          "y''", "large_base_acceleration", "|y''| above its {hi:.0%} quantile"),
    "force": InputKind("force", "N", "force on the mass, base fixed", None, "force", True,
                       "F", "large_force", "|F| above its {hi:.0%} quantile"),
    "base_disp": InputKind("base_disp", "m", "base displacement y (laser, LVDT)", 0,
                           "base_acc", False, "y", "large_base_acceleration",
                           "|y''| (differentiated from y) above its {hi:.0%} quantile"),
}
OUTPUTS: dict[str, OutputKind] = {
    "rel_acc": OutputKind("rel_acc", "m/s^2", "acceleration of the mass relative to the "
                          "base, z''", 2, "z''"),
    "rel_disp": OutputKind("rel_disp", "m", "displacement of the mass relative to the base "
                           "(to ground for a force input), z", 0, "z"),
}


def input_kind(name: str) -> InputKind:
    """The :class:`InputKind` of a column name (KeyError naming the known ones)."""
    try:
        return INPUTS[name]
    except KeyError:
        raise KeyError(f"unknown input kind {name!r}; known: {', '.join(INPUTS)}") from None


def output_kind(name: str) -> OutputKind:
    """The :class:`OutputKind` of a column name (KeyError naming the known ones)."""
    try:
        return OUTPUTS[name]
    except KeyError:
        raise KeyError(f"unknown output kind {name!r}; known: {', '.join(OUTPUTS)}") from None


def model_recording(df: pd.DataFrame, lowpass_hz: float | None = None,
                    source: str = "<recording>") -> tuple[pd.DataFrame, list[str]]:
    """(recording the model can take, notes): a copy whose input column is of a kind the
    simulator is driven by (a ``base_disp`` becomes ``base_acc``, :meth:`InputKind.to_model`,
    band-limited at ``lowpass_hz``); other recordings are returned as they are."""
    from harvester.data.recording import recording_kinds
    from harvester.data.signals import uniform_step
    kinds = recording_kinds(df, source)
    kind = input_kind(kinds.input_kind)
    if kind.model == kind.name:
        return df, []
    dt = uniform_step(df["time"].to_numpy(dtype=float), source)
    x = df[kind.name].to_numpy(dtype=float)
    converted = kind.to_model(x, dt, lowpass_hz)
    out = df.drop(columns=[kind.name]).copy()
    out.insert(list(df.columns).index(kind.name), kind.model, converted)
    cutoff = chain_cutoff(1.0 / dt, lowpass_hz)
    notes = [] if lowpass_hz else _amplified_noise(converted, dt, cutoff, kind, source)
    note = (f"{source}: {kind.model} = second derivative of {kind.name} (frequency domain, "
            f"end-to-end line removed, band-limited at {cutoff:.3g} Hz by an order-"
            f"{DERIVATIVE_FILTER_ORDER} zero-phase Butterworth, "
            + ("the recording's low-pass" if lowpass_hz else "the DAQ's anti-alias edge: no "
               "low-pass given (filtered_at_hz)") + f"); RMS {np.std(converted):.4g} m/s^2")
    return out, [note] + notes


#: A derivative holding more than this share of its power above NOISE_BAND_FRACTION x its
#: cut-off is reported as amplified sensor noise (an excitation rarely lives up there).
NOISE_POWER_SHARE = 0.5
NOISE_BAND_FRACTION = 0.25


def _amplified_noise(x: np.ndarray, dt: float, cutoff: float, kind: InputKind,
                     source: str) -> list[str]:
    """A warning (logged, and returned for the notes) when the derivative of a displacement
    recorded without a known low-pass holds most of its power near the DAQ's edge: the sensor's
    noise, amplified by (2 pi f)^2."""
    import logging
    f, p = signal.welch(x, fs=1.0 / dt, nperseg=min(x.size, int(round(2.0 / dt))))
    edge = NOISE_BAND_FRACTION * cutoff
    share = float(np.sum(p[f > edge]) / max(np.sum(p), 1e-300))
    if share <= NOISE_POWER_SHARE:
        return []
    text = (f"{source}: {share:.0%} of {kind.model}'s power (the second derivative of "
            f"{kind.name}) lies above {edge:.3g} Hz, a quarter of the {cutoff:.3g} Hz edge it is "
            "band-limited at: the displacement sensor's noise, amplified by (2 pi f)^2; give "
            "the low-pass the recording went through (filtered_at_hz, --filtered-at) or "
            "low-pass it where its spectrum meets the sensor's floor")
    logging.getLogger("harvester.data").warning("%s", text)
    return [text]


def paper_case(df: pd.DataFrame, known: Mapping[str, float], lowpass_hz: float | None = None,
               source: str = "<recording>") -> tuple[pd.DataFrame, dict[str, float]]:
    """(recording with ``base_acc`` and ``rel_acc``, known parameters) that the paper's
    base-excited eq. (1) reads as the given recording, for methods written for that case
    (the FRF damping fit of the priors): a base displacement differentiated twice
    (:func:`model_recording`), a displacement output too (:meth:`OutputKind.to_acceleration`),
    and a force F on the mass as the base acceleration -F with m = 1 kg (eq. 1 is then driven
    by -m y'' = F). Copies; the recording passed in is not changed."""
    from harvester.data.recording import recording_kinds
    from harvester.data.signals import uniform_step
    df, _ = model_recording(df, lowpass_hz, source)
    kinds = recording_kinds(df, source)
    inp, out = input_kind(kinds.input_kind), output_kind(kinds.output_kind)
    dt = uniform_step(df["time"].to_numpy(dtype=float), source)
    u = df[inp.name].to_numpy(dtype=float)
    known = dict(known)
    if inp.force_input:
        u, known["m"] = -u, 1.0
    y = out.to_acceleration(df[out.name].to_numpy(dtype=float), dt, lowpass_hz)
    return pd.DataFrame({"time": df["time"].to_numpy(dtype=float), "base_acc": u,
                         "rel_acc": y}), known


def on_ground(df: pd.DataFrame, known: Mapping[str, float], source: str = "<recording>",
              lowpass_hz: float | None = None
              ) -> tuple[pd.DataFrame, dict[str, float], list[str]]:
    """(recording, known, notes) of a device whose friction acts on the mass's own velocity
    (a contact fixed to the ground; the sidecar's ``friction_on: ground``).

    A force input: the base is fixed, so the ground is the base and the relative velocity
    the mass's own; the recording is returned as it is (a copy), whatever its output.

    A base displacement: rewritten in absolute coordinates, where eq. (1) with m = M,
    M x'' + c (x' - y') + k (x - y) + F_f(x') = 0, is M x'' + c x' + k x + F_f(x') =
    k y + c y': driven by the force F = k y (N; the c y' part is left out, as the model's c_m
    is identified) with the output x = z + y (m, about its mean) or x'' = z'' + y'' (m/s^2,
    y'' by :func:`derivative` at ``lowpass_hz``, None: the chain's cut-off), so that every
    friction term acts on x'. Needs k known; m is then unused (and M = m is assumed: a
    frame, not a screw). A base acceleration is refused: y, its double integral, is not
    fixed by the record (the error's message gives what was measured). A copy; the
    recording passed in is not changed."""
    from harvester.data.errors import DataError
    from harvester.data.recording import recording_kinds
    kinds = recording_kinds(df, source)
    inp, out_kind = input_kind(kinds.input_kind), output_kind(kinds.output_kind)
    if inp.force_input:
        return df.copy(), dict(known), [
            f"{source}: friction on the ground (sidecar friction_on) with a force input: the "
            "base is fixed, so the friction acts on the mass's velocity, the model's z'"]
    if inp.order != 0:
        raise DataError(source, f"friction_on: ground with a {inp.name} input needs the "
                        f"base's displacement y (the force k y drives the mass in absolute "
                        f"coordinates), and the double integral of {inp.symbol} does not fix "
                        "it: on two sines (1.1 and 4.7 Hz, 10 s) it was off by 35-231 % of "
                        "y's RMS for high-passes at 0.8-0.1 Hz; record the base's "
                        "displacement (base_disp), or give friction_on: base",
                        column=inp.name)
    if "k" not in known:
        raise DataError(source, "friction_on: ground needs k known (the force k y drives the "
                        "mass in absolute coordinates): give k in the sidecar")
    t = df["time"].to_numpy(dtype=float)
    y = df[inp.name].to_numpy(dtype=float)
    rel = df[out_kind.name].to_numpy(dtype=float)
    if out_kind.order == 0:
        x = rel + y
        x = x - np.mean(x)
    else:  # x'' = z'' + y''
        x = rel + derivative(y, float(np.median(np.diff(t))), 2, lowpass_hz)
    out = pd.DataFrame({"time": t, "force": float(known["k"]) * (y - np.mean(y)),
                        out_kind.name: x})
    known = {p: v for p, v in known.items() if p != "m"}
    what = ("x = rel_disp + base_disp (m, about its mean)" if out_kind.order == 0 else
            "x'' = rel_acc + y'' (y'' differentiated from base_disp)")
    note = (f"{source}: friction on the ground (sidecar friction_on): driven by the force "
            f"k y (k = {known['k']:g} N/m, RMS {np.std(out.force):.4g} N) with the "
            f"output {what}, so that friction acts on x'")
    return out, known, [note]
