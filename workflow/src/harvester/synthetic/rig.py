"""The virtual rig: SIMULATED raw recordings of the ball-screw harvester (not the paper's data).

Green et al. (2015) did not publish their recordings, so this module plays the test rig of
their Figure 2: a shaker, the device of eq. (1) with a friction law richer than the models
identified later, a rocking mode of the mass, two DC-coupled MEMS accelerometers and a DAQ.
It is deliberately independent of the identification code (``simulate.py``, ``physics.py``).
Its electrical half (generator, star load, voltmeter; the loaded records) is
``harvester.synthetic.electrical``, which reuses this module's excitation, sensors and DAQ.

Device, eq. (1), z = x - y positive up:

    M z'' + c_m z' + k z + f = -m y''.

Friction f (N) of the rig, with F_hold = -m y'' - k z the force the friction must hold at rest:

* sliding (z' != 0): f = sgn(z') max(F_s0, F_c tanh(beta |z'|)): the paper's tanh law, with a
  Coulomb floor F_s0 (default 0, i.e. exactly F_c tanh(beta z')).
* sticking, with static friction that grows with the time at rest (dwell), as measured for
  metal contacts since Rabinowicz (1951): F_st(t) = F_s0 + (F_s - F_s0) (1 - exp(-t / dwell_s)).
  The mass sticks when z' reaches zero (or |z'| < v_stick) with |F_hold| <= F_st(0) = F_s0, and
  breaks away when |F_hold| exceeds F_st(t). After a long hold (the static tests of eqs. 4-5)
  the full F_s acts; at the millisecond velocity reversals of the shaker records it does not, so
  those records follow the tanh law. This reconciles the paper's two observations: 8.4 N from
  the static tests, F_c = 11.86 N with beta = 88 s/m from the dynamic records.

Method: fixed-step classical RK4 at the internal rate (``oversample`` x 256 Hz) with y''
linearly interpolated within each step, compiled with numba. Stick-slip events are located
inside the step: a breakaway at the exact instant |F_hold| reaches F_s (F_hold is linear in time
while stuck), a velocity reversal by linear interpolation of z', after which the step is
re-integrated in two parts so that RK4 never straddles the sign change of f (with F_s = 0 the
law is smooth and no events are located). The velocity discarded on sticking from the band
|z'| < v_stick is booked as an impulse in z''. Accelerations are sampled on the internal grid;
first-order convergence in the step near events (z within 2e-6 m of a 16x finer grid).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numba as nb
import numpy as np
import pandas as pd
from numpy.typing import NDArray
from scipy import signal

from harvester.data.daq import G

#: Half-length of the anti-alias FIR, in output samples (filter spans 2 x 24 / 256 s).
AA_HALF_OUTPUT_SAMPLES = 24
#: Anti-alias -6 dB point as a fraction of the output rate, and Kaiser window beta (~80 dB).
AA_CUTOFF_FRACTION = 0.44
AA_KAISER_BETA = 8.0
#: Time (s) the experimenter watches a released mass to see whether it stays put.
STATIC_WATCH_S = 1.0

Array = NDArray[np.float64]


@dataclass(frozen=True)
class Device:
    """Mechanical parameters of the rig (SI units): eq. (1) plus stiction."""

    M: float        # kg, effective mass, eq. (2)
    m: float        # kg, oscillating mass
    k: float        # N/m
    c_m: float      # N s/m, translational viscous coefficient b_m of eq. (1)
    F_c: float      # N, tanh friction amplitude
    beta: float     # s/m, tanh friction slope
    F_s: float      # N, static (breakaway) friction after a long dwell
    v_stick: float  # m/s, speed below which the mass may stick
    F_s0: float = 0.0     # N, static friction at zero dwell, and sliding floor
    dwell_s: float = 1.0  # s, time constant of the growth of static friction at rest

    @classmethod
    def from_config(cls, rig: Mapping[str, Any]) -> Device:
        fr = rig["friction"]
        if fr["law"] != "tanh":
            raise ValueError(f"rig friction law must be 'tanh', got {fr['law']!r}")
        return cls(M=float(rig["M"]), m=float(rig["m"]), k=float(rig["k"]),
                   c_m=float(rig["c_m"]), F_c=float(fr["F_c"]), beta=float(fr["beta"]),
                   F_s=float(fr["F_s"]), v_stick=float(fr["v_stick"]),
                   F_s0=float(fr.get("F_s0", 0.0)), dwell_s=float(fr.get("dwell_s", 1.0)))

    def static_friction(self, dwell: float) -> float:
        """Static friction (N) after ``dwell`` seconds at rest."""
        return self.F_s0 + (self.F_s - self.F_s0) * (1.0 - math.exp(-dwell / self.dwell_s))

    @property
    def v_floor(self) -> float:
        """Speed (m/s) above which the tanh law exceeds the floor F_s0; inf if it never does."""
        if self.F_s0 <= 0.0:
            return 0.0
        if self.F_s0 >= self.F_c:
            return math.inf
        return math.atanh(self.F_s0 / self.F_c) / self.beta


def session_rig(rig: Mapping[str, Any], name: str) -> dict[str, Any]:
    """The rig as record ``name`` of ``rig['records']`` ran it: the rig's sections with the
    record's ``session`` merged over them (one level down: ``{excitation: {peak_m_s2: 6.7}}``
    replaces only the peak). A session holds what the paper's shaker tests had and the other
    records need not share: the excitation level, the sensors' in-band noise, the stick
    behaviour of the contact on that day (docs/design.md, the virtual rig)."""
    out = dict(rig)
    for section, values in (rig["records"][name].get("session") or {}).items():
        if isinstance(values, Mapping):
            out[section] = {**rig.get(section, {}), **values}
        else:
            out[section] = values
    return out


def ground_truth(rig: Mapping[str, Any], record: str | None = None) -> dict[str, float]:
    """The rig's true parameters (SI units) as the config sets them (as ``record`` ran it)."""
    if record is not None:
        rig = session_rig(rig, record)
    dev = Device.from_config(rig)
    rock = rig["rocking"]
    return {
        "M": dev.M, "m": dev.m, "k": dev.k, "c_m": dev.c_m,
        "F_c": dev.F_c, "beta": dev.beta, "F_s": dev.F_s, "F_s0": dev.F_s0,
        "dwell_s": dev.dwell_s, "v_stick": dev.v_stick, "v_floor": dev.v_floor,
        "rocking_frequency_hz": float(rock["frequency_hz"]),
        "rocking_damping_ratio": float(rock["damping_ratio"]),
        "rocking_gain": float(rock["gain"]),
        "noise_m_s2": float(rig["sensors"]["noise_m_s2"]),
        "mass_extra_noise_m_s2": float(rig["sensors"].get("mass_extra_noise_m_s2", 0.0)),
        "excitation_peak_m_s2": float(rig["excitation"]["peak_m_s2"]),
    }


# --------------------------------------------------------------------------- excitation

def base_excitation(n: int, fs: float, cutoff_hz: float, order: int, peak: float,
                    rng: np.random.Generator, n_scale: int | None = None) -> Array:
    """Shaker acceleration y'' (m/s^2): Gaussian white noise through a Butterworth low-pass.

    Scaled so that max |y''| over the first ``n_scale`` samples (default all) equals ``peak``.
    """
    sos = signal.butter(order, cutoff_hz, btype="low", fs=fs, output="sos")
    y = signal.sosfilt(sos, rng.standard_normal(n))
    return y * (peak / np.max(np.abs(y[:n_scale])))


# --------------------------------------------------------------------------- mechanics

@nb.njit(cache=True)
def _friction(v, hold, F_c, beta, F_s):
    """Friction (N): Coulomb-floored tanh while sliding; at v == 0 the reaction, capped at F_s."""
    if v > 0.0:
        return max(F_s, F_c * math.tanh(beta * v))
    if v < 0.0:
        return -max(F_s, -F_c * math.tanh(beta * v))
    return min(max(hold, -F_s), F_s)


@nb.njit(cache=True)
def _acc(drive, z, v, M, k, c, F_c, beta, F_s):
    """Relative acceleration z'' (m/s^2) while sliding, eq. (1); drive = -m y'' (N)."""
    hold = drive - k * z
    return (hold - c * v - _friction(v, hold, F_c, beta, F_s)) / M


@nb.njit(cache=True)
def _rk4(z, v, h, fa, fb, M, k, c, F_c, beta, F_s):
    """One RK4 step of length h; the drive goes linearly from fa to fb over the step."""
    fm = 0.5 * (fa + fb)
    a1 = _acc(fa, z, v, M, k, c, F_c, beta, F_s)
    z2, v2 = z + 0.5 * h * v, v + 0.5 * h * a1
    a2 = _acc(fm, z2, v2, M, k, c, F_c, beta, F_s)
    z3, v3 = z + 0.5 * h * v2, v + 0.5 * h * a2
    a3 = _acc(fm, z3, v3, M, k, c, F_c, beta, F_s)
    z4, v4 = z + h * v3, v + h * a3
    a4 = _acc(fb, z4, v4, M, k, c, F_c, beta, F_s)
    return (z + h / 6.0 * (v + 2.0 * v2 + 2.0 * v3 + v4),
            v + h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4))


@nb.njit(cache=True)
def _integrate(drive, dt, z0, v0, dwell0, M, k, c, F_c, beta, F_s0, F_s, tau, v_stick):
    """Stick-slip integration of eq. (1) on the grid of ``drive``; returns z, z', z'', f, stuck.

    Sliding friction has the floor F_s0; static friction grows from F_s0 to F_s with the dwell
    time (time constant tau). The mass starts at (z0, v0), stuck for ``dwell0`` s if v0 == 0.
    """
    n = drive.size
    z = np.empty(n)
    v = np.empty(n)
    jump = np.zeros(n)
    stuck = np.zeros(n, dtype=np.bool_)
    z[0], v[0] = z0, v0
    dwell = dwell0
    thr = F_s0 + (F_s - F_s0) * (1.0 - math.exp(-dwell / tau))
    is_stuck = v0 == 0.0 and abs(drive[0] - k * z0) <= thr
    stuck[0] = is_stuck
    for i in range(n - 1):
        fa, fb = drive[i], drive[i + 1]
        if is_stuck:
            dwell += dt
            thr = F_s0 + (F_s - F_s0) * (1.0 - math.exp(-dwell / tau))
            hold_b = fb - k * z[i]
            if abs(hold_b) <= thr:
                z[i + 1], v[i + 1], stuck[i + 1] = z[i], 0.0, True
                continue
            hold_a = fa - k * z[i]  # breakaway where F_hold crosses +-thr (linear in time)
            edge = thr if hold_b > 0.0 else -thr
            th = min(max((edge - hold_a) / (hold_b - hold_a), 0.0), 1.0)
            zi, vi = _rk4(z[i], 0.0, (1.0 - th) * dt, fa + th * (fb - fa), fb,
                          M, k, c, F_c, beta, F_s0)
            is_stuck = False
        else:
            zi, vi = _rk4(z[i], v[i], dt, fa, fb, M, k, c, F_c, beta, F_s0)
            if F_s0 > 0.0 and v[i] != 0.0 and vi * v[i] <= 0.0:
                th = v[i] / (v[i] - vi)  # velocity reversal inside the step
                fm = fa + th * (fb - fa)
                zs, _ = _rk4(z[i], v[i], th * dt, fa, fm, M, k, c, F_c, beta, F_s0)
                if abs(fm - k * zs) <= F_s0:
                    zi, vi, is_stuck, dwell = zs, 0.0, True, 0.0
                else:
                    zi, vi = _rk4(zs, 0.0, (1.0 - th) * dt, fm, fb, M, k, c, F_c, beta, F_s0)
        if not is_stuck and abs(vi) < v_stick and abs(fb - k * zi) <= F_s0:
            jump[i + 1] = -vi
            vi, is_stuck, dwell = 0.0, True, 0.0
        z[i + 1], v[i + 1], stuck[i + 1] = zi, vi, is_stuck
    a = np.empty(n)
    f = np.empty(n)
    for i in range(n):
        hold = drive[i] - k * z[i]
        if stuck[i]:
            a[i], f[i] = jump[i] / dt, hold
        else:
            f[i] = _friction(v[i], hold, F_c, beta, F_s0)
            a[i] = (hold - c * v[i] - f[i]) / M
    return z, v, a, f, stuck


@dataclass(frozen=True)
class Motion:
    """Mass motion on the simulation grid: z (m), z' (m/s), z'' (m/s^2), friction f (N)."""

    z: Array
    v: Array
    acc: Array
    friction: Array
    stuck: NDArray[np.bool_]


def simulate_motion(y_dd: Array, fs: float, dev: Device, z0: float = 0.0,
                    v0: float = 0.0, dwell0: float = 0.0) -> Motion:
    """Integrate eq. (1) with the rig's stick-slip friction; y'' (m/s^2) sampled at fs (Hz).

    The mass starts at z0 (m), z' = v0 (m/s); if v0 == 0 it has been at rest for dwell0 (s).
    """
    drive = -dev.m * np.ascontiguousarray(y_dd, dtype=np.float64)
    z, v, a, f, stuck = _integrate(drive, 1.0 / fs, float(z0), float(v0), float(dwell0), dev.M,
                                   dev.k, dev.c_m, dev.F_c, dev.beta, dev.F_s0, dev.F_s,
                                   dev.dwell_s, dev.v_stick)
    return Motion(z, v, a, f, stuck)


# --------------------------------------------------------------------------- rocking mode

def rocking_acceleration(friction: Array, fs: float, M: float, rocking: Mapping[str, Any],
                         speed: Array | None = None,
                         rng: np.random.Generator | None = None) -> Array:
    """Rocking acceleration r (m/s^2) seen by the mass accelerometer, not in eq. (1).

    A second-order mode excited by the screw force on the mass, -f; the sensor sees the mode's
    acceleration, so the response rises as w^2 below resonance (40 dB/decade: little leaks
    into the 0-20 Hz band the model is fitted in) and is flat above it:

        r = gain 2 zeta s^2 / (s^2 + 2 zeta w s + w^2) (-f / M),   w = 2 pi frequency_hz,

    whose peak ratio |r| / |f / M| is ``gain`` at the rocking frequency. The balls rolling
    through the nut add a broadband excitation in proportion to the screw speed |z'|: white
    noise of RMS ``ball_pass_m_s2`` x |z'| / (0.01 m/s) added to -f / M (needs ``speed`` and
    ``rng``). Discretised by the bilinear transform.
    """
    w = 2.0 * np.pi * float(rocking["frequency_hz"])
    zeta = float(rocking["damping_ratio"])
    gain = float(rocking["gain"])
    if gain == 0.0:
        return np.zeros_like(friction)
    drive = -friction / M
    ball = float(rocking.get("ball_pass_m_s2", 0.0))
    if ball > 0.0 and speed is not None and rng is not None:
        drive = drive + ball * np.abs(speed) / 0.01 * rng.standard_normal(speed.size)
    b, a = signal.bilinear([2.0 * zeta * gain, 0.0, 0.0], [1.0, 2.0 * zeta * w, w * w], fs)
    return signal.lfilter(b, a, drive)


# --------------------------------------------------------------------------- measurement chain

def sensor_volts(acc: Array, sensor: Mapping[str, Any]) -> Array:
    """MEMS accelerometer output (V): vertical and DC-coupled, so it reads acc + 1 g.

    V = zero_g_V + sensitivity (acc / g + 1), saturating at zero_g_V +- sensitivity range_g.
    """
    sens = float(sensor["sensitivity_mV_per_g"]) / 1000.0
    zero = float(sensor["zero_g_V"])
    swing = sens * float(sensor["range_g"])
    return np.clip(zero + sens * (acc / G + 1.0), zero - swing, zero + swing)


def anti_alias_taps(oversample: int) -> Array:
    """Linear-phase FIR of the DAQ (unit DC gain): -6 dB at 0.44 x output rate, ~80 dB stop."""
    half = AA_HALF_OUTPUT_SAMPLES * oversample
    return signal.firwin(2 * half + 1, AA_CUTOFF_FRACTION * 2.0 / oversample,
                         window=("kaiser", AA_KAISER_BETA))


def decimate(x: Array, oversample: int, n_out: int) -> Array:
    """Anti-alias filter and keep every ``oversample``-th sample, delay compensated.

    ``x`` holds ``half`` samples before the first output instant and at least ``half`` after
    the last (``half`` = filter half-length), so no output sample sees padding.
    """
    h = anti_alias_taps(oversample)
    half = (h.size - 1) // 2
    y = signal.upfirdn(h, x, up=1, down=oversample)
    first = 2 * half // oversample
    out = y[first:first + n_out]
    if out.size != n_out:
        raise ValueError("signal too short for the anti-alias filter margins")
    return out


def quantise(volts: Array, bits: int, range_V: tuple[float, float]) -> Array:
    """ADC: round to the nearest of 2**bits codes over range_V, saturating at the end codes."""
    lo, hi = range_V
    lsb = (hi - lo) / 2**bits
    code = np.clip(np.rint((volts - lo) / lsb), 0, 2**bits - 1)
    return lo + code * lsb


def noise_rms_internal(noise_m_s2: float, oversample: int) -> float:
    """Internal-rate white-noise RMS (m/s^2) that leaves ``noise_m_s2`` after the DAQ filter."""
    h = anti_alias_taps(oversample)
    return noise_m_s2 / float(np.sqrt(np.sum(h * h)))


# --------------------------------------------------------------------------- records

@dataclass(frozen=True)
class RecordSimulation:
    """One simulated DAQ record: channel voltages at the output rate and the rig's truth.

    ``truth`` holds, at the output instants: ``base_acc`` (y''), ``rel_acc`` (z''),
    ``rocking`` (r) in m/s^2 through the same anti-alias filter as the channels (no noise);
    ``z`` (m), ``v`` (m/s) and ``stuck`` (bool) sampled.
    """

    name: str
    seed: int
    sampling_rate_hz: float
    time: Array
    ai0: Array
    ai1: Array
    truth: dict[str, NDArray[Any]]


def record_seed(rig: Mapping[str, Any], name: str) -> int:
    """Excitation/noise seed of a record: rig seed + the record's seed_offset."""
    return int(rig["seed"]) + int(rig["records"][name]["seed_offset"])


@dataclass(frozen=True)
class RecordGrid:
    """Sample counts of a record: ``n_out`` DAQ samples at ``fs_out`` (Hz), simulated at
    ``oversample`` x that rate with ``half`` internal samples of margin either side for the
    anti-alias filter (the rig at rest before t = 0)."""

    fs_out: float
    oversample: int
    n_out: int

    @property
    def fs(self) -> float:
        """Internal simulation rate (Hz)."""
        return self.fs_out * self.oversample

    @property
    def half(self) -> int:
        return AA_HALF_OUTPUT_SAMPLES * self.oversample

    @property
    def n_rec(self) -> int:
        return self.n_out * self.oversample

    @property
    def at(self) -> slice:
        """Internal samples at the output instants."""
        return slice(self.half, self.half + self.n_rec, self.oversample)


def record_grid(rig: Mapping[str, Any], duration_s: float) -> RecordGrid:
    """The sample grid of a ``duration_s`` record with the config's DAQ."""
    daq = rig["daq"]
    fs_out = float(daq["sampling_rate_hz"])
    return RecordGrid(fs_out, int(daq["oversample"]), int(round(duration_s * fs_out)))


def record_streams(seed: int, n: int = 4) -> list[np.random.Generator]:
    """Independent random streams of a record: excitation, base sensor, mass sensor, ball
    pass, then (n > 4) any the record adds (a shaker record: the mass channel's extra error);
    the first four do not depend on n."""
    return [np.random.default_rng(s) for s in np.random.SeedSequence(seed).spawn(n)]


def shaker_acceleration(rig: Mapping[str, Any], grid: RecordGrid,
                        rng: np.random.Generator) -> Array:
    """y'' (m/s^2) on the internal grid: zero for ``half`` samples, then the excitation."""
    exc = rig["excitation"]
    y_dd = np.zeros(grid.half + grid.n_rec + grid.half)  # rig at rest before t = 0
    y_dd[grid.half:] = base_excitation(grid.n_rec + grid.half, grid.fs, float(exc["cutoff_hz"]),
                                       int(exc["order"]), float(exc["peak_m_s2"]), rng,
                                       n_scale=grid.n_rec)
    return y_dd


def adc(rig: Mapping[str, Any], grid: RecordGrid, volts: Array) -> Array:
    """The DAQ: anti-alias filter, decimation to the output rate, 16-bit quantisation."""
    daq = rig["daq"]
    bits, range_V = int(daq["bits"]), (float(daq["range_V"][0]), float(daq["range_V"][1]))
    return quantise(decimate(volts, grid.oversample, grid.n_out), bits, range_V)


def accelerometer_channels(rig: Mapping[str, Any], grid: RecordGrid, y_dd: Array,
                           mass_terms: tuple[Array, ...], rng_base: np.random.Generator,
                           rng_mass: np.random.Generator,
                           rng_extra: np.random.Generator | None = None) -> tuple[Array, Array]:
    """DAQ voltages ai0 (shaker accelerometer) and ai1 (mass accelerometer).

    The mass accelerometer reads y'' plus ``mass_terms`` (z'', the rocking mode), added in
    that order; each sensor adds its own white noise at the internal rate (RMS ``noise_m_s2``
    over the DAQ band). The mass channel may carry a further white error of its own,
    ``mass_extra_noise_m_s2`` over the DAQ band, drawn from ``rng_extra``: the accelerometer
    rides on the moving mass, whose cable flexes and whose mount vibrates.
    """
    sens = rig["sensors"]
    sd = noise_rms_internal(float(sens["noise_m_s2"]), grid.oversample)
    base = y_dd + sd * rng_base.standard_normal(y_dd.size)
    mass = y_dd
    for term in mass_terms:
        mass = mass + term
    mass = mass + sd * rng_mass.standard_normal(y_dd.size)
    extra = float(sens.get("mass_extra_noise_m_s2", 0.0))
    if extra > 0.0:
        if rng_extra is None:
            raise ValueError("sensors.mass_extra_noise_m_s2 needs its own random stream")
        mass = mass + noise_rms_internal(extra, grid.oversample) * \
            rng_extra.standard_normal(y_dd.size)
    return adc(rig, grid, sensor_volts(base, sens)), adc(rig, grid, sensor_volts(mass, sens))


def simulate_record(rig: Mapping[str, Any], name: str,
                    duration_s: float | None = None) -> RecordSimulation:
    """Run the rig for record ``name`` from rest, with the record's session
    (:func:`session_rig`); ``duration_s`` overrides the config's length."""
    rig = session_rig(rig, name)
    duration = float(rig["records"][name]["duration_s"] if duration_s is None else duration_s)
    grid = record_grid(rig, duration)
    seed = record_seed(rig, name)
    rng_exc, rng_base, rng_mass, rng_ball, rng_extra = record_streams(seed, 5)

    y_dd = shaker_acceleration(rig, grid, rng_exc)
    dev = Device.from_config(rig)
    motion = simulate_motion(y_dd, grid.fs, dev)
    rock = rocking_acceleration(motion.friction, grid.fs, dev.M, rig["rocking"], motion.v,
                                rng_ball)
    ai0, ai1 = accelerometer_channels(rig, grid, y_dd, (motion.acc, rock), rng_base, rng_mass,
                                      rng_extra)
    os_, n_out, at = grid.oversample, grid.n_out, grid.at
    truth = {"base_acc": decimate(y_dd, os_, n_out), "rel_acc": decimate(motion.acc, os_, n_out),
             "rocking": decimate(rock, os_, n_out), "z": motion.z[at], "v": motion.v[at],
             "stuck": motion.stuck[at]}
    return RecordSimulation(name=name, seed=seed, sampling_rate_hz=grid.fs_out,
                            time=np.arange(n_out) / grid.fs_out, ai0=ai0, ai1=ai1, truth=truth)


# --------------------------------------------------------------------------- static friction test

def held_after_release(dev: Device, x0: float, hold_s: float, fs: float,
                       watch_s: float = STATIC_WATCH_S) -> bool:
    """Whether the vertical device, held at rest at x0 (m) for hold_s (s) and released, stays.

    Positions are downward-positive from the frictionless equilibrium (spring extension mg/k),
    so gravity only sets the datum and eq. (1) holds with y'' = 0. The rig's integrator is run
    for ``watch_s`` after the release, with the static friction the hold has built up.
    """
    motion = simulate_motion(np.zeros(int(watch_s * fs) + 1), fs, dev, z0=x0, dwell0=hold_s)
    return bool(motion.stuck.all())


def _largest_held(dev: Device, sign: float, start: float, st: Mapping[str, Any],
                  fs: float) -> float:
    """The experimenter's search: displace in steps from ``start`` until the mass slides."""
    step, hold = float(st["step_m"]), float(st["hold_s"])
    x = start
    while held_after_release(dev, sign * (x + step), hold, fs):
        x += step
    return sign * x


def static_friction_test(rig: Mapping[str, Any]) -> pd.DataFrame:
    """Static friction tests of eqs. (4)-(5): largest displacements at which the mass stays put.

    The experimenter holds the mass at rest, displaced DOWN, for ``hold_s`` and lets go; if it
    stays, the displacement grows by ``step_m`` (starting from a random fraction of a step) and
    the test is repeated; the last position that held is read off the scale (scatter
    N(0, reading_sd_m)) as x1 (~ +F_s/k); likewise UP for x2 (~ -F_s/k). With this
    downward-positive convention F_s ~ k (x1 - x2) / 2 (the paper's 2F_c = k(x2 - x1) measures
    x from the other side). Columns: repeat, direction ('down'/'up'), position_m.
    """
    st = rig["static_test"]
    dev = Device.from_config(rig)
    fs = float(rig["daq"]["sampling_rate_hz"]) * int(rig["daq"]["oversample"])
    rng = np.random.default_rng(int(rig["seed"]) + int(st["seed_offset"]))
    rows = []
    for repeat in range(1, int(st["repeats"]) + 1):
        for direction, sign in (("down", 1.0), ("up", -1.0)):
            start = rng.uniform(0.0, float(st["step_m"]))
            rest = _largest_held(dev, sign, start, st, fs)
            rows.append((repeat, direction, rest + rng.normal(0.0, float(st["reading_sd_m"]))))
    return pd.DataFrame(rows, columns=["repeat", "direction", "position_m"])
