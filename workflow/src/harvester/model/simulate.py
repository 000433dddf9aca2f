"""Forward model: the relative acceleration predicted from the measured base acceleration.

Eq. (1) of Green et al. (2015), M z'' + c_m z' + k z + f(z') = -m y'', plus any terms of
``physics.py``, integrated from rest for many parameter vectors (particles) in one call.

Method: classical fixed-step Runge-Kutta 4 with the base acceleration y'' linearly interpolated
between samples. Each particle gets its own number of sub-steps per sample, chosen from a bound
on the fastest rate of its equations (``physics.step_rates``) so that rate * h <= ``RATE_H``,
which keeps RK4 stable (limit 2.78) and accurate over the whole prior range. The compiled loop
runs particles in parallel threads. A particle whose state leaves the finite range is flagged
failed and its output set to NaN; the likelihood maps it to -inf.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba as nb
import numpy as np
from scipy import signal

from harvester.model.terms import V_EPS, Layout, step_rates
from harvester.data.signals import antialias_decimate

#: Largest (fastest rate x sub-step); RK4 is stable up to 2.78 on a real negative eigenvalue.
RATE_H = 0.5
#: Fewest sub-steps per sample (accuracy near velocity reversals), and most (cost cap).
MIN_SUBSTEPS = 4
MAX_SUBSTEPS = 4096
#: States beyond this magnitude count as a failed (unstable) simulation.
BLOW_UP = 1.0e6
#: Damping ratio of the backlash contact (Kelvin-Voigt, on the reduced mass m J / (m + J)).
#: Without it (a Hunt-Crossley law, damping ~ penetration) the contact rang and chattered: at
#: zero clearance the coupling was an undamped mode, and the log-likelihood of a record of the
#: baseline itself fell by thousands at the library's stiffness (measured).
BACKLASH_ZETA = 0.5


@nb.njit(cache=True, error_model="numpy")
def _rhs(s, u, p, codes, poff, soff, ds, force_input):
    """Time derivative ds of state s = [z, z', internal...]; returns the relative acceleration.

    The input u is the base acceleration y'' (drive -m y'') or, with ``force_input``, a force
    applied to the mass (N) with the base fixed (y'' = 0).
    """
    z = s[0]
    v = s[1]
    M = p[0]
    m = p[1]
    k = p[2]
    c = p[3]
    backlash = -1
    for j in range(codes.shape[0]):
        if codes[j] == 11:
            M += p[poff[j]]
            m += p[poff[j] + 1] * p[poff[j]]
        elif codes[j] == 8:
            backlash = j
    if force_input:
        drive = u
        yb = 0.0
    else:
        drive = -m * u
        yb = u
    w = v
    if backlash >= 0:
        w = v - s[soff[backlash] + 1]
    f_screw = c * w
    f_mass = k * z
    f_mode = 0.0
    for j in range(codes.shape[0]):
        code = codes[j]
        o = poff[j]
        q = soff[j]
        if code == 1:
            f_screw += p[o] * np.tanh(p[o + 1] * w)
        elif code == 2:
            f_screw += p[o] * np.tanh(w / V_EPS)
        elif code == 3:
            r = w / p[o + 1]
            f_screw += p[o] * np.exp(-r * r) * np.tanh(w / V_EPS)
        elif code == 4:
            t = np.tanh(w / V_EPS)
            f_screw += p[o] * t * t
        elif code == 5:
            f_screw += p[o] * w * abs(w)
        elif code == 6:
            f_mass += p[o] * z * z * z
        elif code == 7:
            if z > p[o]:
                f_mass += p[o + 1] * (z - p[o])
            elif z < -p[o]:
                f_mass += p[o + 1] * (z + p[o])
        elif code == 12:
            f_mass += p[o]
        elif code == 9:
            h = s[q]
            f_screw += h
            ds[q] = p[o + 1] * (w - abs(w) * h / p[o])
        elif code == 10:
            wn = 2.0 * np.pi * p[o]
            f_mode += p[o + 2] * (wn * wn * s[q] + 2.0 * p[o + 1] * wn * s[q + 1])
    ds[0] = v
    if backlash < 0:
        a = (drive - f_screw - f_mass + f_mode) / M
        ds[1] = a
    else:
        o = poff[backlash]
        q = soff[backlash]
        d = s[q]
        gap = p[o]
        kb = p[o + 1]
        j_eq = max(M - m, 1e-6)
        c_b = 2.0 * BACKLASH_ZETA * np.sqrt(kb * m * j_eq / (m + j_eq))
        fb = 0.0
        if d > gap:
            fb = max(kb * (d - gap) + c_b * s[q + 1], 0.0)
        elif d < -gap:
            fb = min(kb * (d + gap) + c_b * s[q + 1], 0.0)
        a = (drive - f_mass - fb + f_mode) / m
        r_acc = (fb - f_screw) / j_eq
        ds[1] = a
        ds[q] = s[q + 1]
        ds[q + 1] = a - r_acc
    for j in range(codes.shape[0]):
        if codes[j] == 10:
            q = soff[j]
            o = poff[j]
            wn = 2.0 * np.pi * p[o]
            ds[q] = s[q + 1]
            ds[q + 1] = -(wn * wn * s[q] + 2.0 * p[o + 1] * wn * s[q + 1]) - (a + p[o + 3] * yb)
    return a


@nb.njit(cache=True, error_model="numpy")
def rk4_step(s, u0, du, h, p, codes, poff, soff, k1, k2, k3, k4, tmp, force_input):
    """One classical RK4 step of length h in place on s; the input goes from u0 to u0 + du."""
    n_states = s.shape[0]
    _rhs(s, u0, p, codes, poff, soff, k1, force_input)
    for e in range(n_states):
        tmp[e] = s[e] + 0.5 * h * k1[e]
    _rhs(tmp, u0 + 0.5 * du, p, codes, poff, soff, k2, force_input)
    for e in range(n_states):
        tmp[e] = s[e] + 0.5 * h * k2[e]
    _rhs(tmp, u0 + 0.5 * du, p, codes, poff, soff, k3, force_input)
    for e in range(n_states):
        tmp[e] = s[e] + h * k3[e]
    _rhs(tmp, u0 + du, p, codes, poff, soff, k4, force_input)
    for e in range(n_states):
        s[e] += h / 6.0 * (k1[e] + 2.0 * k2[e] + 2.0 * k3[e] + k4[e])


@nb.njit(cache=True, error_model="numpy")
def _simulate_one(yb, dt, p, codes, poff, soff, n_states, n_sub, out_acc, out_z, out_v,
                  force_input):
    """Integrate one particle from rest; returns False if the state blew up."""
    s = np.zeros(n_states)
    k1 = np.zeros(n_states)
    k2 = np.zeros(n_states)
    k3 = np.zeros(n_states)
    k4 = np.zeros(n_states)
    tmp = np.zeros(n_states)
    h = dt / n_sub
    n = yb.shape[0]
    out_acc[0] = _rhs(s, yb[0], p, codes, poff, soff, k1, force_input)
    out_z[0] = 0.0
    out_v[0] = 0.0
    for i in range(n - 1):
        y0 = yb[i]
        dy = (yb[i + 1] - y0) / n_sub
        for sub in range(n_sub):
            rk4_step(s, y0 + dy * sub, dy, h, p, codes, poff, soff, k1, k2, k3, k4, tmp,
                     force_input)
        ok = True
        for e in range(n_states):
            if not (abs(s[e]) < BLOW_UP):
                ok = False
        if not ok:
            return False
        out_acc[i + 1] = _rhs(s, yb[i + 1], p, codes, poff, soff, k1, force_input)
        out_z[i + 1] = s[0]
        out_v[i + 1] = s[1]
    return True


@nb.njit(cache=True, parallel=True, error_model="numpy")
def _simulate_batch(yb, dt, params, codes, poff, soff, n_states, n_sub, acc, zz, vv, ok,
                    force_input):
    for i in nb.prange(params.shape[0]):
        ok[i] = _simulate_one(yb, dt, params[i], codes, poff, soff, n_states, n_sub[i],
                              acc[i], zz[i], vv[i], force_input)


@dataclass
class Simulation:
    """Batched simulation result: arrays of shape (particles, samples)."""

    rel_acc: np.ndarray  # z'' (m/s^2)
    rel_disp: np.ndarray  # z (m)
    rel_vel: np.ndarray  # z' (m/s)
    ok: np.ndarray  # (particles,) False where the integration failed
    substeps: np.ndarray  # (particles,) sub-steps per sample used


def substeps(layout: Layout, params: np.ndarray, dt: float,
             v_bound: float | None = None) -> np.ndarray:
    """Sub-steps per sample for each particle so that fastest rate x h <= RATE_H
    (``v_bound``: largest velocity in m/s, ``physics.step_rates``; None: its default)."""
    rate = step_rates(layout, params, v_bound)
    n = np.ceil(rate * dt / RATE_H)
    n = np.where(np.isfinite(n), n, MAX_SUBSTEPS)
    return np.clip(n, MIN_SUBSTEPS, MAX_SUBSTEPS).astype(np.int64)


def simulate(layout: Layout, params: np.ndarray, base_acc: np.ndarray, dt: float,
             n_substeps: int | np.ndarray | None = None, force_input: bool = False,
             v_bound: float | None = None, oversample: int = 1) -> Simulation:
    """Relative response to the base acceleration ``base_acc`` (m/s^2) sampled every ``dt`` s.

    With ``force_input`` the input is a force on the mass (N) instead, the base fixed; the
    response is then relative to ground.
    ``params`` is (particles, len(layout.parameter_names)) in the layout's order, or one vector.
    ``n_substeps`` overrides the automatic choice (used to verify convergence); ``v_bound``
    (m/s) tightens it where the largest velocity is known (see ``substeps``).

    ``oversample`` > 1 samples the response as a data acquisition with an anti-alias filter
    does: the input is interpolated band-limited (``scipy.signal.resample_poly``) to
    ``oversample`` x the rate, the model integrated there with the same sub-steps per input
    sample overall, and z'' taken at the input's samples through
    ``signals.antialias_decimate``. Point samples of z'' alias the friction harmonics above the Nyquist frequency
    into the band: on a tanh device recorded through an anti-alias filter, 0.09 x the noise
    RMS of mismatch at the true parameters, 0.02 x with ``oversample=4`` (measured).
    """
    q = int(oversample)
    if q < 1:
        raise ValueError(f"oversample must be a positive integer, got {oversample}")
    if q > 1:
        return _oversampled(layout, params, base_acc, dt, n_substeps, force_input, v_bound, q)
    p = np.ascontiguousarray(np.atleast_2d(params), dtype=np.float64)
    if p.shape[1] != len(layout.parameter_names):
        raise ValueError(f"params has {p.shape[1]} columns, layout needs "
                         f"{len(layout.parameter_names)}: {layout.parameter_names}")
    yb = np.ascontiguousarray(base_acc, dtype=np.float64)
    n_part, n = p.shape[0], yb.shape[0]
    if n_substeps is None:
        n_sub = substeps(layout, p, dt, v_bound)
    else:
        n_sub = np.broadcast_to(np.asarray(n_substeps, dtype=np.int64), (n_part,)).copy()
    acc = np.empty((n_part, n))
    zz = np.empty((n_part, n))
    vv = np.empty((n_part, n))
    ok = np.zeros(n_part, dtype=np.bool_)
    valid = np.all(np.isfinite(p), axis=1)
    _simulate_batch(yb, float(dt), np.where(valid[:, None], p, 0.0), layout.codes,
                    layout.param_offsets, layout.state_offsets, layout.n_states, n_sub,
                    acc, zz, vv, ok, bool(force_input))
    ok &= valid & np.all(np.isfinite(acc), axis=1)
    acc[~ok] = np.nan
    return Simulation(acc, zz, vv, ok, n_sub)


def _oversampled(layout: Layout, params: np.ndarray, base_acc: np.ndarray, dt: float,
                 n_substeps: int | np.ndarray | None, force_input: bool,
                 v_bound: float | None, q: int) -> Simulation:
    """:func:`simulate` at q x the rate, anti-aliased and taken at every q-th sample."""
    p = np.atleast_2d(params)
    u = np.asarray(base_acc, dtype=np.float64)
    n = u.shape[0]
    coarse = (substeps(layout, p, dt, v_bound) if n_substeps is None else
              np.broadcast_to(np.asarray(n_substeps, dtype=np.int64), (p.shape[0],)))
    fine_sub = np.maximum(1, -(-np.asarray(coarse, dtype=np.int64) // q))
    fine = simulate(layout, p, signal.resample_poly(u, q, 1)[: n * q], dt / q,
                    n_substeps=fine_sub, force_input=force_input)
    acc = np.full((p.shape[0], n), np.nan)
    if fine.ok.any():
        acc[fine.ok] = antialias_decimate(fine.rel_acc[fine.ok], q / dt, q)
    return Simulation(acc, fine.rel_disp[:, ::q].copy(), fine.rel_vel[:, ::q].copy(), fine.ok,
                      fine_sub * q)
