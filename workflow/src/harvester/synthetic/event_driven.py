"""An event-driven reference for a single-degree-of-freedom oscillator with dry friction that
sticks, written independently of the library's physics (it imports nothing from
``harvester``) to verify the library's sticking law (``harvester.model.stick``).

    M x'' + c x' + k x + F_f = f(t),    f(t) piecewise linear between the samples,

F_f = s F(s x') while sliding in the direction s = +-1 (F: the friction's magnitude at a
speed, F(0) its static level F_s), x' = 0 held while stuck with |f(t) - k x| <= F_s. As in
Marino and Cicirello's ``FrictionSDOF.m`` (repository l-marino/switching-GPLFM, after Marino
and Cicirello 2022, J. Sound Vib.): sliding phases are integrated by an adaptive ODE solver
(here ``scipy.integrate.solve_ivp``, DOP853 at a tight tolerance) up to the event x' = 0; a
stuck phase ends where |f(t) - k x| reaches F_s, found exactly on the linear segment of the
input where it is first exceeded.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

#: The solver's tolerances (relative, and absolute as a share of the velocity scale).
RTOL, ATOL_SHARE = 1e-11, 1e-12


@dataclass(frozen=True)
class Oscillator:
    """M (kg), c (N s/m), k (N/m), ``magnitude(speed)`` the sliding friction (N) at a speed
    >= 0 (m/s, vectorised), ``static`` F_s (N) the holding level."""

    M: float
    c: float
    k: float
    magnitude: Callable[[np.ndarray], np.ndarray]
    static: float


@dataclass(frozen=True)
class Trajectory:
    """x (m), x' (m/s), x'' (m/s^2) and stuck (bool) at the samples; the events' times (s)."""

    x: np.ndarray
    v: np.ndarray
    a: np.ndarray
    stuck: np.ndarray
    events: np.ndarray


def _breakaway(osc: Oscillator, force: np.ndarray, dt: float, t0: float, x: float) -> float:
    """The first time >= t0 at which |f - k x| exceeds F_s (inf if never): f is linear on
    each sample interval and x held, so the instant is exact."""
    need = force - osc.k * x
    first = int(np.floor(t0 / dt + 1e-12))
    for j in range(first, force.size - 1):
        start = max(t0, j * dt)
        lo = need[j] + (start / dt - j) * (need[j + 1] - need[j])
        hi = need[j + 1]
        if abs(lo) > osc.static:
            return start
        if abs(hi) > osc.static:
            level = np.copysign(osc.static, hi)
            return start + (level - lo) / (hi - lo) * ((j + 1) * dt - start)
    return np.inf


def simulate(osc: Oscillator, force: np.ndarray, dt: float, v_scale: float = 1.0
             ) -> Trajectory:
    """The response from rest to the force samples ``force`` (N) every ``dt`` s."""
    n = force.size
    times = np.arange(n) * dt
    f_at = lambda t: np.interp(t, times, force)  # noqa: E731
    x_out, v_out, a_out = np.zeros(n), np.zeros(n), np.zeros(n)
    stuck = np.zeros(n, dtype=bool)
    t, x, s, events = 0.0, 0.0, 0.0, []
    end = times[-1]
    while t < end:
        if s == 0.0:
            t1 = min(_breakaway(osc, force, dt, t, x), end)
            sel = (times >= t) & (times <= t1)
            x_out[sel], v_out[sel], a_out[sel], stuck[sel] = x, 0.0, 0.0, True
            if t1 >= end:
                break
            t, s = t1, float(np.sign(f_at(t1) - osc.k * x))
            events.append(t)
            continue

        def rhs(tt, y, s=s):
            fric = s * osc.magnitude(max(s * y[1], 0.0))
            return [y[1], (f_at(tt) - osc.c * y[1] - osc.k * y[0] - fric) / osc.M]

        def stop(tt, y, s=s):
            return y[1]
        stop.terminal, stop.direction = True, -s
        sol = solve_ivp(rhs, (t, end), [x, 0.0], method="DOP853", rtol=RTOL,
                        atol=[ATOL_SHARE * v_scale, ATOL_SHARE * v_scale], dense_output=True,
                        events=stop, max_step=dt)
        t1 = sol.t_events[0][0] if sol.t_events[0].size else end
        sel = (times > t) & (times <= t1)
        y = sol.sol(times[sel])
        x_out[sel], v_out[sel] = y[0], y[1]
        fric = s * osc.magnitude(np.maximum(s * y[1], 0.0))
        a_out[sel] = (force[sel] - osc.c * y[1] - osc.k * y[0] - fric) / osc.M
        if t1 >= end:
            break
        x, t = float(sol.sol(t1)[0]), t1
        events.append(t)
        need = f_at(t) - osc.k * x
        s = 0.0 if abs(need) <= osc.static else float(np.sign(need))
    return Trajectory(x_out, v_out, a_out, stuck, np.array(events))


def karnopp_drive(seed: int = 3):
    """The case the literature generator's Karnopp element is compared on: its device drawn
    with ``seed``, a base acceleration of two tones (0.8 and 1.7 x f_n) ramped in over 0.5 s,
    at twice the generator's internal rate; returns (device, time base, y'' (m/s^2), the
    effect-free response's RMS velocity (m/s))."""
    from harvester.synthetic import literature as lit
    dev = lit.draw_device(np.random.default_rng(seed))
    tb = lit.TimeBase(256.0, 8 * 256)
    tg = np.arange(2 * tb.n_int + 8) * tb.h_int / 2
    y2 = 0.25 * dev.peak_base_acc * np.minimum(tg / 0.5, 1) ** 2 * (
        0.7 * np.sin(2 * np.pi * 0.8 * dev.f_n * tg)
        + 0.3 * np.sin(2 * np.pi * 1.7 * dev.f_n * tg + 0.4))
    v_rms = float(np.std(lit.simulate(lit.NONE, dev.params(), y2, tb, 4)[2]))
    return dev, tb, y2, v_rms
