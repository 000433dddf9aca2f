"""What the missing force looks like: a small dictionary of shapes fitted to the latent force
(``latent.LatentForce``), each with the share of the missing force it explains,

    share = 1 - sum (f - f_shape)^2 / sum f^2      (f the posterior mean over the window),

and the best one said in one sentence ("a force periodic in z, period 3.0 mm, amplitude
5.0 N, explains 70 % of the missing force"). The shapes, each linear in its amplitudes, with
at most one scanned parameter:

The force's mean (a preload, a sensor's offset) is taken out first and stated apart; the
shares are of what varies. Units are written for N and m; the sentences label each size in
the recording's own (``lf.units``, ``data.units``: a circuit's volts say "V", "V/V"), and
show small displacements in mm only when the displacement is in m; the parameters' names
keep their SI suffixes (``F_N`` holds volts for a recording in volts).

``odd in z``        k_1 z + k_3 z^3 + k_5 z^5 (a stiffness error, a hardening spring)
``even in z``       f_0 + k_2 z^2 + k_4 z^4 (an offset, an asymmetric spring)
``friction``        F tanh(z' / v_0) + c z', v_0 scanned (Coulomb to a smooth sign law; c the
                    viscous part a fitted baseline's c_m took from it)
``damping``         c z' + c_2 z'|z'| (a viscous error, quadratic damping)
``periodic in z``   a cos(2 pi z / P) + b sin(2 pi z / P), the period P scanned (cogging,
                    a ball screw's or a gear's pitch, a magnetic detent)
``drift``           f_0 + s t (a slow change: temperature, a sensor's offset creeping)
``drifting friction``  (F + s t) tanh(z' / v_0) + c z', v_0 scanned (a friction level that
                    changes slowly: a lubricant warming; a slow force itself z'' cannot see)
``line``            a cos(2 pi f_0 t) + b sin(2 pi f_0 t), f_0 from the force's periodogram
                    (mains hum, a motor's or a pump's frequency, a structural mode driven
                    from outside)
``loop``            F h(t), h the library's Dahl state (``hysteresis``) at unit force, its
                    pre-sliding displacement delta scanned (a hysteresis loop in (z, f))
``... on the ground``  friction, loop and stick-slip on the absolute velocity x' = z' + y'
                    (a contact fixed to the ground: while it sticks it holds the mass still,
                    f = -(c_m z' + k z) there; Marino and Cicirello's frame)
``inertial``        dM z'' + dm y'' (a mass error, the diagnosis's catch-all name; it is
                    here so that a named mass error can be checked against the force's shape)
"""

from __future__ import annotations

import copy
import dataclasses
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy import optimize, signal, special, stats

from harvester.diagnosis.size.latent import LatentForce
from harvester.model.term_forces import term_force
from harvester.model.structures import structure
from harvester.model.terms import STICKING_FRICTION, TERMS, is_friction, term

#: Points of each scanned parameter's grid before the refinement.
SCAN_POINTS = 40
#: Share of the input's power in its strongest line above which it is a harmonic excitation.
INPUT_LINE_SHARE = 0.5
#: mean (f / sd)^2 above which the missing force stands out of its band.
SIGNAL_RATIO = 1.0
#: A shape is preferred to one earlier in the dictionary only if it explains this much more.
SHARE_MARGIN = 0.02
#: The missing force is read where its best shape stands this many sd out of the draws'
#: spread along it (:func:`standing`), whether or not its samples stand out of their sd;
#: without draws, where its samples do (SIGNAL_RATIO). Against a nominal false-read rate of
#: 5 %: on 80 effect-free records of the literature grid (seeds 0-79,
#: ``benchmarks/bench_shape_null.py``) none was read (95 % Wilson 0-4.6 %); the best shape
#: stood 1.78 sd out at the median, 3.95 at the 95th percentile and 6.17 at most (any shape:
#: 7.64). The nominal rate alone would put the threshold near 4 sd; it sits higher because a
#: wrong shape stands out beside a library effect too (periodic in z at 5.5 sd on a record of
#: direction-dependent friction), while the right shapes of forms outside the library stood
#: 13.8-52 sd out (docs/latent-force.md).
SHAPE_SD = 10.0


@dataclass
class Shape:
    """One shape fitted to the missing force: its share, parameters and sentence."""

    name: str
    share: float
    parameters: dict[str, float]
    sentence: str
    fitted: np.ndarray = field(repr=False)
    #: the fitted force in sd of the posterior draws' spread along it (:func:`standing`)
    standing_sd: float = float("nan")
    #: free coefficients and scanned parameters of the fit (a constant per stick phase each)
    dof: int = 1

    def to_dict(self) -> dict:
        return {"shape": self.name, "share": self.share, "parameters": self.parameters,
                "sentence": self.sentence, "standing_sd": self.standing_sd, "dof": self.dof}


@dataclass
class ShapeDescription:
    """Every shape of the dictionary, best first, and the one-sentence description."""

    shapes: list[Shape]
    rms_N: float
    mean_sd_N: float
    sentence: str
    offset_N: float = 0.0  # the force's mean, taken out before the shapes
    #: whether the force stands out of its band (``beyond_uncertainty``)
    readable: bool = True
    force: np.ndarray = field(repr=False, default_factory=lambda: np.empty(0))
    #: what the shapes' bases pass through beyond the latent force's band (the determined
    #: band's mask; none without draws)
    mask: Callable = field(repr=False, default=lambda x: x)
    #: shapes whose fit rests on the force's slow part, which the record does not determine
    #: (``slow_shapes``)
    slow: frozenset = frozenset()

    @property
    def best(self) -> Shape:
        return self.shapes[0]

    @property
    def determined(self) -> list[Shape]:
        """The shapes, best first, whose fit the record determines (not ``slow``)."""
        return [s for s in self.shapes if s.name not in self.slow]

    def share_of(self, banded: np.ndarray) -> float:
        """The share of the missing force a force explains, as each shape's is read: less
        its mean, within the determined band (``banded``: already through the latent
        force's band, as ``views.effect_force`` gives a named effect's)."""
        g = self.mask(banded - np.mean(banded))
        return _share(self.force, g)

    def shape(self, name: str) -> Shape:
        return next(s for s in self.shapes if s.name == name)

    def to_dict(self) -> dict:
        return {"sentence": self.sentence, "rms_N": self.rms_N, "mean_sd_N": self.mean_sd_N,
                "offset_N": self.offset_N, "readable": self.readable,
                "shapes": [s.to_dict() for s in self.shapes]}


def _fit(f: np.ndarray, basis: np.ndarray, band: Callable) -> tuple[np.ndarray, np.ndarray,
                                                                     float]:
    """(coefficients, fitted, share) of least squares of f on the columns of ``basis``, each
    column through ``band`` first (the low-pass the latent force is estimated in)."""
    basis = band(np.asarray(basis, dtype=float).T).T
    coef, *_ = np.linalg.lstsq(basis, f, rcond=None)
    fitted = basis @ coef
    return coef, fitted, _share(f, fitted)


def _share(f: np.ndarray, fitted: np.ndarray) -> float:
    """1 - sum (f - fitted)^2 / sum f^2; 0 for a force that is zero (none to explain: every
    shape would read 1, as they did on records whose force lies wholly outside its
    determined band)."""
    total = float(np.sum(f**2))
    if total <= 0.0:
        return 0.0
    return 1.0 - float(np.sum((f - fitted) ** 2)) / total


def _unfiltered(x: np.ndarray) -> np.ndarray:
    return x


def _scan(f: np.ndarray, make: Callable[[float], np.ndarray], grid: np.ndarray,
          band: Callable, sharp: bool = False) -> tuple[float, np.ndarray, np.ndarray, float]:
    """(best scanned value, coefficients, fitted, share): the best of ``grid`` (positive),
    refined by a bounded search between its neighbours. Smooth bases (a period, a line) are
    scanned unfiltered, which moves no peak and costs a tenth; ``sharp`` ones (a sign law, a
    loop: edges the band rounds off) through the band, or the scan picks the width that
    mimics the band's rounding: on two friction-drift records (truth's transition 0.45 mm/s)
    the unfiltered scan chose 21-26 mm/s and read the drift 20-27 % high, through the band
    0.4-0.5 mm/s and 0-4 %."""
    shares = [_fit(f, make(x), band if sharp else _unfiltered)[2] for x in grid]
    i = int(np.argmax(shares))
    ends = np.log([grid[max(i - 1, 0)], grid[min(i + 1, len(grid) - 1)]])
    lo, hi = ends.min(), ends.max()
    if hi > lo:
        res = optimize.minimize_scalar(lambda u: -_fit(f, make(np.exp(u)), band)[2],
                                       bounds=(lo, hi), method="bounded",
                                       options={"xatol": 1e-4})
        x = float(np.exp(res.x)) if -res.fun > _fit(f, make(grid[i]), band)[2] \
            else float(grid[i])
    else:
        x = float(grid[i])
    coef, fitted, share = _fit(f, make(x), band)
    return x, coef, fitted, share


def _rms(x: np.ndarray) -> float:
    return float(max(np.sqrt(np.mean(x**2)), 1e-12))


def _explains(share: float) -> str:
    return f"explains {100.0 * max(share, 0.0):.0f} % of the missing force"


def odd_in_z(lf: LatentForce, f: np.ndarray) -> Shape:
    """k_1 z + k_3 z^3 + k_5 z^5 for the share; k_1 (N/m) and k_3 (N/m^3) from k_1 z + k_3 z^3
    alone (with z^5 beside it k_3 trades against k_5)."""
    s = _rms(lf.rel_disp)
    x = lf.rel_disp / s
    _, fitted, share = _fit(f, np.column_stack([x, x**3, x**5]), lf.band)
    coef = _fit(f, np.column_stack([x, x**3]), lf.band)[0]
    k = coef / s ** np.array([1, 3])
    u = lf.units
    sentence = (f"a force odd in z (k_1 = {k[0]:.3g} {u.label('N/m')}, k_3 = {k[1]:.3g} "
                f"{u.label('N/m^3')}), {_explains(share)}")
    return Shape("odd in z", share, {"k1_N_per_m": k[0], "k3_N_per_m3": k[1]}, sentence,
                 fitted, dof=3)


def even_in_z(lf: LatentForce, f: np.ndarray) -> Shape:
    """f_0 + k_2 z^2 + k_4 z^4 for the share; the offset (N) and k_2 (N/m^2) from f_0 + k_2
    z^2 alone (with z^4 beside it k_2 trades against k_4: on two quadratic-spring records
    k_2 read 12-17 % low with it, 1-3 % without)."""
    s = _rms(lf.rel_disp)
    x = lf.rel_disp / s
    _, fitted, share = _fit(f, np.column_stack([np.ones_like(x), x**2, x**4]), lf.band)
    coef = _fit(f, np.column_stack([np.ones_like(x), x**2]), lf.band)[0]
    k = coef / s ** np.array([0, 2])
    u = lf.units
    sentence = (f"a force even in z (offset {k[0]:.3g} {u.label('N')}, k_2 = {k[1]:.3g} "
                f"{u.label('N/m^2')}), {_explains(share)}")
    return Shape("even in z", share, {"offset_N": k[0], "k2_N_per_m2": k[1]}, sentence,
                 fitted, dof=3)


def _sign_law(lf: LatentForce, f: np.ndarray, w: np.ndarray, name: str, what: str) -> Shape:
    """F tanh(w / v_0) + c z' (N, N s/m), v_0 (m/s) scanned from 1e-3 to 1 x the RMS of w:
    a friction law beside the viscous damping a fitted baseline gave it (equivalent
    linearisation puts part of any friction into c_m; the rest is missing as F sgn - c z')."""
    sv = _rms(w)
    grid = np.geomspace(1e-3 * sv, sv, SCAN_POINTS)
    v0, coef, fitted, share = _scan(
        f, lambda v: np.column_stack([np.tanh(w / v), lf.rel_vel]), grid, lf.band, sharp=True)
    u = lf.units
    scale, vel = u.small("velocity")
    sentence = (f"a friction-like force F sgn({what}) of {coef[0]:.3g} {u.label('N')} "
                f"(smoothed over {scale * v0:.2g} {vel}; with {coef[1]:.3g} "
                f"{u.label('N s/m')} of viscous damping), {_explains(share)}")
    return Shape(name, share, {"F_N": coef[0], "v0_m_per_s": v0, "c_N_s_per_m": coef[1]},
                 sentence, fitted, dof=3)


def friction(lf: LatentForce, f: np.ndarray) -> Shape:
    """F tanh(z' / v_0): friction on the velocity relative to the base."""
    return _sign_law(lf, f, lf.rel_vel, "friction", "z'")


#: Where |z'| exceeds this many of its posterior sd, its sign is known: the drifting friction's
#: level and trend are read there.
SURE_SIGN_SD = 3.0


def drifting_friction(lf: LatentForce, f: np.ndarray) -> Shape:
    """(F + s (t - t_mid)) tanh(z' / v_0) + c z' (N, N/s, N s/m), v_0 scanned as for
    ``friction``: a friction whose level changes slowly over the window (a lubricant warming).
    Its share is the scanned fit's over the window (its bases hold friction's, so it goes
    first only by SHARE_MARGIN more). F and s are read where |z'| > SURE_SIGN_SD sd of its
    draws: near a reversal the smoothed z' carries the wrong sign often enough to attenuate
    the law, and more where the motion is slower, which biases a trend (on a test record
    whose envelope slowed the motion from 20 to 13 mm/s RMS, 0.20 N/s for 0.25 over all
    samples, 0.235 where the sign is sure)."""
    w = lf.rel_vel
    t = lf.time - 0.5 * (lf.time[0] + lf.time[-1])
    sv = _rms(w)

    def basis(v0: float) -> np.ndarray:
        sign = np.tanh(w / v0)
        return np.column_stack([sign, t * sign, w])

    v0, coef, fitted, share = _scan(f, basis, np.geomspace(1e-3 * sv, sv, SCAN_POINTS),
                                    lf.band, sharp=True)
    if lf.state_draws.shape[1] > 1:
        sure = np.abs(w) > SURE_SIGN_SD * lf.state_draws[1].std(axis=0)
        if sure.sum() > 10 * basis(v0).shape[1]:
            banded = lf.band(basis(v0).T).T
            coef, *_ = np.linalg.lstsq(banded[sure], f[sure], rcond=None)
    span = float(lf.time[-1] - lf.time[0])
    u = lf.units
    force, (scale, vel) = u.label("N"), u.small("velocity")
    sentence = (f"a friction-like force F sgn(z') drifting in time, {coef[1]:.3g} "
                f"{u.label('N/s')} (from {coef[0] - 0.5 * span * coef[1]:.3g} {force} to "
                f"{coef[0] + 0.5 * span * coef[1]:.3g} {force} over {span:.3g} s; smoothed over "
                f"{scale * v0:.2g} {vel}, with {coef[2]:.3g} {u.label('N s/m')} of viscous "
                f"damping), {_explains(share)}")
    return Shape("drifting friction", share, {"F_N": coef[0], "slope_N_per_s": coef[1],
                                              "v0_m_per_s": v0, "c_N_s_per_m": coef[2]},
                 sentence, fitted, dof=4)


def base_velocity(lf: LatentForce) -> np.ndarray:
    """y' (m/s) of the latent force's record (``model.simulate.base_velocity``, what a
    ``ground`` term of the model sees); zeros for a force input (the base is fixed)."""
    if lf.input_kind != "base_acc":
        return np.zeros_like(lf.input)
    from harvester.model.simulate import base_velocity as of_input
    return of_input(lf.input, float(lf.time[1] - lf.time[0]))


def friction_on_ground(lf: LatentForce, f: np.ndarray) -> Shape:
    """F tanh(x' / v_0), x' = z' + y': friction on the absolute velocity (a contact fixed to
    the ground, as on Marino and Cicirello's frame)."""
    return _sign_law(lf, f, lf.rel_vel + base_velocity(lf), "friction on the ground", "x'")


def damping(lf: LatentForce, f: np.ndarray) -> Shape:
    """c z' + c_2 z'|z'| (N s/m, N s^2/m^2)."""
    v = lf.rel_vel
    coef, fitted, share = _fit(f, np.column_stack([v, v * np.abs(v)]), lf.band)
    u = lf.units
    sentence = (f"a damping force (c = {coef[0]:.3g} {u.label('N s/m')}, c_2 = {coef[1]:.3g} "
                f"{u.label('N s^2/m^2')}), {_explains(share)}")
    return Shape("damping", share, {"c_N_s_per_m": coef[0], "c2_N_s2_per_m2": coef[1]},
                 sentence, fitted, dof=2)


def _pair(phase: np.ndarray) -> np.ndarray:
    return np.column_stack([np.cos(phase), np.sin(phase)])


def periodic_in_z(lf: LatentForce, f: np.ndarray) -> Shape:
    """a cos(2 pi z / P) + b sin(2 pi z / P), P (m) scanned from the range of z to 1/200 of
    it in steps of a quarter of a period over the range (the peak's width)."""
    z = lf.rel_disp
    span = float(np.ptp(z)) or 1e-9
    grid = span / np.arange(1.0, 200.0, 0.25)
    P, coef, fitted, share = _scan(f, lambda p: _pair(2.0 * np.pi * z / p), grid, lf.band)
    amp = float(np.hypot(*coef))
    z_sd = float(np.sqrt(np.mean(lf.disp_sd**2)))
    scale, disp = lf.units.small("displacement")
    caveat = (f" (z is known to +-{scale * z_sd:.2g} {disp} only: the amplitude is a lower "
              "bound)" if P < 4.0 * z_sd else "")
    sentence = (f"a force periodic in z, period {scale * P:.3g} {disp}, amplitude {amp:.3g} "
                f"{lf.units.label('N')}{caveat}, {_explains(share)}")
    return Shape("periodic in z", share, {"period_m": P, "amplitude_N": amp}, sentence,
                 fitted, dof=3)


def drift(lf: LatentForce, f: np.ndarray) -> Shape:
    """f_0 + s t: a slow change (N, N/s) over the window."""
    t = lf.time - lf.time.mean()
    coef, fitted, share = _fit(f, np.column_stack([np.ones_like(t), t]), lf.band)
    u = lf.units
    sentence = (f"a force drifting slowly in time, {coef[1]:.3g} {u.label('N/s')} (from "
                f"{fitted[0]:.3g} {u.label('N')} to {fitted[-1]:.3g} {u.label('N')}), "
                f"{_explains(share)}")
    return Shape("drift", share, {"slope_N_per_s": coef[1], "mean_N": coef[0]}, sentence,
                 fitted, dof=2)


def _input_lines(lf: LatentForce, freqs: np.ndarray, n: int, dt: float) -> np.ndarray:
    """Where ``freqs`` lie within two bins of the input's line and its harmonics, when a line
    holds most of the input's power (a harmonic excitation: every force of the motion is
    periodic there, so a line there is no external cause); all False otherwise."""
    u = lf.input - lf.input.mean()
    power = np.abs(np.fft.rfft(u, n)) ** 2
    j = int(np.argmax(power[1:])) + 1
    width = max(2, n // len(u)) * 2
    if power[max(j - width, 0): j + width + 1].sum() < INPUT_LINE_SHARE * power.sum():
        return np.zeros(freqs.size, dtype=bool)
    f_in = freqs[j]
    resolution = 2.0 / (len(u) * dt)
    harmonic = np.round(freqs / f_in)
    return (harmonic >= 1) & (np.abs(freqs - harmonic * f_in) < resolution)


#: Below this gain of the smoother's response at a line's frequency its amplitude is given
#: as the posterior mean holds it (:func:`response_gain`).
GAIN_FLOOR = 0.05


def response_gain(lf: LatentForce, frequency_hz: float) -> float:
    """|W(f)|, the gain of the smoother's response (``latent.smoother_response``) at
    ``frequency_hz``: how much of a force at that frequency the posterior mean holds (1
    without a response)."""
    h = lf.response
    if h is None or h.size < 2:
        return 1.0
    dt = float(lf.time[1] - lf.time[0])
    k = np.arange(h.size) - h.size // 2
    return float(abs(np.sum(h * np.exp(-2j * np.pi * frequency_hz * k * dt))))


def line(lf: LatentForce, f: np.ndarray) -> Shape:
    """a cos(2 pi f_0 t) + b sin(2 pi f_0 t), f_0 (Hz) at the periodogram's peak (zero-padded
    8x; not at a harmonic excitation's line or its harmonics) refined by least squares. The
    amplitude is the force's: the fitted one over the smoother's gain at f_0 (a sinusoid
    goes through a stationary filter as a sinusoid, so the share does not change; a 50 Hz
    hum on a z'' record was held at about a twelfth, 0.070 N of 0.90 N), unless the gain is
    below GAIN_FLOOR. The bases of the other shapes are built on the smoothed states and do
    not go through W (docs/latent-force.md)."""
    t = lf.time
    dt = float(np.median(np.diff(t)))
    n = 8 * len(t)
    power = np.abs(np.fft.rfft(f - f.mean(), n)) ** 2
    freqs = np.fft.rfftfreq(n, dt)
    power[_input_lines(lf, freqs, n, dt)] = 0.0
    j = int(np.argmax(power[1:])) + 1
    grid = freqs[max(j - 1, 1): j + 2]
    f0, coef, fitted, share = _scan(f, lambda x: _pair(2.0 * np.pi * x * t), grid, lf.band)
    gain = response_gain(lf, f0)
    amp = float(np.hypot(*coef)) / (gain if gain >= GAIN_FLOOR else 1.0)
    span = float(t[-1] - t[0])
    what = (f"a slow change (one period in {1.0 / f0:.3g} s over a {span:.3g} s record)"
            if f0 < 2.0 / span else f"a line at {f0:.4g} Hz")
    sentence = f"{what}, amplitude {amp:.3g} {lf.units.label('N')}, {_explains(share)}"
    return Shape("line", share, {"frequency_hz": f0, "amplitude_N": amp}, sentence, fitted,
                 dof=3)


def _stick_runs(x_vel: np.ndarray, vs: float, shortest: int) -> np.ndarray:
    """Index of the stick phase each sample is in (-1: sliding): runs of |x'| < v_s at least
    ``shortest`` samples long (a shorter one is a reversal passing through zero)."""
    stick = np.abs(x_vel) < vs
    edges = np.diff(np.concatenate([[0], stick.astype(np.int8), [0]]))
    runs = np.full(x_vel.size, -1)
    starts, stops = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
    for j, (a, b) in enumerate((a, b) for a, b in zip(starts, stops) if b - a >= shortest):
        runs[a:b] = j
    return runs


def _stick_slip_fit(f: np.ndarray, x_vel: np.ndarray, z_vel: np.ndarray, held: np.ndarray,
                    runs: np.ndarray) -> tuple[float, float, float, np.ndarray, float]:
    """(F, c, b, fitted, share) of f = F sgn(x') + c z' while sliding, b held + c_j in stick
    phase j (c: the viscous part a fitted baseline's c_m took from the friction). The two
    parts have disjoint supports and c_j is each phase's mean, so the fit is the sliding
    samples' least squares and the phases' demeaned regression (O(samples))."""
    stick = runs >= 0
    slide = np.column_stack([np.sign(x_vel), z_vel])[~stick]
    coef = np.linalg.lstsq(slide, f[~stick], rcond=None)[0] if slide.size else np.zeros(2)
    if stick.any():
        count = np.bincount(runs[stick]).astype(float)
        mean = lambda x: (np.bincount(runs[stick], x[stick]) / count)[runs[stick]]  # noqa: E731
        f_dm, h_dm = f[stick] - mean(f), held[stick] - mean(held)
        b = float(h_dm @ f_dm / max(h_dm @ h_dm, 1e-300))
        held_part = mean(f) + b * h_dm
    else:
        b, held_part = 0.0, np.empty(0)
    fitted = np.empty_like(f)
    fitted[~stick] = slide @ coef
    fitted[stick] = held_part
    return float(coef[0]), float(coef[1]), b, fitted, _share(f, fitted)


#: Shortest stick phase (s): a shorter run of |x'| < v_s is a reversal passing through zero.
SHORTEST_STICK_S = 0.05


def stick_slip_on_ground(lf: LatentForce, f: np.ndarray) -> Shape:
    """Stick and slip of a contact fixed to the ground (Karnopp): while |x'| < v_s (for at
    least SHORTEST_STICK_S) the contact holds the mass where it stuck and carries what eq. (1)
    then leaves, b [-(c_m z' + k z) + (M - m) y''] plus a constant per stick phase (k x_stick;
    b = 1 is the law, fitted and reported); else it slides with F sgn(x') + c z' (c the
    viscous part a fitted baseline's c_m took, as in ``friction``). v_s (m/s) scanned
    from 1e-2 to 0.5 x the RMS of x'. Fitted without the band (the phases are long)."""
    x_vel = lf.rel_vel + base_velocity(lf)
    v = lf.values
    yb = lf.input if lf.input_kind == "base_acc" else np.zeros_like(lf.input)
    held = -(v["c_m"] * lf.rel_vel + v["k"] * lf.rel_disp) + (v["M"] - v["m"]) * yb
    shortest = max(2, int(round(SHORTEST_STICK_S / float(lf.time[1] - lf.time[0]))))
    sv = _rms(x_vel)
    fits = [(vs, *_stick_slip_fit(f, x_vel, lf.rel_vel, held,
                                  _stick_runs(x_vel, vs, shortest)))
            for vs in np.geomspace(1e-2 * sv, 0.5 * sv, SCAN_POINTS)]
    vs, F, c, b, fitted, share = max(fits, key=lambda r: r[-1])
    runs = _stick_runs(x_vel, vs, shortest)
    stuck = float(np.mean(runs >= 0))
    scale, vel = lf.units.small("velocity")
    sentence = (f"stick and slip on the ground: slides at {F:.3g} {lf.units.label('N')} "
                f"(with {c:.3g} {lf.units.label('N s/m')} of viscous damping), sticks below "
                f"{scale * vs:.2g} {vel} ({100 * stuck:.0f} % of the time), {_explains(share)}")
    return Shape("stick-slip on the ground", share, {"F_N": F, "c_N_s_per_m": c,
                                                     "v_stick_m_per_s": vs, "held_gain": b,
                                                     "stuck_share": stuck},
                 sentence, fitted, dof=4 + int(runs.max() + 1))


def _dahl(lf: LatentForce, f: np.ndarray, w: np.ndarray, name: str, what: str) -> Shape:
    """F h(t): the library's Dahl state at unit force (``hysteresis``) along the velocity w,
    its pre-sliding displacement delta (m) scanned from 1e-3 to 1 x the RMS displacement."""
    t_h = term("hysteresis")
    sz = _rms(lf.rel_disp)
    zero = np.zeros_like(lf.time)
    dt = float(lf.time[1] - lf.time[0])

    def basis(delta: float) -> np.ndarray:
        values = {"F_hyst": 1.0, "delta_hyst": delta, "c_hyst": 0.0}
        return term_force(t_h, values, zero, w, zero, zero, dt)[0][:, None]

    grid = np.geomspace(1e-3 * sz, sz, SCAN_POINTS // 2)
    delta, coef, fitted, share = _scan(f, basis, grid, lf.band, sharp=True)
    scale, disp = lf.units.small("displacement")
    sentence = (f"a hysteresis loop in ({what}, f), {coef[0]:.3g} {lf.units.label('N')} at "
                f"saturation, pre-sliding over {scale * delta:.2g} {disp}, {_explains(share)}")
    return Shape(name, share, {"F_N": coef[0], "delta_m": delta}, sentence, fitted, dof=2)


def loop(lf: LatentForce, f: np.ndarray) -> Shape:
    """A Dahl loop along z' (pre-sliding friction between the mass and the base)."""
    return _dahl(lf, f, lf.rel_vel, "loop", "z")


def loop_on_ground(lf: LatentForce, f: np.ndarray) -> Shape:
    """A Dahl loop along x' = z' + y' (stick and slip of a contact fixed to the ground)."""
    return _dahl(lf, f, lf.rel_vel + base_velocity(lf), "loop on the ground", "x")


def inertial(lf: LatentForce, f: np.ndarray) -> Shape:
    """dM z'' + dm y'' (kg): a mass error (dm only for a base-acceleration input)."""
    cols = [lf.rel_acc] + ([lf.input] if lf.input_kind == "base_acc" else [])
    coef, fitted, share = _fit(f, np.column_stack(cols), lf.band)
    dm = float(coef[1]) if len(coef) > 1 else 0.0
    mass = lf.units.label("kg")
    sentence = (f"an inertial force (dM = {coef[0]:.3g} {mass} on z'', dm = {dm:.3g} {mass} on "
                f"y''), {_explains(share)}")
    return Shape("inertial", share, {"dM_kg": float(coef[0]), "dm_kg": dm}, sentence, fitted,
                 dof=len(coef))


#: The dictionary, in the order a tie goes (simpler and more common physics first). The
#: inertial shape is not in it: every force above the device's resonance moves z'' by about
#: -f / M, so a regression on z'' explains any fast force as a large negative mass error (a
#: Coulomb force of 6 N came out as dM = -10 kg on M = 12.8 kg, 94 %); it serves to check a
#: named mass error (``describe(lf, DICTIONARY + (inertial,))``).
DICTIONARY = (odd_in_z, even_in_z, friction, damping, periodic_in_z, drift, line,
              drifting_friction, loop, friction_on_ground, loop_on_ground, stick_slip_on_ground)


def beyond_uncertainty(lf: LatentForce) -> bool:
    """Whether the missing force stands out of its band: mean (f / sd)^2 > SIGNAL_RATIO. A
    posterior mean of a force that is not there stays inside its sd (shrinkage): 1e-6 on an
    effect-free record, 0.4 on a drift z'' cannot see; a fitted linear baseline's missing
    tanh friction (RMS 1.7 N, sd 0.9 N, 20 % of the samples beyond 2 sd) gave 3.4."""
    ratio = np.mean((lf.force / np.maximum(lf.sd, 1e-12)) ** 2)
    return bool(ratio > SIGNAL_RATIO)


#: Bins of the 2x zero-padded spectrum averaged in :func:`determined` (0.55 Hz over 29 s).
DETERMINED_BINS = 32


def _moving_mean(x: np.ndarray, width: int) -> np.ndarray:
    return np.convolve(x, np.ones(width) / width, mode="same")


def determined(lf: LatentForce) -> tuple[LatentForce, Callable]:
    """(the latent force whose ``band`` passes a shape's bases through its determined band,
    that band's mask alone, for a force already through the latent force's band): the
    frequencies where the force's posterior mean stands out of its draws' spread (smoothed
    power of the mean above that of the draws' deviations, SIGNAL_RATIO), the rest removed
    from the force and from every shape's bases (zero-padded FFT; after the likelihood's
    band). From z'' a slow force is amplified by (f_n / f)^2 out of small residuals: on a
    record with 50 Hz mains hum on the sensor (0.90 N as a force), 78 % of the posterior
    mean's power lay at 0.5-2 Hz, with the draws' spread as large, and the line found was
    0.87 Hz; in the determined band it is 50.0 Hz, 0.88 N. Without draws: unchanged."""
    if lf.draws.ndim != 2 or lf.draws.shape[0] < 2:
        return lf, _unfiltered
    n = lf.force.size
    nfft = 2 * n
    spread = np.mean(np.abs(np.fft.rfft(lf.draws - lf.force, nfft, axis=1)) ** 2, axis=0)
    power = np.abs(np.fft.rfft(lf.force - lf.force.mean(), nfft)) ** 2
    keep = (_moving_mean(power, DETERMINED_BINS)
            > SIGNAL_RATIO * _moving_mean(spread, DETERMINED_BINS)).astype(float)
    if keep.all():
        return lf, _unfiltered
    band = lf.band

    def mask(x: np.ndarray) -> np.ndarray:
        return np.fft.irfft(np.fft.rfft(x, nfft, axis=-1) * keep, nfft, axis=-1)[..., :n]

    def through(x: np.ndarray) -> np.ndarray:
        return mask(band(x))

    seen = copy.copy(lf)
    seen.band = through  # the shapes read the band from here (an instance attribute)
    return seen, mask


def describe(lf: LatentForce, dictionary=DICTIONARY) -> ShapeDescription:
    """Every shape of ``dictionary`` fitted to the missing force less its mean (a constant
    force, a preload or a sensor's offset, is stated apart) within its determined band
    (:func:`determined`), best first (a shape later in the dictionary goes first only if it
    explains SHARE_MARGIN more; a shape of the slow part, :func:`slow_shapes`, only if every
    shape is one), and the sentence (sizes in ``lf.units``)."""
    offset = float(np.mean(lf.force))
    seen, mask = determined(lf)
    f = mask(lf.force - offset)  # the force is in its band already; the bases go through it
    fitted = [shape(seen, f) for shape in dictionary]
    if not any(is_friction(t) for t in structure(lf.baseline).layout.terms):
        fitted = [passive(s) for s in fitted]
    spread = mask(lf.draws - lf.force) if lf.draws.ndim == 2 and lf.draws.shape[0] > 1 \
        else None
    fitted = [dataclasses.replace(s, standing_sd=standing(s, spread)) for s in fitted]
    slow = slow_shapes(lf, fitted)
    pool = [s for s in fitted if s.name not in slow] or fitted
    top = max(s.share for s in pool)
    best = next(s for s in pool if s.share >= top - SHARE_MARGIN)
    ranked = [best] + sorted((s for s in fitted if s is not best), key=lambda s: -s.share)
    by_samples = beyond_uncertainty(lf)
    readable = best.standing_sd > SHAPE_SD if np.isfinite(best.standing_sd) else by_samples
    return ShapeDescription(ranked, lf.rms_N, float(np.mean(lf.sd)),
                            _sentence(lf, best, offset, readable, by_samples), offset,
                            readable, f, mask, slow)


def standing(shape: Shape, spread: np.ndarray | None) -> float:
    """How far ``shape``'s fitted force stands out of the force's uncertainty, in sd: its
    norm over the sd of the posterior draws' deviations (``spread``, through the same mask)
    projected on it, referred to the shape's ``dof`` (:func:`_one_dof`). A force whose
    samples each lie within their sd can still hold a shape the record determines, summed
    over thousands of samples: on the literature generator's records of forms outside the
    library the right shape stood 13.8-52 sd out (mains hum, friction drifts, quadratic
    springs, cogging of seed 1), while on twelve effect-free records of its grid no shape stood
    more than 7.6 sd out (docs/latent-force.md). NaN without draws (nothing to stand out of)."""
    norm = float(np.linalg.norm(shape.fitted))
    if spread is None:
        return float("nan")
    if norm == 0.0:
        return 0.0
    sd = float(np.std(spread @ (shape.fitted / norm)))
    return _one_dof(norm / sd, shape.dof) if sd > 0.0 else float("inf")


def _one_dof(s: float, dof: int) -> float:
    """The standing ``s`` of a fit with ``dof`` free coefficients as the one coefficient's
    standing of the same tail probability. Fitted to noise alone, k coefficients give a
    norm^2 of about sd^2 chi^2_k, so s^2 is referred to chi^2_k: a stick-slip fit with a
    constant for each of 77 stick phases stood 13.5 sd out on an effect-free record (6.2
    referred to its 81 coefficients); a scanned parameter counts as one coefficient. s
    itself for one, or where the tail underflows (s above about 38)."""
    if dof <= 1 or not np.isfinite(s):
        return s
    z = -float(special.ndtri_exp(stats.chi2.logsf(s * s, dof) - np.log(2.0)))
    return z if np.isfinite(z) else s


#: Where z's posterior sd exceeds this share of its RMS, the unread force's sentence says so.
Z_UNKNOWN_SHARE = 0.5


def _z_unknown(lf: LatentForce) -> str:
    """'; z itself is known to +-X only ...' where the record leaves z that uncertain (an
    acceleration record of a small motion: on a cogging record of the literature generator,
    86 um RMS known to 124 um, with a 0.1 mm period no shape could read), else ''."""
    z_sd = float(np.sqrt(np.mean(lf.disp_sd**2)))
    if z_sd <= Z_UNKNOWN_SHARE * _rms(lf.rel_disp):
        return ""
    scale, disp = lf.units.small("displacement")
    return (f"; z itself is known to +-{scale * z_sd:.2g} {disp} only (RMS "
            f"{scale * _rms(lf.rel_disp):.2g} {disp}): a force that varies with z on a finer "
            "scale cannot be read")


def _sentence(lf: LatentForce, best: Shape, offset: float, readable: bool,
              by_samples: bool) -> str:
    """The description's one sentence (sizes in ``lf.units``)."""
    rms, sd, force = lf.rms_N, float(np.mean(lf.sd)), lf.units.label("N")
    if not readable:
        return (f"no missing force beyond its uncertainty (RMS {rms:.3g} {force} against an "
                f"sd of {sd:.3g} {force}){_z_unknown(lf)}")
    about = f" about a constant {offset:.3g} {force}" if abs(offset) > 0.1 * rms else ""
    if by_samples:
        return f"{best.sentence}{about} (RMS {rms:.3g} {force})"
    return (f"{best.sentence}{about} (RMS {rms:.3g} {force}, within its sd of {sd:.3g} "
            f"{force} sample by sample; the shape stands {best.standing_sd:.0f} sd out)")


def passive(shape: Shape) -> Shape:
    """``shape``, or, for a friction shape whose level F is not positive, the same shape
    explaining nothing: a friction takes energy from the motion; one that pushes the mass
    along its velocity is not friction (the frame's loop read -0.34 N under the linear
    baseline). A drifting friction's level is its level at the record's start. For a
    baseline without friction only (:func:`describe`): under one with friction, a negative
    missing friction is the baseline's taking too much."""
    family = library_terms(shape.name)
    friction = shape.name == "drifting friction" or (family and is_friction(TERMS[family[0]]))
    if not friction or shape.parameters.get("F_N", 1.0) > 0:
        return shape
    return dataclasses.replace(shape, share=0.0)


#: Share of a shape's fitted power below SLOW_FREQUENCY x the device's natural frequency above
#: which, on an acceleration record, the shape rests on the force's slow part; there z''
#: sees a force by (1/3)^2, an order of magnitude less than at the resonance.
SLOW_SHARE = 0.5
SLOW_FREQUENCY = 1.0 / 3.0


def slow_shapes(lf: LatentForce, shapes: Sequence[Shape]) -> frozenset:
    """The names of ``shapes`` whose fitted force has more than SLOW_SHARE of its power below
    SLOW_FREQUENCY x f_n (f_n = sqrt(k / M) / 2 pi, the baseline's), on an acceleration
    record only: z'' responds to a force below the resonance by (f / f_n)^2 of what it does
    at it, so the smoother's slow part is its prior more than the data. On the literature
    generator's records at half the noise RMS the latent force's RMS was 4-67 x the truth's
    (the stride rounded down, before 106b3e0), best fitted by a line at 0.23-0.49 Hz or by
    stick-slip's constants per stick phase
    (devices of 5.7-6 Hz). Shares below f_n / 3 on the eight records of forms outside the
    library and a cubic spring's test record: lines 0.97-1.0, drifts 0.73-0.99, stick-slip
    0.57-0.62 where it fitted the slow part; the cubic spring's odd shape 0.33."""
    if lf.output_kind != "rel_acc" or lf.time.size < 4:
        return frozenset()
    f_n = np.sqrt(lf.values["k"] / lf.values["M"]) / (2.0 * np.pi)
    freqs = np.fft.rfftfreq(lf.time.size, float(lf.time[1] - lf.time[0]))
    below = freqs < SLOW_FREQUENCY * f_n
    out = set()
    for s in shapes:
        power = np.abs(np.fft.rfft(s.fitted - np.mean(s.fitted))) ** 2
        if power.sum() > 0 and power[below].sum() > SLOW_SHARE * power.sum():
            out.add(s.name)
    return frozenset(out)


def library_terms(shape: str) -> tuple[str, ...]:
    """The library's terms whose force has ``shape`` (a shape's name); none for a shape
    outside the library. Friction on the ground is the same term acting on the mass's own
    velocity (``topology``). Stick and slip is the shape of the friction laws that hold
    (``STICKING_FRICTION`` and their refinements), a smooth law's force creeps instead. A
    loop is also the shape of a hysteretic spring's departure from its linear part."""
    friction = tuple(name for name, t in TERMS.items() if is_friction(t))
    sticking = tuple(name for name, t in TERMS.items() if name in STICKING_FRICTION
                     or set(t.refines) & set(STICKING_FRICTION))
    return {"odd in z": ("cubic_stiffness", "end_stop"), "damping": ("quadratic_damping",),
            "friction": friction, "loop": friction + ("hysteretic_spring",),
            "friction on the ground": friction,
            "loop on the ground": friction, "stick-slip on the ground": sticking,
            "inertial": ("inertia_error",)}.get(shape, ())


#: A named term whose force explains this much less of the missing force than the best shape,
#: a shape none of its terms has, does not have the missing force's shape.
NAME_MARGIN = 0.1


def has_its_shape(description: ShapeDescription, terms: Sequence[str], share: float) -> bool:
    """Whether the named ``terms``, whose force together explains ``share`` of the missing
    force (``ShapeDescription.share_of``), have the missing force's shape: the best shape the
    record determines (not one of ``description.slow``) is one of theirs (``library_terms``),
    or their force explains within NAME_MARGIN of what it does. True where the force cannot
    be read or no shape is determined (nothing to check against)."""
    determined = description.determined
    if not description.readable or not determined:
        return True
    best = determined[0]
    return bool(set(terms) & set(library_terms(best.name))) or share >= best.share - NAME_MARGIN
