"""The missing force: the force f(t) (N) that would make the baseline reproduce the recording,
estimated as a latent force with its uncertainty (Alvarez, Luengo and Lawrence 2009;
Hartikainen and Sarkka 2010; Marino and Cicirello 2023).

The baseline (eq. 1 with its terms T, at its posterior mean) and the missing force f:

    M z'' + c_m z' + k z + sum_T X_T(z, z', ...) + f = drive,     drive = -m y'' or F,

X_T the terms' forces on the stated masses (``term_forces``). The smoother estimates the total
force beyond the linear part, g = sum_T X_T + f, as a Matern Gaussian process (3/2 or 5/2)
in state-space form, augmented to (z, z'): a linear Gaussian model, so the Kalman filter and
the Rauch-Tung-Striebel smoother are exact, with no linearisation of sign-like laws that an
extended filter would turn into a gain of F_c / 1 mm/s. This is the restoring-force surface's
logic (Masri and Caughey 1979: the force beyond the known linear part, from the measured
motion) and the GPLFM's (a known linear model plus a latent force), with the baseline's terms
taken out afterwards: f = g - W sum_T X_T along joint draws of the smoothed state path
(forward filtering, backward sampling), which carries the states' uncertainty into f; W is
the smoother's own response (``smoother_response``), through which g's posterior mean holds
the baseline's terms.

Band. The recording holds the motion only inside the measurement chain's band (the
likelihood's low-pass, ``ChainProblem.band_hz``), so the force is estimated inside it: the
drive and the recorded output go through that low-pass, and the force (each draw) too. The
noise went through the low-pass as well: white before it, band-limited and correlated over
the filter's memory after it. Two ways to measure it:

* the noise's level given (the recording's own floor, ``floor.py``, as the diagnosis does)
  on a displacement record: the band-limited noise is a state space of its own
  (``state_space.filtered_noise``: the zero-phase filter's spectrum, run causally), and
  every sample is measured without its correlated noise being counted as independent; what
  the stop band holds beyond the filter's response is a floor of FLOOR_SHARE x the
  baseline's sigma. Every 12th sample of the frame's displacement (an 8 Hz band at 143 Hz)
  was too few to see its friction (docs/latent-force.md).
* otherwise the output is measured every ``stride`` samples, fs / (2 band) rounded up (7 at
  256 Hz for a 20 Hz recording), where the band-limited noise is close to independent, as
  white noise (``measurement_stride``).
  With its level free, band-limited noise explains a mismatch whose spectrum is as flat as a
  sign law's as well as a force does (a 6 N Coulomb friction missing from a 12 s z''
  record: the noise at the baseline's sigma scored 4000 nats above the force with the noise
  at the sensor's level); and from z'' (``OutputKind.holds_slow_motion``) every sample
  measured let the slow part the record leaves open grow (a cubic spring's 1.37 N: 2.57 N
  of error, 2.51 N of it below 1 Hz, against 0.59 N at the stride).

Hyperparameters. The process's length scale and sd, and the noise sd, maximise the Kalman
filter's marginal likelihood; the noise sd is bounded above by the baseline's sigma, which
holds the mismatch as well as the noise (``noise='baseline'`` fixes it there instead; a
value fixes it there: the diagnosis gives the recording's own noise floor, measured where
the model has no say, ``floor.py``, so that what the baseline leaves beyond the noise is
force).
The baseline's parameters are held at their posterior mean (their uncertainty is not
carried).
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field

import numpy as np
from scipy import linalg, optimize, signal

from harvester.data.signals import butterworth_sos, lowpass
from harvester.data.units import SI, Units
from harvester.inference.map_fit import BaselineState
from harvester.inference.state_space import (MATERN_STATES, Discrete, backward_sample,
                                             discretise, filtered_noise, kalman_filter,
                                             kalman_loglik, matern, rts_smoother)
from harvester.model.term_forces import term_forces

log = logging.getLogger("harvester.diagnosis")

#: Length scales (s) the marginal likelihood's search starts from.
LENGTH_STARTS_S = (0.02, 0.08, 0.3, 1.0)
#: Draws of the state path that carry the uncertainty into f.
PATH_DRAWS = 100
#: What the recording holds beyond its chain's response (its stop band), as a share of the
#: baseline's sigma: the measurement noise that is not band-limited (rounding, leakage).
FLOOR_SHARE = 1e-3


@dataclass
class LatentForce:
    """The missing force over a window: posterior mean and sd (N) at every sample, the
    smoothed states, the baseline's term forces along them, and how it was estimated."""

    time: np.ndarray  # s
    force: np.ndarray  # N, posterior mean of f (in the band)
    sd: np.ndarray  # N
    rel_disp: np.ndarray  # m, smoothed z
    disp_sd: np.ndarray  # m, its posterior sd (an acceleration record leaves z's slow part open)
    rel_vel: np.ndarray  # m/s, smoothed z'
    rel_acc: np.ndarray  # m/s^2, smoothed z''
    input: np.ndarray  # the input (m/s^2 or N) in the band
    baseline_terms: np.ndarray  # N, sum_T X_T along the smoothed states (in the band)
    baseline: str
    values: dict  # the baseline's layout parameters (SI)
    input_kind: str
    output_kind: str
    kernel: str
    length_scale_s: float
    amplitude_N: float
    noise_sd: float  # unit of the output
    baseline_noise_sd: float
    log_marginal: float  # nats
    band_hz: float
    stride: int  # samples between the outputs measured
    seconds: float
    filter_order: int = 8  # the band's zero-phase Butterworth low-pass
    noise_in_band: bool = False  # the noise modelled as band-limited (module docstring)
    draws: np.ndarray = field(repr=False, default_factory=lambda: np.empty((0, 0)))
    #: joint draws of (z, z', z'') along the window, (3, draws, samples), SI units
    state_draws: np.ndarray = field(repr=False, default_factory=lambda: np.empty((3, 0, 0)))
    #: the same draws over the record before the window, and the input there: a term's own
    #: states (hysteresis, a mode) settle along them before the window starts
    lead_draws: np.ndarray = field(repr=False, default_factory=lambda: np.empty((3, 0, 0)))
    lead_input: np.ndarray = field(repr=False, default_factory=lambda: np.empty(0))
    #: the recording's units (``data.units``): "N" and "m" above stand for them
    units: Units = SI
    #: the smoother's response W (``smoother_response``), None: the identity
    response: np.ndarray | None = field(repr=False, default=None)
    #: the recording less the smoother's output (the baseline's dynamics under the posterior
    #: mean force), in the output's unit: its noise and what the force model cannot hold
    output_residual: np.ndarray = field(repr=False, default_factory=lambda: np.empty(0))

    @property
    def lower(self) -> np.ndarray:
        return self.force - 2.0 * self.sd

    @property
    def upper(self) -> np.ndarray:
        return self.force + 2.0 * self.sd

    @property
    def rms_N(self) -> float:
        return float(np.sqrt(np.mean(self.force**2)))

    def band(self, x: np.ndarray) -> np.ndarray:
        """``x`` (samples along the last axis) through the band's low-pass, as the force."""
        if not np.isfinite(self.band_hz):
            return np.asarray(x, dtype=float)
        fs = 1.0 / float(self.time[1] - self.time[0])
        return lowpass(x, fs, self.band_hz, self.filter_order)

    def to_dict(self) -> dict:
        """diagnosis.json's entry: size, settings and hyperparameters (no time history)."""
        return {"baseline": self.baseline, "rms_N": self.rms_N,
                "peak_N": float(np.max(np.abs(self.force))),
                "mean_sd_N": float(np.mean(self.sd)),
                "share_beyond_2sd": float(np.mean(np.abs(self.force) > 2.0 * self.sd)),
                "disp_sd_m": float(np.sqrt(np.mean(self.disp_sd**2))),
                "window_s": [float(self.time[0]), float(self.time[-1])],
                "input_kind": self.input_kind, "output_kind": self.output_kind,
                "kernel": self.kernel, "length_scale_s": self.length_scale_s,
                "amplitude_N": self.amplitude_N, "noise_sd": self.noise_sd,
                "baseline_noise_sd": self.baseline_noise_sd, "log_marginal": self.log_marginal,
                "band_hz": self.band_hz, "stride": self.stride,
                "noise_in_band": self.noise_in_band, "seconds": self.seconds,
                "force_unit": self.units.label("force")}


@dataclass
class _Device:
    """The baseline's linear part, its drive and measurement over the record."""

    values: dict
    dt: float
    drive: np.ndarray  # N
    base: np.ndarray  # y'' in the band (zeros for a force input)
    input: np.ndarray
    y: np.ndarray
    kind: str
    z_scale: float
    v_scale: float
    #: the chain's noise (``state_space.filtered_noise``: A, c, P), None: white noise
    noise: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
    stride: int = 1  # samples between measurements
    initial_sd: float = 0.01  # prior sd of (z, z') at the first sample / their RMS
    floor: float = 0.0  # sd of the noise beyond the chain's response (output's unit)

    @property
    def M(self) -> float:
        return float(self.values["M"])

    def H(self) -> tuple[np.ndarray, float]:
        """Measurement row on (z, z', g) and the drive's feedthrough."""
        M, c, k = self.M, self.values["c_m"], self.values["k"]
        if self.kind == "rel_disp":
            return np.array([1.0, 0.0, 0.0]), 0.0
        return np.array([-k / M, -c / M, -1.0 / M]), 1.0 / M


def _device(state: BaselineState, stop: int) -> tuple[_Device, np.ndarray]:
    """The baseline's linear part, drive and measurement, and its residual in the output's
    kind (both through the chain) over the record's first ``stop`` samples."""
    p = state.problem
    theta = np.asarray(state.theta, dtype=float)
    values = dict(p.known)
    values.update(zip(p.structure.free_parameters, theta[:-1]))
    u = p.chain(np.asarray(p.input, dtype=float))[:stop]
    force_input = p.input_kind == "force"
    drive = u if force_input else -values["m"] * u
    y = p.measured_chain[:stop]
    sim = p.simulate(theta)
    if not sim.ok[0]:
        raise RuntimeError(f"the baseline {p.structure.name} cannot be simulated at theta")
    out = sim.rel_disp[0] if p.output_kind == "rel_disp" else sim.rel_acc[0]
    scale = lambda x: float(max(np.sqrt(np.mean(np.square(x[:stop]))), 1e-9))  # noqa: E731
    dev = _Device(values, p.dt, drive, np.zeros(stop) if force_input else u, u, y,
                  p.output_kind, scale(sim.rel_disp[0]), scale(sim.rel_vel[0]))
    return dev, y - p.chain(out)[:stop]


#: Prior sd of (z, z') at the record's first sample, in units of their RMS: the model starts
#: at rest (``Problem``); a record that does not is given a wider one (``initial_sd``).
INITIAL_SD = 0.01


def _model(dev: _Device, kernel: str, length: float, amp: float, noise: float):
    """The augmented model in scaled states (z / z_s, z' / v_s, g^(j) / (amp lam^j), and the
    chain's noise states in units of its white input): (discrete model, H, D, R, initial
    mean and covariance, scales)."""
    F, q, P_inf = matern(kernel, length, amp)
    p = len(F)
    n = 2 + p
    M, c, k = dev.M, dev.values["c_m"], dev.values["k"]
    A = np.zeros((n, n))
    A[0, 1], A[1, 0], A[1, 1], A[1, 2] = 1.0, -k / M, -c / M, -1.0 / M
    A[2:, 2:] = F
    b = np.zeros(n)
    b[1] = 1.0 / M
    W = np.zeros((n, n))
    W[-1, -1] = q
    lam = np.sqrt(2.0 * (p - 0.5)) / length
    T = np.concatenate([[dev.z_scale, dev.v_scale], amp * lam ** np.arange(p)])
    Ti = 1.0 / T
    disc = discretise(Ti[:, None] * A * T[None, :], Ti * b, Ti[:, None] * W * Ti[None, :],
                      dev.dt)
    h3, D = dev.H()
    H = np.zeros(n)
    H[:3] = h3 * T[:3]
    P0 = np.zeros((n, n))
    P0[:2, :2] = np.diag([dev.initial_sd**2] * 2)
    P0[2:, 2:] = P_inf * np.outer(Ti[2:], Ti[2:])
    if dev.noise is None:
        return disc, H, D, noise**2, np.zeros(n), P0, T
    return _with_chain_noise(disc, H, D, P0, T, dev, noise)


def _with_chain_noise(disc: Discrete, H, D, P0, T, dev: _Device, noise: float):
    """The model with the chain's band-limited noise of sd ``noise`` (output's unit) as
    states (``state_space.filtered_noise``), measured through them; the white floor beyond
    the chain's response left as the measurement noise."""
    An, cn, Pn = dev.noise
    m = len(An)
    Q = np.zeros((m, m))
    Q[-1, -1] = 1.0
    aug = Discrete(linalg.block_diag(disc.Phi, An), np.concatenate([disc.G0, np.zeros(m)]),
                   np.concatenate([disc.G1, np.zeros(m)]), linalg.block_diag(disc.Q, Q))
    n = len(H) + m
    return (aug, np.concatenate([H, noise * cn]), D, max(dev.floor, 1e-300) ** 2, np.zeros(n),
            linalg.block_diag(P0, Pn), np.concatenate([T, np.ones(m)]))


def _measured(dev: _Device) -> np.ndarray:
    measured = np.zeros(len(dev.y), dtype=bool)
    measured[::dev.stride] = True
    return measured


def _filter(dev: _Device, kernel: str, length: float, amp: float, noise: float):
    """(the Kalman filter's output, the discrete model, its measurement row H and
    feedthrough D, the states' scales T)."""
    disc, H, D, R, m0, P0, T = _model(dev, kernel, length, amp, noise)
    out = kalman_filter(disc.Phi, disc.G0, disc.G1, disc.Q, H, D, R, dev.drive, dev.y,
                        _measured(dev), m0, P0)
    return out, disc, H, D, T


#: The smoother's response is kept out to where it falls below this share of its peak.
RESPONSE_TAIL = 1e-4


def smoother_response(dev: _Device, kernel: str, length: float, amp: float, noise: float,
                      centre: int) -> np.ndarray:
    """The smoother's response W (odd length, centred): the posterior mean of the force is
    W * f + (noise) for a true force f, a linear filter in the record's interior, which
    shrinks what the measurement sees poorly (a z'' record's slow forces, a noisy
    displacement's fast ones). Found by smoothing the noise-free response to a one-sample
    force pulse at ``centre`` (averaged over the measurement's phases when only every
    ``stride``-th sample is measured). The baseline's own terms go through W before they
    are taken from g (``_forces``); the shapes' bases, built on the smoothed states, do not
    (docs/latent-force.md)."""
    disc, H, D, R, m0, P0, T = _model(dev, kernel, length, amp, noise)
    n, out = len(dev.y), np.zeros(len(dev.y))
    pulse = _pulse_output(disc, H, D, n, centre)
    phases = [p for p in range(dev.stride) if centre + p + 1 < n]
    for phase in phases:  # the pulse one sample later each time, the measurements fixed
        y = np.zeros(n)
        y[phase:] = pulse[:n - phase]
        mf, Pf, mp, Pp, _ = kalman_filter(disc.Phi, disc.G0, disc.G1, disc.Q, H, D, R,
                                          np.zeros(n), y, _measured(dev), np.zeros(len(m0)),
                                          P0)
        ms, _, _ = rts_smoother(disc.Phi, mf, Pf, mp, Pp)
        out += np.roll(ms[:, 2] * T[2], -phase) / len(phases)
    keep = np.nonzero(np.abs(out) > RESPONSE_TAIL * np.max(np.abs(out)))[0]
    half = min(int(max(centre - keep[0], keep[-1] - centre)), centre, n - 1 - centre)
    return out[centre - half:centre + half + 1]


def _pulse_output(disc: Discrete, H: np.ndarray, D: float, n: int, j: int) -> np.ndarray:
    """The noise-free output (``n`` samples) of the device alone (the process's and the
    noise's states at rest) to a one-sample force pulse of 1 N at sample ``j``: a force f
    enters eq. (1) as a drive of -f, through the same first-order hold as the drive."""
    x = np.zeros((n, len(disc.G0)))
    x[j] = -disc.G1
    if j + 1 < n:
        x[j + 1] = disc.Phi @ x[j] - disc.G0
    for k in range(j + 1, n - 1):
        x[k + 1] = disc.Phi @ x[k]
    y = x @ H
    y[j] -= D
    return y


def through_response(x: np.ndarray, response: np.ndarray | None) -> np.ndarray:
    """``x`` (samples along the last axis) through the smoother's response (centred)."""
    x = np.asarray(x, dtype=float)
    if response is None:
        return x
    half = response.size // 2
    full = signal.fftconvolve(x, response.reshape((1,) * (x.ndim - 1) + (-1,)), axes=-1)
    return full[..., half:half + x.shape[-1]]


def fit_hyperparameters(dev: _Device, kernel: str, amp0: float, noise_max: float,
                        fit_noise: bool) -> tuple[float, float, float, float]:
    """(length scale s, amplitude N, noise sd, log marginal likelihood) maximising the
    Kalman filter's marginal likelihood; the noise sd at most ``noise_max`` (fixed there
    unless ``fit_noise``)."""
    duration = dev.dt * len(dev.y)
    lo = np.log([4.0 * dev.dt, 1e-3 * amp0, 1e-3 * noise_max])
    hi = np.log([duration / 4.0, 1e3 * amp0, noise_max])

    def cost(x):
        length, amp, noise = np.exp(x) if fit_noise else (*np.exp(x), noise_max)
        try:
            disc, H, D, R, m0, P0, _ = _model(dev, kernel, length, amp, noise)
            value = -kalman_loglik(disc.Phi, disc.G0, disc.G1, disc.Q, H, D, R, dev.drive,
                                   dev.y, dev.stride, m0, P0)
        except (np.linalg.LinAlgError, ValueError):
            return 1e300
        return value if np.isfinite(value) else 1e300

    dims = 3 if fit_noise else 2
    starts = [np.array([np.log(ls), np.log(amp0), np.log(0.5 * noise_max)])[:dims]
              for ls in LENGTH_STARTS_S if np.log(ls) > lo[0]]
    x0 = min(starts, key=cost)
    res = optimize.minimize(cost, x0, method="L-BFGS-B",
                            bounds=list(zip(lo[:dims], hi[:dims])), options={"maxiter": 60})
    length, amp, noise = np.exp(res.x) if fit_noise else (*np.exp(res.x), noise_max)
    return float(length), float(amp), float(noise), float(-res.fun)


def measurement_stride(state: BaselineState) -> int:
    """Samples between the outputs the smoother measures with white noise: fs / (2 x the
    chain's band) rounded up, so that the measured samples' Nyquist frequency lies inside
    the band and the band-limited noise is close to independent (1 without a band below
    Nyquist). Rounded down, the samples keep part of the noise's stop band, and a noise with
    a stop band is predictable from its past: at a band of 0.32 fs (stride 1, the band an
    unfiltered record gets) the marginal likelihood put the noise at 0.15 x its floor and read
    the rest as a force, 4-67 x the truth's on the literature grid (docs/latent-force.md)."""
    p = state.problem
    band = getattr(p, "band_hz", None)
    if band is None or not np.isfinite(band):
        return 1
    return max(1, int(np.ceil(0.5 / (p.dt * band) - 1e-9)))


def chain_noise(state: BaselineState) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """The measurement chain's noise as a state space (``state_space.filtered_noise`` of the
    likelihood's zero-phase low-pass), None where the chain has no band below Nyquist."""
    p = state.problem
    band = getattr(p, "band_hz", None)
    if band is None or not np.isfinite(band) or band >= 0.5 / p.dt:
        return None
    return filtered_noise(butterworth_sos(1.0 / p.dt, float(band),
                                          int(getattr(p, "filter_order", 8))))


def _measurement(dev: _Device, state: BaselineState, fixed: float | None,
                 noise_floor: float | None) -> float | None:
    """Sets how ``dev``'s output is measured (module docstring) and returns the noise's level
    (None: fitted). On a record that fixes the slow motion with a level given (the
    ``noise_floor`` first, at most the baseline's sigma): band-limited noise, every sample;
    otherwise white noise every ``measurement_stride`` samples."""
    sigma_b = float(state.theta[-1])
    if state.problem.output_type.holds_slow_motion:
        fixed = fixed if noise_floor is None else min(float(noise_floor), sigma_b)
        if fixed is not None:
            dev.noise, dev.floor = chain_noise(state), FLOOR_SHARE * sigma_b
            return fixed
    dev.stride = measurement_stride(state)
    return fixed


def _force_scale(dev: _Device, residual: np.ndarray) -> float:
    """The force the baseline's residual implies (N): M x its RMS for an acceleration, k x it
    for a displacement; the search's starting amplitude."""
    gain = dev.values["k"] if dev.kind == "rel_disp" else dev.M
    return max(gain * float(np.std(residual)), 1e-6)


def _smoothed_output(dev: _Device, kernel: str, H: np.ndarray, D: float, T: np.ndarray,
                     mean: np.ndarray) -> np.ndarray:
    """The output the smoothed states ``mean`` (SI) give through the model's ``H``, ``D``
    and scales ``T`` (output's unit): the device's measurement of (z, z', g) and the
    drive's feedthrough, without the chain's noise states."""
    n = 2 + MATERN_STATES[kernel]
    return (mean[:, :n] / T[:n]) @ H[:n] + D * dev.drive


def _paths(dev: _Device, disc, T, filtered, draws: int, seed: int):
    """Smoothed means (samples, states) and joint draws of the state path (draws, samples,
    states), in SI units."""
    mf, Pf, mp, Pp, _ = filtered
    ms, J, C = rts_smoother(disc.Phi, mf, Pf, mp, Pp)
    noise = np.random.default_rng(seed).standard_normal((draws, len(dev.y), len(T)))
    return ms * T, backward_sample(mf, mp, J, C, noise) * T


def _acceleration(dev: _Device, z, v, g):
    """z'' (m/s^2) of the linear part under the total force g."""
    return (dev.drive - dev.values["c_m"] * v - dev.values["k"] * z - g) / dev.M


def _terms_along(state: BaselineState, dev: _Device, z, v, g) -> np.ndarray:
    """sum_T X_T (N) of the baseline's terms along paths (draws, samples); 0 without terms."""
    layout = state.problem.structure.layout
    if not layout.terms:
        return np.zeros_like(np.atleast_2d(z))
    a = _acceleration(dev, z, v, g)
    forces = term_forces(layout, dev.values, z, v, a, dev.base, dev.dt)
    return sum(forces.values())


def _forces(state: BaselineState, dev: _Device, mean: np.ndarray, paths: np.ndarray,
            response: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(f's posterior mean, its draws, the baseline's term forces along the mean path), each
    through the band (N): f = g - W sum_T X_T per draw, the terms through the smoother's
    response W as g's smoothed mean holds them (a sharp tanh friction's switches, which g
    cannot follow, left a friction-like force of the opposite sign: -0.37 N, z-score 15, on
    an effect-free record of the literature grid); without terms f's mean is the smoother's
    own, exact."""
    band = state.problem.chain

    def terms(z, v, g):
        return band(through_response(_terms_along(state, dev, z, v, g), response))

    z, v, g = paths[..., 0], paths[..., 1], paths[..., 2]
    f_paths = band(g) - terms(z, v, g)
    terms_mean = terms(mean[:, 0], mean[:, 1], mean[:, 2])[0]
    if not state.problem.structure.layout.terms:
        return band(mean[:, 2]), f_paths, terms_mean
    return f_paths.mean(axis=0), f_paths, terms_mean


def latent_force(state: BaselineState, window: tuple[int, int] | None = None, *,
                 kernel: str = "matern52", noise: str | float = "fit",
                 noise_floor: float | None = None, draws: int = PATH_DRAWS, seed: int = 0,
                 initial_sd: float = INITIAL_SD, units: Units = SI) -> LatentForce:
    """The missing force of the baseline ``state`` over ``window`` (samples; the problem's
    by default), module docstring. ``kernel``: 'matern32' or 'matern52'; ``noise``: 'fit'
    (marginal likelihood, at most the baseline's sigma; white, every ``stride`` samples),
    'baseline' (its sigma) or a value in the output's unit; a given level is modelled
    band-limited, every sample measured, on a record that fixes the slow motion;
    ``noise_floor``: the recording's own noise floor (output's unit, ``floor.py``), taken as
    the noise's level on such a record and ignored on others (``noise`` then); ``draws``:
    joint draws of the state path behind the sd; ``initial_sd``: :data:`INITIAL_SD`;
    ``units``: the recording's (labels)."""
    if kernel not in MATERN_STATES:
        raise ValueError(f"kernel must be one of {sorted(MATERN_STATES)}, got {kernel!r}")
    clock = time.perf_counter()
    p = state.problem
    start, stop = window or p.window
    dev, residual = _device(state, stop)
    dev.initial_sd = float(initial_sd)
    sigma_b = float(state.theta[-1])
    fixed = _measurement(dev, state, None if noise == "fit" else (
        sigma_b if noise == "baseline" else float(noise)), noise_floor)
    length, amp, noise_sd, logml = fit_hyperparameters(
        dev, kernel, _force_scale(dev, residual[start:stop]), fixed or sigma_b, fixed is None)
    filtered, disc, H, D, T = _filter(dev, kernel, length, amp, noise_sd)
    mean, paths = _paths(dev, disc, T, filtered, draws, seed)
    response = smoother_response(dev, kernel, length, amp, noise_sd, (start + stop) // 2)
    force, f_paths, terms_mean = _forces(state, dev, mean, paths, response)
    w = slice(start, stop)
    z, v, g = paths[..., 0], paths[..., 1], paths[..., 2]
    states = np.stack([z, v, _acceleration(dev, z, v, g)])
    z = z[:, w]
    out = LatentForce(
        time=np.arange(stop)[w] * p.dt, force=force[w], sd=f_paths.std(axis=0)[w],
        rel_disp=mean[w, 0], disp_sd=z.std(axis=0), rel_vel=mean[w, 1],
        rel_acc=_acceleration(dev, mean[:, 0], mean[:, 1], mean[:, 2])[w],
        input=dev.input[w], baseline_terms=terms_mean[w], baseline=p.structure.name,
        values=dev.values, input_kind=p.input_kind, output_kind=p.output_kind, kernel=kernel,
        length_scale_s=length, amplitude_N=amp, noise_sd=noise_sd, baseline_noise_sd=sigma_b,
        log_marginal=logml, band_hz=float(getattr(p, "band_hz", np.nan)), stride=dev.stride,
        noise_in_band=dev.noise is not None,
        seconds=time.perf_counter() - clock, filter_order=int(getattr(p, "filter_order", 8)),
        draws=f_paths[:, w], state_draws=states[..., w], lead_draws=states[..., :start],
        lead_input=dev.input[:start], units=units, response=response,
        output_residual=(dev.y - _smoothed_output(dev, kernel, H, D, T, mean))[w])
    unit = units.label("force")
    log.info("latent force of %s: RMS %.3g %s (sd %.2g %s), length scale %.3g s, noise %.3g "
             "(baseline's sigma %.3g), %.1f s", p.structure.name, out.rms_N, unit,
             np.mean(out.sd), unit, length, noise_sd, sigma_b, out.seconds)
    return out
