"""Pre-sliding friction with memory (Dahl 1968): the friction force h follows

    h' = (F_hyst / delta_hyst) (w - |w| h / F_hyst),

rising along a bristle of stiffness F_hyst / delta_hyst when the motion reverses and
saturating at F_hyst while sliding. delta_hyst (m) is the pre-sliding displacement; delta
-> 0 is Coulomb friction. Dahl's law is LuGre's (Canudas de Wit et al. 1995) without its
bristle damping and Stribeck part, and the first-order Bouc-Wen form.

The law is rate-independent: dh / dx = (F_hyst s - h) / delta_hyst along a screw displacement x
moving in the direction s, so after a monotone displacement dx

    h -> F_hyst s + (h - F_hyst s) exp(-|dx| / delta_hyst),    s = sgn(dx),

exactly (``displacement_update``). The integrator advances h that way, so its relaxation rate
|w| / delta_hyst, thousands per second for micrometre pre-sliding, does not bound the step;
the bristle stiffness does, through the mechanics (``rate_bound``).
"""

from __future__ import annotations

import numpy as np

from harvester.model import fastmath as fm
from harvester.model.priors import Prior
from harvester.model.terms import Motion, Parameter, Probe, RateBound, Term


def force(w, h, F_hyst, delta_hyst):
    """f = h (N), the Dahl state."""
    return h + 0.0 * w


def state_rates(w, h, F_hyst, delta_hyst):
    """h' = (F_hyst / delta_hyst) (w - |w| h / F_hyst) (N/s)."""
    return (F_hyst * w - abs(w) * h) / delta_hyst


def displacement_update(h, dx, F_hyst, delta_hyst):
    """h after a monotone screw displacement dx (m): the exact solution of the law (N)."""
    target = F_hyst * fm.sign(dx)
    return target + (h - target) * fm.exp(-abs(dx) / delta_hyst)


def rate_bound(p: dict, motion: Motion) -> RateBound:
    """The bristle stiffness d h / d x <= 2 F / delta (just after a reversal from
    saturation); the relaxation is advanced exactly (``displacement_update``)."""
    delta = np.maximum(np.abs(p["delta_hyst"]), 1e-9)
    return RateBound(stiffness=2.0 * np.abs(p["F_hyst"]) / delta)


TERM = Term(
    name="hysteresis", kind="screw", n_states=1,
    parameters=(
        Parameter("F_hyst", "N", Prior(
            "loguniform", 0.01, 2.0, "force",
            why="its saturation force from a hundredth of the damping force the motion shows "
                "to twice it"),
            "saturation force of the pre-sliding branch"),
        Parameter("delta_hyst", "m", Prior(
            "loguniform", 1.0 / 300.0, 1.0, "z",
            why="pre-sliding displacements (micrometres in ball screws, up to millimetres in "
                "polymer contacts) from 1/300 of the RMS displacement, below which the data "
                "cannot tell it from Coulomb friction, to the RMS displacement itself"),
            "pre-sliding displacement F_hyst / (bristle stiffness)"),
    ),
    equation="Dahl: h' = (F_hyst / delta_hyst) (w - |w| h / F_hyst), f = h",
    description="pre-sliding friction with memory (Dahl model)",
    force=force, state_rates=state_rates, rate_bound=rate_bound,
    displacement_update=displacement_update,
    probe=Probe("F_hyst", lambda d: 0.1 * d.force,
                shapes=lambda d: [{"delta_hyst": f * d.z} for f in (0.01, 0.1)]),
    source=__file__)
