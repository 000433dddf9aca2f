"""The virtual rig's electrical half: SIMULATED generator, load and voltmeter (not paper data).

Green et al. (2015, "Device description" and "Experiment") drive a three-phase brushless
generator from the sprung mass through a ball screw, connect its terminals to three variable
resistors in star (their Figure 2), and record the voltage across the generator terminals at
256 Hz beside the two accelerometers; the records they identify were all taken in open
circuit. This module adds that half to the virtual rig (``harvester.synthetic.rig``) so that
loaded records can be simulated. Like the rest of the rig it is a truth generator,
independent of the identification code (nothing from ``harvester.model`` or
``harvester.inference``).

The constants of the generator are ASSUMED: the paper gives none, and the device
descriptions it cites (Hendijanizadeh 2014; Simeone et al. 2014; Hendijanizadeh et al. 2013)
gave no numbers that could be retrieved. They are chosen to be consistent with the rig's
mechanics (``rig.M - rig.m`` = J (2 pi / l)^2) and so that the electrical damping at the
matched load is comparable to, not larger than, c_m; ``docs/virtual-rig-electrical.md`` and
``config/config.yaml`` (``rig.generator``) give the values and the reasoning.

Model (SI units; phases k = 0, 1, 2 = a, b, c; G = 2 pi / l the screw ratio, rad/m):

    theta_m = theta_0 + G z,        omega_m = G z'                   (rotor angle, speed)
    e_k = K_e omega_m sin(p theta_m - 2 pi k / 3)                    (back-EMF, abc form)
    L_s i_k' = e_k - v_N - (R_s + R_L) i_k,   v_N = (e_a + e_b + e_c) / 3
    i_a + i_b + i_c = 0                                              (star, isolated neutrals)
    T_e = sum_k e_k i_k / omega_m = K_e sum_k i_k sin(p theta_m - 2 pi k / 3)
    M z'' + c_m z' + k z + f + F_e = -m y'',     F_e = G T_e          (eq. 1 plus the generator)

K_e is the peak line-to-neutral back-EMF per rad/s of the rotor (V s/rad), R_s and L_s the
per-phase resistance and synchronous inductance of the star-connected winding, R_L each of the
three balanced load resistors (R_L -> inf: open circuit, no current, F_e = 0). The states are
z, z', i_a, i_b (i_c = -i_a - i_b); for balanced sinusoidal EMFs v_N = 0 and the equations are
those of the dq model with L_d = L_q = L_s and torque (3/2) K_e i_q. With L_s -> 0 the force is
viscous: F_e = c_e z' with

    c_e = (3/2) G^2 K_e^2 / (R_s + R_L),

since sum_k sin^2(p theta - 2 pi k / 3) = 3/2. Energy: F_e z' = (R_s + R_L) sum_k i_k^2 +
d/dt (L_s / 2 sum_k i_k^2).

The recorded voltages are line-to-line, between generator terminals a and b and between b
and c: v_ab = R_L (i_a - i_b), v_bc = R_L (i_b - i_c) (= e_a - e_b, e_b - e_c in open
circuit). Two line voltages give the space vector of the three, whose magnitude does not
depend on the rotor angle (one line voltage alone does: ``docs/electrical.md``). The paper's voltmeter measured "the
voltage across the generator terminals, that is, the load resistance"; a voltage across the
terminals is between two of them, and with a star load it is the voltage across the two load
resistors of those phases in series; the star point need not be reachable.

Method: the rig's fixed-step RK4 with its stick-slip events (``rig._integrate``), extended to
the two phase currents, with ``n_sub`` RK4 sub-steps per internal sample so that the electrical
rate (R_s + R_L) / L_s and the electrical frequency p G z' (for z' up to ``V_BOUND``) times the
sub-step stay below ``RATE_STEP``. While the mass sticks the EMF is zero and the currents decay
exactly, e^(-(R_s + R_L) t / L_s); the breakaway instant is located as in the rig, with the
holding force, now including F_e, interpolated linearly over the step (exact when the currents
are zero, as at the start of every record). In open circuit there is one sub-step, no current
and the integrator repeats ``rig._integrate`` operation for operation (the same z, z'). The
voltage goes through the DAQ's anti-alias filter and ADC (``rig.adc``), behind a voltage sensor
with its own gain, offset, range and noise (``voltage_sensor_volts``).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numba as nb
import numpy as np
from numpy.typing import NDArray

from harvester.synthetic import rig
from harvester.synthetic.rig import _friction

Array = NDArray[np.float64]

#: Largest (electrical rate x sub-step) of the coupled RK4.
RATE_STEP = 0.25
#: Relative speed (m/s) up to which the electrical frequency p G z' is resolved by the sub-step.
V_BOUND = 1.0
_TWO_PI_3 = 2.0 * math.pi / 3.0
#: Parameter vector layout of the compiled integrator.
_M, _K, _C, _FC, _BETA, _FS0, _G, _TH0, _P, _KE, _R, _L = range(12)


@dataclass(frozen=True)
class Generator:
    """The three-phase brushless PM generator and its ball screw (SI units); values ASSUMED."""

    lead_m: float     # m, ball-screw lead l
    pole_pairs: int   # p
    K_e: float        # V s/rad, peak line-to-neutral back-EMF per rad/s of the rotor
    R_s: float        # ohm, phase resistance
    L_s: float        # H, phase (synchronous) inductance

    @classmethod
    def from_config(cls, rig_cfg: Mapping[str, Any]) -> Generator:
        g = rig_cfg["generator"]
        return cls(lead_m=float(g["lead_m"]), pole_pairs=int(g["pole_pairs"]),
                   K_e=float(g["K_e"]), R_s=float(g["R_s"]), L_s=float(g["L_s"]))

    @property
    def screw_ratio(self) -> float:
        """G = 2 pi / l (rad/m): rotor angle per metre of travel."""
        return 2.0 * math.pi / self.lead_m

    @property
    def torque_constant(self) -> float:
        """K_t = (3/2) K_e (N m/A): torque per ampere of the dq current i_q (peak phase)."""
        return 1.5 * self.K_e

    @property
    def coupling(self) -> float:
        """(3/2) G^2 K_e^2 (N s/m x ohm): c_e (R_s + R_L), the translational coupling."""
        return 1.5 * (self.screw_ratio * self.K_e) ** 2

    def electrical_damping(self, load_ohm: float | None) -> float:
        """c_e (N s/m) of the L_s -> 0 limit at load R_L; 0 in open circuit (None)."""
        return 0.0 if load_ohm is None else self.coupling / (self.R_s + load_ohm)

    def matched_loads(self, c_m: float) -> dict[str, float]:
        """Load resistances (ohm) of maximum load power for a linear device (L_s -> 0).

        ``harmonic``: sinusoidal excitation at resonance, R_L = R_s + K^2 / c_m;
        ``broadband``: white-noise excitation, R_L = R_s sqrt(1 + K^2 / (R_s c_m)), where
        K^2 = ``coupling``. Friction is left out, so these only place the loads.
        """
        a = self.coupling / (self.R_s * c_m)
        return {"harmonic": self.R_s * (1.0 + a), "broadband": self.R_s * math.sqrt(1.0 + a)}

    def substeps(self, load_ohm: float | None, dt: float) -> int:
        """RK4 sub-steps per internal step of length dt (s): rate x sub-step <= RATE_STEP."""
        if load_ohm is None:
            return 1
        rate = max((self.R_s + load_ohm) / self.L_s,
                   self.pole_pairs * self.screw_ratio * V_BOUND)
        return max(1, math.ceil(rate * dt / RATE_STEP))


def reflected_inertia(M: float, m: float, lead_m: float) -> float:
    """J (kg m^2) of rotor and screw implied by eq. (2): (M - m) / (2 pi / l)^2."""
    return (M - m) / (2.0 * math.pi / lead_m) ** 2


def load_of(rig_cfg: Mapping[str, Any], name: str) -> float | None:
    """Load resistance (ohm) of loaded record ``name``; None in open circuit."""
    value = rig_cfg["loaded_records"][name]["load_ohm"]
    return None if value is None else float(value)


def loaded_record_seed(rig_cfg: Mapping[str, Any], name: str) -> int:
    """Seed of a loaded record: rig seed + its seed_offset."""
    return int(rig_cfg["seed"]) + int(rig_cfg["loaded_records"][name]["seed_offset"])


# --------------------------------------------------------------------------- compiled model

@nb.njit(cache=True)
def _phases(z, prm):
    """sin(p theta_m - 2 pi k / 3) for k = a, b, c."""
    th = prm[_P] * (prm[_TH0] + prm[_G] * z)
    return math.sin(th), math.sin(th - _TWO_PI_3), math.sin(th + _TWO_PI_3)


@nb.njit(cache=True)
def _force(z, ia, ib, prm, coupled):
    """Electrical force F_e = G T_e (N) on the mass, opposing its motion."""
    if not coupled:
        return 0.0
    sa, sb, sc = _phases(z, prm)
    return prm[_G] * prm[_KE] * (ia * sa + ib * sb + (-ia - ib) * sc)


@nb.njit(cache=True)
def _deriv(drive, z, v, ia, ib, prm, coupled):
    """z'', i_a', i_b' while sliding; drive = -m y'' (N)."""
    if coupled:
        sa, sb, sc = _phases(z, prm)
        fe = prm[_G] * prm[_KE] * (ia * sa + ib * sb + (-ia - ib) * sc)
        w = prm[_KE] * prm[_G] * v
        ea, eb, ec = w * sa, w * sb, w * sc
        vn = (ea + eb + ec) / 3.0
        dia = (ea - vn - prm[_R] * ia) / prm[_L]
        dib = (eb - vn - prm[_R] * ib) / prm[_L]
    else:
        fe, dia, dib = 0.0, 0.0, 0.0
    hold = drive - prm[_K] * z - fe
    a = (hold - prm[_C] * v - _friction(v, hold, prm[_FC], prm[_BETA], prm[_FS0])) / prm[_M]
    return a, dia, dib


@nb.njit(cache=True)
def _rk4(z, v, ia, ib, h, fa, fb, prm, coupled):
    """One RK4 step of length h; the drive goes linearly from fa to fb (as ``rig._rk4``)."""
    fm = 0.5 * (fa + fb)
    a1, p1, q1 = _deriv(fa, z, v, ia, ib, prm, coupled)
    z2, v2 = z + 0.5 * h * v, v + 0.5 * h * a1
    i2, j2 = ia + 0.5 * h * p1, ib + 0.5 * h * q1
    a2, p2, q2 = _deriv(fm, z2, v2, i2, j2, prm, coupled)
    z3, v3 = z + 0.5 * h * v2, v + 0.5 * h * a2
    i3, j3 = ia + 0.5 * h * p2, ib + 0.5 * h * q2
    a3, p3, q3 = _deriv(fm, z3, v3, i3, j3, prm, coupled)
    z4, v4 = z + h * v3, v + h * a3
    i4, j4 = ia + h * p3, ib + h * q3
    a4, p4, q4 = _deriv(fb, z4, v4, i4, j4, prm, coupled)
    return (z + h / 6.0 * (v + 2.0 * v2 + 2.0 * v3 + v4),
            v + h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4),
            ia + h / 6.0 * (p1 + 2.0 * p2 + 2.0 * p3 + p4),
            ib + h / 6.0 * (q1 + 2.0 * q2 + 2.0 * q3 + q4))


@nb.njit(cache=True)
def _steps(z, v, ia, ib, span, fa, fb, nsub, prm, coupled):
    """``nsub`` RK4 steps over ``span`` s, the drive linear from fa to fb."""
    if nsub == 1:
        return _rk4(z, v, ia, ib, span, fa, fb, prm, coupled)
    h = span / nsub
    f0 = fa
    for j in range(nsub):
        f1 = fb if j == nsub - 1 else fa + (fb - fa) * ((j + 1) / nsub)
        z, v, ia, ib = _rk4(z, v, ia, ib, h, f0, f1, prm, coupled)
        f0 = f1
    return z, v, ia, ib


@nb.njit(cache=True)
def _decay(prm, coupled, t):
    """Factor by which the currents fall in t seconds at rest (no EMF)."""
    return math.exp(-prm[_R] * t / prm[_L]) if coupled else 1.0


@nb.njit(cache=True)
def _integrate_loaded(drive, dt, nsub, z0, v0, dwell0, F_s, tau, v_stick, prm, coupled):
    """``rig._integrate`` with the generator: returns z, z', i_a, i_b, z'', f, F_e, stuck."""
    n = drive.size
    z = np.empty(n)
    v = np.empty(n)
    ia = np.zeros(n)
    ib = np.zeros(n)
    jump = np.zeros(n)
    stuck = np.zeros(n, dtype=np.bool_)
    k, F_s0 = prm[_K], prm[_FS0]
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
            g = _decay(prm, coupled, dt)
            hold_b = fb - k * z[i] - _force(z[i], g * ia[i], g * ib[i], prm, coupled)
            if abs(hold_b) <= thr:
                z[i + 1], v[i + 1], stuck[i + 1] = z[i], 0.0, True
                ia[i + 1], ib[i + 1] = g * ia[i], g * ib[i]
                continue
            hold_a = fa - k * z[i] - _force(z[i], ia[i], ib[i], prm, coupled)
            edge = thr if hold_b > 0.0 else -thr
            th = min(max((edge - hold_a) / (hold_b - hold_a), 0.0), 1.0)
            g = _decay(prm, coupled, th * dt)
            zi, vi, ii, ji = _steps(z[i], 0.0, g * ia[i], g * ib[i], (1.0 - th) * dt,
                                    fa + th * (fb - fa), fb, nsub, prm, coupled)
            is_stuck = False
        else:
            zi, vi, ii, ji = _steps(z[i], v[i], ia[i], ib[i], dt, fa, fb, nsub, prm, coupled)
            if F_s0 > 0.0 and v[i] != 0.0 and vi * v[i] <= 0.0:
                th = v[i] / (v[i] - vi)  # velocity reversal inside the step
                fm = fa + th * (fb - fa)
                zs, _, i_s, j_s = _steps(z[i], v[i], ia[i], ib[i], th * dt, fa, fm, nsub, prm,
                                         coupled)
                if abs(fm - k * zs - _force(zs, i_s, j_s, prm, coupled)) <= F_s0:
                    g = _decay(prm, coupled, (1.0 - th) * dt)
                    zi, vi, ii, ji, is_stuck, dwell = zs, 0.0, g * i_s, g * j_s, True, 0.0
                else:
                    zi, vi, ii, ji = _steps(zs, 0.0, i_s, j_s, (1.0 - th) * dt, fm, fb, nsub,
                                            prm, coupled)
        if (not is_stuck and abs(vi) < v_stick
                and abs(fb - k * zi - _force(zi, ii, ji, prm, coupled)) <= F_s0):
            jump[i + 1] = -vi
            vi, is_stuck, dwell = 0.0, True, 0.0
        z[i + 1], v[i + 1], stuck[i + 1] = zi, vi, is_stuck
        ia[i + 1], ib[i + 1] = ii, ji
    a, f, fe = _outputs(drive, dt, z, v, ia, ib, jump, stuck, prm, coupled)
    return z, v, ia, ib, a, f, fe, stuck


@nb.njit(cache=True)
def _outputs(drive, dt, z, v, ia, ib, jump, stuck, prm, coupled):
    """z'' (the velocity jump over dt where the mass sticks), friction f and F_e per sample."""
    n = drive.size
    k, F_s0 = prm[_K], prm[_FS0]
    a = np.empty(n)
    f = np.empty(n)
    fe = np.empty(n)
    for i in range(n):
        fe[i] = _force(z[i], ia[i], ib[i], prm, coupled)
        hold = drive[i] - k * z[i] - fe[i]
        if stuck[i]:
            a[i], f[i] = jump[i] / dt, hold
        else:
            f[i] = _friction(v[i], hold, prm[_FC], prm[_BETA], F_s0)
            a[i] = (hold - prm[_C] * v[i] - f[i]) / prm[_M]
    return a, f, fe


# --------------------------------------------------------------------------- motion

@dataclass(frozen=True)
class LoadedMotion:
    """Mass motion and generator state on the simulation grid.

    z (m), v = z' (m/s), acc = z'' (m/s^2), friction f (N), stuck; phase currents i_a, i_b,
    i_c (A), electrical force F_e (N), rotor angle theta_m (rad) and speed omega_m (rad/s),
    the line-to-line terminal voltages v_ab and v_bc (V); ``load_ohm`` None in open circuit.
    """

    z: Array
    v: Array
    acc: Array
    friction: Array
    stuck: NDArray[np.bool_]
    i_a: Array
    i_b: Array
    force: Array
    theta_m: Array
    omega_m: Array
    voltage: Array
    load_ohm: float | None
    voltage_bc: Array | None = None

    @property
    def i_c(self) -> Array:
        return -self.i_a - self.i_b

    @property
    def current_squares(self) -> Array:
        """sum_k i_k^2 (A^2)."""
        return self.i_a ** 2 + self.i_b ** 2 + self.i_c ** 2


def back_emf(gen: Generator, theta_m: Array, omega_m: Array) -> Array:
    """Phase back-EMFs e_a, e_b, e_c (V), shape (3, n)."""
    th = gen.pole_pairs * theta_m
    return gen.K_e * omega_m * np.stack([np.sin(th), np.sin(th - _TWO_PI_3),
                                         np.sin(th + _TWO_PI_3)])


def simulate_loaded_motion(y_dd: Array, fs: float, dev: rig.Device, gen: Generator,
                           load_ohm: float | None, theta0: float = 0.0, z0: float = 0.0,
                           v0: float = 0.0, dwell0: float = 0.0,
                           nsub: int | None = None) -> LoadedMotion:
    """Integrate eq. (1) with the generator into the star load ``load_ohm`` (None: open).

    y'' (m/s^2) sampled at fs (Hz); the mass starts at z0, z' = v0 (at rest for dwell0 s if
    v0 == 0) with no current; theta0 (rad) is the rotor angle at z = 0. ``nsub`` overrides
    the sub-steps per sample (``Generator.substeps``).
    """
    coupled = load_ohm is not None
    if coupled and not (math.isfinite(load_ohm) and load_ohm >= 0.0):
        raise ValueError(f"load resistance must be finite and >= 0 ohm, got {load_ohm}")
    dt = 1.0 / fs
    nsub = gen.substeps(load_ohm, dt) if nsub is None else int(nsub)
    prm = np.array([dev.M, dev.k, dev.c_m, dev.F_c, dev.beta, dev.F_s0, gen.screw_ratio,
                    float(theta0), float(gen.pole_pairs), gen.K_e,
                    gen.R_s + (load_ohm if coupled else 0.0), gen.L_s])
    drive = -dev.m * np.ascontiguousarray(y_dd, dtype=np.float64)
    z, v, ia, ib, a, f, fe, stuck = _integrate_loaded(
        drive, dt, nsub, float(z0), float(v0), float(dwell0), dev.F_s, dev.dwell_s,
        dev.v_stick, prm, coupled)
    theta = theta0 + gen.screw_ratio * z
    omega = gen.screw_ratio * v
    if coupled:
        voltage, voltage_bc = load_ohm * (ia - ib), load_ohm * (2.0 * ib + ia)
    else:
        emf = back_emf(gen, theta, omega)
        voltage, voltage_bc = emf[0] - emf[1], emf[1] - emf[2]
    return LoadedMotion(z, v, a, f, stuck, ia, ib, fe, theta, omega, voltage, load_ohm,
                        voltage_bc)


# --------------------------------------------------------------------------- records

def voltage_sensor_volts(voltage: Array, sensor: Mapping[str, Any]) -> Array:
    """Voltage sensor output (V) for a load voltage (V): zero_V + gain voltage, saturating at
    zero_V +- gain range_V (an isolating attenuator in front of the DAQ's 0-5 V input)."""
    gain, zero = float(sensor["gain_V_per_V"]), float(sensor["zero_V"])
    swing = gain * float(sensor["range_V"])
    return np.clip(zero + gain * voltage, zero - swing, zero + swing)


@dataclass(frozen=True)
class LoadedRecordSimulation:
    """One simulated loaded record: three channel voltages at the output rate and the truth.

    ai0, ai1 as ``rig.RecordSimulation``; ai2, ai3 the outputs (V) of the voltage sensors on
    v_ab and v_bc. ``truth`` adds to the rig's (base_acc, rel_acc, rocking, z, v, stuck):
    ``voltage`` (v_ab, V), ``voltage_bc`` (v_bc, V) and
    ``electrical_force`` (F_e, N) through the anti-alias filter without noise; ``i_a``,
    ``i_b`` (A) sampled; ``theta0`` (rad), ``load_ohm`` (None in open circuit), ``substeps``.
    """

    name: str
    seed: int
    sampling_rate_hz: float
    time: Array
    ai0: Array
    ai1: Array
    ai2: Array
    load_ohm: float | None
    truth: dict[str, Any]
    ai3: Array | None = None


def simulate_loaded_record(rig_cfg: Mapping[str, Any], name: str,
                           duration_s: float | None = None) -> LoadedRecordSimulation:
    """Run the rig with the generator for loaded record ``name`` (``rig.loaded_records``).

    The shaker, accelerometers, rocking mode, anti-alias filter and ADC are the rig's; the
    voltage sensors (one per line voltage, v_ab and v_bc) add their own noise
    (``voltage_sensor.noise_V`` RMS over the DAQ band) and the rotor starts at a random angle.
    The v_bc sensor's noise is a seventh stream, so the first six and ai0-ai2 do not depend
    on it. The rocking mode is driven by the whole screw force,
    friction plus F_e.
    """
    spec = rig_cfg["loaded_records"][name]
    duration = float(spec["duration_s"] if duration_s is None else duration_s)
    grid = rig.record_grid(rig_cfg, duration)
    seed = loaded_record_seed(rig_cfg, name)
    rng_exc, rng_base, rng_mass, rng_ball, rng_volt, rng_angle, rng_volt_bc = \
        rig.record_streams(seed, 7)
    load = load_of(rig_cfg, name)
    gen = Generator.from_config(rig_cfg)
    dev = rig.Device.from_config(rig_cfg)
    theta0 = float(rng_angle.uniform(0.0, 2.0 * math.pi))

    y_dd = rig.shaker_acceleration(rig_cfg, grid, rng_exc)
    motion = simulate_loaded_motion(y_dd, grid.fs, dev, gen, load, theta0=theta0)
    screw = motion.friction + motion.force
    rock = rig.rocking_acceleration(screw, grid.fs, dev.M, rig_cfg["rocking"], motion.v,
                                    rng_ball)
    ai0, ai1 = rig.accelerometer_channels(rig_cfg, grid, y_dd, (motion.acc, rock), rng_base,
                                          rng_mass)
    sensor = rig_cfg["generator"]["voltage_sensor"]
    sd = rig.noise_rms_internal(float(sensor["noise_V"]), grid.oversample)
    measured = motion.voltage + sd * rng_volt.standard_normal(motion.voltage.size)
    ai2 = rig.adc(rig_cfg, grid, voltage_sensor_volts(measured, sensor))
    measured_bc = motion.voltage_bc + sd * rng_volt_bc.standard_normal(motion.voltage.size)
    ai3 = rig.adc(rig_cfg, grid, voltage_sensor_volts(measured_bc, sensor))

    os_, n_out, at = grid.oversample, grid.n_out, grid.at
    truth: dict[str, Any] = {
        "base_acc": rig.decimate(y_dd, os_, n_out),
        "rel_acc": rig.decimate(motion.acc, os_, n_out),
        "rocking": rig.decimate(rock, os_, n_out),
        "voltage": rig.decimate(motion.voltage, os_, n_out),
        "voltage_bc": rig.decimate(motion.voltage_bc, os_, n_out),
        "electrical_force": rig.decimate(motion.force, os_, n_out),
        "z": motion.z[at], "v": motion.v[at], "stuck": motion.stuck[at],
        "i_a": motion.i_a[at], "i_b": motion.i_b[at],
        "theta0": theta0, "load_ohm": load, "substeps": gen.substeps(load, 1.0 / grid.fs)}
    return LoadedRecordSimulation(name=name, seed=seed, sampling_rate_hz=grid.fs_out,
                                  time=np.arange(n_out) / grid.fs_out, ai0=ai0, ai1=ai1,
                                  ai2=ai2, load_ohm=load, truth=truth, ai3=ai3)


def electrical_truth(rig_cfg: Mapping[str, Any]) -> dict[str, Any]:
    """The generator's true constants, derived quantities, and c_e per loaded record."""
    gen = Generator.from_config(rig_cfg)
    c_m = float(rig_cfg["c_m"])
    return {
        "lead_m": gen.lead_m, "pole_pairs": gen.pole_pairs, "K_e": gen.K_e, "R_s": gen.R_s,
        "L_s": gen.L_s, "K_t": gen.torque_constant, "coupling": gen.coupling,
        "J": reflected_inertia(float(rig_cfg["M"]), float(rig_cfg["m"]), gen.lead_m),
        "matched_load_ohm": gen.matched_loads(c_m),
        "c_e": {name: gen.electrical_damping(load_of(rig_cfg, name))
                for name in rig_cfg.get("loaded_records", {})},
    }
