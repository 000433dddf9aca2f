"""Output signatures of candidate effects: how z''(t) would change if the effect were present.

For a candidate term e of the physics library (``physics.TERMS``) added to the baseline at its
posterior mean, the signature is the secant

    g_e(t) = (z''(theta, e at strength a) - z''(theta, e switched off)) / a

computed by the batched simulator, so it carries the full (nonlinear) dynamics of the
baseline: a missing force is seen through the structure's response, not as a force. ``a`` is a
small probe strength (a force of about 1 N, a mass of 0.1 kg); for effects with a shape
parameter (clearance of an end stop, Stribeck velocity, frequency of a mode, steepness of
friction) a small grid of shapes is scanned, scaled to the baseline's own motion (displacement
and velocity quantiles, passband) so that the grid means the same on any rig.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from harvester.diagnosis.baseline import BaselineState
from harvester.model.structures import Layout
from harvester.model.terms import TERMS, term
from harvester.model.simulate import simulate

log = logging.getLogger("harvester.diagnosis")


@dataclass(frozen=True)
class MotionScale:
    """Typical magnitudes of the baseline's simulated motion over the analysis window."""

    z: float  # RMS displacement (m)
    v: float  # RMS velocity (m/s)
    z_quantiles: dict[float, float]  # quantiles of |z| (m)
    f_high: float  # upper edge of the analysed band (Hz)
    force: float | None = None  # dissipative force scale c_eq v (N), :func:`dissipative_force`


#: A grid of shape values (dict parameter -> value) from the motion scale.
ShapeGrid = Callable[[MotionScale], list[dict[str, float]]]


@dataclass(frozen=True)
class Probe:
    """How to switch on a small amount of one term of the library.

    strength: the parameter whose zero switches the effect off; amount(scale): the probe
    strength; signed: the strength may be negative (two-sided test); shapes(scale): grid of
    the term's other parameters (others stay at the library's prior mean); reference:
    "baseline" (effect off = the baseline itself) or "zero" (the term kept with strength 0,
    when zero strength still changes the structure, as a backlash coupling does).
    ``start_shape``: a shape parameter whose posterior is a peak too narrow for a few hundred
    prior draws to hit (a resonance's frequency): the candidate's TMCMC starts part of its
    particles where this scan's scores place it (``confirm.scan_factor``).
    """

    term: str
    strength: str
    amount: Callable[[MotionScale], float]
    signed: bool = False
    shapes: ShapeGrid = field(default=lambda s: [{}])
    reference: str = "baseline"
    amount_is_shape: bool = False  # the strength itself is scanned (backlash clearance)
    start_shape: str | None = None


def _geom(lo: float, hi: float, n: int) -> list[float]:
    return list(np.geomspace(lo, hi, n))


PROBES: dict[str, Probe] = {p.term: p for p in (
    Probe("tanh_friction", "F_c", lambda s: 1.0,
          shapes=lambda s: [{"beta": b / s.v} for b in (1.0, 3.0, 10.0, 30.0)]),
    Probe("coulomb_friction", "F_coulomb", lambda s: 1.0),
    Probe("stribeck_friction", "F_stribeck", lambda s: 1.0,
          shapes=lambda s: [{"v_stribeck": f * s.v} for f in (0.1, 0.3, 1.0)]),
    Probe("asymmetric_friction", "F_asym", lambda s: 0.5, signed=True),
    Probe("quadratic_damping", "c_quad", lambda s: 1.0 / s.v**2),
    Probe("cubic_stiffness", "k_cubic", lambda s: 1.0 / s.z**3, signed=True),
    Probe("end_stop", "k_stop", lambda s: 1.0 / s.z,
          shapes=lambda s: [{"gap_stop": s.z_quantiles[q]} for q in (0.5, 0.75, 0.9, 0.97)]),
    Probe("backlash", "gap_backlash", lambda s: 0.0, reference="zero", amount_is_shape=True,
          shapes=lambda s: [{"gap_backlash": g} for g in (2e-6, 1e-5)]),
    Probe("hysteresis", "F_hyst", lambda s: 0.5,
          shapes=lambda s: [{"k_hyst": 0.5 / d} for d in (3e-5, 3e-4)]),
    Probe("unmodelled_mode", "mass_mode", lambda s: 0.05,
          shapes=lambda s: [{"f_mode": f, "zeta_mode": 0.15, "drive_base": d}
                            for d in (1.0, 0.0)
                            for f in _geom(1.5, 0.95 * s.f_high,
                                           1 + int(np.log(0.95 * s.f_high / 1.5)
                                                   / np.log(1.2)))],
          start_shape="f_mode"),
    Probe("offset_force", "F_offset", lambda s: 0.5, signed=True),
    Probe("inertia_error", "dM", lambda s: 0.1, signed=True,
          shapes=lambda s: [{"m_share": share} for share in (0.0, 1.0)]),
)}


@dataclass
class Signature:
    """The output signature of one candidate effect at one shape.

    ``values`` (n_record,) is d z'' / d strength (m/s^2 per unit of ``strength``).
    """

    effect: str
    strength: str
    amount: float
    signed: bool
    shape: dict[str, float]
    values: np.ndarray = field(repr=False)

    @property
    def label(self) -> str:
        if not self.shape:
            return self.effect
        return self.effect + "(" + ", ".join(f"{k}={v:.3g}" for k, v in self.shape.items()) + ")"


def dissipative_force(base_acc: np.ndarray, rel_vel: np.ndarray, m: float) -> float | None:
    """The damping the motion shows, as a force: c_eq sigma_v (N), with c_eq = <F_d z'> /
    <z'^2> the equivalent viscous damping of all dissipative forces F_d (viscous, friction,
    ...) and sigma_v the RMS velocity.

    Eq. (1) times z', averaged: the kinetic and potential energy terms average to their
    end-point differences over the record, so the power dissipated equals the power the base
    puts in, <F_d z'> = -m <y'' z'>, whatever the split between viscous damping and friction.
    A force input F(t) (N, EMPS-like drives) is ``base_acc=F, m=-1``. None when the
    estimate is not positive (m unknown or 0, or no motion).
    """
    v = np.asarray(rel_vel, dtype=float)
    power = -float(m) * float(np.mean(np.asarray(base_acc, dtype=float) * v))
    sigma_v = float(np.sqrt(np.mean(v**2)))
    if not (power > 0.0 and sigma_v > 0.0 and np.isfinite(power)):
        return None
    return power / sigma_v


def motion_scale(state: BaselineState, window: tuple[int, int], f_high: float) -> MotionScale:
    start, stop = window
    z = state.rel_disp[start:stop]
    v = state.rel_vel[start:stop]
    zc = z - np.median(z)
    az = np.abs(zc)
    prob = state.problem
    gain = prob.known.get("m", 0.0) if prob.input_kind == "base_acc" else -1.0  # force input
    force = dissipative_force(prob.base_acc[start:stop], v, gain)
    return MotionScale(z=float(np.sqrt(np.mean(zc**2))) or 1e-3,
                       v=float(np.sqrt(np.mean(v**2))) or 1e-3,
                       z_quantiles={q: float(np.quantile(az, q)) for q in (0.5, 0.75, 0.9, 0.97)},
                       f_high=f_high, force=force)


def candidate_terms(structure_terms: tuple[str, ...], allowed: tuple[str, ...] | None = None
                    ) -> list[str]:
    """Library terms that can be added to a structure: not already in it, with a probe, and,
    for a refinement of another law (``Term.refines``), with that law in the structure."""
    names = [t for t in TERMS if t in PROBES and t not in structure_terms
             and (not TERMS[t].refines or set(TERMS[t].refines) & set(structure_terms))]
    if allowed is not None:
        unknown = [t for t in allowed if t not in TERMS]
        if unknown:
            raise KeyError(f"unknown candidate effects {unknown}; known: {sorted(TERMS)}")
        names = [t for t in names if t in allowed]
    return names


def signatures(state: BaselineState, scale: MotionScale,
               candidates: list[str]) -> list[Signature]:
    """Signatures of every candidate at every shape of its grid (one simulation per term)."""
    problem = state.problem
    base_params = problem.layout_params(state.theta)[0]
    base_terms = problem.structure.terms
    out: list[Signature] = []
    for name in candidates:
        probe = PROBES[name]
        t = term(name)
        layout = Layout.of(base_terms + (name,))
        defaults = {p.name: p.prior_mean for p in t.parameters}
        rows, meta = [], []
        for shape in probe.shapes(scale):
            values = {**defaults, **shape}
            amount = values[probe.strength] if probe.amount_is_shape else probe.amount(scale)
            on = {**values, probe.strength: amount}
            rows.append(np.concatenate([base_params, [on[p.name] for p in t.parameters]]))
            ref = None
            if probe.reference == "zero":
                off = {**values, probe.strength: 0.0}
                ref = len(rows)
                rows.append(np.concatenate([base_params, [off[p.name] for p in t.parameters]]))
            meta.append((shape, amount, ref))
        sim = simulate(layout, np.array(rows), problem.base_acc, problem.dt,
                       oversample=problem.oversample)
        i = 0
        for shape, amount, ref in meta:
            reference = state.rel_acc if ref is None else sim.rel_acc[ref]  # through the chain
            ok = sim.ok[i] and (ref is None or sim.ok[ref])
            if ok and amount != 0:
                on_acc = problem.chain(sim.rel_acc[i])
                ref_acc = reference if ref is None else problem.chain(reference)
                g = (on_acc - ref_acc) / amount
                out.append(Signature(name, probe.strength, float(amount), probe.signed,
                                     {k: float(v) for k, v in shape.items()}, g))
            else:
                log.warning("signature of %s at %s could not be simulated", name, shape)
            i += 1 if ref is None else 2
    return out
