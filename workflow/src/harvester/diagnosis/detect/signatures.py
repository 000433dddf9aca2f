"""Output signatures of candidate effects: how the output would change with the effect present.

For a candidate term e of the physics library (``harvester.model.terms``) added to the baseline at its
posterior mean, the signature is the secant

    g_e(t) = (y(theta, e at strength a) - y(theta, e switched off)) / a

with y the simulated output in the recording's kind (z'' or z, ``OutputKind.simulated`` of
``harvester.data.kinds``), driven by its input kind (a base acceleration or a force),
computed by the batched simulator, so it carries the full (nonlinear) dynamics of the
baseline: a missing force is seen through the structure's response, not as a force. ``a`` is a
small probe strength (a tenth of the damping force, a hundredth of the mass); for effects
with a shape parameter (clearance of an end stop, Stribeck velocity, frequency of a mode,
steepness of friction) a small grid of shapes is scanned, scaled to the baseline's own motion
(displacement and velocity quantiles, passband) so that the grid means the same on any rig.
Each term's probe is in its own file (``harvester.model.terms.Probe``).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np

from harvester.inference.map_fit import BaselineState
from harvester.model import stick
from harvester.model.priors import REFERENCE_DEVICE, DeviceScale
from harvester.model.simulate import simulate
from harvester.model.structures import Layout
from harvester.model.terms import TERMS, Probe, term

log = logging.getLogger("harvester.diagnosis")


def probe(name: str) -> Probe:
    """The term's probe (``harvester.model.terms.Probe``)."""
    return term(name).probe


def _centre(spec) -> float:
    """A prior's centre in its own coordinate, as a value (a shape's default in a probe)."""
    return float(spec.from_coordinate(spec.center))


@dataclass
class Signature:
    """The output signature of one candidate effect at one shape.

    ``values`` (n_record,) is d output / d strength (the output's unit, m/s^2 or m, per
    unit of ``strength``).
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
    A force input F(t) (N, EMPS-like drives) is ``base_acc=F, m=-1``
    (``InputKind.dissipative_force`` of ``harvester.data.kinds`` chooses for a recording's
    kind). None when the estimate is not positive (m unknown or 0, or no motion).
    """
    v = np.asarray(rel_vel, dtype=float)
    power = -float(m) * float(np.mean(np.asarray(base_acc, dtype=float) * v))
    sigma_v = float(np.sqrt(np.mean(v**2)))
    if not (power > 0.0 and sigma_v > 0.0 and np.isfinite(power)):
        return None
    return power / sigma_v


#: Quantiles of |z| a device's scale records (1.0: the largest).
Z_QUANTILES = (0.5, 0.75, 0.9, 0.97, 0.99, 0.999, 1.0)


def motion_scale(state: BaselineState, window: tuple[int, int], f_high: float) -> DeviceScale:
    """The device's scales (``DeviceScale``) from the baseline's simulated motion over the
    window, its known (or estimated) masses and spring, and the analysed band."""
    start, stop = window
    z = state.rel_disp[start:stop]
    v = state.rel_vel[start:stop]
    zc = z - np.median(z)
    az = np.abs(zc)
    prob = state.problem
    force = prob.input_type.dissipative_force(prob.input[start:stop], v, prob.known)
    values = dict(zip(prob.parameter_names, state.theta))
    masses = {n: float(prob.known.get(n, values.get(n, np.nan))) for n in ("M", "m", "k")}
    return DeviceScale(force=force or REFERENCE_DEVICE.force,
                       v=float(np.sqrt(np.mean(v**2))) or 1e-3,
                       z=float(np.sqrt(np.mean(zc**2))) or 1e-3, f_high=f_high,
                       M=masses["M"], m=masses["m"], k=masses["k"],
                       z_quantiles={q: float(np.quantile(az, q)) for q in Z_QUANTILES})


def candidate_terms(structure_terms: tuple[str, ...], allowed: tuple[str, ...] | None = None
                    ) -> list[str]:
    """Library terms that can be added to a structure: nameable (``Term.nameable``), not
    already in it, for a refinement of another law (``Term.refines``) with that law in
    the structure, and one the integrator takes beside it (a dry friction that sticks
    with no coupling or path-driven state: ``harvester.model.stick.compatible``)."""
    names = [t for t in TERMS if t not in structure_terms and TERMS[t].nameable
             and (not TERMS[t].refines or set(TERMS[t].refines) & set(structure_terms))
             and stick.compatible([TERMS[n] for n in structure_terms + (t,)])]
    if allowed is not None:
        unknown = [t for t in allowed if t not in TERMS]
        if unknown:
            raise KeyError(f"unknown candidate effects {unknown}; known: {sorted(TERMS)}")
        names = [t for t in names if t in allowed]
    return names


def signatures(state: BaselineState, scale: DeviceScale,
               candidates: list[str]) -> list[Signature]:
    """Signatures of every candidate at every shape of its grid (one simulation per term)."""
    problem = state.problem
    base_params = problem.layout_params(state.theta)[0]
    base_terms = problem.structure.terms
    out: list[Signature] = []
    for name in candidates:
        t = term(name)
        probe = t.probe
        layout = Layout.of(base_terms + (name,))
        defaults = {p.name: _centre(p.prior_on(scale)) for p in t.parameters}
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
        sim = simulate(layout, np.array(rows), problem.input, problem.dt,
                       force_input=problem.input_type.force_input,
                       oversample=problem.oversample)
        output = problem.output_type.simulated(sim)  # the recording's output kind
        i = 0
        for shape, amount, ref in meta:
            reference = state.output if ref is None else output[ref]  # through the chain
            ok = sim.ok[i] and (ref is None or sim.ok[ref])
            if ok and amount != 0:
                on_acc = problem.chain(output[i])
                ref_acc = reference if ref is None else problem.chain(reference)
                g = (on_acc - ref_acc) / amount
                out.append(Signature(name, probe.strength, float(amount), probe.signed,
                                     {k: float(v) for k, v in shape.items()}, g))
            else:
                log.warning("signature of %s at %s could not be simulated", name, shape)
            i += 1 if ref is None else 2
    return out
