"""A resonance of the output's sensor is not a mode of the device.

``unmodelled_mode`` puts a second mass on its own spring into the device: it takes force from
the mass and energy from the drive, so it changes the device's response itself, and its
resonance comes with an anti-resonance (the part moving against the rest) and leaves the
response above it at the rigid rest's level. A sensor's own resonance (an accelerometer's
seismic mass, Bendat and Piersol 2010, sec. 2.4) touches nothing of the device: the recorded
output is the true one read through H(f) = 1 / (1 - (f/f_s)^2 + 2 j zeta f/f_s), unit gain
below f_s, a peak of 1 / (2 zeta) at it and falling as (f_s/f)^2 above, without zeros.

The test holds the two physical readings against the same record. The sensor's: the model
the mode was added to, at its posterior, its output read through H (f_s, zeta fitted by least
squares over the detection window; on a rig whose output is the mass accelerometer less the
base's, the mass accelerometer reads the absolute acceleration: y = H (z'' + y'') - y''). The
device's: the structure with the mode at the best of its posterior's representative draw
(``map_fit.representative``) and DEVICE_DRAWS draws, as the sensor's is its best fit. Each is
scored by its gain of tempered log-likelihood over the model without the mode (sigma profiled:
lambda n/2 log(sse_before / sse)). The sensor's reading has two parameters and none of the
device's refitted, the mode four and all of them refitted: the resonance is said to be the
sensor's where its reading gains more than the mode's by the naming margin log(1/alpha) (the
one ``confirm.mark_ties`` asks of one named model over another) and the reading is a
resonance (its damping ratio below ZETA_SPAN's top: a peak of at least 2), the device's where
the mode gains more by that margin or the sensor's best reading is no resonance the record
shows (its damping on the bound, or its frequency above the analysed band: on the literature
generator's Dahl record recorded as base_disp -> rel_acc, a "sensor" at 105 Hz above the
81.5 Hz band, at the derivative's filter edge, had withdrawn hysteresis); in between
one output channel does not tell them apart, and the mode's name carries that caveat.

Any other accepted candidate is held the same way: a sensor's resonance distorts the output
everywhere, and a friction law or a spring fitted to that distortion is a wrong name (a 45 Hz
accelerometer on an effect-free record had hysteresis named at +22.6 nats). Where the round
accepts nothing while the detection finds a mismatch, the sensor's reading is held the same
way against the library's best fit of the round (the screened candidate of the
largest likelihood at its MAP): a resonance of the sensor then leaves "the library explains
none of the mismatch" with its cause. By MAP on the literature generator's records (tanh
baseline, fast settings, ``docs/measurements.md``): a 45 Hz accelerometer (zeta 0.05) on
effect-free devices was found at 45.0 and 45.4 Hz, +2606 and +2631 nats against a mode's
+11.5 and +8.5; a secondary mode and a flexible mount (seed 0) stayed the device's (+2295
and +1190 against the sensor's +274 and +170), and so did Dahl, Bouc-Wen and Duffing records
by their right names; on effect-free records without a sensor the sensor's reading gained
-1.3 and -0.2 nats.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy import optimize

from harvester.diagnosis.name.results import ConfirmSettings
from harvester.diagnosis.name.simulable import withdraw
from harvester.inference.map_fit import BaselineState, ChainProblem, representative
from harvester.model.structures import ModelStructure

log = logging.getLogger("harvester.diagnosis")

#: Posterior draws of an accepted candidate read beside its representative draw: the device's
#: best reading is the best of them (on the frame at 250 g the posterior mean of hysteresis
#: fitted 57 nats worse than the linear model, its evidence +7.5 nats better).
DEVICE_DRAWS = 64
#: The effect a sensor's resonance is held against.
MODE = "unmodelled_mode"
#: The sensor's resonance searched over the mode prior's span (``unmodelled_mode``: a
#: hundredth to four times the band's top) and damping ratios 0.5 % to 25 %: a resonance, a
#: peak of at least 2 (1 / (2 zeta)). A more damped sensor shows no resonance, and its gentle
#: roll-off is what the measurement chain and a friction law's harmonics also make: with
#: damping up to 50 % a "sensor" at 43.1 Hz, zeta 0.46, gained +89.6 nats on the literature
#: generator's LuGre record (seed 0) against its right name's (hysteresis) +39.6 by MAP.
F_SPAN = (0.01, 4.0)
ZETA_SPAN = (0.005, 0.25)
#: A reading whose damping ratio lies within this share of ZETA_SPAN's top is no resonance
#: (its best fit wants more damping than a resonance has): it rules the sensor out. With the
#: span up to 25 %, LuGre's record (seed 0) still read a "sensor" at 34.6 Hz on the bound,
#: +60.4 nats against hysteresis's +39.6.
ZETA_PILE = 0.99


def sensor_response(f: np.ndarray, f_s: float, zeta: float) -> np.ndarray:
    """H(f) of a second-order sensor with its resonance at f_s (Hz), damping ratio zeta."""
    r = np.asarray(f, dtype=float) / f_s
    return 1.0 / (1.0 - r * r + 2j * zeta * r)


def through_sensor(x: np.ndarray, fs: float, f_s: float, zeta: float) -> np.ndarray:
    """The record ``x`` (sampled at ``fs``) read through the sensor, in the frequency domain
    (the records start from rest)."""
    n = x.shape[-1]
    spec = np.fft.rfft(x, axis=-1) * sensor_response(np.fft.rfftfreq(n, 1.0 / fs), f_s, zeta)
    return np.fft.irfft(spec, n, axis=-1)


@dataclass
class SensorReading:
    """The resonance held against the output's sensor: the sensor's fitted resonance, which
    sensor reads it, each reading's gain (tempered nats), the device's effect it was held
    against, whether that is the round's accepted mode (else its best fit) and what is
    concluded ('sensor', 'device' or 'undecided')."""

    f_hz: float
    zeta: float
    sensor: str
    sensor_gain: float
    device_gain: float
    margin: float
    conclusion: str
    effect: str = MODE
    accepted: bool = True
    f_high: float = float("inf")  # the analysed band's top (Hz)

    @property
    def no_peak(self) -> bool:
        """Whether the record shows no resonance of the sensor: its best reading wants the
        damping's bound, or it lies above the analysed band, where only the peak's flank
        (a gain rising as (f / f_s)^2, an apparent mass) reaches the record."""
        return self.zeta >= ZETA_PILE * ZETA_SPAN[1] or self.f_hz > self.f_high

    def sentence(self) -> str:
        rival = ("a mode in the device" if self.accepted and self.effect == MODE else
                 f"{self.effect} in the device" if self.accepted else
                 f"the library's best fit ({self.effect})")
        gains = (f"the output read through a sensor resonating at {self.f_hz:.3g} Hz "
                 f"(zeta {self.zeta:.2g}, {self.sensor}) gains {self.sensor_gain:+.1f} nats "
                 f"over the model without it, {rival} {self.device_gain:+.1f}")
        if not self.accepted:
            return {"sensor": "the mismatch is the output sensor's own resonance, not the "
                              f"device's: {gains} (the library models the device, not its "
                              "sensors)",
                    "device": f"the mismatch is not the output sensor's: {gains}"
                              + self._no_peak(),
                    "undecided": "the mismatch may be the output sensor's resonance: "
                                 f"{gains}, within the {self.margin:.1f}-nat margin"
                    }[self.conclusion]
        if self.effect != MODE:
            return self._effect_sentence(gains)
        if self.conclusion == "sensor":
            return (f"the resonance is the output sensor's, not a mode of the device: {gains}; "
                    f"{MODE} not named (the library models the device, not its sensors)")
        if self.conclusion == "device":
            return f"the resonance is the device's, not the output sensor's: {gains}" + \
                self._no_peak()
        return (f"the resonance may be the output sensor's as well as a mode of the device: "
                f"{gains}, within the {self.margin:.1f}-nat margin; one output channel does not "
                "tell them apart here (a second sensor on the mass, or the sensor's "
                "calibration, would)")

    def _effect_sentence(self, gains: str) -> str:
        if self.conclusion == "sensor":
            return (f"the mismatch is the output sensor's own resonance, not {self.effect}: "
                    f"{gains}; {self.effect} not named (the library models the device, not "
                    "its sensors)")
        if self.conclusion == "undecided":
            return (f"the mismatch may be the output sensor's resonance as well as "
                    f"{self.effect}: {gains}, within the {self.margin:.1f}-nat margin")
        return f"the mismatch is {self.effect}'s, not the output sensor's: {gains}" + \
            self._no_peak()

    def _no_peak(self) -> str:
        if self.f_hz > self.f_high:
            return (f" (the sensor's best reading lies above the analysed band's "
                    f"{self.f_high:.3g} Hz: the record shows no peak of it)")
        return ("" if self.zeta < ZETA_PILE * ZETA_SPAN[1] else
                f" (the sensor's best reading is no resonance: its damping on the "
                f"{ZETA_SPAN[1]:.0%} bound)")

    def to_dict(self) -> dict:
        return {"f_hz": self.f_hz, "zeta": self.zeta, "sensor": self.sensor,
                "sensor_gain_nats": self.sensor_gain, "device_effect": self.effect,
                "device_effect_accepted": self.accepted,
                "device_gain_nats": self.device_gain, "margin_nats": self.margin,
                "band_top_hz": self.f_high,
                "conclusion": self.conclusion, "sentence": self.sentence()}


def _gain(problem: ChainProblem, before: np.ndarray, residual: np.ndarray) -> float:
    """lambda n/2 log(sse_before / sse) over the likelihood's samples."""
    w = problem.samples
    sse0, sse = np.sum(before[w] ** 2), np.sum(residual[w] ** 2)
    return float(0.5 * problem.temper * problem.n_data * np.log(sse0 / sse))


def _readings(state: BaselineState) -> dict[str, Callable[[float, float], np.ndarray]]:
    """Each sensor that may read the output, as the output it would record at (f_s, zeta)."""
    p = state.problem
    fs, model = 1.0 / p.dt, np.asarray(state.output, dtype=float)
    out = {"the output's sensor": lambda f, z: through_sensor(model, fs, f, z)}
    if p.input_kind == "base_acc" and p.output_kind == "rel_acc":
        base = p.chain(np.asarray(p.input, dtype=float))
        out["the mass accelerometer, less the base's"] = \
            lambda f, z: through_sensor(model + base, fs, f, z) - base
    return out


def fit_sensor(state: BaselineState, f_high: float) -> tuple[float, float, str, float]:
    """(f_s, zeta, which sensor, gain in nats) of the best sensor reading of the baseline's
    output (grid over F_SPAN x f_high, ZETA_SPAN, then Nelder-Mead in the logs, within
    them)."""
    p, measured = state.problem, state.problem.measured_chain
    best = (np.nan, np.nan, "", -np.inf)
    for name, read in _readings(state).items():
        def loss(q):
            r = measured - read(float(np.exp(q[0])), float(np.exp(q[1])))
            return -_gain(p, state.residual, r)
        span = [(np.log(F_SPAN[0] * f_high), np.log(F_SPAN[1] * f_high)),
                tuple(np.log(ZETA_SPAN))]
        grid = [(f, z) for f in np.linspace(*span[0], 48) for z in np.linspace(*span[1], 8)]
        start = min(grid, key=loss)
        res = optimize.minimize(loss, start, method="Nelder-Mead", bounds=span,
                                options={"xatol": 1e-4, "fatol": 1e-3, "maxiter": 400})
        if -res.fun > best[3]:
            best = (float(np.exp(res.x[0])), float(np.exp(res.x[1])), name, float(-res.fun))
    return best


def device_gain(state: BaselineState, problem: ChainProblem, theta: np.ndarray) -> float:
    """The gain (tempered nats) over ``state``'s model of ``problem``'s structure at the best
    of the rows of ``theta`` (a fit, or posterior draws: the device's best reading, as the
    sensor's is its best fit), on the same record; RuntimeError where none can be
    simulated."""
    rows = np.atleast_2d(theta)
    pred, ok = problem.predicted(rows)
    if not np.any(ok):
        raise RuntimeError(f"{problem.structure.name} cannot be simulated at its fit")
    return max(_gain(state.problem, state.residual, problem.measured_chain - pred[i])
               for i in np.flatnonzero(ok))


def read_resonance(state: BaselineState, effect: str, problem: ChainProblem,
                   theta: np.ndarray, f_high: float, settings: ConfirmSettings,
                   accepted: bool = True) -> SensorReading:
    """The device's ``effect`` (``problem``'s structure at ``theta``, added to ``state``'s;
    ``accepted``: the round's accepted mode, else its best fit) held against the output's
    sensor (module docstring)."""
    gain_d = device_gain(state, problem, theta)
    f_s, zeta, sensor, gain = fit_sensor(state, f_high)
    margin = settings.base_threshold
    reading = SensorReading(f_s, zeta, sensor, gain, gain_d, margin, "", effect, accepted,
                            f_high)
    reading.conclusion = ("device" if reading.no_peak or gain_d - gain > margin else
                          "sensor" if gain - gain_d > margin else "undecided")
    return reading


def _rival(rnd, problem_of) -> tuple[str, ChainProblem, np.ndarray, bool] | None:
    """What the sensor is held against: the accepted candidate at its posterior, or, where
    the round accepted nothing but detected a mismatch, its best screened fit at its MAP."""
    accepted = [r for r in rnd.confirmed if r.accepted]
    if accepted:
        problem = problem_of(accepted[0].fit.structure)
        draws = accepted[0].fit.samples
        pick = np.random.default_rng(0).choice(len(draws), min(DEVICE_DRAWS, len(draws)),
                                              replace=False)
        rows = np.vstack([representative(problem, draws)[0], draws[pick]])
        return accepted[0].effect, problem, rows, True
    fits = [] if rnd.screen is None else [s for s in rnd.screen.candidates if not s.failed]
    if accepted or not rnd.detection.significant or not fits:
        return None
    best = max(fits, key=lambda s: s.max_loglike)
    problem = problem_of(rnd.state.problem.structure.with_term(best.effect))
    return best.effect, problem, best.theta, False


def hold_against_sensor(rnd, problem_of: Callable[[ModelStructure], ChainProblem],
                        f_high: float, settings: ConfirmSettings
                        ) -> tuple[SensorReading | None, list[str]]:
    """Hold the round (``rounds.Round``: its confirmed candidates, best first, its state,
    detection and screen) against a resonance of the output's sensor (:func:`_rival`,
    :func:`read_resonance`); withdraw the accepted candidate where the mismatch is the
    sensor's. (the reading or None, notes: a mode's reading, or any where the sensor is not
    ruled out)."""
    try:
        rival = _rival(rnd, problem_of)
        if rival is None:
            return None, []
        effect, problem, theta, accepted = rival
        reading = read_resonance(rnd.state, effect, problem, theta, f_high, settings, accepted)
    except RuntimeError as err:  # the device's fit cannot be simulated over the record
        log.warning("the mismatch was not held against the output's sensor: %s", err)
        return None, [f"the mismatch was not held against the output's sensor: {err}"]
    log.info("%s", reading.sentence())
    if reading.accepted and reading.conclusion == "sensor":
        withdraw(rnd.confirmed, [reading.effect], settings)
    said = reading.effect == MODE and reading.accepted or reading.conclusion != "device"
    return reading, [reading.sentence()] if said else []
