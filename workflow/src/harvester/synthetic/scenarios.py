"""Concealed-effect scenarios: recordings of a device carrying one effect too small to see.

A scenario is (effect, contribution-to-noise ratio r, seed). The device is the study's baseline
(eq. 1 with tanh friction at the paper's Table 5 means, or the linear device for
``coulomb_friction``) plus ONE effect of the physics library, generated with a functional form
that differs from the library's where a physical alternative exists, by a simulator of its own
(below), so that the diagnosis is not tested on its own equations (no inverse crime).

The effect's strength is CALIBRATED so that its contribution

    c(t) = LP[ z''(with the effect) - z''(without) ](t),    same excitation, no noise,

LP the study's zero-phase 20 Hz low-pass, has RMS = r x the noise RMS of the recorded relative
acceleration over the analysis window (the record after ``lead_in_s``). The noise RMS is the
sensors' white noise as it appears in the recorded z'' channel: both accelerometers' noise
(z'' = mass channel - base channel) through the same low-pass, sqrt(2) x sigma_sensor x the
filter's noise gain (0.022 m/s^2 for 0.04 m/s^2 sensors at 256 Hz). The strength is solved by
a bracketed secant on log(strength) against log(contribution); the shape parameters are drawn
per seed from the ranges of :data:`FAMILIES`.

Generating forms, force f added to the left-hand side of eq. (1) (opposing z, z' when positive);
w is the screw-side velocity (z' without backlash), sgn_e(w) = w / sqrt(w^2 + e^2):

========================= ====================================================================
effect (library name)     generating form (library's form in brackets)
========================= ====================================================================
coulomb_friction          linear device + Coulomb friction with stiction (Karnopp): F sgn(w)
                          while sliding; while |w| < 0.5 mm/s it holds the applied force up to
                          the breakaway F [F sgn(w), sgn regularised as tanh(w / 1 mm/s)]
stribeck_friction         F exp(-|w| / v_s) sgn_e(w), exponent 1, e = 0.2 mm/s, v_s drawn in
                          [1, 8] mm/s [a free exponent: F exp(-|w/v_s|^delta) sgn(w)]
asymmetric_friction       friction stronger in one direction: the tanh law times (1 +- a),
                          i.e. f = A |tanh(beta w)|, beta the baseline's, sign of A drawn
                          [A tanh(w / v_asym)^2, its own transition]
quadratic_damping         c |w|^1.8 sgn(w)  [c w |w|]
cubic_stiffness           progressive (hardening) spring k |z|^2.5 sgn(z) [k z^3]; softening
                          at a visible strength turns the total stiffness negative within the
                          motion, so only hardening is generated
end_stop                  Hertzian stop k (|z| - g)_+^1.5 sgn(z), g at a quantile of |z| drawn
                          in [0.7, 0.9]  [linear k (|z| - g)_+]
backlash                  gap g (the strength) between the mass and the screw side (J = M - m),
                          Hertzian contact with Tsuji damping k_c delta^1.5 +
                          c_c delta^0.25 delta' (compressive only), k_c = 1e11 N/m^1.5,
                          c_c = 1e5 N s/m^1.25 [linear contact with Hunt-Crossley damping]
hysteresis                Bouc-Wen pre-sliding force, n = 2:
                          h' = A w - beta |w| |h| h - gamma w h^2, beta = gamma = A / (2 F^2),
                          A = F / delta, pre-sliding displacement delta drawn in [0.1, 0.5] mm
                          [Dahl, n = 1]
unmodelled_mode           a secondary rotor on a flexible coupling to the screw: driven by the
                          relative motion z (m_2 u'' = k_2 (z - u) + c_2 (z' - u')), strength
                          m_2, f_mode drawn in [3, 18] Hz, zeta in [0.02, 0.1]
                          [a mode driven by z'' + drive_base y'': the rotor is the library's
                          drive_base = 0 case in another parametrisation (m_2, k_2, c_2);
                          the library's default prior centres on 0.5, between mass and screw]
inertia_error             extra mass dm on the oscillating mass: m and M both change, so the
                          drive -m y'' changes too; sign drawn [M + dM, m + m_share dM:
                          the generator's case is m_share = 1]
========================= ====================================================================

Effect-free scenarios (``none_tanh``, ``none_linear``; r = 0) carry no effect: they measure the
diagnosis's false-alarm rate.

Besides the calibrated ratio, each scenario's truth records how the effect hides:
``peak_to_noise`` (largest |c(t)| over the noise RMS; the effect is called *invisible* in the
time history when it is below 3, i.e. inside the band the noise itself fills),
``window_rms_to_noise`` (largest 1 s RMS of c over the noise RMS), ``filter_removed_share``
(share of the contribution's energy the 20 Hz low-pass removed: masked by the filter) and
``unabsorbed_to_noise`` (RMS of c after the baseline's free parameters (c_m, F_c, beta) absorb
what they can, by linearised least squares, over the noise RMS: what is left after masking
by friction and damping).
"""

from __future__ import annotations

import logging
import math
import zlib
from collections.abc import Callable, Mapping
from dataclasses import asdict, dataclass, field, replace
from typing import Any

import numba as nb
import numpy as np
import pandas as pd
from scipy import signal

from harvester.synthetic import rig
from harvester.data.signals import butterworth_sos, lowpass

log = logging.getLogger("harvester.synthetic.scenarios")

#: Peak |contribution| below this many noise RMS counts as invisible in the time history.
INVISIBLE_PEAK = 3.0
#: Relative accuracy of the calibrated contribution ratio.
CALIBRATION_RTOL = 0.005
#: Regularising velocity (m/s) of the generator's sign functions (the library uses 1 mm/s tanh).
SIGN_EPS = 2.0e-4

# Generator law codes (compiled right-hand side below).
NONE, STRIBECK, ASYMMETRIC, POWER_DAMPING, POWER_SPRING, HERTZ_STOP, BACKLASH, BOUC_WEN, \
    ROTOR_MODE, EXTRA_MASS, KARNOPP = range(11)


# --------------------------------------------------------------------------- the device


@dataclass(frozen=True)
class Device:
    """Baseline device of eq. (1): masses (kg), k (N/m), c_m (N s/m), tanh friction F_c (N), beta (s/m).

    ``F_c = 0`` is the linear device.
    """

    M: float = 12.8
    m: float = 8.0
    k: float = 250.0
    c_m: float = 109.5
    F_c: float = 11.86
    beta: float = 88.35

    @classmethod
    def from_rig(cls, rig_cfg: Mapping[str, Any], baseline: str) -> "Device":
        """The study's rig device (config ``rig``) as the ``tanh`` or ``linear`` baseline."""
        fr = rig_cfg["friction"]
        tanh = baseline == "tanh"
        if baseline not in ("tanh", "linear"):
            raise ValueError(f"baseline must be 'tanh' or 'linear', got {baseline!r}")
        return cls(M=float(rig_cfg["M"]), m=float(rig_cfg["m"]), k=float(rig_cfg["k"]),
                   c_m=float(rig_cfg["c_m"]), F_c=float(fr["F_c"]) if tanh else 0.0,
                   beta=float(fr["beta"]))

    @property
    def baseline(self) -> str:
        return "tanh" if self.F_c > 0 else "linear"

    @property
    def known(self) -> dict[str, float]:
        """Parameters the diagnosis takes as known (Table 1: M, m, k)."""
        return {"M": self.M, "m": self.m, "k": self.k}

    def free_values(self) -> dict[str, float]:
        """True values of the baseline's identified parameters."""
        out = {"c_m": self.c_m}
        if self.F_c > 0:
            out.update(F_c=self.F_c, beta=self.beta)
        return out


@nb.njit(cache=True)
def _sgn_eps(w, eps):
    return w / math.sqrt(w * w + eps * eps)


@nb.njit(cache=True)
def _law_forces(s, yb, m, z, v, w, f_screw, f_mass, code, amp, shape, ds):
    """(f_screw, f_mass) in N with the generator law ``code`` added (module docstring's
    forms); a law with states of its own writes their rates into ds[2:]."""
    if code == KARNOPP:
        if abs(w) < shape[0]:  # stuck: friction holds the applied force up to breakaway
            applied = -m * yb - f_mass - f_screw
            f_screw += min(max(applied, -amp), amp)
        else:
            f_screw += amp if w > 0 else -amp
    elif code == STRIBECK:
        f_screw += amp * math.exp(-abs(w) / shape[0]) * _sgn_eps(w, SIGN_EPS)
    elif code == ASYMMETRIC:
        f_screw += amp * abs(math.tanh(shape[0] * w))
    elif code == POWER_DAMPING:
        f_screw += amp * abs(w) ** shape[0] * (1.0 if w >= 0 else -1.0)
    elif code == POWER_SPRING:
        f_mass += amp * abs(z) ** shape[0] * (1.0 if z >= 0 else -1.0)
    elif code == HERTZ_STOP:
        d = abs(z) - shape[0]
        if d > 0.0:
            f_mass += amp * d ** 1.5 * (1.0 if z >= 0 else -1.0)
    elif code == BOUC_WEN:
        h = s[2]
        f_screw += h
        if amp > 0.0:
            a = amp / shape[0]  # initial stiffness F / delta
            b = 0.5 * a / (amp * amp)
            ds[2] = a * w - b * abs(w) * abs(h) * h - b * w * h * h
        else:
            ds[2] = 0.0
    elif code == ROTOR_MODE:
        wn = 2.0 * math.pi * shape[0]
        zeta = shape[1]
        u_acc = wn * wn * (z - s[2]) + 2.0 * zeta * wn * (v - s[3])  # coupling force / m_2
        f_screw += amp * u_acc
        ds[2] = s[3]
        ds[3] = u_acc
    return f_screw, f_mass


@nb.njit(cache=True)
def _backlash_rates(s, yb, M, m, f_screw, f_mass, gap, shape, ds):
    """z'' (m/s^2) of the mass m (z, z') and the screw side J = M - m (r, r' = s[2], s[3]) in
    contact across a gap (m): delta = |z - r| - gap; Tsuji contact force k_c delta^1.5 +
    c_c delta^0.25 delta' (continuous at touch-down), compressive only. Writes ds[1:]."""
    jq = M - m
    d = s[0] - s[2]
    dd = s[1] - s[3]
    sg = 1.0 if d >= 0 else -1.0
    pen = abs(d) - gap
    fb = 0.0
    if pen > 0.0:
        fb = sg * max(shape[0] * pen ** 1.5 + shape[1] * pen ** 0.25 * sg * dd, 0.0)
    acc = (-m * yb - f_mass - fb) / m
    ds[1] = acc
    ds[2] = s[3]
    ds[3] = (fb - f_screw) / jq
    return acc


@nb.njit(cache=True)
def _rhs(s, yb, dev, code, amp, shape, ds):
    """ds = time derivative of the state s; returns the mass's relative acceleration z''.

    dev = (M, m, k, c_m, F_c, beta); s = (z, z', extra states of the law).
    """
    M, m, k, c, Fc, beta = dev[0], dev[1], dev[2], dev[3], dev[4], dev[5]
    if code == EXTRA_MASS:
        M += amp
        m += amp
    z = s[0]
    v = s[1]
    w = v
    if code == BACKLASH:
        w = s[3]  # screw-side velocity
    f_screw, f_mass = _law_forces(s, yb, m, z, v, w, c * w + Fc * math.tanh(beta * w), k * z,
                                  code, amp, shape, ds)
    ds[0] = v
    if code == BACKLASH:
        return _backlash_rates(s, yb, M, m, f_screw, f_mass, amp, shape, ds)
    acc = (-m * yb - f_screw - f_mass) / M
    ds[1] = acc
    return acc


@nb.njit(cache=True)
def _integrate(yb, dt, dev, code, amp, shape, n_states, n_sub):
    """Classical RK4 from rest, ``n_sub`` steps per sample of y'' (linear between samples);
    returns z'' and z at each sample."""
    n = yb.shape[0]
    s = np.zeros(n_states)
    k1 = np.zeros(n_states)
    k2 = np.zeros(n_states)
    k3 = np.zeros(n_states)
    k4 = np.zeros(n_states)
    tmp = np.zeros(n_states)
    out = np.empty(n)
    zz = np.zeros(n)
    out[0] = _rhs(s, yb[0], dev, code, amp, shape, k1)
    h = dt / n_sub
    for i in range(n - 1):
        dy = (yb[i + 1] - yb[i]) / n_sub
        for j in range(n_sub):
            ya = yb[i] + j * dy
            _rhs(s, ya, dev, code, amp, shape, k1)
            for e in range(n_states):
                tmp[e] = s[e] + 0.5 * h * k1[e]
            _rhs(tmp, ya + 0.5 * dy, dev, code, amp, shape, k2)
            for e in range(n_states):
                tmp[e] = s[e] + 0.5 * h * k2[e]
            _rhs(tmp, ya + 0.5 * dy, dev, code, amp, shape, k3)
            for e in range(n_states):
                tmp[e] = s[e] + h * k3[e]
            _rhs(tmp, ya + dy, dev, code, amp, shape, k4)
            for e in range(n_states):
                s[e] += h / 6.0 * (k1[e] + 2.0 * k2[e] + 2.0 * k3[e] + k4[e])
        out[i + 1] = _rhs(s, yb[i + 1], dev, code, amp, shape, k1)
        zz[i + 1] = s[0]
    return out, zz


#: RK4 steps per sample of the simulation grid, by law (the stiff Hertzian backlash contact).
SUBSTEPS = {BACKLASH: 8}


def device_motion(y_dd: np.ndarray, fs: float, device: Device, code: int = NONE,
                  amplitude: float = 0.0, shape: tuple[float, ...] = (), substeps: int = 0
                  ) -> tuple[np.ndarray, np.ndarray]:
    """(z'' in m/s^2, z in m) of the device carrying one generator law, from rest, on the grid
    of y''. ``code`` a law of this module, ``amplitude`` its strength, ``shape`` its fixed
    parameters; ``substeps`` RK4 steps per sample (0: :data:`SUBSTEPS` or 1).
    """
    y = np.ascontiguousarray(y_dd, dtype=np.float64)
    n_states = {BOUC_WEN: 3, ROTOR_MODE: 4, BACKLASH: 4}.get(code, 2)
    dev = np.array([device.M, device.m, device.k, device.c_m, device.F_c, device.beta])
    sh = np.zeros(4)
    sh[:len(shape)] = shape
    n_sub = int(substeps) or SUBSTEPS.get(code, 1)
    acc, z = _integrate(y, 1.0 / fs, dev, int(code), float(amplitude), sh, n_states, n_sub)
    if not np.all(np.isfinite(acc)):
        raise FloatingPointError(f"generator law {code} at strength {amplitude} blew up")
    return acc, z


def device_acceleration(y_dd: np.ndarray, fs: float, device: Device, code: int = NONE,
                        amplitude: float = 0.0, shape: tuple[float, ...] = (),
                        substeps: int = 0) -> np.ndarray:
    """z'' (m/s^2) of :func:`device_motion`."""
    return device_motion(y_dd, fs, device, code, amplitude, shape, substeps)[0]


# --------------------------------------------------------------------------- families


@dataclass(frozen=True)
class Family:
    """How one library effect is generated: law, strength parameter, shape draw, baseline.

    ``shapes(rng, motion)`` draws the fixed shape parameters of one seed (dict name -> value)
    given the baseline (``motion``: its displacement ``z`` on the output grid and its friction
    slope ``beta``). ``signed``: the strength's sign is drawn per seed (+ or -).
    ``guess``: a strength of the right order to start the calibration.
    """

    effect: str
    code: int
    strength: str
    unit: str
    form: str
    library_form: str
    guess: float
    baseline: str = "tanh"
    signed: bool = False
    shapes: Callable[[np.random.Generator, Mapping[str, Any]],
                     dict[str, float]] = field(default=lambda rng, motion: {}, repr=False)
    shape_order: tuple[str, ...] = ()

    def shape_vector(self, shape: Mapping[str, float]) -> tuple[float, ...]:
        return tuple(float(shape[k]) for k in self.shape_order)


def _loguniform(rng: np.random.Generator, lo: float, hi: float) -> float:
    return float(np.exp(rng.uniform(np.log(lo), np.log(hi))))


def _stop_gap(rng, motion):
    q = rng.uniform(0.7, 0.9)
    z = motion["z"]
    return {"gap_quantile": q, "gap": float(np.quantile(np.abs(z - np.median(z)), q))}


FAMILIES: dict[str, Family] = {f.effect: f for f in (
    Family("coulomb_friction", KARNOPP, "F_coulomb", "N",
           "linear device + Coulomb friction with stiction (Karnopp): F sgn(w) while sliding, "
           "the applied force up to F while |w| < 0.5 mm/s",
           "F_coulomb tanh(w / 1 mm/s)", guess=0.3, baseline="linear",
           shapes=lambda rng, motion: {"v_karnopp": 5e-4}, shape_order=("v_karnopp",)),
    Family("stribeck_friction", STRIBECK, "F_stribeck", "N",
           "F exp(-|w| / v_s) sgn_e(w) (exponent 1)",
           "F_stribeck exp(-|w / v_stribeck|^delta_stribeck) sgn(w)", guess=0.5,
           shapes=lambda rng, motion: {"v_s": _loguniform(rng, 1e-3, 8e-3)},
           shape_order=("v_s",)),
    Family("asymmetric_friction", ASYMMETRIC, "A", "N",
           "A |tanh(beta w)| (friction amplitude F_c + A up, F_c - A down; beta the baseline's)",
           "F_asym tanh(w / v_asym)^2", guess=0.2, signed=True,
           shapes=lambda rng, motion: {"beta_asym": motion["beta"]}, shape_order=("beta_asym",)),
    Family("quadratic_damping", POWER_DAMPING, "c_power", "N (s/m)^1.8",
           "c |w|^1.8 sgn(w)", "c_quad w |w|", guess=500.0,
           shapes=lambda rng, motion: {"exponent": 1.8}, shape_order=("exponent",)),
    Family("cubic_stiffness", POWER_SPRING, "k_power", "N/m^2.5",
           "k |z|^2.5 sgn(z) (progressive spring, hardening)",
           "k_cubic z^3", guess=1e6,
           shapes=lambda rng, motion: {"exponent": 2.5}, shape_order=("exponent",)),
    Family("end_stop", HERTZ_STOP, "k_hertz", "N/m^1.5",
           "k (|z| - gap)_+^1.5 sgn(z) (Hertzian stop), gap at a quantile of |z| drawn in "
           "[0.7, 0.9]", "k_stop (|z| - gap_stop)_+ sgn(z)", guess=1e5,
           shapes=_stop_gap, shape_order=("gap",)),
    Family("backlash", BACKLASH, "gap", "m",
           "gap in the screw-nut coupling; Tsuji contact k_c delta^1.5 + c_c delta^0.25 delta' "
           "(compressive), k_c = 1e11 N/m^1.5, c_c = 1e5 N s/m^1.25",
           "k_backlash dz(d, gap) + c_b d' in contact (linear, Kelvin-Voigt)", guess=2e-5,
           shapes=lambda rng, motion: {"k_contact": 1e11, "c_contact": 1e5},
           shape_order=("k_contact", "c_contact")),
    Family("hysteresis", BOUC_WEN, "F_hyst", "N",
           "Bouc-Wen n = 2: h' = (F/delta) w - beta |w||h|h - gamma w h^2, "
           "beta = gamma = 1/(2 F delta); pre-sliding displacement delta drawn in [0.1, 0.5] mm",
           "Dahl h' = (F_hyst / delta_hyst) (w - |w| h / F_hyst)", guess=0.3,
           shapes=lambda rng, motion: {"delta": _loguniform(rng, 1e-4, 5e-4)},
           shape_order=("delta",)),
    Family("unmodelled_mode", ROTOR_MODE, "mass_2", "kg",
           "secondary rotor (equivalent mass m_2) on a flexible coupling to the screw, "
           "f_mode drawn in [3, 18] Hz, zeta in [0.02, 0.1], driven by z",
           "mode driven by z'' + drive_base y''", guess=0.05,
           shapes=lambda rng, motion: {"f_mode": _loguniform(rng, 3.0, 18.0),
                                       "zeta": rng.uniform(0.02, 0.1)},
           shape_order=("f_mode", "zeta")),
    Family("inertia_error", EXTRA_MASS, "dm", "kg",
           "extra mass dm on the oscillating mass (m and M both + dm)",
           "M -> M + dM, m -> m + m_share dM",
           guess=0.05, signed=True),
)}

#: Effect-free scenario names and their baseline.
EFFECT_FREE: dict[str, str] = {"none_tanh": "tanh", "none_linear": "linear"}


def baseline_of(effect: str) -> str:
    """The baseline structure ('tanh' or 'linear') of a scenario's effect."""
    if effect in EFFECT_FREE:
        return EFFECT_FREE[effect]
    try:
        return FAMILIES[effect].baseline
    except KeyError:
        raise KeyError(f"unknown scenario effect {effect!r}; known: "
                       f"{sorted(FAMILIES) + sorted(EFFECT_FREE)}") from None


# --------------------------------------------------------------------------- settings


@dataclass(frozen=True)
class ScenarioSettings:
    """The virtual test: excitation, sensors, chain, record length (config ``rig``, ``preprocess``,
    ``detection.scenario``)."""

    duration_s: float = 30.0
    fs: float = 256.0
    oversample: int = 16
    noise_m_s2: float = 0.04  # RMS of each accelerometer's white noise
    peak_m_s2: float = 4.0
    cutoff_hz: float = 15.0
    excitation_order: int = 4
    lowpass_hz: float = 20.0
    filter_order: int = 8
    lead_in_s: float = 1.0
    seed: int = 0

    @classmethod
    def from_config(cls, config: Mapping[str, Any], **overrides: Any) -> "ScenarioSettings":
        """From the study's config (rig, preprocess) and ``detection.scenario``."""
        r, p = config["rig"], config["preprocess"]
        det = config.get("detection", {}).get("scenario", {})
        s = cls(fs=float(r["daq"]["sampling_rate_hz"]), oversample=int(r["daq"]["oversample"]),
                noise_m_s2=float(r["sensors"]["noise_m_s2"]),
                peak_m_s2=float(r["excitation"]["peak_m_s2"]),
                cutoff_hz=float(r["excitation"]["cutoff_hz"]),
                excitation_order=int(r["excitation"]["order"]),
                lowpass_hz=float(p["lowpass_hz"]), filter_order=int(p["filter_order"]))
        return replace(s, **{k: v for k, v in {**det, **overrides}.items()
                             if k in cls.__dataclass_fields__})

    @property
    def n(self) -> int:
        return int(round(self.duration_s * self.fs))

    @property
    def lead_in(self) -> int:
        return int(round(self.lead_in_s * self.fs))

    def noise_rms(self) -> float:
        """Expected RMS (m/s^2) of the noise in the recorded z'': both sensors, low-passed.

        sqrt(2) sigma_sensor sqrt(g), g = mean over (0, fs/2) of |H(f)|^4, |H| the Butterworth
        magnitude (the zero-phase filter squares it, and power squares it again).
        """
        sos = butterworth_sos(self.fs, self.lowpass_hz, self.filter_order)
        _, h = signal.sosfreqz(sos, worN=1 << 15, fs=self.fs)
        return float(np.sqrt(2.0) * self.noise_m_s2 * np.sqrt(np.mean(np.abs(h) ** 4)))


# --------------------------------------------------------------------------- one scenario


@dataclass
class Excitation:
    """The shaker's y'' on the simulation grid (rest for ``half`` samples first), and the rate."""

    y_fine: np.ndarray
    fs_fine: float
    oversample: int
    n_out: int

    def decimate(self, x_fine: np.ndarray) -> np.ndarray:
        """The DAQ's anti-alias filter and decimation to the output rate (``rig.decimate``)."""
        return rig.decimate(x_fine, self.oversample, self.n_out)


def excitation(settings: ScenarioSettings, seed: int) -> tuple[Excitation, np.random.Generator,
                                                                np.random.Generator]:
    """Seed -> (excitation, base-sensor noise stream, mass-sensor noise stream).

    The same seed gives the same excitation and noise for every effect and ratio (common random
    numbers), so rates at different ratios compare like with like.
    """
    exc_ss, base_ss, mass_ss = np.random.SeedSequence([settings.seed, seed]).spawn(3)
    os_ = settings.oversample
    fs_fine = settings.fs * os_
    half = rig.AA_HALF_OUTPUT_SAMPLES * os_
    n_rec = settings.n * os_
    y = np.zeros(half + n_rec + half)
    y[half:] = rig.base_excitation(n_rec + half, fs_fine, settings.cutoff_hz,
                                   settings.excitation_order, settings.peak_m_s2,
                                   np.random.default_rng(exc_ss), n_scale=n_rec)
    return (Excitation(y, fs_fine, os_, settings.n), np.random.default_rng(base_ss),
            np.random.default_rng(mass_ss))


def shape_rng(settings: ScenarioSettings, effect: str, seed: int) -> np.random.Generator:
    """The stream that draws an effect's shape (and sign) for one seed."""
    return np.random.default_rng([settings.seed, seed, zlib.crc32(effect.encode())])


class Contribution:
    """c(strength) = LP[decimated z''(with) - z''(without)] for one family, shape and excitation."""

    def __init__(self, family: Family, shape: tuple[float, ...], exc: Excitation,
                 device: Device, settings: ScenarioSettings, acc_without_fine: np.ndarray):
        self.family, self.shape, self.exc, self.device, self.settings = (family, shape, exc,
                                                                         device, settings)
        self.without = acc_without_fine
        self.evaluations = 0

    def fine(self, strength: float) -> np.ndarray:
        return device_acceleration(self.exc.y_fine, self.exc.fs_fine, self.device,
                                   self.family.code, strength, self.shape)

    def series(self, strength: float) -> tuple[np.ndarray, np.ndarray]:
        """(decimated, low-passed) contribution over the whole record."""
        self.evaluations += 1
        raw = self.exc.decimate(self.fine(strength) - self.without)
        s = self.settings
        return raw, lowpass(raw, s.fs, s.lowpass_hz, s.filter_order)

    def rms(self, strength: float) -> float:
        _, c = self.series(strength)
        return float(np.sqrt(np.mean(c[self.settings.lead_in:] ** 2)))


def calibrate(contribution: Callable[[float], float], target: float, guess: float,
              rtol: float = CALIBRATION_RTOL, max_evaluations: int = 60
              ) -> tuple[float, float, int]:
    """Strength s >= 0 with contribution(s) = target (relative ``rtol``): (s, achieved, evals).

    Brackets the target by factors of 4 from ``guess``, then a secant on (log s, log c) kept
    inside the bracket (bisection in log s when the secant leaves it). The contribution must
    grow with the strength (it does for every family over the ranges used).
    """
    evals = 0

    def f(s: float) -> float:
        nonlocal evals
        evals += 1
        return contribution(s)

    s, c = guess, f(guess)
    lo = hi = None
    for _ in range(30):
        if c < target:
            lo = (s, c)
            if hi is not None:
                break
            s *= 4.0
        else:
            hi = (s, c)
            if lo is not None:
                break
            s /= 4.0
        c = f(s)
        if abs(c / target - 1.0) <= rtol:
            return s, c, evals
    if lo is None or hi is None:
        raise RuntimeError(f"could not bracket a contribution of {target:.3g} "
                           f"(last strength {s:.3g} gave {c:.3g})")
    best = lo if abs(lo[1] / target - 1) < abs(hi[1] / target - 1) else hi
    while evals < max_evaluations:
        (s0, c0), (s1, c1) = lo, hi
        ls0, ls1 = math.log(s0), math.log(s1)
        if c0 > 0 and c1 > c0:
            x = ls0 + (math.log(target) - math.log(c0)) * (ls1 - ls0) / (math.log(c1) - math.log(c0))
        else:
            x = 0.5 * (ls0 + ls1)
        if not ls0 < x < ls1:
            x = 0.5 * (ls0 + ls1)
        # keep both ends moving (Illinois-like): avoid crawling from one side
        x = min(max(x, ls0 + 0.02 * (ls1 - ls0)), ls1 - 0.02 * (ls1 - ls0))
        s = math.exp(x)
        c = f(s)
        if abs(c / target - 1.0) < abs(best[1] / target - 1.0):
            best = (s, c)
        if abs(c / target - 1.0) <= rtol:
            return s, c, evals
        if c < target:
            lo = (s, c)
        else:
            hi = (s, c)
    log.warning("calibration stopped at %d evaluations: %.4g of %.4g", evals, best[1], target)
    return best[0], best[1], evals


def _baseline_sensitivities(exc: Excitation, device: Device, settings: ScenarioSettings
                            ) -> np.ndarray:
    """d LP[z''] / d (c_m, F_c, beta) of the baseline (central differences), (n_out, P)."""
    cols = []
    steps = {"c_m": 0.01 * device.c_m}
    if device.F_c > 0:
        steps.update(F_c=0.01 * device.F_c, beta=0.01 * device.beta)
    for name, h in steps.items():
        up = device_acceleration(exc.y_fine, exc.fs_fine,
                                 replace(device, **{name: getattr(device, name) + h}))
        down = device_acceleration(exc.y_fine, exc.fs_fine,
                                   replace(device, **{name: getattr(device, name) - h}))
        d = exc.decimate((up - down) / (2 * h))
        cols.append(lowpass(d, settings.fs, settings.lowpass_hz, settings.filter_order))
    return np.column_stack(cols)


def _window_rms_max(x: np.ndarray, width: int) -> float:
    n = (len(x) // width) * width
    if n == 0:
        return float(np.sqrt(np.mean(x**2)))
    return float(np.max(np.sqrt(np.mean(x[:n].reshape(-1, width) ** 2, axis=1))))


@dataclass
class Scenario:
    """A generated scenario: the recording (time, base_acc, rel_acc), its truth, and c(t)."""

    recording: pd.DataFrame
    truth: dict[str, Any]
    contribution: np.ndarray  # LP[z''(with) - z''(without)] (m/s^2), zeros when effect-free


def _scenario_device(effect: str, ratio: float, device: Device | None,
                     rig_cfg: Mapping[str, Any] | None) -> tuple[Device, str]:
    """(device, baseline) of a scenario, checked against its effect and ratio."""
    baseline = baseline_of(effect)
    if device is None:
        device = (Device.from_rig(rig_cfg, baseline) if rig_cfg is not None
                  else Device() if baseline == "tanh" else Device(F_c=0.0))
    if device.baseline != baseline:
        raise ValueError(f"{effect} needs the {baseline} baseline, device is {device.baseline}")
    if effect in EFFECT_FREE and ratio != 0:
        raise ValueError(f"effect-free scenario {effect} needs ratio 0, got {ratio}")
    if effect not in EFFECT_FREE and not ratio > 0:
        raise ValueError(f"scenario {effect} needs a positive ratio, got {ratio}")
    return device, baseline


def _calibrated_effect(fam: Family, effect: str, seed: int, settings: ScenarioSettings,
                       exc: Excitation, device: Device, without: np.ndarray,
                       z_fine: np.ndarray, target: float, noise_rms: float
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
    """The effect at the strength whose contribution's RMS is ``target`` (m/s^2): (z'' on the
    simulation grid, raw and low-passed contribution on the output grid, truth entries)."""
    motion = {"z": exc.decimate(z_fine), "beta": device.beta}
    srng = shape_rng(settings, effect, seed)
    shape = fam.shapes(srng, motion)
    sign = float(srng.choice([-1.0, 1.0])) if fam.signed else 1.0
    contrib = Contribution(fam, fam.shape_vector(shape), exc, device, settings, without)
    strength, _, evals = calibrate(
        lambda s: contrib.rms(sign * s if fam.signed else s), target, fam.guess)
    strength *= sign
    acc_fine = contrib.fine(strength)
    raw, contribution = contrib.series(strength)
    truth = {
        "form": fam.form, "library_form": fam.library_form, "strength_name": fam.strength,
        "strength_unit": fam.unit, "strength": float(strength), "shape": shape,
        "calibration_evaluations": evals,
        "zero_strength_ratio": (contrib.rms(0.0) / noise_rms if fam.code == BACKLASH else 0.0),
    }
    return acc_fine, raw, contribution, truth


def _how_it_hides(contribution: np.ndarray, raw: np.ndarray, settings: ScenarioSettings,
                  noise_rms: float) -> dict[str, Any]:
    """The truth's measures of how visible the contribution is (module docstring)."""
    c_w = contribution[settings.lead_in:]
    c_rms = float(np.sqrt(np.mean(c_w**2)))
    raw_energy = float(np.sum(raw[settings.lead_in:] ** 2))
    peak = float(np.max(np.abs(c_w))) / noise_rms if c_rms > 0 else 0.0
    return {
        "contribution_rms": c_rms,
        "contribution_ratio": c_rms / noise_rms,
        "peak_to_noise": peak,
        "window_rms_to_noise": _window_rms_max(c_w, int(round(settings.fs))) / noise_rms,
        "filter_removed_share": (1.0 - float(np.sum(c_w**2)) / raw_energy
                                 if raw_energy > 0 else 0.0),
        "invisible": bool(peak < INVISIBLE_PEAK),
    }


def _unabsorbed(exc: Excitation, device: Device, settings: ScenarioSettings,
                contribution: np.ndarray, noise_rms: float) -> dict[str, Any]:
    """What the baseline's c_m, F_c, beta absorb of the contribution (linearised least
    squares over the analysis window) and the RMS left, over the noise RMS."""
    c_w = contribution[settings.lead_in:]
    jac = _baseline_sensitivities(exc, device, settings)[settings.lead_in:]
    beta, *_ = np.linalg.lstsq(jac, c_w, rcond=None)
    left = c_w - jac @ beta
    return {"unabsorbed_to_noise": float(np.sqrt(np.mean(left**2))) / noise_rms,
            "absorbed_shift": dict(zip(["c_m", "F_c", "beta"], (-beta).tolist()))}


def _record(exc: Excitation, acc_fine: np.ndarray, settings: ScenarioSettings,
            rng_base: np.random.Generator, rng_mass: np.random.Generator
            ) -> tuple[pd.DataFrame, float]:
    """(recording, realised RMS of the noise in its z'' over the analysis window, m/s^2): both
    sensors' noise, then the study's zero-phase low-pass on both channels."""
    y_out = exc.decimate(exc.y_fine)
    z_out = exc.decimate(acc_fine)
    base = y_out + settings.noise_m_s2 * rng_base.standard_normal(settings.n)
    mass = y_out + z_out + settings.noise_m_s2 * rng_mass.standard_normal(settings.n)
    lp = dict(fs=settings.fs, cutoff_hz=settings.lowpass_hz, order=settings.filter_order)
    noise_rel = lowpass((mass - y_out - z_out) - (base - y_out), **lp)
    rec = pd.DataFrame({"time": np.arange(settings.n) / settings.fs,
                        "base_acc": lowpass(base, **lp), "rel_acc": lowpass(mass - base, **lp)})
    return rec, float(np.sqrt(np.mean(noise_rel[settings.lead_in:] ** 2)))


def make_scenario(effect: str, ratio: float, seed: int, settings: ScenarioSettings,
                  device: Device | None = None, rig_cfg: Mapping[str, Any] | None = None,
                  masking: bool = True) -> Scenario:
    """Generate one scenario: calibrate the effect's strength, then record with noise.

    ``device`` defaults to :class:`Device` (the Table 5 tanh device or its linear version, by
    the effect's baseline), or the config's rig device when ``rig_cfg`` is given. ``masking``:
    also compute the share of the contribution the baseline's parameters absorb (3-6 more
    simulations).
    """
    device, baseline = _scenario_device(effect, ratio, device, rig_cfg)
    exc, rng_base, rng_mass = excitation(settings, seed)
    noise_rms = settings.noise_rms()
    fam = FAMILIES.get(effect)
    without, z_fine = device_motion(exc.y_fine, exc.fs_fine, device)
    truth: dict[str, Any] = {
        "effect": effect, "ratio": float(ratio), "seed": int(seed), "baseline": baseline,
        "device": asdict(device), "known": device.known, "baseline_truth": device.free_values(),
        "noise_rms": noise_rms, "sensor_noise_m_s2": settings.noise_m_s2,
        "settings": asdict(settings),
    }
    acc_fine, raw, contribution = without, np.zeros(settings.n), np.zeros(settings.n)
    if fam is not None:
        acc_fine, raw, contribution, effect_truth = _calibrated_effect(
            fam, effect, seed, settings, exc, device, without, z_fine, ratio * noise_rms,
            noise_rms)
        truth.update(effect_truth)
    truth.update(_how_it_hides(contribution, raw, settings, noise_rms))
    if masking and truth["contribution_rms"] > 0:
        truth.update(_unabsorbed(exc, device, settings, contribution, noise_rms))
    rec, truth["noise_rms_realised"] = _record(exc, acc_fine, settings, rng_base, rng_mass)
    log.info("scenario %s r=%g seed=%d: %s", effect, ratio, seed,
             ", ".join(f"{k}={truth[k]:.4g}" for k in ("contribution_ratio", "peak_to_noise")
                       if k in truth) + (f", {truth['strength_name']}={truth['strength']:.4g}"
                                         if "strength" in truth else ""))
    return Scenario(rec, truth, contribution)


def write_scenario(scenario: Scenario, csv_path, truth_path) -> None:
    """Recording as a converted recording CSV (``daq.write_recording``) and the truth as JSON."""
    from harvester.data.daq import write_recording
    from harvester.data.fileio import write_json

    write_recording(scenario.recording, csv_path)
    write_json(scenario.truth, truth_path)
