"""The forces of a model's terms along given state paths, each as the force it adds to the
left-hand side of eq. (1) with the stated masses M and m:

    M z'' + c_m z' + k z + sum_T X_T = drive,     drive = -m y'' (base input) or F (force).

``screw``    X = force(z', h...; params), internal states h (one or two) advanced along the
             path from 0 (``displacement_update`` where the term has one, else its
             ``state_rates``)
``mass``     X = force(z; params)
``ground``   X = force(z' + y'; params), y' the base velocity of the path's y''
             (``simulate.base_velocity``; zeros for a force input, whose y'' is zeros)
``inertia``  (M, m) -> (M', m') = masses(M, m; params): X = (M' - M) z'' + (m' - m) y''
``mode``     states (u, u') driven by the path's z'' and y'' (RK4 with the acceleration
             linear in a step); X = -force(u, u'; params) + (M' - M) z'' + (m' - m) y''
``stick``    X = sgn(z') force(|z'|; params) while the path moves; where it is stuck (z' = 0
             exactly, a simulated path) the holding force is what the drive leaves, which
             ``term_force`` does not get: 0 there; :func:`named_force`, given the drive,
             puts the holding force there
``coupling`` not expressible as a force on the mass (a dead zone between two inertias)

Each term's law is the library's own (``harvester.model.codegen.compiled``): no physics is
written twice. Paths are arrays (draws, samples); all in SI units (N).
"""

from __future__ import annotations

from collections.abc import Mapping

import numba as nb
import numpy as np

from harvester.model.codegen import compiled
from harvester.model.simulate import base_velocity
from harvester.model.structures import Layout
from harvester.model.terms import Term

#: Why the loops below are not cached on disk: they take a term's compiled laws as arguments,
#: and a compiled law's type differs in every process, so Numba's cache never found an entry,
#: added one per process (121 in a working copy) and at times failed to write its index
#: ("underlying object has vanished"). They compile once per process instead.
NOT_CACHED = ("_stateless", "_with_update", "_with_rates", "_with_two_rates", "_mode")

#: Fewest sub-steps per sample for a mode's states, and its largest omega_n h.
MODE_SUBSTEPS, MODE_RATE_H = 4, 0.3


@nb.njit(cache=False)  # takes compiled laws: see NOT_CACHED
def _stateless(force, x, params):
    out = np.empty_like(x)
    for i in range(x.shape[0]):
        for k in range(x.shape[1]):
            out[i, k] = force(x[i, k], *params)
    return out


@nb.njit(cache=False)  # takes compiled laws: see NOT_CACHED
def _with_update(force, update, v, dt, params):
    """A screw term with one rate-independent state: h advanced by the exact update along
    each step's displacement (trapezoidal velocity), from h = 0."""
    out = np.empty_like(v)
    for i in range(v.shape[0]):
        h = 0.0
        for k in range(v.shape[1]):
            if k > 0:
                h = update(h, 0.5 * (v[i, k - 1] + v[i, k]) * dt, *params)
            out[i, k] = force(v[i, k], h, *params)
    return out


@nb.njit(cache=False)  # takes compiled laws: see NOT_CACHED
def _with_rates(force, rates, v, dt, n_sub, params):
    """A screw term with one state: h' = rates(w, h) by RK2 with ``n_sub`` steps per
    sample, w linear in the sample, from h = 0."""
    out = np.empty_like(v)
    hs = dt / n_sub
    for i in range(v.shape[0]):
        h = 0.0
        for k in range(v.shape[1]):
            if k > 0:
                for s in range(n_sub):
                    w0 = v[i, k - 1] + (v[i, k] - v[i, k - 1]) * s / n_sub
                    w1 = v[i, k - 1] + (v[i, k] - v[i, k - 1]) * (s + 1) / n_sub
                    k1 = rates(w0, h, *params)
                    k2 = rates(w1, h + hs * k1, *params)
                    h = h + 0.5 * hs * (k1 + k2)
            out[i, k] = force(v[i, k], h, *params)
    return out


@nb.njit(cache=False)  # takes compiled laws: see NOT_CACHED
def _with_two_rates(force, rates, v, dt, n_sub, params):
    """A screw term with two states (h, g)' = rates(w, h, g), as :func:`_with_rates`."""
    out = np.empty_like(v)
    hs = dt / n_sub
    for i in range(v.shape[0]):
        h, g = 0.0, 0.0
        for k in range(v.shape[1]):
            if k > 0:
                for s in range(n_sub):
                    w0 = v[i, k - 1] + (v[i, k] - v[i, k - 1]) * s / n_sub
                    w1 = v[i, k - 1] + (v[i, k] - v[i, k - 1]) * (s + 1) / n_sub
                    k1 = rates(w0, h, g, *params)
                    k2 = rates(w1, h + hs * k1[0], g + hs * k1[1], *params)
                    h = h + 0.5 * hs * (k1[0] + k2[0])
                    g = g + 0.5 * hs * (k1[1] + k2[1])
            out[i, k] = force(v[i, k], h, g, *params)
    return out


@nb.njit(cache=False)  # takes compiled laws: see NOT_CACHED
def _mode(force, rates, a, yb, dt, n_sub, params):
    """A mode's force on the mass along paths of z'' (a) and y'' (yb), RK4 from rest."""
    out = np.empty_like(a)
    hs = dt / n_sub
    for i in range(a.shape[0]):
        u, ud = 0.0, 0.0
        for k in range(a.shape[1]):
            if k > 0:
                a0, da = a[i, k - 1], (a[i, k] - a[i, k - 1]) / n_sub
                y0, dy = yb[k - 1], (yb[k] - yb[k - 1]) / n_sub
                for s in range(n_sub):
                    p1 = rates(u, ud, a0 + da * s, y0 + dy * s, *params)
                    am, ym = a0 + da * (s + 0.5), y0 + dy * (s + 0.5)
                    p2 = rates(u + 0.5 * hs * p1[0], ud + 0.5 * hs * p1[1], am, ym, *params)
                    p3 = rates(u + 0.5 * hs * p2[0], ud + 0.5 * hs * p2[1], am, ym, *params)
                    p4 = rates(u + hs * p3[0], ud + hs * p3[1], a0 + da * (s + 1),
                               y0 + dy * (s + 1), *params)
                    u += hs / 6.0 * (p1[0] + 2.0 * p2[0] + 2.0 * p3[0] + p4[0])
                    ud += hs / 6.0 * (p1[1] + 2.0 * p2[1] + 2.0 * p3[1] + p4[1])
            out[i, k] = force(u, ud, *params)
    return out


def _inertial(t: Term, values: Mapping[str, float], params: tuple, a: np.ndarray,
              yb: np.ndarray) -> np.ndarray:
    """(M' - M) z'' + (m' - m) y'' of a term that changes the masses."""
    M, m = values["M"], values["m"]
    M2, m2 = t.masses(M, m, *params)
    return (M2 - M) * a + (m2 - m) * yb[None, :]


def term_force(t: Term, values: Mapping[str, float], z: np.ndarray, v: np.ndarray,
               a: np.ndarray, yb: np.ndarray, dt: float) -> np.ndarray:
    """X_T (N) of one term (module docstring) along paths (draws, samples) of z (m), z'
    (m/s) and z'' (m/s^2), with y'' (m/s^2, samples; zeros for a force input)."""
    params = tuple(float(values[p]) for p in t.parameter_names)
    z, v, a = (np.atleast_2d(np.asarray(x, dtype=float)) for x in (z, v, a))
    yb = np.asarray(yb, dtype=float)
    if t.kind == "mass":
        return _stateless(compiled(t.name, "force"), z, params)
    if t.kind == "ground":
        vb = base_velocity(yb, dt) if np.any(yb) else np.zeros_like(yb)
        return _stateless(compiled(t.name, "force"), v + vb[None, :], params)
    if t.kind == "screw" and t.n_states == 0:
        return _stateless(compiled(t.name, "force"), v, params)
    if t.kind == "screw" and t.displacement_update is not None:
        return _with_update(compiled(t.name, "force"), compiled(t.name, "displacement_update"),
                            v, dt, params)
    if t.kind == "screw" and t.n_states == 1:
        return _with_rates(compiled(t.name, "force"), compiled(t.name, "state_rates"), v, dt,
                           16, params)
    if t.kind == "screw" and t.n_states == 2:
        return _with_two_rates(compiled(t.name, "force"), compiled(t.name, "state_rates"), v,
                               dt, 16, params)
    if t.kind == "stick":  # sliding: sgn(z') times its magnitude; stuck (z' = 0): 0 here
        return np.sign(v) * _stateless(compiled(t.name, "force"), np.abs(v), params)
    if t.kind == "inertia":
        return _inertial(t, values, params, a, yb)
    if t.kind == "mode":
        rate = 2.0 * np.pi * abs(values.get("f_mode", 0.0)) * dt
        n_sub = max(MODE_SUBSTEPS, int(np.ceil(rate / MODE_RATE_H)))
        f = _mode(compiled(t.name, "force"), compiled(t.name, "state_rates"), a, yb, dt, n_sub,
                  params)
        return -f + _inertial(t, values, params, a, yb)
    raise NotImplementedError(f"term {t.name} ({t.kind}) has no force on the mass alone")


def term_forces(layout: Layout, values: Mapping[str, float], z: np.ndarray, v: np.ndarray,
                a: np.ndarray, yb: np.ndarray, dt: float) -> dict[str, np.ndarray]:
    """X_T (N) of every term of ``layout`` (by name) along paths (:func:`term_force`);
    ``values`` holds every layout parameter."""
    return {t.name: term_force(t, values, z, v, a, yb, dt) for t in layout.terms}


def model_force(layout: Layout, values: Mapping[str, float], z: np.ndarray, v: np.ndarray,
                a: np.ndarray, yb: np.ndarray, dt: float) -> np.ndarray:
    """c_m z' + k z + sum_T X_T (N) along paths: everything of eq. (1) but M z'' and the
    drive."""
    z, v = np.atleast_2d(z), np.atleast_2d(v)
    total = values["c_m"] * v + values["k"] * z
    for f in term_forces(layout, values, z, v, a, yb, dt).values():
        total = total + f
    return total


def named_force(layout: Layout, values: Mapping[str, float], z: np.ndarray, v: np.ndarray,
                a: np.ndarray, yb: np.ndarray, drive: np.ndarray, dt: float,
                names: tuple[str, ...]) -> np.ndarray:
    """The summed X_T (N) of the terms ``names`` along a simulated path (draws, samples).
    Where the path is stuck (z' = 0 exactly) and the layout holds ``stick`` terms, their force
    is the holding force, what eq. (1) leaves with the drive (N, samples): drive - M z'' -
    c_m z' - k z - the other terms' X_T, shared among the stick terms by their holding
    levels (``Term.static``); elsewhere each term's own law (:func:`term_force`)."""
    z, v, a = (np.atleast_2d(np.asarray(x, dtype=float)) for x in (z, v, a))
    sticks = [t for t in layout.terms if t.kind == "stick"]
    if not any(t.name in names for t in sticks):  # the named terms' laws alone
        return sum((term_force(t, values, z, v, a, yb, dt) for t in layout.terms
                    if t.name in names), np.zeros_like(z))
    forces = term_forces(layout, values, z, v, a, yb, dt)
    out = sum((forces[n] for n in names), np.zeros_like(z))
    others = sum((f for n, f in forces.items() if n not in {t.name for t in sticks}),
                 np.zeros_like(z))
    hold = (np.asarray(drive, dtype=float)[None, :] - values["M"] * a - values["c_m"] * v
            - values["k"] * z - others)
    levels = {t.name: abs(float(compiled(t.name, "static")(
        *(float(values[p]) for p in t.parameter_names)))) for t in sticks}
    total = sum(levels.values())
    share = (sum(levels[n] for n in names if n in levels) / total if total > 0 else
             sum(n in levels for n in names) / len(sticks))
    return np.where(v == 0.0, share * hold, out)
