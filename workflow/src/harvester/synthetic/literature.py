"""Test recordings from the friction, contact and structural-dynamics literature's own forms.

A second generator of recordings with one concealed effect each, written independently of the
library's physics (it imports nothing from ``harvester``): the forms, ranges, integrator and
acquisition come from the published models cited per scenario, so that a diagnosis tested on
it is tested on physics it was not written from. ``generate(name, seed)`` returns the
recording (``time, base_acc, rel_acc``), its sidecar (the "known" M, m, k) and the truth.

Recording kinds (``kind``, :data:`KINDS`; the same device, excitation and effect per seed):
``base_acc->rel_acc`` (default) the two accelerometers below; ``base_disp->rel_disp`` the
base displacement y (y'' integrated twice, with the constant base velocity that leaves y no
straight-line trend) and the relative displacement z; ``base_disp->rel_acc`` y and z'';
``force->rel_disp`` the base fixed and the force F = -m y'' on the mass (eq. 1 is then driven
by F, the motion the same), z (to ground). Their channels each carry their own white noise
through the DAQ, sized by what the model takes of the channel (y'' of a base displacement,
z' of a relative one: :data:`NOISE_SHARES`); the strength's ratio is to the realised noise
RMS of the recorded output.

Device (:func:`draw_device`, per seed): eq. (1) of Green et al. (2015), a base-excited
oscillator ``M z'' + c z' + k z + F_c S(z'/v_t) = -m y''``, z = x - y, M the effective mass
(m plus the rotor's reflected inertia); f_n 0.5-8 Hz, M 0.5-20 kg, m/M 0.3-0.95, zeta
0.01-0.1, peak base acceleration 1-8 m/s^2, F_c 3-40 % of m max|y''| (redrawn while F_c / M
is below the noise), v_t 10^(-2..-0.5) x the baseline's RMS velocity. S is tanh by default
(the diagnosis's baseline law); ``friction_form`` gives (2/pi) atan or v/sqrt(1 + v^2), whose
own misfit to the tanh law is reported (``baseline_form_unabsorbed_to_noise``).

Scenarios (:data:`SCENARIOS`; F: friction on the mass, s: the calibrated strength):

======================  ==========================================  =========================
scenario                form (citation in the registry)             correct (related) names
======================  ==========================================  =========================
lugre                   (1-s) F_dev + s LuGre, sigma0 1e3-1e6 N/m   hysteresis (coulomb)
dahl                    (1-s) F_dev + s Dahl, alpha 0.5-2           hysteresis (coulomb)
bouc_wen                (1-s) F_dev + s F_c w, Bouc-Wen n 1-3       hysteresis (coulomb)
karnopp                 (1-s) F_dev + s Karnopp, F_s/F_c 1.2-2      stribeck, coulomb, sticking
stribeck_exponential    F_dev (1 + s exp(-|v|/v_s))                 stribeck (coulomb)
stribeck_gaussian       F_dev (1 + s exp(-(v/v_s)^2))               stribeck (coulomb)
asymmetric_friction     F_dev (1 + s tanh(v/v_a))                   asymmetric (offset_force)
end_stop_linear         k_c d + c_c d', d = |z| - gap               end_stop (cubic)
end_stop_hertz          K d^1.5                                     end_stop (cubic)
end_stop_hunt_crossley  K d^n (1 + 3(1-e)/2 d'/v_impact)            end_stop (cubic)
duffing                 k3 z^3                                      cubic (end_stop)
power_hardening         k_p |z|^p sgn z, p 1.5-2.5 or 4-6           cubic (end_stop)
flexible_mount          2 DOF: the screw's base on m_b, k_b, c_b    unmodelled_mode
secondary_mode          2 DOF: m2 of the mass on k2, c2             unmodelled_mode (inertia)
payload_error           true m, M = sidecar's + s M                 inertia_error
rotor_inertia_error     true M = sidecar's + s M, m right           inertia_error
quadratic_damping       c2 v|v|                                     quadratic_damping
power_damping           c_a |v|^a sgn v, a 1.3-3                    quadratic_damping
none                    the device only (false-alarm check)         --
cogging                 A sin(2 pi z / P + phi), P 0.67-2 z_rms     -- (none)
quadratic_spring        k2 z^2 (a spring stiffer on one side)       -- (offset_force)
friction_drift          F_dev (1 + s (t - T/2) / T), T the record   -- (none)
mains_hum               rel_acc + A sin(2 pi 50|60 Hz t + phi)      -- (unmodelled_mode)
maxwell_slip            (1-s) F_dev + s 2 Maxwell-slip elements     hysteresis, sticking (coulomb)
spring_dead_zone        k dz(z, g) in place of k z, g = s z_max     -- (end_stop, backlash)
backlash                2 DOF: m, J = M - m through a play +-g      backlash (mode, end_stop)
ground_friction         (1-s) F_dev + s F_c S((z' + y')/v_t)        ground, coulomb* (sticking)
======================  ==========================================  =========================

The last three were added after Maxwell-slip (issue 63). A dead zone in the main spring
(Nordin and Gutman 2002) has no library term: end_stop adds a stiffness beyond a gap (it would
need the spring removed), backlash couples the mass to the screw side. Backlash: the mass m
carries the spring, the screw side J = M - m the damping and friction, coupled through a
Kelvin-Voigt contact beyond +-g. Friction on the ground (a contact fixed to the frame, as in
Marino and Cicirello 2023) moves a share s to the mass's absolute velocity; the sidecar is
silent about ``friction_on``. *A friction name is right only where the diagnosis also takes
the topology "ground" (base_disp inputs); ``ground_friction``, the library's term on the
mass's absolute velocity beside the base's friction, names it on any base input. With a force
input the base is the ground and the form is the baseline itself (refused); with base_acc y'
is the band-limited integral of y''.

The four after the effect-free one are outside the library (no correct name): a force
periodic in the displacement (a generator's cogging through the screw), an even spring, a
slow change (the friction's level drifting; a slow force itself would not show in z'', whose
response to it falls as (f / f_n)^2), and the acquisition's own line (mains hum on the mass accelerometer's
channel, added to the reading before the DAQ's filter, not to the motion). Maxwell-slip, a
friction law with memory, was added after them, so that the earlier scenarios keep their
places in the grids.

Naming: ``correct_names`` are the library terms that name the mechanism; ``related_names``
describe part of its signature but another physical cause, and are not counted. A memory law's
sliding limit is Coulomb-sharp, so ``coulomb_friction`` explains part of it, not its memory.
Karnopp's element is Coulomb sliding plus breakaway and a true stick: ``stribeck_friction``,
``coulomb_friction`` and their sticking forms name it. Maxwell-slip's elements hold
elastically (pre-sliding) and slip at their levels: ``hysteresis`` and ``sticking_friction``
name it. Direction-dependent friction equals symmetric friction plus a
constant force while sliding, but exerts nothing at rest, so ``offset_force`` (a preload or
gravity, which does) is related only. Stops are local (a gap) and a cubic spring global: each
is the other's related name. Below a secondary mode the whole mass moves and above it part of
it decouples, an apparent inertia change: ``inertia_error`` is related.

Strength: solved (:func:`solve_strength`) so that the contribution c(t) = z''(with) -
z''(without), same excitation, no noise, through the same acquisition, has an RMS of ``ratio``
x the realised rel_acc noise RMS after a 1 s lead-in (within CALIBRATION_RTOL, 1 % where the
contribution jumps with the strength). Shapes are drawn per seed from the stated ranges; a
shape (then a device) whose effect cannot reach the ratio within the strength's physical
bounds is drawn again, so shapes follow their ranges conditioned on reachability. The truth
also gives the contribution's RMS left after the tanh baseline's (c, F_c, v_t) absorb what they
can by linearised least squares (``unabsorbed_to_noise``), and how far the contribution moves
when the device is driven by the recorded base acceleration instead of the true one
(``input_driven_to_clean_contribution``, :func:`recorded_input_contribution`).

Excitation (:func:`draw_excitation`): random-phase multisine, flat over 0.25-0.6 x to 2-5 x
f_n, with a slow sinusoidal envelope and a 0.5 s raised-cosine fade-in from rest. Integration
(:func:`simulate`): RK4 at ``n_sub`` sub-steps per internal sample (8 x the output rate), 8 x
finer within steps that may meet a stop or the stick band; the input is exact at two samples
per step (inverse FFT) and 6-point Lagrange-interpolated between. The memory laws' internal
variable is advanced by an exponential midpoint rule at frozen velocity in a Strang splitting
(stable for any bristle stiffness, exact for LuGre). ``n_sub`` is doubled until halving the
step changes the recorded z'' by <= CONVERGENCE_TOL x the noise RMS. Acquisition
(:func:`daq`): both accelerometers sampled simultaneously through one linear-phase FIR
decimator (Kaiser; flat to 1e-5 up to 0.4 fs, >= 100 dB from 0.5 fs), delay-compensated;
white noise per sensor band-limited by the same filter; optional quantisation; no other
filtering.

References
----------
Green, P.L., Hendijanizadeh, M., Simeone, L., Elliott, S.J. (2015) Probabilistic modelling of
a rotational energy harvester. J. Intell. Mater. Syst. Struct. 27(4):528-536.
"""

from __future__ import annotations

import functools
import json
import os
import tempfile
import zlib
from collections.abc import Callable
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any

import numba as nb
import numpy as np
import pandas as pd
from scipy import signal

__all__ = ["SCENARIOS", "Device", "Excitation", "GeneratedRecording", "LiteratureScenario",
           "anti_alias_fir", "daq", "draw_device", "draw_excitation", "generate", "simulate"]

#: Internal (integration) rate / output rate.
OVERSAMPLE = 8
#: Lead-in (s) excluded from every RMS.
LEAD_IN_S = 1.0
#: Raised-cosine fade-in of the excitation (s): the device starts at rest with no input.
FADE_IN_S = 0.5
#: Anti-alias FIR: flat to PASSBAND x fs, stop band from STOPBAND x fs at FIR_ATTENUATION_DB.
PASSBAND, STOPBAND, FIR_ATTENUATION_DB = 0.4, 0.5, 100.0
#: Step halving must change the recorded channels by less than this x the noise RMS; 1e-2
#: for Karnopp's law, whose force jumps at the stick band's edges (RK4 converges at first
#: order there).
CONVERGENCE_TOL, KARNOPP_CONVERGENCE_TOL = 1.0e-3, 1.0e-2
#: Sub-steps are this many times finer in an internal step that may meet a contact or
#: Karnopp's stick band.
SWITCH_REFINE = 8
#: Most RK4 sub-steps per internal sample (away from contacts and stick bands); backlash's,
#: whose contact switches on and off within the motion (RK4 at first order at each touch).
MAX_SUBSTEPS, MAX_SUBSTEPS_BACKLASH = 64, 512
#: Most shape draws per device, and devices per recording, before giving up.
MAX_SHAPE_DRAWS, MAX_DEVICE_DRAWS = 12, 8
#: Relative tolerance of the calibrated contribution RMS.
CALIBRATION_RTOL = 2.0e-3
#: Smooth-sign forms of the device's sliding friction.
FRICTION_FORMS = ("tanh", "atan", "algebraic")

# Parameter vector: device, then the effect's parameters from E.
_M, _MOSC, _K, _C, _FC, _VT, _FORM, _VREF, E = range(9)
N_PARAMS = E + 8
# Effect kinds of the compiled right-hand side.
(NONE, LUGRE, DAHL, BOUC_WEN, KARNOPP, STRIBECK, ASYMMETRIC, STOP_KV, STOP_POWER,
 SPRING_POWER, DAMP_POWER, MOUNT, SECONDARY, PERIODIC_Z, SPRING_EVEN, FRICTION_DRIFT,
 SENSOR_LINE, MAXWELL_SLIP, GROUND_FRICTION, SPRING_DEAD_ZONE, BACKLASH) = range(21)


# --------------------------------------------------------------------------- compiled physics

@nb.njit(cache=True)
def _smooth_sign(form, x):
    """tanh x (0), (2/pi) atan x (1) or x / sqrt(1 + x^2) (2)."""
    if form == 0:
        return np.tanh(x)
    if form == 1:
        return 2.0 / np.pi * np.arctan(x)
    return x / np.sqrt(1.0 + x * x)


@nb.njit(cache=True)
def _kinetic(p, v):
    """The device's sliding friction F_c S(v / v_t) (N)."""
    return p[_FC] * _smooth_sign(int(p[_FORM]), v / p[_VT])


@nb.njit(cache=True)
def _memory_force(kind, p, v, w):
    """LuGre: sigma0 z_b + sigma1 z_b' (z_b in m); Dahl, Bouc-Wen: F_c w (w normalised)."""
    if kind == LUGRE:
        s0 = p[E + 1]
        return s0 * w + p[E + 2] * (v - s0 * abs(v) * w / p[_FC])
    return p[_FC] * w


@nb.njit(cache=True)
def _friction(kind, p, v, w, rest):
    """Friction force (N) on the mass at velocity v; ``rest``: the other forces (N)."""
    f = _kinetic(p, v)
    if kind == NONE or kind >= STOP_KV:
        return f
    s = p[E]
    if kind <= BOUC_WEN:  # a share s of the contact has memory
        return (1.0 - s) * f + s * _memory_force(kind, p, v, w)
    if kind == KARNOPP:  # Karnopp (1985): stuck inside |v| < dv up to the breakaway force
        if abs(v) < p[E + 2]:
            fs = s * p[E + 1] * p[_FC]
            return (1.0 - s) * f + min(max(rest - (1.0 - s) * f, -fs), fs)
        return (1.0 - s) * f + s * p[_FC] * np.sign(v)
    if kind == STRIBECK:
        return f * (1.0 + s * np.exp(-(abs(v) / p[E + 1]) ** p[E + 2]))
    return f * (1.0 + s * np.tanh(v / p[E + 1]))  # ASYMMETRIC


@nb.njit(cache=True)
def _slip_force(p, z, w1, w2):
    """Maxwell-slip (Iwan 1966; Al-Bender, Lampaert and Swevers 2005): two elasto-slip
    elements, element i's spring k_i = W_i / D_i from its slider at w_i, its force held within
    +-W_i (the slider moves when it would exceed it, :func:`_play`): W_1 = a s F_c,
    W_2 = (1 - a) s F_c, each W_i (z - w_i) / D_i clipped to +-W_i (N)."""
    w_total = p[E] * p[_FC]
    f1 = p[E + 1] * w_total * min(max((z - w1) / p[E + 2], -1.0), 1.0)
    f2 = (1.0 - p[E + 1]) * w_total * min(max((z - w2) / p[E + 3], -1.0), 1.0)
    return f1 + f2


@nb.njit(cache=True)
def _play(p, x):
    """The sliders of :func:`_slip_force` after a step: each within D_i of z (exact)."""
    for j, d in ((2, p[E + 2]), (3, p[E + 3])):
        x[j] = min(max(x[j], x[0] - d), x[0] + d)


@nb.njit(cache=True)
def _extra_force(kind, p, z, v, v_impact):
    """Restoring/dissipative force (N) of an end stop, a stiffening spring or a power damper."""
    if kind == STOP_KV or kind == STOP_POWER:
        depth = abs(z) - p[E + 3]
        if depth <= 0.0:
            return 0.0
        side = np.sign(z)
        rate = v * side  # d(depth)/dt
        if kind == STOP_KV:
            return side * max(p[E] * depth + p[E + 2] * rate, 0.0)
        return side * max(p[E] * depth ** p[E + 1] * (1.0 + p[E + 2] * rate / v_impact), 0.0)
    if kind == SPRING_POWER:
        return p[E] * abs(z) ** p[E + 1] * np.sign(z)
    if kind == DAMP_POWER:
        return p[E] * abs(v) ** p[E + 1] * np.sign(v)
    if kind == PERIODIC_Z:
        return p[E] * np.sin(2.0 * np.pi * z / p[E + 1] + p[E + 2])
    if kind == SPRING_EVEN:
        return p[E] * z * z
    if kind == SPRING_DEAD_ZONE:  # k dz(z, g) in place of k z: k dz - k z = -k clip(z, +-g)
        return -p[_K] * min(max(z, -p[E]), p[E])
    return 0.0


@nb.njit(cache=True)
def _contact(p, d, dd):
    """Dead-zone coupling (the dead-zone model, Nordin and Gutman 2002, with a Kelvin-Voigt
    contact): k_b dz(d, g) + c_b d' while in contact, compressive only (N)."""
    g = p[E]
    if d > g:
        return max(p[E + 1] * (d - g) + p[E + 2] * dd, 0.0)
    if d < -g:
        return min(p[E + 1] * (d + g) + p[E + 2] * dd, 0.0)
    return 0.0


@nb.njit(cache=True)
def _rhs_backlash(p, x, yb, dx):
    """Backlash between the mass m (spring k) and the screw side J = M - m (c and the
    friction on its velocity r'): m z'' = -m y'' - k z - F_b, J r'' = F_b - c r' - F(r')."""
    z, v, r, dr = x[0], x[1], x[2], x[3]
    fb = _contact(p, z - r, v - dr)
    acc = (-p[_MOSC] * yb - p[_K] * z - fb) / p[_MOSC]
    dx[0], dx[1], dx[2] = v, acc, dr
    dx[3] = (fb - p[_C] * dr - _kinetic(p, dr)) / (p[_M] - p[_MOSC])
    dx[4] = 0.0
    return acc


@nb.njit(cache=True)
def _rhs_mount(p, x, yb, dx):
    """Flexible mount: the screw/spring sits on a body m_b (k_b, c_b to the base), 2 DOF."""
    z, v, w, dw = x[0], x[1], x[2], x[3]
    mb, kb, cb = p[E], p[E + 1], p[E + 2]
    rotor = p[_M] - p[_MOSC]
    du = v - dw
    fd = p[_K] * (z - w) + p[_C] * du + _kinetic(p, du)
    a_mass = -p[_MOSC] * yb - fd
    a_mount = -mb * yb + fd - kb * w - cb * dw
    det = p[_M] * (mb + rotor) - rotor * rotor
    acc = (a_mass * (mb + rotor) + rotor * a_mount) / det
    dx[0], dx[1], dx[2] = v, acc, dw
    dx[3] = (p[_M] * a_mount + rotor * a_mass) / det
    dx[4] = 0.0
    return acc


@nb.njit(cache=True)
def _rhs_secondary(p, x, yb, dx):
    """Secondary mode on the mass: m2 (of m) hangs on k2, c2; the sensor sees the rest."""
    z, v, q, dq = x[0], x[1], x[2], x[3]
    m2, k2, c2 = p[E], p[E + 1], p[E + 2]
    fq = k2 * q + c2 * dq
    acc = (-(p[_MOSC] - m2) * yb - p[_C] * v - p[_K] * z - _kinetic(p, v) + fq) / (p[_M] - m2)
    dx[0], dx[1], dx[2] = v, acc, dq
    dx[3] = -fq / m2 - yb - acc
    dx[4] = 0.0
    return acc


@nb.njit(cache=True)
def _rhs(kind, p, x, yb, dx):
    """d(state)/dt into dx for base acceleration yb (m/s^2); returns z'' (m/s^2).

    State: z, z', then the effect's: memory variable (kept by :func:`_relax`), or the second
    body's displacement and velocity; x[4] holds the last impact velocity of a stop, the
    time for a drifting friction (started at p[_VREF] = 0), or the base velocity y' for
    friction on the ground (started at p[_VREF] = y'(0), :attr:`_Run.base_motion`).
    """
    if kind == MOUNT:
        return _rhs_mount(p, x, yb, dx)
    if kind == SECONDARY:
        return _rhs_secondary(p, x, yb, dx)
    if kind == BACKLASH:
        return _rhs_backlash(p, x, yb, dx)
    z, v = x[0], x[1]
    rest = -p[_MOSC] * yb - p[_C] * v - p[_K] * z - _extra_force(kind, p, z, v, x[4])
    if kind == FRICTION_DRIFT:  # x[4] holds the time (s)
        acc = (rest - _kinetic(p, v) * (1.0 + p[E] * (x[4] - p[E + 1]) / p[E + 2])) / p[_M]
    elif kind == MAXWELL_SLIP:  # sliders x[2], x[3], moved by _play
        acc = (rest - (1.0 - p[E]) * _kinetic(p, v) - _slip_force(p, z, x[2], x[3])) / p[_M]
    elif kind == GROUND_FRICTION:  # x[4] holds the base velocity y' (m/s)
        acc = (rest - (1.0 - p[E]) * _kinetic(p, v) - p[E] * _kinetic(p, v + x[4])) / p[_M]
    else:
        acc = (rest - _friction(kind, p, v, x[2], rest)) / p[_M]
    dx[0], dx[1] = v, acc
    dx[2] = dx[3] = 0.0
    dx[4] = 1.0 if kind == FRICTION_DRIFT else yb if kind == GROUND_FRICTION else 0.0
    return acc


@nb.njit(cache=True)
def _memory_rates(kind, p, v, w):
    """(P, Q) of the memory law written dw/dt = P - Q w with Q >= 0, at velocity v.

    LuGre: z_b' = v - sigma0 |v| z_b / F_c. Dahl: w' = (sigma0/F_c) v |1 - w sgn v|^alpha
    sgn(1 - w sgn v). Bouc-Wen: w' = (v - beta |v| |w|^(n-1) w - gamma v |w|^n) / z_y, z_y =
    F_c / k_b.
    """
    s, av = np.sign(v), abs(v)
    if kind == LUGRE:
        return v, p[E + 1] * av / p[_FC]
    if kind == DAHL:
        a = p[E + 1] / p[_FC] * av * max(abs(1.0 - w * s), 1e-12) ** (p[E + 2] - 1.0)
        return a * s, a
    zy = p[_FC] / p[E + 1]
    return v / zy, av / zy * abs(w) ** (p[E + 2] - 1.0) * (p[E + 3] + p[E + 4] * s * np.sign(w))


@nb.njit(cache=True)
def _phi(q, h):
    """(1 - exp(-q h)) / q, -> h as q -> 0."""
    x = q * h
    if x < 1e-8:
        return h
    return -np.expm1(-x) / q


@nb.njit(cache=True)
def _relax(kind, p, x, h):
    """Advance the memory variable x[2] by h at frozen velocity (exponential midpoint rule)."""
    v, w = x[1], x[2]
    pp, q = _memory_rates(kind, p, v, w)
    half = w + (pp - q * w) * _phi(q, 0.5 * h)
    pp, q = _memory_rates(kind, p, v, half)
    x[2] = w + (pp - q * w) * _phi(q, h)


@nb.njit(cache=True)
def _note_impact(p, x, z0, v0):
    """Store the velocity at which a stop was entered during the last sub-step (x[4])."""
    gap = p[E + 3]
    if abs(x[0]) > gap >= abs(z0):
        theta = (gap - abs(z0)) / (abs(x[0]) - abs(z0))
        x[4] = max(abs(v0 + theta * (x[1] - v0)), p[E + 4])


@nb.njit(cache=True)
def _substep(kind, p, x, y0, ym, y1, h, work):
    """One RK4 step of h (base acceleration y0, ym, y1 at its start, middle and end)."""
    memory = LUGRE <= kind <= BOUC_WEN
    if memory:
        _relax(kind, p, x, 0.5 * h)
    z0, v0 = x[0], x[1]
    k1, k2, k3, k4, tmp = work[0], work[1], work[2], work[3], work[4]
    _rhs(kind, p, x, y0, k1)
    for j in range(5):
        tmp[j] = x[j] + 0.5 * h * k1[j]
    _rhs(kind, p, tmp, ym, k2)
    for j in range(5):
        tmp[j] = x[j] + 0.5 * h * k2[j]
    _rhs(kind, p, tmp, ym, k3)
    for j in range(5):
        tmp[j] = x[j] + h * k3[j]
    _rhs(kind, p, tmp, y1, k4)
    for j in range(5):
        x[j] += h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j])
    if memory:
        _relax(kind, p, x, 0.5 * h)
    if kind == MAXWELL_SLIP:
        _play(p, x)
    if kind == STOP_POWER:
        _note_impact(p, x, z0, v0)


def lagrange_weights(n_sub: int) -> tuple[np.ndarray, np.ndarray]:
    """Where the sub-step ends and middles r / (2 n_sub), r = 0..2 n_sub, of an internal step
    fall on the input grid of two samples per step: (first grid offset 0..2, 6-point Lagrange
    weights on grid offsets -2..3 from it)."""
    u = np.arange(2 * n_sub + 1) / n_sub
    first = np.floor(u + 1e-12).astype(np.int64)
    frac = u - first
    nodes = np.arange(-2, 4)
    w = np.ones((u.size, 6))
    for k in range(6):
        for j in range(6):
            if j != k:
                w[:, k] *= (frac - nodes[j]) / (nodes[k] - nodes[j])
    return first, w


@nb.njit(cache=True)
def _input_at(y2, i, first, w, r):
    """Base acceleration at offset r of internal step i (6-point Lagrange; 0 before t = 0)."""
    j0 = 2 * i + first[r] - 2
    total = 0.0
    for k in range(6):
        if j0 + k >= 0:
            total += w[r, k] * y2[j0 + k]
    return total


@nb.njit(cache=True)
def _near_switch(kind, p, x, acc, h_int):
    """Whether a contact or Karnopp's stick band may be met within the next internal step."""
    reach = abs(x[1]) * h_int + 0.5 * abs(acc) * h_int * h_int
    if kind == STOP_KV or kind == STOP_POWER:
        return abs(x[0]) + reach >= p[E + 3]
    if kind == KARNOPP:
        return abs(x[1]) - abs(acc) * h_int <= p[E + 2]
    if kind == BACKLASH:  # the contact's edge |z - r| = g within two steps' travel
        return abs(abs(x[0] - x[2]) - p[E]) <= 2.0 * abs(x[1] - x[3]) * h_int + 1e-12
    return False


@nb.njit(cache=True)
def _integrate(kind, p, y2, n, n_sub, h_int, coarse, fine, refine):
    """z'' (m/s^2), z (m), z' (m/s) at n internal samples from rest.

    ``y2``: base acceleration at two samples per internal step (t = j h_int / 2), exact;
    ``coarse``, ``fine``: :func:`lagrange_weights` for n_sub and n_sub x refine sub-steps, the
    latter in an internal step that may meet a contact or the stick band (:func:`_near_switch`).
    """
    acc, zs, vs = np.empty(n), np.empty(n), np.empty(n)
    x = np.zeros(5)
    x[4] = p[_VREF]
    work = np.zeros((5, 5))
    for i in range(n):
        if i > 0:
            first, w, m = coarse[0], coarse[1], n_sub
            if _near_switch(kind, p, x, acc[i - 1], h_int):
                first, w, m = fine[0], fine[1], n_sub * refine
            for j in range(m):
                _substep(kind, p, x, _input_at(y2, i - 1, first, w, 2 * j),
                         _input_at(y2, i - 1, first, w, 2 * j + 1),
                         _input_at(y2, i - 1, first, w, 2 * j + 2), h_int / m, work)
        acc[i] = _rhs(kind, p, x, y2[2 * i], work[4])
        zs[i], vs[i] = x[0], x[1]
    return acc, zs, vs


# --------------------------------------------------------------------------- device, excitation

def _log_uniform(rng: np.random.Generator, lo: float, hi: float) -> float:
    return float(np.exp(rng.uniform(np.log(lo), np.log(hi))))


@dataclass(frozen=True)
class Device:
    """The baseline device (SI units): eq. (1) with F(v) = F_c S(v / v_t)."""

    M: float              # effective mass, kg (oscillating mass + rotor inertia)
    m: float              # oscillating mass, kg
    k: float              # spring, N/m
    c: float              # viscous damping, N s/m
    F_c: float            # sliding friction, N
    v_t: float            # friction transition velocity, m/s (1/beta of the tanh law)
    friction_form: str    # S: 'tanh' | 'atan' | 'algebraic'
    transition_ratio: float  # v_t / the baseline's RMS relative velocity (see settle_v_t)
    f_n: float            # natural frequency sqrt(k/M) / 2 pi, Hz
    zeta: float           # viscous damping ratio
    peak_base_acc: float  # peak |y''| of the excitation, m/s^2

    @property
    def velocity_scale(self) -> float:
        """m max|y''| / (M 2 pi f_n) (m/s): the order of the relative velocity."""
        return self.m * self.peak_base_acc / (self.M * 2.0 * np.pi * self.f_n)

    def params(self, **overrides: float) -> np.ndarray:
        """The compiled model's parameter vector (device part; M, m, v_ref overridable)."""
        p = np.zeros(N_PARAMS)
        p[[_M, _MOSC, _K, _C, _FC, _VT]] = [self.M, self.m, self.k, self.c, self.F_c, self.v_t]
        p[_FORM] = FRICTION_FORMS.index(self.friction_form)
        p[_VREF] = self.velocity_scale
        for name, value in overrides.items():
            p[{"M": _M, "m": _MOSC, "c": _C, "F_c": _FC, "v_t": _VT, "v_ref": _VREF}[name]] = value
        return p


def _draw_device_once(rng: np.random.Generator) -> Device:
    f_n, M = _log_uniform(rng, 0.5, 8.0), _log_uniform(rng, 0.5, 20.0)
    m = M * rng.uniform(0.3, 0.95)
    zeta, peak = _log_uniform(rng, 0.01, 0.1), rng.uniform(1.0, 8.0)
    k = M * (2.0 * np.pi * f_n) ** 2
    F_c = _log_uniform(rng, 0.03, 0.4) * m * peak
    ratio = 10.0 ** rng.uniform(-2.0, -0.5)
    v_scale = m * peak / (M * 2.0 * np.pi * f_n)
    return Device(M=M, m=m, k=k, c=2.0 * zeta * np.sqrt(k * M), F_c=F_c, v_t=v_scale * ratio,
                  friction_form=FRICTION_FORMS[int(rng.integers(len(FRICTION_FORMS)))],
                  transition_ratio=ratio, f_n=f_n, zeta=zeta, peak_base_acc=peak)


def draw_device(rng: np.random.Generator, min_friction_acc: float = 0.0,
                friction_form: str = "tanh") -> Device:
    """A device from broad ranges: f_n 0.5-8 Hz, M 0.5-20 kg (log-uniform), m/M 0.3-0.95,
    zeta 0.01-0.1 (log-uniform), peak base acceleration 1-8 m/s^2, F_c 3-40 % of m max|y''|
    (log-uniform), v_t / v_rms 10^(-2..-0.5); S ``friction_form`` or, for 'drawn', one of
    FRICTION_FORMS at even odds.

    v_t is provisional (the velocity scale m max|y''| / (M 2 pi f_n) stands for v_rms) until
    :func:`settle_v_t`. Drawn again while the friction's acceleration F_c / M is below
    ``min_friction_acc`` (m/s^2): a friction-dominated device's friction shows above the
    sensor noise.
    """
    if friction_form not in (*FRICTION_FORMS, "drawn"):
        raise ValueError(f"friction_form must be one of {FRICTION_FORMS} or 'drawn'")
    for _ in range(1000):
        device = _draw_device_once(rng)
        if device.F_c / device.M >= min_friction_acc:
            if friction_form == "drawn":
                return device
            return replace(device, friction_form=friction_form)
    raise RuntimeError(f"no device with F_c / M >= {min_friction_acc} m/s^2")


@dataclass(frozen=True)
class Excitation:
    """y''(t) = scale fade(t) (1 + depth sin(2 pi t / env_period + env_phase))
    sum_k cos(2 pi k t / period + phase_k), periodic over ``period`` (s)."""

    period: float
    bins: np.ndarray = field(repr=False)
    phases: np.ndarray = field(repr=False)
    env_depth: float
    env_period: float
    env_phase: float
    scale: float = 1.0

    def _shape(self, t: np.ndarray) -> np.ndarray:
        fade = np.where(t < FADE_IN_S, 0.5 * (1.0 - np.cos(np.pi * t / FADE_IN_S)), 1.0)
        env = 1.0 + self.env_depth * np.sin(2.0 * np.pi * t / self.env_period + self.env_phase)
        return self.scale * np.where(t > 0.0, fade, 0.0) * env

    def at(self, t: np.ndarray | float) -> np.ndarray:
        """y''(t) (m/s^2) by the sum of cosines (slow; for reference solutions)."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        arg = 2.0 * np.pi * np.outer(t, self.bins / self.period) + self.phases
        return self._shape(t) * np.cos(arg).sum(axis=1)

    def on_grid(self, rate: float) -> np.ndarray:
        """y'' (m/s^2) at t = i / rate, i = 0..period x rate (inclusive), by inverse FFT."""
        n = round(self.period * rate)
        spec = np.zeros(n // 2 + 1, dtype=complex)
        spec[self.bins] = 0.5 * n * np.exp(1j * self.phases)
        lines = np.fft.irfft(spec, n)
        lines = np.append(lines, lines[0])
        return self._shape(np.arange(n + 1) / rate) * lines


def draw_excitation(rng: np.random.Generator, device: Device, period: float, record_s: float,
                    fs: float) -> Excitation:
    """Random-phase multisine, flat over [0.25-0.6, 2-5] x f_n (>= 0.15 Hz, <= 0.3 fs),
    envelope depth 0.2-0.6 and period 5-15 s, scaled to the device's peak over the record."""
    f_lo = max(device.f_n * rng.uniform(0.25, 0.6), 0.15)
    f_hi = max(min(device.f_n * rng.uniform(2.0, 5.0), 0.3 * fs), 2.0 * f_lo)
    bins = np.arange(int(np.ceil(f_lo * period)), int(np.floor(f_hi * period)) + 1)
    exc = Excitation(period=period, bins=bins, phases=rng.uniform(0.0, 2.0 * np.pi, bins.size),
                     env_depth=rng.uniform(0.2, 0.6), env_period=rng.uniform(5.0, 15.0),
                     env_phase=rng.uniform(0.0, 2.0 * np.pi))
    rate = 2.0 * OVERSAMPLE * fs
    y = exc.on_grid(rate)[: round(record_s * rate) + 1]
    return replace(exc, scale=device.peak_base_acc / np.max(np.abs(y)))


# --------------------------------------------------------------------------- acquisition

@functools.lru_cache(maxsize=8)
def anti_alias_fir(q: int = OVERSAMPLE) -> np.ndarray:
    """Linear-phase low-pass FIR of a sigma-delta DAQ decimating by q (Kaiser window).

    Flat within 10^(-FIR_ATTENUATION_DB / 20) up to PASSBAND x the output rate and attenuating
    by FIR_ATTENUATION_DB from STOPBAND x the output rate (the output Nyquist frequency); odd
    length 2 D + 1 with the delay D a multiple of q.
    """
    width = 2.0 * (STOPBAND - PASSBAND) / q  # transition width / input Nyquist
    taps, beta = signal.kaiserord(FIR_ATTENUATION_DB, width)
    delay = int(np.ceil((taps - 1) / 2 / q)) * q
    return signal.firwin(2 * delay + 1, (PASSBAND + STOPBAND) / q, window=("kaiser", beta))


def daq(x: np.ndarray, n_out: int, q: int = OVERSAMPLE) -> np.ndarray:
    """Decimate x (internal rate, x = 0 before its first sample) to n_out output samples.

    Output k is the FIR's output centred on internal sample k q (delay compensated), so
    x must hold at least (n_out - 1) q + D + 1 samples.
    """
    h = anti_alias_fir(q)
    delay = (h.size - 1) // 2
    if x.size < (n_out - 1) * q + delay + 1:
        raise ValueError("too few internal samples for the FIR's delay")
    return signal.upfirdn(h, x, up=1, down=q)[delay // q: delay // q + n_out]


def sensor_noise(rng: np.random.Generator, rms: float, n_out: int,
                 q: int = OVERSAMPLE) -> np.ndarray:
    """White sensor noise through the DAQ, ``rms`` (m/s^2) at its output in expectation."""
    h = anti_alias_fir(q)
    delay = (h.size - 1) // 2
    raw = rng.standard_normal((n_out - 1) * q + 2 * delay + 1) * rms / np.sqrt(np.sum(h * h))
    return signal.upfirdn(h, raw, up=1, down=q)[2 * delay // q: 2 * delay // q + n_out]


# --------------------------------------------------------------------------- simulation

@dataclass(frozen=True)
class TimeBase:
    """Output rate fs (Hz) and n_out samples; the internal grid runs q = OVERSAMPLE times
    faster and D (the FIR's delay) samples longer, so every output sample is fully filtered."""

    fs: float
    n_out: int

    @property
    def h_int(self) -> float:
        return 1.0 / (OVERSAMPLE * self.fs)

    @property
    def n_int(self) -> int:
        return (self.n_out - 1) * OVERSAMPLE + (anti_alias_fir().size - 1) // 2 + 1

    @property
    def period(self) -> float:
        """The excitation's period (s): the simulated span plus the interpolation's reach."""
        return (self.n_int + 4) * self.h_int

    @property
    def window(self) -> slice:
        """Output samples after the lead-in."""
        return slice(round(LEAD_IN_S * self.fs), self.n_out)


def simulate(kind: int, p: np.ndarray, y2: np.ndarray, tb: TimeBase,
             n_sub: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """z'' (m/s^2), z (m), z' (m/s) at the internal rate, from rest (for SENSOR_LINE, z'' as
    the mass accelerometer reads it: the motion's plus its hum).

    ``y2``: the base acceleration at two samples per internal step, ``excitation.on_grid(2 /
    h_int)``. Raises FloatingPointError if the motion is not finite.
    """
    if y2.size < 2 * tb.n_int + 4:
        raise ValueError("the excitation grid is shorter than the record")
    acc, z, v = _integrate(int(kind), np.ascontiguousarray(p, dtype=float), y2, tb.n_int,
                           int(n_sub), tb.h_int, lagrange_weights(int(n_sub)),
                           lagrange_weights(int(n_sub) * SWITCH_REFINE), SWITCH_REFINE)
    if kind == SENSOR_LINE:  # the mass accelerometer's reading: a hum on top of the motion
        acc = acc + p[E] * np.sin(2.0 * np.pi * p[E + 1] * tb.h_int * np.arange(acc.size)
                                  + p[E + 2])
    if not np.all(np.isfinite(acc)):
        raise FloatingPointError(f"effect kind {kind}: the motion diverged (n_sub = {n_sub})")
    return acc, z, v


class _Run:
    """One record's excitation and time base: its input grid and (cached) simulated outputs;
    ``channel``: the recorded output, z'' ("acc") or z ("disp")."""

    def __init__(self, excitation: Excitation, tb: TimeBase, channel: str = "acc"):
        self.excitation, self.tb, self.channel = excitation, tb, channel
        self._outputs: dict[tuple, np.ndarray] = {}
        self.sims = 0

    @functools.cached_property
    def grid(self) -> np.ndarray:
        """y'' (m/s^2) at two samples per internal step."""
        return self.excitation.on_grid(2.0 / self.tb.h_int)

    def base_internal(self) -> np.ndarray:
        """y'' (m/s^2) at the internal samples."""
        return self.grid[: 2 * self.tb.n_int: 2]

    @functools.cached_property
    def base_motion(self) -> tuple[np.ndarray, np.ndarray]:
        """(y', y) (m/s, m) at the internal samples: y'' integrated twice (trapezoid on the
        input grid) with the constant base velocity that leaves y no straight-line trend over
        the record (least squares: a base that returns to where it oscillates; y'(0) is minus
        that constant), y about its mean. A constant y' leaves y'' unchanged."""
        h, n = 0.5 * self.tb.h_int, 2 * self.tb.n_int
        g = self.grid[:n]
        v = np.concatenate([[0.0], np.cumsum(0.5 * h * (g[1:] + g[:-1]))])
        y = np.concatenate([[0.0], np.cumsum(0.5 * h * (v[1:] + v[:-1]))])
        t = h * np.arange(n)
        record = slice(0, 2 * (self.tb.n_out - 1) * OVERSAMPLE + 1)
        slope = np.polyfit(t[record], y[record], 1)[0]
        v, y = v - slope, y - slope * t
        return v[::2], (y - np.mean(y[record]))[::2]

    def output(self, kind: int, p: np.ndarray, n_sub: int,
               internal: bool = False) -> np.ndarray | tuple[np.ndarray, ...]:
        """Noise-free recorded output (z'' or z, :attr:`channel`; output rate), cached;
        with ``internal``, also z'', z, z' at the internal rate."""
        key = (int(kind), p.tobytes(), int(n_sub))
        if internal or key not in self._outputs:
            self.sims += 1
            acc, z, v = simulate(kind, p, self.grid, self.tb, n_sub)
            self._outputs[key] = daq(acc if self.channel == "acc" else z, self.tb.n_out)
            if internal:
                return self._outputs[key], acc, z, v
        return self._outputs[key]


# --------------------------------------------------------------------------- scenarios

@dataclass(frozen=True)
class Context:
    """What a scenario's shape draw may depend on: the device, the baseline motion, fs."""

    device: Device
    fs: float
    z_rms: float          # RMS relative displacement after the lead-in (m)
    v_rms: float          # RMS relative velocity after the lead-in (m/s)
    z_max: float          # largest |z| (m) over the simulated span
    abs_z: np.ndarray = field(repr=False)  # sorted |z| (m) over the simulated span
    record_s: float = 0.0  # time (s) of the record's last output sample
    base_v0: float = 0.0   # the base's velocity y' at t = 0 (m/s, :attr:`_Run.base_motion`)

    @classmethod
    def of(cls, device: Device, fs: float, z: np.ndarray, v: np.ndarray,
           window: slice, base_v0: float = 0.0) -> Context:
        """From the baseline's internal-rate z, z' and the internal window after the lead-in
        (which ends at the record's last output sample)."""
        abs_z = np.sort(np.abs(z))
        return cls(device, fs, _rms(z[window]), _rms(v[window]), float(abs_z[-1]), abs_z,
                   (window.stop - 1) / (OVERSAMPLE * fs), base_v0)

    def gap(self, quantile: float) -> float:
        """The |z| quantile (m) of the baseline motion (1: its largest |z|, never exceeded)."""
        return float(np.quantile(self.abs_z, quantile))


#: (kind, effect parameters, device overrides) of a scenario at a strength.
Effect = tuple[int, list[float], dict[str, float]]


@dataclass(frozen=True)
class LiteratureScenario:
    """A concealed effect: its literature form, the library names that name it, and how to
    draw its shape, bound its strength and build it (callables: see ``_SPECS``)."""

    name: str
    family: str
    form: str                          # the equation, in the literature's notation
    correct_names: tuple[str, ...]     # library terms counted as naming it (preferred first)
    related_names: tuple[str, ...]     # terms that describe part of it (not counted correct)
    description: str
    citation: str
    strength: str                      # what the calibrated strength is, with its bounds
    shapes: str                        # the shape parameters' ranges
    draw_shape: Callable[[np.random.Generator, Context], dict] = field(repr=False,
                                                                       compare=False)
    bounds: Callable[[Context, dict], tuple[float, float]] = field(repr=False, compare=False)
    effect: Callable[[Context, dict, float], Effect] = field(repr=False, compare=False)


def _bristle_stiffness(rng: np.random.Generator, ctx: Context) -> float:
    """Log-uniform in 1e3-1e6 N/m, narrowed to pre-sliding distances F_c / sigma0 of 1 um to
    min(1 mm, 0.2 z_rms) (the nearest plausible value if that leaves nothing)."""
    f_c = ctx.device.F_c
    lo = max(1e3, f_c / min(1e-3, 0.2 * ctx.z_rms))
    hi = min(1e6, f_c / 1e-6)
    if lo >= hi:
        return float(np.clip(np.sqrt(lo * hi), 1e3, 1e6))
    return _log_uniform(rng, lo, hi)


def _relative(rng: np.random.Generator, scale: float, lo_dec: float, hi_dec: float) -> float:
    return scale * 10.0 ** rng.uniform(lo_dec, hi_dec)


def _stop_shape(rng: np.random.Generator, ctx: Context, exponent: float | None) -> dict:
    n = rng.uniform(1.2, 2.0) if exponent is None else exponent
    return {"stiffness": _log_uniform(rng, 1e3, 1e7), "restitution": rng.uniform(0.3, 0.9),
            "exponent": n}


def _stop_kv(ctx: Context, sh: dict, beyond: float) -> Effect:
    """Kelvin-Voigt stops at the (1 - beyond)-quantile of |z|: c_c = 2 zeta_c sqrt(k_c M),
    zeta_c from the restitution e."""
    ln_e, k_c = np.log(sh["restitution"]), sh["stiffness"]
    zeta = -ln_e / np.sqrt(np.pi ** 2 + ln_e ** 2)
    return (STOP_KV, [k_c, 1.0, 2.0 * zeta * np.sqrt(k_c * ctx.device.M), ctx.gap(1.0 - beyond)],
            {})


def _stop_power(ctx: Context, sh: dict, beyond: float, damped: bool) -> Effect:
    """K delta^n (1 + 3 (1 - e) / 2 delta' / v_impact) (Hunt-Crossley; undamped: Hertz)
    stops at the (1 - beyond)-quantile of |z|; v_impact floored at 0.05 v_rms."""
    damping = 1.5 * (1.0 - sh["restitution"]) if damped else 0.0
    return (STOP_POWER, [sh["stiffness"], sh["exponent"], damping, ctx.gap(1.0 - beyond),
                         0.05 * ctx.v_rms], {"v_ref": ctx.v_rms})


def _mode_shape(rng: np.random.Generator, ctx: Context, zeta: tuple[float, float]) -> dict:
    f = min(ctx.device.f_n * rng.uniform(1.5, 8.0), 0.35 * ctx.fs)
    return {"frequency_hz": f, "zeta": _log_uniform(rng, *zeta)}


def _mount(ctx: Context, sh: dict, compliance: float) -> Effect:
    """Mount of mass m_b = mass_ratio M at f_b = f_n / sqrt(compliance): k_b = m_b (2 pi
    f_b)^2, c_b = 2 zeta sqrt(k_b m_b); compliance -> 0 is a rigid mount."""
    mb = ctx.device.M * sh["mass_ratio"]
    kb = mb * (2.0 * np.pi * ctx.device.f_n) ** 2 / compliance
    return MOUNT, [mb, kb, 2.0 * sh["zeta"] * np.sqrt(kb * mb)], {}


def _mount_bounds(ctx: Context, sh: dict) -> tuple[float, float]:
    """(f_n / f_b)^2 for f_b from 0.35 fs down to 1.5 f_n."""
    return (ctx.device.f_n / (0.35 * ctx.fs)) ** 2, 1.0 / 1.5 ** 2


def _secondary(ctx: Context, sh: dict, ratio: float) -> Effect:
    """Secondary mass m2 = ratio m on k2 = m2 (2 pi f)^2, c2 = 2 zeta sqrt(k2 m2)."""
    m2 = ctx.device.m * ratio
    k2 = m2 * (2.0 * np.pi * sh["frequency_hz"]) ** 2
    return SECONDARY, [m2, k2, 2.0 * sh["zeta"] * np.sqrt(k2 * m2)], {}


def _mass_error(ctx: Context, sh: dict, fraction: float, payload: bool) -> Effect:
    """True M (and for a payload, m) = nominal + sign x fraction x M."""
    d = ctx.device
    delta = sh["sign"] * fraction * d.M
    return NONE, [], ({"M": d.M + delta, "m": d.m + delta} if payload else {"M": d.M + delta})


def _mass_error_bounds(ctx: Context, sh: dict, payload: bool) -> tuple[float, float]:
    """Up to 30 % of M; a loss leaves >= half of m (payload) or of the rotor's M - m."""
    d = ctx.device
    room = 0.5 * (d.m if payload else d.M - d.m) / d.M
    return 1e-6, 0.3 if sh["sign"] > 0 else min(0.3, room)


def _sign(rng: np.random.Generator, ctx: Context) -> dict:
    return {"sign": float(rng.choice([-1.0, 1.0]))}


_SHARE = (1e-5, 1.0)
_BEYOND = (1e-6, 0.5)

_CITE = {
    "lugre": "Canudas de Wit, C., Olsson, H., Astrom, K.J., Lischinsky, P. (1995) A new model "
             "for control of systems with friction. IEEE Trans. Autom. Control 40(3):419-425.",
    "dahl": "Dahl, P.R. (1968) A solid friction model. Tech. Rep. TOR-0158(3107-18)-1, The "
            "Aerospace Corporation; exponent form: Dahl, P.R. (1976) Solid friction damping of "
            "mechanical vibrations. AIAA J. 14(12):1675-1682.",
    "bouc_wen": "Bouc, R. (1967) Forced vibration of mechanical systems with hysteresis. Proc. "
                "4th Conf. Nonlinear Oscillations, Prague; Wen, Y.-K. (1976) Method for random "
                "vibration of hysteretic systems. J. Eng. Mech. Div. ASCE 102(2):249-263.",
    "maxwell_slip": "Iwan, W.D. (1966) A distributed-element model for hysteresis and its "
                    "steady-state dynamic response. J. Appl. Mech. 33(4):893-900; Al-Bender, "
                    "F., Lampaert, V., Swevers, J. (2005) The generalized Maxwell-slip model: "
                    "a novel model for friction simulation and compensation. IEEE Trans. "
                    "Autom. Control 50(11):1883-1887.",
    "karnopp": "Karnopp, D. (1985) Computer simulation of stick-slip friction in mechanical "
               "dynamic systems. ASME J. Dyn. Syst. Meas. Control 107(1):100-103.",
    "stribeck": "Armstrong-Helouvry, B., Dupont, P., Canudas de Wit, C. (1994) A survey of "
                "models, analysis tools and compensation methods for the control of machines "
                "with friction. Automatica 30(7):1083-1138; exponent 1: Bo, L.C., Pavelescu, D. "
                "(1982) The friction-speed relation and its influence on the critical velocity "
                "of stick-slip motion. Wear 82(3):277-289.",
    "asymmetric": "Direction-dependent Coulomb levels F_c+ != F_c-: Johnson, C.T., Lorenz, R.D. "
                  "(1992) Experimental identification of friction and its compensation in "
                  "precise, position controlled mechanisms. IEEE Trans. Ind. Appl. "
                  "28(6):1392-1398; Armstrong-Helouvry et al. (1994), Automatica 30(7).",
    "kelvin_voigt": "Goldsmith, W. (1960) Impact. Arnold, London; restitution-damping relation "
                    "as surveyed by Gilardi, G., Sharf, I. (2002) Literature survey of contact "
                    "dynamics modelling. Mech. Mach. Theory 37(10):1213-1239.",
    "hertz": "Hertz, H. (1882) Ueber die Beruehrung fester elastischer Koerper. J. reine angew. "
             "Math. 92:156-171.",
    "hunt_crossley": "Hunt, K.H., Crossley, F.R.E. (1975) Coefficient of restitution "
                     "interpreted as damping in vibroimpact. ASME J. Appl. Mech. 42(2):440-445.",
    "duffing": "Duffing, G. (1918) Erzwungene Schwingungen bei veraenderlicher Eigenfrequenz. "
               "Vieweg; Kovacic, I., Brennan, M.J. (eds.) (2011) The Duffing Equation. Wiley.",
    "power_spring": "Worden, K., Tomlinson, G.R. (2001) Nonlinearity in Structural Dynamics. "
                    "IOP; Kerschen, G., Worden, K., Vakakis, A.F., Golinval, J.-C. (2006) Past, "
                    "present and future of nonlinear system identification in structural "
                    "dynamics. Mech. Syst. Signal Process. 20(3):505-592.",
    "quadratic_damping": "Morison, J.R., O'Brien, M.P., Johnson, J.W., Schaaf, S.A. (1950) The "
                         "force exerted by surface waves on piles. Petroleum Trans. AIME "
                         "189:149-154 (drag proportional to v|v|).",
    "power_damping": "Jacobsen, L.S. (1930) Steady forced vibration as influenced by damping. "
                     "Trans. ASME 52:169-181 (damping proportional to |v|^n); Worden & "
                     "Tomlinson (2001).",
    "mount": "Den Hartog, J.P. (1956) Mechanical Vibrations, 4th ed. McGraw-Hill (two-degree-"
             "of-freedom base excitation); eq. (1) of Green et al. (2015) on a compliant mount.",
    "mode": "Ewins, D.J. (2000) Modal Testing: Theory, Practice and Application, 2nd ed. "
            "Research Studies Press (unmodelled and residual modes).",
    "mass": "Green, P.L., Hendijanizadeh, M., Simeone, L., Elliott, S.J. (2015) Probabilistic "
            "modelling of a rotational energy harvester. J. Intell. Mater. Syst. Struct. "
            "27(4):528-536, eq. (1): M = m + rotor inertia reflected through the screw lead.",
    "none": "Green et al. (2015), eq. (1), with the device's own smooth friction law.",
    "cogging": "Zhu, Z.Q., Howe, D. (2000) Influence of design parameters on cogging torque in "
               "permanent magnet machines. IEEE Trans. Energy Convers. 15(4):407-412; Bianchi, "
               "N., Bolognani, S. (2002) Design techniques for reducing the cogging torque in "
               "surface-mounted PM motors. IEEE Trans. Ind. Appl. 38(5):1259-1265 (the "
               "harvester's generator, reflected through the screw lead as in Green et al. "
               "2015).",
    "quadratic_spring": "Worden, K., Tomlinson, G.R. (2001) Nonlinearity in Structural "
                        "Dynamics. IOP (asymmetric, even restoring forces); Nayfeh, A.H., "
                        "Mook, D.T. (1979) Nonlinear Oscillations. Wiley (quadratic "
                        "nonlinearity).",
    "friction_drift": "Bittencourt, A.C., Gunnarsson, S. (2012) Static friction in a robot "
                      "joint - modeling and identification of load and temperature effects. "
                      "ASME J. Dyn. Syst. Meas. Control 134(5):051013; Armstrong-Helouvry et "
                      "al. (1994), Automatica 30(7) (friction's dependence on temperature and "
                      "time).",
    "mains_hum": "Bendat, J.S., Piersol, A.G. (2010) Random Data: Analysis and Measurement "
                 "Procedures, 4th ed. Wiley (periodic contamination of measured data, power-"
                 "line pickup); Ewins, D.J. (2000) Modal Testing, 2nd ed. (mains hum in "
                 "transducer signals).",
    "dead_zone": "Nordin, M., Gutman, P.-O. (2002) Controlling mechanical systems with "
                 "backlash - a survey. Automatica 38(10):1633-1649 (the dead-zone model); "
                 "Tao, G., Kokotovic, P.V. (1996) Adaptive Control of Systems with "
                 "Actuator and Sensor Nonlinearities. Wiley (dead zones).",
    "backlash": "Nordin, M., Gutman, P.-O. (2002) Controlling mechanical systems with backlash "
                "- a survey. Automatica 38(10):1633-1649 (two inertias coupled through a "
                "dead zone); contact damping from the restitution as Gilardi & "
                "Sharf (2002), Mech. Mach. Theory 37(10).",
    "ground_friction": "Marino, L., Cicirello, A. (2023) A switching Gaussian process latent "
                       "force model for the identification of mechanical systems with a "
                       "discontinuous nonlinearity. arXiv:2303.03858 (a base-excited frame "
                       "whose friction contact is fixed to the ground).",
}


def _memory(name: str, kind: int, form: str, shapes: str, extra: Callable) -> LiteratureScenario:
    """A friction law with memory carrying a share s of the contact (rest: the device's law)."""
    def draw(rng: np.random.Generator, ctx: Context) -> dict:
        return {"stiffness": _bristle_stiffness(rng, ctx), **extra(rng)}

    def effect(ctx: Context, sh: dict, s: float) -> Effect:
        if kind == LUGRE:
            sigma1 = 2.0 * sh["zeta_bristle"] * np.sqrt(sh["stiffness"] * ctx.device.M)
            return kind, [s, sh["stiffness"], sigma1], {}
        if kind == DAHL:
            return kind, [s, sh["stiffness"], sh["alpha"]], {}
        return kind, [s, sh["stiffness"], sh["n"], sh["beta"], 1.0 - sh["beta"]], {}

    return LiteratureScenario(
        name, "pre-sliding friction with memory", f"F = (1 - s) F_c S(v/v_t) + s F_mem; {form}",
        ("hysteresis",), ("coulomb_friction",),
        f"{name} friction (bristle/hysteretic memory) carries a share s of the contact",
        _CITE[name], "share s of the friction with memory, 1e-5..1",
        "stiffness 1e3-1e6 N/m log-uniform (pre-sliding F_c/stiffness 1 um..min(1 mm, "
        f"0.2 z_rms)); {shapes}", draw, lambda ctx, sh: _SHARE, effect)


def _maxwell_slip() -> LiteratureScenario:
    """Two Maxwell-slip elements carrying a share s of the contact (appended after the forms
    outside the library, so that the grid's earlier scenarios keep their places)."""
    def draw(rng: np.random.Generator, ctx: Context) -> dict:
        return {"stiffness": _bristle_stiffness(rng, ctx), "first": rng.uniform(0.3, 0.7),
                "spread": _log_uniform(rng, 3.0, 10.0)}

    def effect(ctx: Context, sh: dict, s: float) -> Effect:
        d1 = ctx.device.F_c / sh["stiffness"]
        return MAXWELL_SLIP, [s, sh["first"], d1, sh["spread"] * d1], {}

    return LiteratureScenario(
        "maxwell_slip", "pre-sliding friction with memory",
        "F = (1 - s) F_c S(v/v_t) + sum_i clip(W_i (z - w_i) / D_i, +-W_i), slider w_i kept "
        "within D_i of z; W_1 = a s F_c, W_2 = (1 - a) s F_c",
        ("hysteresis", "sticking_friction"), ("coulomb_friction",),
        "two Maxwell-slip (elasto-slip) elements carry a share s of the contact: each sticks "
        "elastically until its spring holds W_i, then slips",
        _CITE["maxwell_slip"], "share s of the contact, 1e-5..1",
        "D_1 = F_c / k with k 1e3-1e6 N/m log-uniform (1 um..min(1 mm, 0.2 z_rms)), D_2 = r D_1 "
        "with r 3-10 log-uniform, first element's share a 0.3-0.7",
        draw, lambda ctx, sh: _SHARE, effect)


def _backlash(ctx: Context, sh: dict, s: float) -> Effect:
    """Gap g = s z_rms between the mass m and the screw side J = M - m; contact stiffness
    k_b = mu (2 pi f_b)^2 on the reduced mass mu = m J / (m + J), c_b = 2 zeta_b sqrt(k_b mu),
    zeta_b from the restitution e as :func:`_stop_kv`."""
    d = ctx.device
    mu = d.m * (d.M - d.m) / d.M
    k_b = mu * (2.0 * np.pi * sh["contact_hz"]) ** 2
    ln_e = np.log(sh["restitution"])
    zeta = -ln_e / np.sqrt(np.pi ** 2 + ln_e ** 2)
    return BACKLASH, [s * ctx.z_rms, k_b, 2.0 * zeta * np.sqrt(k_b * mu)], {}


def _appended() -> list[LiteratureScenario]:
    """The spring's dead zone, backlash and friction on the ground (issue 63), appended so that
    the grid's earlier scenarios keep their places."""
    S = LiteratureScenario
    return [
        S("spring_dead_zone", "dead zone", "F_spring = k dz(z, g) in place of k z, dz(z, g) = "
          "z - g sgn z for |z| > g, else 0", (), ("end_stop", "backlash", "cubic_stiffness"),
          "the main spring acts through a play of +-g (a dead zone in its mount): no restoring "
          "force within the gap; no library term has it (end_stop adds a stiffness beyond a "
          "gap, backlash couples the mass to the screw side, not to the spring)",
          _CITE["dead_zone"], "g / z_max, 1e-6..0.5", "none",
          lambda rng, ctx: {}, lambda ctx, sh: (1e-6, 0.5),
          lambda ctx, sh, s: (SPRING_DEAD_ZONE, [s * ctx.z_max], {})),
        S("backlash", "backlash", "m z'' = -m y'' - k z - F_b, J r'' = F_b - c r' - F_c S(r'/v_t)"
          ", F_b = max(k_b dz(z - r, g) + c_b (z' - r'), 0) sgn(z - r) in contact, J = M - m",
          ("backlash",), ("unmodelled_mode", "end_stop"),
          "a play of +-g between the mass and the screw side (the nut's backlash), 2 DOF",
          _CITE["backlash"], "g / z_rms, 1e-6..1",
          "contact frequency on m J / (m + J) 0.5-2 fs (log-uniform); restitution 0.3-0.9",
          lambda rng, ctx: {"contact_hz": _log_uniform(rng, 0.5 * ctx.fs, 2.0 * ctx.fs),
                            "restitution": rng.uniform(0.3, 0.9)},
          lambda ctx, sh: (1e-6, 1.0), _backlash),
        S("ground_friction", "friction on the ground",
          "F = (1 - s) F_c S(z'/v_t) + s F_c S((z' + y')/v_t)",
          ("ground_friction", "coulomb_friction"),
          ("sticking_friction", "stribeck_friction", "hysteresis"),
          "a share s of the device's friction acts on the mass's absolute velocity (a contact "
          "fixed to the ground); the sidecar is silent (no friction_on). Right only with the "
          "diagnosis's topology 'ground' (base_disp inputs); with a force input the base is "
          "the ground and the form is the baseline itself (not generated)",
          _CITE["ground_friction"], "share s on the ground, 1e-5..1", "none",
          lambda rng, ctx: {}, lambda ctx, sh: _SHARE,
          lambda ctx, sh, s: (GROUND_FRICTION, [s], {"v_ref": ctx.base_v0})),
    ]


def _friction_scenarios() -> list[LiteratureScenario]:
    S, rel = LiteratureScenario, _relative
    entries = [
        _memory("lugre", LUGRE, "z_b' = v - sigma0 |v| z_b / F_c, F_mem = sigma0 z_b + "
                "sigma1 z_b', sigma1 = 2 zeta_b sqrt(sigma0 M)", "zeta_b 0.1-1",
                lambda rng: {"zeta_bristle": rng.uniform(0.1, 1.0)}),
        _memory("dahl", DAHL, "dF/dx = sigma0 |1 - F/F_c sgn x'|^alpha sgn(1 - F/F_c sgn x')",
                "alpha 0.5-2", lambda rng: {"alpha": rng.uniform(0.5, 2.0)}),
        _memory("bouc_wen", BOUC_WEN, "F_mem = F_c w, z_y w' = v - beta |v||w|^(n-1) w - gamma "
                "v |w|^n, z_y = F_c / k_b, gamma = 1 - beta", "n 1-3, beta 0.5-1",
                lambda rng: {"n": rng.uniform(1.0, 3.0), "beta": rng.uniform(0.5, 1.0)}),
        S("karnopp", "stiction/breakaway", "F = (1 - s) F_c S(v/v_t) + F_K; F_K = clip(F_rest, "
          "+-s r F_c) if |v| < dv else s F_c sgn v",
          ("stribeck_friction", "coulomb_friction", "sticking_stribeck", "sticking_friction"),
          (), "Karnopp stick-slip element (breakaway r F_c) carries a share s of the contact",
          _CITE["karnopp"], "share s, 1e-5..1",
          "breakaway ratio r 1.2-2; stick band dv 10^(-1.5..-0.5) v_rms",
          lambda rng, ctx: {"breakaway_ratio": rng.uniform(1.2, 2.0),
                            "stick_band": rel(rng, ctx.v_rms, -1.5, -0.5)},
          lambda ctx, sh: _SHARE,
          lambda ctx, sh, s: (KARNOPP, [s, sh["breakaway_ratio"], sh["stick_band"]], {})),
    ]
    for exponent, label in ((1.0, "exponential"), (2.0, "gaussian")):
        entries.append(S(
            f"stribeck_{label}", "stiction/breakaway",
            f"F = F_c S(v/v_t) (1 + s exp(-(|v|/v_s)^{exponent:g}))", ("stribeck_friction",),
            ("coulomb_friction",), f"Stribeck friction, {label} decay from F_s = (1 + s) F_c",
            _CITE["stribeck"], "s = F_s/F_c - 1, 1e-5..2", "v_s 10^(-2..0) v_rms",
            lambda rng, ctx, e=exponent: {"v_s": rel(rng, ctx.v_rms, -2.0, 0.0), "delta": e},
            lambda ctx, sh: (1e-5, 2.0),
            lambda ctx, sh, s: (STRIBECK, [s, sh["v_s"], sh["delta"]], {})))
    return entries + [S(
        "asymmetric_friction", "direction-dependent friction",
        "F = F_c S(v/v_t) (1 + s tanh(v/v_a)): F_c (1 + s) forwards, F_c (1 - s) backwards",
        ("asymmetric_friction",), ("offset_force",),
        "sliding friction differs with direction, switching over its own velocity v_a",
        _CITE["asymmetric"], "s, 1e-5..0.8", "v_a 10^(-2..0) v_rms",
        lambda rng, ctx: {"v_a": rel(rng, ctx.v_rms, -2.0, 0.0)},
        lambda ctx, sh: (1e-5, 0.8), lambda ctx, sh, s: (ASYMMETRIC, [s, sh["v_a"]], {}))]


def _stop_scenarios() -> list[LiteratureScenario]:
    S = LiteratureScenario
    bounds = (lambda ctx, sh: _BEYOND)
    strength = ("fraction of the baseline's time beyond the gap, 1e-6..0.5 (the gap is the "
                "baseline's |z| quantile 1 - it)")
    shapes = "stiffness 1e3-1e7 (N/m^n) log-uniform; restitution e 0.3-0.9"
    return [
        S("end_stop_linear", "end stop contact", "F = max(k_c d + c_c d', 0), d = |z| - g > 0, "
          "c_c = 2 zeta_c sqrt(k_c M), zeta_c = -ln e / sqrt(pi^2 + ln^2 e)", ("end_stop",),
          ("cubic_stiffness",), "symmetric spring-dashpot stops at +-g", _CITE["kelvin_voigt"],
          strength, shapes, lambda rng, ctx: _stop_shape(rng, ctx, 1.0), bounds, _stop_kv),
        S("end_stop_hertz", "end stop contact", "F = K d^1.5, d = |z| - g > 0", ("end_stop",),
          ("cubic_stiffness",), "symmetric elastic Hertzian stops at +-g", _CITE["hertz"],
          strength, "stiffness 1e3-1e7 N/m^1.5 log-uniform",
          lambda rng, ctx: _stop_shape(rng, ctx, 1.5), bounds,
          lambda ctx, sh, k: _stop_power(ctx, sh, k, damped=False)),
        S("end_stop_hunt_crossley", "end stop contact",
          "F = max(K d^n (1 + 3 (1 - e) / 2 d' / v_impact), 0), v_impact per impact",
          ("end_stop",), ("cubic_stiffness",), "symmetric Hunt-Crossley stops at +-g",
          _CITE["hunt_crossley"], strength, shapes + "; n 1.2-2",
          lambda rng, ctx: _stop_shape(rng, ctx, None), bounds,
          lambda ctx, sh, k: _stop_power(ctx, sh, k, damped=True)),
    ]


def _spring_scenarios() -> list[LiteratureScenario]:
    S = LiteratureScenario

    def effect(ctx: Context, sh: dict, kappa: float) -> Effect:
        p = sh["exponent"]
        return SPRING_POWER, [kappa * ctx.device.k / ctx.z_max ** (p - 1.0), p], {}

    return [
        S("duffing", "hardening spring", "F = k3 z^3, k3 = kappa k / z_max^2",
          ("cubic_stiffness",), ("end_stop",), "Duffing cubic hardening spring",
          _CITE["duffing"], "kappa (added stiffness at z_max / k), 1e-6..10", "none",
          lambda rng, ctx: {"exponent": 3.0}, lambda ctx, sh: (1e-6, 10.0), effect),
        S("power_hardening", "hardening spring",
          "F = k_p |z|^p sgn z, k_p = kappa k / z_max^(p - 1)", ("cubic_stiffness",),
          ("end_stop",), "power-law hardening spring of a non-cubic exponent",
          _CITE["power_spring"], "kappa, 1e-6..10", "p 1.5-2.5 or 4-6 (even odds)",
          lambda rng, ctx: {"exponent": rng.uniform(*rng.choice([(1.5, 2.5), (4.0, 6.0)]))},
          lambda ctx, sh: (1e-6, 10.0), effect),
    ]


def _structural_and_mass() -> list[LiteratureScenario]:
    S = LiteratureScenario
    return [
        S("flexible_mount", "flexible mount / secondary mode",
          "m_b (w'' + y'') = F_d - k_b w - c_b w', F_d = k u + c u' + F(u') + (M - m) u'', "
          "u = z - w", ("unmodelled_mode",), (),
          "the screw's base side sits on a mount of its own frequency and damping (2 DOF)",
          _CITE["mount"], "compliance (f_n / f_b)^2, f_b from 0.35 fs down to 1.5 f_n",
          "m_b / M 0.2-5, zeta_b 0.01-0.1 (log-uniform)",
          lambda rng, ctx: {"mass_ratio": _log_uniform(rng, 0.2, 5.0),
                            "zeta": _log_uniform(rng, 0.01, 0.1)}, _mount_bounds, _mount),
        S("secondary_mode", "flexible mount / secondary mode",
          "m2 (y'' + z'' + q'') = -k2 q - c2 q', the sensor on the rest (m - m2)",
          ("unmodelled_mode",), ("inertia_error",),
          "a part m2 of the mass hangs on its own spring (a secondary mode on the mass)",
          _CITE["mode"], "m2 / m, 1e-6..0.5",
          "mode frequency 1.5-8 x f_n (<= 0.35 fs); zeta_2 0.005-0.05 log-uniform",
          lambda rng, ctx: _mode_shape(rng, ctx, (0.005, 0.05)),
          lambda ctx, sh: (1e-6, 0.5), _secondary),
        S("payload_error", "mass error", "true m and M = sidecar's + sign x fraction x M",
          ("inertia_error",), (), "an unweighed payload: oscillating and effective mass both "
          "differ from the sidecar", _CITE["mass"],
          "fraction of M, 1e-6..0.3 (a loss leaves >= m/2)", "sign +-1 (even odds)", _sign,
          lambda ctx, sh: _mass_error_bounds(ctx, sh, payload=True),
          lambda ctx, sh, f: _mass_error(ctx, sh, f, payload=True)),
        S("rotor_inertia_error", "mass error", "true M = sidecar's + sign x fraction x M, m "
          "as given", ("inertia_error",), (), "the rotor's reflected inertia differs from the "
          "sidecar's M; the oscillating mass is right", _CITE["mass"],
          "fraction of M, 1e-6..0.3 (a loss leaves >= (M - m)/2)", "sign +-1 (even odds)",
          _sign, lambda ctx, sh: _mass_error_bounds(ctx, sh, payload=False),
          lambda ctx, sh, f: _mass_error(ctx, sh, f, payload=False)),
    ]


def _damping() -> list[LiteratureScenario]:
    S = LiteratureScenario

    def effect(ctx: Context, sh: dict, kappa: float) -> Effect:
        d, a = ctx.device, sh["exponent"]
        return DAMP_POWER, [kappa * d.m * d.peak_base_acc / ctx.v_rms ** a, a], {}

    return [
        S("quadratic_damping", "fluid damping", "F = c2 v |v|, c2 = kappa m max|y''| / v_rms^2",
          ("quadratic_damping",), (), "quadratic (turbulent drag) damping",
          _CITE["quadratic_damping"], "kappa (drag at v_rms / m max|y''|), 1e-6..1", "none",
          lambda rng, ctx: {"exponent": 2.0}, lambda ctx, sh: (1e-6, 1.0), effect),
        S("power_damping", "fluid damping",
          "F = c_a |v|^a sgn v, c_a = kappa m max|y''| / v_rms^a", ("quadratic_damping",), (),
          "power-law damping of a drawn exponent", _CITE["power_damping"],
          "kappa, 1e-6..1", "a 1.3-3",
          lambda rng, ctx: {"exponent": rng.uniform(1.3, 3.0)},
          lambda ctx, sh: (1e-6, 1.0), effect),
    ]


#: Mains frequencies (Hz) a hum may have.
MAINS_HZ = (50.0, 60.0)


def _mains(rng: np.random.Generator, ctx: Context) -> dict:
    """50 or 60 Hz (even odds, among those <= 0.35 fs, inside the DAQ's flat band), a phase."""
    usable = [f for f in MAINS_HZ if f <= 0.35 * ctx.fs]
    if not usable:
        raise ValueError(f"mains_hum needs fs >= {MAINS_HZ[0] / 0.35:.0f} Hz")
    return {"frequency_hz": float(rng.choice(usable)),
            "phase_rad": rng.uniform(0.0, 2.0 * np.pi)}


def _cogging(ctx: Context, sh: dict, s: float) -> Effect:
    """A sin(2 pi z / P + phi): A = s m max|y''|, P = 4 z_rms / (periods over +-2 z_rms)."""
    d = ctx.device
    return (PERIODIC_Z, [s * d.m * d.peak_base_acc, 4.0 * ctx.z_rms / sh["periods"],
                         sh["phase_rad"]], {})


def _friction_drift(ctx: Context, sh: dict, s: float) -> Effect:
    """F_c (1 + sign s (t - T/2) / T) over the record's span T; x[4] runs as the time."""
    return (FRICTION_DRIFT, [sh["sign"] * s, 0.5 * ctx.record_s, ctx.record_s],
            {"v_ref": 0.0})


def _outside_library() -> list[LiteratureScenario]:
    """Forms no library term names (correct names empty): a force periodic in z, an even
    spring, a slow change of the friction, and a line the acquisition adds."""
    S = LiteratureScenario
    return [
        S("cogging", "force periodic in z", "F = A sin(2 pi z / P + phi)", (), (),
          "the generator's cogging torque (a detent per magnet pitch) through the screw lead: "
          "a force periodic in the displacement", _CITE["cogging"],
          "A / (m max|y''|), 1e-6..1",
          "P = 4 z_rms / n, n 2-6 periods over +-2 z_rms (uniform); phi 0-2 pi",
          lambda rng, ctx: {"periods": rng.uniform(2.0, 6.0),
                            "phase_rad": rng.uniform(0.0, 2.0 * np.pi)},
          lambda ctx, sh: (1e-6, 1.0), _cogging),
        S("quadratic_spring", "asymmetric spring", "F = k2 z^2, k2 = sign kappa k / z_max",
          (), ("offset_force",), "a spring stiffer on one side than the other (a quadratic, "
          "even-in-z restoring force)", _CITE["quadratic_spring"],
          "kappa (added stiffness at z_max / k), 1e-6..0.3 (the second equilibrium beyond "
          "3 z_max)", "sign +-1 (even odds)", _sign, lambda ctx, sh: (1e-6, 0.3),
          lambda ctx, sh, kappa: (SPRING_EVEN, [sh["sign"] * kappa * ctx.device.k
                                                / ctx.z_max], {})),
        S("friction_drift", "slow change", "F = F_c S(v/v_t) (1 + sign s (t - T/2) / T), T "
          "the record's span", (), (), "the sliding friction's level drifts linearly in time "
          "(the lubricant warming or cooling)", _CITE["friction_drift"],
          "s (the level's change over the record / F_c), 1e-5..1.5", "sign +-1 (even odds)",
          _sign, lambda ctx, sh: (1e-5, 1.5), _friction_drift),
        S("mains_hum", "acquisition", "rel_acc += A sin(2 pi f_mains t + phi) (the mass "
          "accelerometer's channel only)", (), ("unmodelled_mode",),
          "mains hum picked up by one accelerometer's cable (a ground loop): a line at a fixed "
          "frequency, not a force", _CITE["mains_hum"], "A (m/s^2), 1e-9..1e3",
          "f_mains 50 or 60 Hz (even odds, <= 0.35 fs); phi 0-2 pi", _mains,
          lambda ctx, sh: (1e-9, 1e3),
          lambda ctx, sh, a: (SENSOR_LINE, [a, sh["frequency_hz"], sh["phase_rad"]], {})),
    ]


def _scenarios() -> dict[str, LiteratureScenario]:
    """The registry, in the order of the module docstring's table (the forms outside the
    library after the effect-free one)."""
    none = LiteratureScenario(
        "none", "effect-free", "the baseline device only", (), (),
        "no concealed effect (false-alarm check)", _CITE["none"], "none", "none",
        lambda rng, ctx: {}, lambda ctx, sh: (0.0, 0.0), lambda ctx, sh, s: (NONE, [], {}))
    entries = (_friction_scenarios() + _stop_scenarios() + _spring_scenarios()
               + _structural_and_mass() + _damping() + [none] + _outside_library()
               + [_maxwell_slip()] + _appended())
    return {e.name: e for e in entries}


#: The scenarios by name.
SCENARIOS: dict[str, LiteratureScenario] = _scenarios()


# --------------------------------------------------------------------------- calibration

_KIND_NAMES = ("none", "lugre", "dahl", "bouc_wen", "karnopp", "stribeck", "asymmetric",
               "stop_kelvin_voigt", "stop_power", "spring_power", "damper_power", "mount",
               "secondary_mode", "periodic_in_z", "spring_even", "friction_drift",
               "sensor_line", "maxwell_slip", "ground_friction", "spring_dead_zone",
               "backlash")
#: Names of the effect parameters p[E:] per kind (SI units).
EFFECT_PARAMETERS: dict[int, tuple[str, ...]] = {
    NONE: (), LUGRE: ("share", "sigma0_N_per_m", "sigma1_N_s_per_m"),
    DAHL: ("share", "sigma0_N_per_m", "alpha"),
    BOUC_WEN: ("share", "k_b_N_per_m", "n", "beta", "gamma"),
    KARNOPP: ("share", "breakaway_ratio", "stick_band_m_per_s"),
    STRIBECK: ("F_s_over_F_c_minus_1", "v_s_m_per_s", "exponent"),
    ASYMMETRIC: ("s", "v_a_m_per_s"),
    STOP_KV: ("k_c_N_per_m", "exponent", "c_c_N_s_per_m", "gap_m"),
    STOP_POWER: ("K_N_per_m^n", "n", "damping_3(1-e)/2", "gap_m", "v_impact_floor_m_per_s"),
    SPRING_POWER: ("k_p_N_per_m^p", "p"), DAMP_POWER: ("c_a_N_(s/m)^a", "a"),
    MOUNT: ("m_b_kg", "k_b_N_per_m", "c_b_N_s_per_m"),
    SECONDARY: ("m2_kg", "k2_N_per_m", "c2_N_s_per_m"),
    PERIODIC_Z: ("amplitude_N", "period_m", "phase_rad"), SPRING_EVEN: ("k2_N_per_m2",),
    FRICTION_DRIFT: ("change_over_record", "t_centre_s", "record_s"),
    SENSOR_LINE: ("amplitude_m_per_s2", "frequency_hz", "phase_rad"),
    MAXWELL_SLIP: ("share", "first_element_share", "D1_m", "D2_m"),
    GROUND_FRICTION: ("share_on_ground",), SPRING_DEAD_ZONE: ("gap_m",),
    BACKLASH: ("gap_m", "k_b_N_per_m", "c_b_N_s_per_m"),
}


class UnreachableRatio(RuntimeError):
    """No drawn shape of the effect reaches the ratio within its strength bounds."""


def _rms(x: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(x))))


def effect_params(device: Device, effect: Effect) -> tuple[int, np.ndarray]:
    """(kind, parameter vector) of the device with an effect."""
    kind, values, overrides = effect
    p = device.params(**overrides)
    p[E: E + len(values)] = values
    return kind, p


def _next_guess(pts: list[tuple[float, float]], target: float, a: float, b: float,
                ends_known: tuple[bool, bool]) -> float:
    """Safeguarded log-log secant: the next log strength inside the bracket (a, b)."""
    x, r = pts[-1]
    slope = 1.0
    if len(pts) > 1 and pts[-1][0] != pts[-2][0]:
        slope = (r - pts[-2][1]) / (x - pts[-2][0])
    guess = x + (target - r) / slope if slope > 0.05 else 0.5 * (a + b)
    if guess <= a:
        return a if not ends_known[0] else 0.5 * (a + b)
    if guess >= b:
        return b if not ends_known[1] else 0.5 * (a + b)
    return guess


def solve_strength(rms_of: Callable[[float], float], lo: float, hi: float, target: float,
                   start: float | None = None) -> tuple[float, float] | None:
    """(strength, RMS) with RMS within CALIBRATION_RTOL of target; RMS increasing in strength.

    None if the target lies outside [rms_of(lo), rms_of(hi)], or if the RMS jumps across the
    target (a bracket narrower than 1e-6 relative whose ends both miss it by > 1 %).
    """
    a, b = np.log(lo), np.log(hi)
    known = [False, False]
    x = b if start is None else float(np.clip(np.log(start), a, b))
    pts: list[tuple[float, float]] = []
    best = (np.inf, 0.0, 0.0)
    for _ in range(60):
        r = rms_of(float(np.exp(x)))
        best = min(best, (abs(r / target - 1.0), float(np.exp(x)), r))
        if best[0] < CALIBRATION_RTOL or (known[0] and known[1] and b - a < 1e-6):
            return (best[1], best[2]) if best[0] < 0.01 else None
        if r < target:
            if x >= b:
                return None
            a, known[0] = x, True
        else:
            if x <= a and not known[0]:
                return None
            b, known[1] = x, True
        pts.append((x, np.log(max(r, 1e-300))))
        x = _next_guess(pts, np.log(target), a, b, (known[0], known[1]))
    raise RuntimeError("the strength calibration did not converge")


@dataclass
class _Calibrated:
    n_sub: int
    context: Context
    shape: dict
    strength: float | None
    kind: int
    p: np.ndarray
    baseline: np.ndarray      # noise-free rel_acc of the device (output rate)
    with_effect: np.ndarray   # noise-free rel_acc with the effect
    shape_draws: int
    step_change: float        # RMS change under step halving / noise RMS


def _initial_substeps(device: Device, tb: TimeBase) -> int:
    """A power of two with the friction's stiffness rate F_c / (v_t M) x step <= 1."""
    rate = device.F_c / (device.v_t * device.M)
    return int(min(MAX_SUBSTEPS, max(2, 2 ** np.ceil(np.log2(max(rate * tb.h_int, 1.0))))))


def _internal_window(tb: TimeBase) -> slice:
    return slice(round(LEAD_IN_S * tb.fs) * OVERSAMPLE, (tb.n_out - 1) * OVERSAMPLE + 1)


def settle_v_t(run: _Run, device: Device) -> Device:
    """The device with v_t = transition_ratio x the RMS relative velocity (after the lead-in)
    of the device at its provisional v_t: the transition sits where the motion puts it."""
    n_sub = _initial_substeps(device, run.tb)
    _, _, _, v = run.output(NONE, device.params(), n_sub, internal=True)
    return replace(device, v_t=device.transition_ratio * _rms(v[_internal_window(run.tb)]))


def _contribution_rms(run: _Run, scen: LiteratureScenario, ctx: Context, shape: dict,
                      n_sub: int, base: np.ndarray) -> Callable[[float], float]:
    """strength -> RMS (m/s^2) of the recorded contribution after the lead-in."""
    def rms_of(s: float) -> float:
        kind, p = effect_params(ctx.device, scen.effect(ctx, shape, s))
        return _rms((run.output(kind, p, n_sub) - base)[run.tb.window])

    return rms_of


def _draw_and_solve(run: _Run, scen: LiteratureScenario, ctx: Context, base: np.ndarray,
                    n_sub: int, rng: np.random.Generator,
                    target: float) -> tuple[dict, float, int]:
    """Draw shapes until one reaches the target within its bounds; (shape, strength, draws)."""
    for draw in range(1, MAX_SHAPE_DRAWS + 1):
        shape = scen.draw_shape(rng, ctx)
        lo, hi = scen.bounds(ctx, shape)
        solved = solve_strength(_contribution_rms(run, scen, ctx, shape, n_sub, base), lo, hi,
                                target)
        if solved is not None:
            return shape, solved[0], draw
    raise UnreachableRatio(f"{scen.name}: no shape in {MAX_SHAPE_DRAWS} draws reaches the "
                           "ratio within the strength bounds")


def _step_change(run: _Run, device: Device, kind: int, p: np.ndarray, n_sub: int) -> float:
    """Largest RMS change (m/s^2) of the baseline's and the effect's recorded z'' when the
    step is halved."""
    win = run.tb.window
    base_p = device.params()
    change = 0.0
    for k, q in ((NONE, base_p), (kind, p)):
        fine = run.output(k, q, 2 * n_sub)
        change = max(change, _rms((fine - run.output(k, q, n_sub))[win]))
    return change


def _calibrate(run: _Run, scen: LiteratureScenario, device: Device, rng: np.random.Generator,
               target: float, noise_rms: float) -> _Calibrated:
    """Draw the shape, solve the strength, halve the step until converged (re-solving)."""
    tb = run.tb
    n_sub = _initial_substeps(device, tb)
    base, _, z, v = run.output(NONE, device.params(), n_sub, internal=True)
    ctx = Context.of(device, tb.fs, z, v, _internal_window(tb), float(run.base_motion[0][0]))
    shape, s, draws = {}, None, 0
    if scen.name != "none":
        shape, s, draws = _draw_and_solve(run, scen, ctx, base, n_sub, rng, target)
    lo, hi = scen.bounds(ctx, shape)
    while True:
        kind, p = effect_params(device, scen.effect(ctx, shape, 0.0 if s is None else s))
        change = _step_change(run, device, kind, p, n_sub) / noise_rms
        tol = KARNOPP_CONVERGENCE_TOL if kind == KARNOPP else CONVERGENCE_TOL
        if change <= tol or 2 * n_sub > (MAX_SUBSTEPS_BACKLASH if kind == BACKLASH
                                         else MAX_SUBSTEPS):
            break
        n_sub *= 2
        if s is not None:
            base = run.output(NONE, device.params(), n_sub)
            solved = solve_strength(_contribution_rms(run, scen, ctx, shape, n_sub, base), lo,
                                    hi, target, start=s)
            if solved is None:
                raise UnreachableRatio(f"{scen.name}: the ratio is out of reach at {n_sub} "
                                       "sub-steps")
            s = solved[0]
    return _Calibrated(n_sub, ctx, shape, s, kind, p, run.output(NONE, device.params(), n_sub),
                       run.output(kind, p, n_sub), draws, change)


def sensitivities(run: _Run, device: Device, n_sub: int) -> np.ndarray:
    """d(recorded z'')/d(log theta) for the baseline's free parameters theta = (c, F_c, v_t),
    by central differences (columns of an n_out x 3 array)."""
    cols = []
    for name in ("c", "F_c", "v_t"):
        value = getattr(device, name)
        plus = run.output(NONE, device.params(**{name: value * np.exp(1e-3)}), n_sub)
        minus = run.output(NONE, device.params(**{name: value * np.exp(-1e-3)}), n_sub)
        cols.append((plus - minus) / 2e-3)
    return np.column_stack(cols)


def unabsorbed(c: np.ndarray, jac: np.ndarray, window: slice) -> float:
    """RMS (m/s^2) of c after the least-squares combination of jac's columns is taken off."""
    cw, jw = c[window], jac[window]
    coef, *_ = np.linalg.lstsq(jw, cw, rcond=None)
    return _rms(cw - jw @ coef)


def _tanh_equivalent(device: Device) -> Device:
    """The tanh-law device with the same F_c and slope at v = 0."""
    factor = {"tanh": 1.0, "atan": np.pi / 2.0, "algebraic": 1.0}[device.friction_form]
    return replace(device, friction_form="tanh", v_t=device.v_t * factor)


def form_mismatch(run: _Run, device: Device, n_sub: int) -> float:
    """RMS (m/s^2) of the device's recorded z'' minus the tanh baseline's that the tanh law's
    (c, F_c, v_t) cannot absorb (linearised at the slope-matched tanh device); 0 for tanh."""
    if device.friction_form == "tanh":
        return 0.0
    tanh = _tanh_equivalent(device)
    diff = run.output(NONE, device.params(), n_sub) - run.output(NONE, tanh.params(), n_sub)
    return unabsorbed(diff, sensitivities(run, tanh, n_sub), run.tb.window)


# --------------------------------------------------------------------------- generation

def _plain(obj: Any) -> Any:
    """JSON-ready copy: numpy scalars and arrays to Python numbers and lists."""
    if isinstance(obj, dict):
        return {str(k): _plain(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple, np.ndarray)):
        return [_plain(v) for v in obj]
    if isinstance(obj, np.generic):
        return obj.item()
    return obj


def _atomic_write(path: Path, text: str) -> None:
    """Write text to a temporary file beside path, then rename it over path."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8", newline="\n") as fh:
            fh.write(text)
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)


@dataclass
class GeneratedRecording:
    """A recording, its sidecar (the 'known' M, m, k) and its ground truth."""

    recording: pd.DataFrame        # time (s), input, output (base_acc, rel_acc by default)
    sidecar: dict[str, float]      # M (kg), m (kg), k (N/m) as weighed/measured
    truth: dict[str, Any]          # JSON-serialisable
    #: c(t), noise-free outputs with the effect and of the device, at the output rate, in the
    #: output's unit (rel_acc m/s^2 or rel_disp m: the kind's output; names kept)
    contribution: np.ndarray = field(repr=False)
    clean_rel_acc: np.ndarray = field(repr=False)
    baseline_rel_acc: np.ndarray = field(repr=False)
    #: the contribution as a model driven by the recorded base_acc produces it
    #: (:func:`recorded_input_contribution`)
    input_contribution: np.ndarray = field(repr=False)

    def write(self, out_dir: str | Path) -> dict[str, Path]:
        """Write recording.csv, recording.yaml (sidecar) and truth.json atomically."""
        out = Path(out_dir)
        paths = {"recording": out / "recording.csv", "sidecar": out / "recording.yaml",
                 "truth": out / "truth.json"}
        _atomic_write(paths["recording"], self.recording.to_csv(index=False,
                                                                float_format="%.10g"))
        _atomic_write(paths["sidecar"], "".join(f"{k}: {float(v)!r}\n"
                                                for k, v in self.sidecar.items()))
        _atomic_write(paths["truth"], json.dumps(self.truth, indent=2) + "\n")
        return paths


def _streams(name: str, seed: int) -> list[np.random.Generator]:
    """Independent generators for the device, excitation, effect shape and noise."""
    seq = np.random.SeedSequence([int(seed), zlib.crc32(name.encode())])
    return [np.random.default_rng(s) for s in seq.spawn(4)]


def accelerometer(x: np.ndarray, fs: float, f_hz: float, zeta: float) -> np.ndarray:
    """An accelerometer's mechanical response to the acceleration ``x`` sampled at ``fs``:
    a seismic mass on its own spring, H(s) = w^2 / (s^2 + 2 zeta w s + w^2) (unit gain below
    its resonance f_hz, a peak of 1 / (2 zeta) at it, falling as (f_hz / f)^2 above; Bendat
    and Piersol 2010, sec. 2.4), causal, from rest; bilinear, its frequency pre-warped so
    that the resonance lies at f_hz exactly."""
    w = 2.0 * fs * np.tan(np.pi * f_hz / fs)
    b, a = signal.bilinear([w * w], [1.0, 2.0 * zeta * w, w * w], fs)
    return signal.lfilter(b, a, x)


def _record(run: _Run, cal: _Calibrated, noise: tuple[np.ndarray, np.ndarray],
            lsb: float | None, sensor: tuple[float, float] | None = None) -> pd.DataFrame:
    """Both channels through the DAQ, plus noise (and quantisation); rel = mass - base. The
    mass accelerometer reads the mass's absolute acceleration through its own resonance
    ``sensor`` = (f Hz, zeta) where given (:func:`accelerometer`; its electrical noise is
    added after it)."""
    tb = run.tb
    _, acc, _, _ = run.output(cal.kind, cal.p, cal.n_sub, internal=True)
    y = run.base_internal()
    base = daq(y, tb.n_out) + noise[0]
    x = acc + y if sensor is None else accelerometer(acc + y, 1.0 / tb.h_int, *sensor)
    mass = daq(x, tb.n_out) + noise[1]
    if lsb is not None:
        base, mass = np.round(base / lsb) * lsb, np.round(mass / lsb) * lsb
    return pd.DataFrame({"time": np.arange(tb.n_out) / tb.fs, "base_acc": base,
                         "rel_acc": mass - base})


#: Recording kinds, "input->output" (column names of ``harvester.data.recording``); the first,
#: the paper's base-excited accelerometer pair, is the default.
KINDS = ("base_acc->rel_acc", "base_disp->rel_disp", "base_disp->rel_acc", "force->rel_disp")
#: Each channel's noise in the kinds after the first: its RMS in what the model takes of the
#: channel (:data:`NOISE_ORDER`: y'' of base_disp, z' of rel_disp, the others as they are;
#: derivatives spectral, up to PASSBAND x fs) as a share of that quantity's noise-free RMS
#: (the output's over the baseline device), after the lead-in; the accelerometer pair's rel_acc
#: noise was 5-40 % of its RMS at seed 0 (karnopp, maxwell_slip, none). A force's is 0.5 %
#: (a load cell's): at 5 % the device's response to it was 7.9 x the displacement's noise
#: floor on ``none`` (seed 20260501, 20 s) and the diagnosis read it as missing physics.
#: ``generate``'s ``noise_scale`` multiplies them.
NOISE_SHARES = {"base_disp": 0.05, "rel_disp": 0.05, "rel_acc": 0.05, "force": 5e-3}
#: Time derivatives of a channel its noise share is stated in.
NOISE_ORDER = {"base_disp": 2, "rel_disp": 1, "rel_acc": 0, "force": 0}


def generate(name: str, seed: int, ratio: float = 0.5, duration_s: float = 40.0,
             fs: float = 256.0, noise_rel_acc: float = 0.09, lsb: float | None = None,
             friction_form: str = "tanh", shared_input_noise: bool = True,
             sensor_resonance: tuple[float, float] | None = None, kind: str = KINDS[0],
             noise_scale: float = 1.0) -> GeneratedRecording:
    """A recording of a device drawn for ``seed`` with the scenario ``name``'s effect.

    The effect's contribution to the recorded output has RMS = ratio x the output channel's
    noise RMS (after a 1 s lead-in). ``kind`` (:data:`KINDS`): what is recorded.
    base_acc->rel_acc: ``noise_rel_acc`` (m/s^2) is the rel_acc channel's noise RMS (each
    accelerometer's is 1/sqrt(2) of it); ``lsb`` (m/s^2): quantisation step of both
    channels, None for none. ``friction_form``: the device's smooth sign S ('tanh', the
    diagnosis's baseline law; 'atan', 'algebraic', or 'drawn' per seed); a form other than
    tanh is a second, unnamed departure from the baseline (its size is in the truth's
    ``baseline_form_unabsorbed_to_noise``). ``shared_input_noise``: rel_acc is the mass
    accelerometer less the base accelerometer, which is also the recorded input, so the base
    sensor's noise is in both (a rig with two accelerometers); False: the base channel is
    noise-free and the mass sensor carries sqrt(2) x its noise, the same rel_acc noise drawn
    from the same stream but independent of the input (a relative sensor). The device, the
    excitation and the effect are the same either way. ``sensor_resonance`` (f Hz, zeta): the
    mass accelerometer's own resonance (:func:`accelerometer`), on the output channel only, a
    second departure outside the device; the truth's ``sensor_resonance`` gives its change of
    the recorded rel_acc over the noise RMS. The other kinds (:func:`_kind_recording`): each
    channel has its own white noise through the DAQ, ``noise_scale`` x its
    :data:`NOISE_SHARES` x its noise-free RMS (the output's over the baseline device); lsb,
    sensor_resonance and shared_input_noise are the accelerometer pair's and are refused.
    """
    _check_request(name, kind, duration_s, ratio, noise_rel_acc, noise_scale,
                   lsb is not None or sensor_resonance is not None or not shared_input_noise)
    scen = SCENARIOS[name]
    rng_device, rng_excitation, rng_shape, rng_noise = _streams(name, seed)
    tb = TimeBase(fs, round(duration_s * fs))
    rngs = (rng_device, rng_excitation, rng_shape, rng_noise)
    if kind != KINDS[0]:
        return _generate_kind(scen, seed, ratio, duration_s, tb, kind, noise_scale, rngs,
                              noise_rel_acc, friction_form)
    return _generate_pair(scen, seed, ratio, duration_s, tb, rngs, noise_rel_acc, lsb,
                          friction_form, shared_input_noise, sensor_resonance)


def _generate_pair(scen: LiteratureScenario, seed: int, ratio: float, duration_s: float,
                   tb: TimeBase, rngs: tuple, noise_rel_acc: float, lsb: float | None,
                   friction_form: str, shared_input_noise: bool,
                   sensor_resonance: tuple[float, float] | None) -> GeneratedRecording:
    """:func:`generate` for the accelerometer pair, base_acc -> rel_acc."""
    rng_device, rng_excitation, rng_shape, rng_noise = rngs
    sensor = noise_rel_acc / np.sqrt(2.0)
    noise = (sensor_noise(rng_noise, sensor, tb.n_out), sensor_noise(rng_noise, sensor, tb.n_out))
    if not shared_input_noise:
        noise = (0.0 * noise[0], np.sqrt(2.0) * noise[1])
    noise_rms = _rms((noise[1] - noise[0])[tb.window])
    run, device, cal, device_draw = _calibrated_device(
        scen, tb, duration_s, (rng_device, rng_excitation, rng_shape), noise_rel_acc,
        friction_form, ratio, lambda run, device: noise_rms)
    contribution = cal.with_effect - cal.baseline
    jac = sensitivities(run, device, cal.n_sub)
    truth = _truth(scen, seed, run, cal, contribution, jac, noise_rms, sensor, lsb, ratio)
    truth["effect"]["device_draws"] = device_draw
    sidecar = {"M": device.M, "m": device.m, "k": device.k}
    recording = _record(run, cal, noise, lsb, sensor_resonance)
    if sensor_resonance is not None:
        truth["sensor_resonance"] = _sensor_truth(run, cal, noise, lsb, sensor_resonance,
                                                  recording, noise_rms)
    driven = recorded_input_contribution(run, cal, recording["base_acc"].to_numpy())
    truth["input_driven_to_clean_contribution"] = (
        _rms((driven - contribution)[tb.window]) / max(_rms(contribution[tb.window]), 1e-300))
    truth.update(missing_force_truth(run, cal))
    truth["shared_input_noise"] = bool(shared_input_noise)
    return GeneratedRecording(recording, sidecar, truth, contribution, cal.with_effect,
                              cal.baseline, driven)


def _check_request(name: str, kind: str, duration_s: float, ratio: float,
                   noise_rel_acc: float, noise_scale: float, pair_options: bool) -> None:
    """ValueError naming what is wrong with a request to :func:`generate`."""
    if name not in SCENARIOS:
        raise ValueError(f"unknown scenario {name!r}; known: {', '.join(SCENARIOS)}")
    if kind not in KINDS:
        raise ValueError(f"unknown recording kind {kind!r}; known: {', '.join(KINDS)}")
    if duration_s <= 2.0 * LEAD_IN_S or ratio < 0.0 or noise_rel_acc <= 0.0:
        raise ValueError("need duration_s > 2 s, ratio >= 0 and noise_rel_acc > 0")
    if kind != KINDS[0] and (pair_options or noise_scale <= 0.0):
        raise ValueError(f"{kind}: lsb, sensor_resonance and shared_input_noise=False are the "
                         "accelerometer pair's (base_acc->rel_acc); noise_scale must be > 0")
    if kind.startswith("force") and name == "ground_friction":
        raise ValueError("ground_friction with a force input: the base is fixed, so the "
                         "ground is the base and the form is the baseline device itself")


def _generate_kind(scen: LiteratureScenario, seed: int, ratio: float, duration_s: float,
                   tb: TimeBase, kind: str, scale: float, rngs: tuple, noise_rel_acc: float,
                   friction_form: str) -> GeneratedRecording:
    """:func:`generate` for the kinds after the first (:func:`_kind_recording`)."""
    unit = (sensor_noise(rngs[3], 1.0, tb.n_out), sensor_noise(rngs[3], 1.0, tb.n_out))
    inp, out = kind.split("->")
    channel = "acc" if out == "rel_acc" else "disp"
    share = (scale * NOISE_SHARES[inp], scale * NOISE_SHARES[out])

    def noise_of(run: _Run, device: Device) -> float:  # the output's realised noise RMS
        base = run.output(NONE, device.params(), _initial_substeps(device, tb))
        return _noise_scale(base, unit[1], NOISE_ORDER[out], share[1], tb) * _rms(
            unit[1][tb.window])

    run, device, cal, device_draw = _calibrated_device(
        scen, tb, duration_s, rngs[:3], noise_rel_acc, friction_form, ratio, noise_of,
        channel)
    noise_rms = noise_of(run, device)
    contribution = cal.with_effect - cal.baseline
    jac = sensitivities(run, device, cal.n_sub)
    truth = _truth(scen, seed, run, cal, contribution, jac, noise_rms, float("nan"), None,
                   ratio)
    recording, noise = _kind_recording(run, cal, kind, unit, share[0],
                                       noise_rms / _rms(unit[1][tb.window]))
    noise["noise_share"] = {inp: share[0], out: share[1]}
    for key in ("noise_rms_rel_acc", "noise_rms_per_sensor"):
        truth.pop(key)
    truth["effect"]["device_draws"] = device_draw
    if kind.startswith("force"):
        truth["excitation"]["input"] = "force F = -m y'' on the mass (N), the base fixed"
    truth.update(missing_force_truth(run, cal), **noise, recording_kind=kind,
                 input_driven_to_clean_contribution=None, noise_rms_output=noise_rms)
    sidecar = {"M": device.M, "m": device.m, "k": device.k}
    return GeneratedRecording(recording, sidecar, truth, contribution, cal.with_effect,
                              cal.baseline, contribution)


def _kind_recording(run: _Run, cal: _Calibrated, kind: str, unit: tuple, share: float,
                    out_scale: float) -> tuple[pd.DataFrame, dict[str, Any]]:
    """(recording, noise truth) of a kind after the first. Input: the base displacement y
    (:attr:`_Run.base_motion`) or, with the base fixed, the force -m y'' on the mass (eq. 1
    driven by F = -m y'' moves the mass as the base acceleration y'' does); output: z'' or z.
    Each channel through the DAQ plus its own noise (``unit``, unit RMS, scaled: the input's
    by :func:`_noise_scale` at ``share``, the output's by ``out_scale``)."""
    tb = run.tb
    _, acc, z, _ = run.output(cal.kind, cal.p, cal.n_sub, internal=True)
    inp, out = kind.split("->")
    clean = (daq(-cal.p[_MOSC] * run.base_internal(), tb.n_out) if inp == "force"
             else _daq_moving(run.base_motion, tb))
    in_scale = _noise_scale(clean, unit[0], NOISE_ORDER[inp], share, tb)
    recorded_in = clean + in_scale * unit[0]
    recorded_out = daq(acc if out == "rel_acc" else z, tb.n_out) + out_scale * unit[1]
    frame = pd.DataFrame({"time": np.arange(tb.n_out) / tb.fs, inp: recorded_in,
                          out: recorded_out})
    return frame, {"noise_rms_input": in_scale * _rms(unit[0][tb.window]),
                   "noise_relative_to": (
                       "per channel, the noise-free RMS of what the model takes of it (y'' of "
                       "base_disp, z' of rel_disp, the others as they are; the output's over "
                       "the baseline device) after the lead-in; white through the DAQ's "
                       "filter, independent")}


def _spectral_rms(x: np.ndarray, order: int, tb: TimeBase) -> float:
    """RMS after the lead-in (and before the last LEAD_IN_S) of the order-th derivative of x
    (output rate; its end-to-end line removed, (i 2 pi f)^order up to PASSBAND x fs)."""
    if order == 0:
        return _rms(x[tb.window])
    r = x - np.linspace(x[0], x[-1], x.size)
    f = np.fft.rfftfreq(x.size, 1.0 / tb.fs)
    d = np.fft.irfft(np.fft.rfft(r) * (2j * np.pi * f) ** order * (f <= PASSBAND * tb.fs),
                     x.size)
    return _rms(d[tb.window.start: x.size - tb.window.start])


def _noise_scale(clean: np.ndarray, unit: np.ndarray, order: int, share: float,
                 tb: TimeBase) -> float:
    """The factor on ``unit`` noise that makes its order-th derivative's RMS ``share`` x the
    clean channel's (:func:`_spectral_rms`)."""
    return share * _spectral_rms(clean, order, tb) / _spectral_rms(unit, order, tb)


def _daq_moving(base_motion: tuple[np.ndarray, np.ndarray], tb: TimeBase) -> np.ndarray:
    """The base displacement y through the DAQ, the base having moved at its constant
    starting velocity before t = 0 (not resting at 0, which :func:`daq` assumes: a step):
    the line y(0) + y'(0) t passes the linear-phase, unit-gain filter unchanged."""
    v, y = base_motion
    line = y[0] + v[0] * tb.h_int * np.arange(y.size)
    return daq(y - line, tb.n_out) + y[0] + v[0] * np.arange(tb.n_out) / tb.fs


def _calibrated_device(scen: LiteratureScenario, tb: TimeBase, duration_s: float, rngs: tuple,
                       noise_rel_acc: float, friction_form: str, ratio: float,
                       noise_of: Callable[[_Run, Device], float], channel: str = "acc"
                       ) -> tuple[_Run, Device, _Calibrated, int]:
    """(run, device, calibration, draws made): devices drawn (``rngs``: the device's, the
    excitation's and the shape's streams) until one reaches the ratio x ``noise_of`` (the
    output's noise RMS for the run and device), at most MAX_DEVICE_DRAWS; ``channel``: the
    recorded output (:class:`_Run`)."""
    rng_device, rng_excitation, rng_shape = rngs
    for device_draw in range(1, MAX_DEVICE_DRAWS + 1):
        device = draw_device(rng_device, noise_rel_acc, friction_form)
        run = _Run(draw_excitation(rng_excitation, device, tb.period, duration_s, tb.fs), tb,
                   channel)
        device = settle_v_t(run, device)
        noise_rms = noise_of(run, device)
        try:
            cal = _calibrate(run, scen, device, rng_shape, ratio * noise_rms, noise_rms)
            return run, device, cal, device_draw
        except UnreachableRatio:
            continue
    raise UnreachableRatio(f"{scen.name}: no device in {MAX_DEVICE_DRAWS} draws reaches the "
                           f"ratio {ratio}")


def _sensor_truth(run: _Run, cal: _Calibrated, noise, lsb, sensor_resonance: tuple,
                  recording: pd.DataFrame, noise_rms: float) -> dict[str, float]:
    """The mass accelerometer's resonance (f Hz, zeta) and its change of the recorded rel_acc
    over the noise RMS."""
    change = recording["rel_acc"] - _record(run, cal, noise, lsb)["rel_acc"]
    return {"f_hz": float(sensor_resonance[0]), "zeta": float(sensor_resonance[1]),
            "change_to_noise": _rms(change[run.tb.window]) / noise_rms}


def missing_force_truth(run: _Run, cal: _Calibrated) -> dict[str, float]:
    """RMS (N) after the lead-in of the force the nominal device misses along the true path
    (``missing_force_rms_N``), its mean (``missing_force_mean_N``) and its RMS about the mean
    (``missing_force_varying_rms_N``, what a record of accelerations fixes): f = -(M z'' +
    m y'' + c z' + k z + F_c S(z' / v_t)) with the sidecar's masses and the device's c, k and
    sliding law, z'' the mass's (its accelerometer's, with a hum) at the internal rate. For an
    effect added to the device (a stop, a spring, a damper) it is the effect's own force; for
    a mass error, dM z'' + dm y''; for a friction law with memory, the law's departure from
    the sliding one."""
    _, acc, z, v = run.output(cal.kind, cal.p, cal.n_sub, internal=True)
    d = cal.context.device
    law = d.F_c * _smooth_sign(FRICTION_FORMS.index(d.friction_form), v / d.v_t)
    f = -(d.M * acc + d.m * run.base_internal() + d.c * v + d.k * z + law)
    f = f[_internal_window(run.tb)]
    return {"missing_force_rms_N": _rms(f), "missing_force_mean_N": float(np.mean(f)),
            "missing_force_varying_rms_N": float(np.std(f))}

def recorded_input_contribution(run: _Run, cal: _Calibrated, base_acc: np.ndarray
                                ) -> np.ndarray:
    """The effect's contribution to rel_acc (m/s^2, output rate) as a model driven by the
    recorded base acceleration ``base_acc`` produces it: the device with and without the
    effect, simulated from the excitation plus the base channel's recording error (noise,
    quantisation), interpolated band-limited onto the excitation grid.

    The recording holds the contribution made from the true excitation; a model is driven
    by the recorded one. Where the effect is sensitive to the difference (friction whose
    structure lies within the input noise's velocity: an exponential Stribeck excess at
    1.3 mm/s inside a 2.4 mm/s transition differed by 31 % of its RMS), the part that differs
    is out of any such model's reach. The information a record holds is measured on this
    contribution (``harvester.grid.information``)."""
    tb = run.tb
    error = base_acc - daq(run.base_internal(), tb.n_out)
    fine = signal.resample_poly(error, 2 * OVERSAMPLE, 1)  # onto the grid, 2 / h_int
    grid = run.grid.copy()
    n = min(grid.size, fine.size)
    grid[:n] += fine[:n]
    device = cal.context.device
    with_effect = simulate(cal.kind, cal.p, grid, tb, cal.n_sub)[0]
    without = simulate(NONE, device.params(), grid, tb, cal.n_sub)[0]
    return daq(with_effect, tb.n_out) - daq(without, tb.n_out)


def _truth(scen: LiteratureScenario, seed: int, run: _Run, cal: _Calibrated,
           contribution: np.ndarray, jac: np.ndarray, noise_rms: float, sensor: float,
           lsb: float | None, ratio: float) -> dict[str, Any]:
    """The ground truth: device, excitation, effect, achieved ratios, integration, DAQ."""
    tb, device, win = run.tb, cal.context.device, run.tb.window
    exc = run.excitation
    c = contribution
    return _plain({
        "scenario": scen.name, "family": scen.family, "form": scen.form,
        "citation": scen.citation, "correct_names": scen.correct_names,
        "related_names": scen.related_names, "seed": int(seed), "simulated": True,
        "generator": "harvester.synthetic.literature",
        "device": asdict(device), "sidecar": {"M": device.M, "m": device.m, "k": device.k},
        "true_masses": {"M": cal.p[_M], "m": cal.p[_MOSC]},
        "baseline_motion": {"z_rms_m": cal.context.z_rms, "v_rms_m_per_s": cal.context.v_rms,
                            "z_max_m": cal.context.z_max},
        "excitation": {"kind": "random-phase multisine", "band_hz": [
            exc.bins[0] / exc.period, exc.bins[-1] / exc.period], "lines": exc.bins.size,
            "envelope_depth": exc.env_depth, "envelope_period_s": exc.env_period,
            "fade_in_s": FADE_IN_S, "peak_m_s2": device.peak_base_acc},
        "effect": {"kind": _KIND_NAMES[cal.kind], "shape": cal.shape, "strength": cal.strength,
                   "strength_meaning": scen.strength, "shape_ranges": scen.shapes,
                   "shape_draws": cal.shape_draws, "parameters": dict(zip(
                       EFFECT_PARAMETERS[cal.kind], cal.p[E:E + len(EFFECT_PARAMETERS[
                           cal.kind])]))},
        "ratio_target": ratio, "ratio_achieved": _rms(c[win]) / noise_rms,
        "peak_to_noise": float(np.max(np.abs(c[win]))) / noise_rms,
        "unabsorbed_to_noise": unabsorbed(c, jac, win) / noise_rms,
        "baseline_form_unabsorbed_to_noise": form_mismatch(run, device, cal.n_sub) / noise_rms,
        "noise_rms_rel_acc": noise_rms, "noise_rms_per_sensor": sensor, "lsb_m_s2": lsb,
        "fs_hz": tb.fs, "duration_s": tb.n_out / tb.fs, "lead_in_s": LEAD_IN_S,
        "integration": {"method": "RK4, Strang-split exponential midpoint for memory laws",
                        "internal_rate_hz": 1.0 / tb.h_int, "substeps": cal.n_sub,
                        "step_halving_change_to_noise": cal.step_change,
                        "simulations": run.sims},
        "daq": {"fir_taps": anti_alias_fir().size, "passband_hz": PASSBAND * tb.fs,
                "stopband_hz": STOPBAND * tb.fs, "attenuation_db": FIR_ATTENUATION_DB,
                "oversample": OVERSAMPLE},
    })
