"""Pre-sliding friction with memory (Dahl 1968; LuGre, Canudas de Wit et al. 1995): the
bristle force h follows

    h' = (F_hyst / delta_hyst) (w - |w| h / F_hyst),

rising along a bristle of stiffness F_hyst / delta_hyst when the motion reverses and
saturating at F_hyst while sliding, and the friction force is

    f = h + c_hyst (w - |w| h / F_hyst),

the bristle force and the bristles' damping, which acts only while they deflect (after a
reversal; it vanishes once h saturates). delta_hyst (m) is the pre-sliding displacement;
delta -> 0 is Coulomb friction. With c_hyst -> 0 it is Dahl's law (and the first-order
Bouc-Wen form); with c_hyst it is LuGre's pre-sliding part (h = sigma_0 z_b, c_hyst =
sigma_1), whose Stribeck part is a separate term (``stribeck_friction``). The damping has a
parameter of its own, not one tied to F_hyst, because a record may show the bristle damping
far more than the bristle force: in LuGre sigma_1 = 2 zeta sqrt(sigma_0 M), 10-1000 x a
device's viscous damping, acting over micrometres.

The law is rate-independent: dh / dx = (F_hyst s - h) / delta_hyst along a screw displacement x
moving in the direction s, so after a monotone displacement dx

    h -> F_hyst s + (h - F_hyst s) exp(-|dx| / delta_hyst),    s = sgn(dx),

exactly (``displacement_update``). The integrator advances h that way, so its relaxation rate
|w| / delta_hyst, thousands per second for micrometre pre-sliding, does not bound the step;
the bristle stiffness does, through the mechanics (``rate_bound``).

Priors:

- F_hyst: its saturation force from a thousandth of the damping force the motion shows to
  twice it: a pre-sliding branch may carry a small share of a contact's friction, which a
  record of low noise still resolves. With a hundredth, the literature generator's Dahl and
  LuGre records as base_disp -> rel_disp (shares of 1.5 % and less of the friction, at half
  the noise RMS) piled against the bound (F_hyst 1.8 mN against 1.6 mN, +230 and +166 nats)
  and were not trusted. The wider range costs a posterior inside it ln(7.6 / 5.3) = 0.36 nats
- delta_hyst: pre-sliding displacements (micrometres in ball screws, bristle stiffnesses of
  1e4-1e8 N/m in the LuGre literature, up to millimetres in polymer contacts) from 1e-4 of the
  RMS displacement to the RMS displacement itself. A 1/300 bound cut off a Bouc-Wen contact
  of 7 um at 8.7 mm RMS, which the data told from Coulomb friction by 136 nats
- c_hyst: from a thousandth of the damping the motion shows, where the law is Dahl's, to a
  hundred times it: LuGre's critically damped bristles, 2 sqrt(sigma_0 M), reach 10-1000 x a
  device's viscous damping
"""

from __future__ import annotations

import numpy as np

from harvester.model import fastmath as fm
from harvester.model.priors import Prior
from harvester.model.terms import Motion, Parameter, Probe, RateBound, Term


#: The probe's bristle damping in units of the motion's damping (force / v): Dahl's law (1e-3)
#: and two damped shapes. A probe's F_hyst is 0.1 x force, so 3 puts c_hyst / F_hyst at 30 /
#: v; on the literature generator's LuGre record (c_hyst / F_hyst about 800 s/m, 15 / v) the
#: shape at 3 explains 4.7 % of the mismatch against 0.6 % for the best shape without it
#: (``quick_detect``).
BRISTLE_DAMPING_SHAPES = (1e-3, 0.3, 3.0)


def force(w, h, F_hyst, delta_hyst, c_hyst):
    """f = h + c_hyst (w - |w| h / F_hyst) (N): the bristle force and its damping."""
    return h + c_hyst * (w - abs(w) * h / F_hyst)


def state_rates(w, h, F_hyst, delta_hyst, c_hyst):
    """h' = (F_hyst / delta_hyst) (w - |w| h / F_hyst) (N/s)."""
    return (F_hyst * w - abs(w) * h) / delta_hyst


def displacement_update(h, dx, F_hyst, delta_hyst, c_hyst):
    """h after a monotone screw displacement dx (m): the exact solution of the law (N)."""
    target = F_hyst * fm.sign(dx)
    return target + (h - target) * fm.exp(-abs(dx) / delta_hyst)


def rate_bound(p: dict, motion: Motion) -> RateBound:
    """The bristle stiffness d h / d x <= 2 F / delta (just after a reversal from
    saturation) and its damping d f / d w <= 2 c_hyst (|h| <= F); the relaxation is advanced
    exactly (``displacement_update``)."""
    delta = np.maximum(np.abs(p["delta_hyst"]), 1e-9)
    return RateBound(damping=2.0 * np.abs(p["c_hyst"]),
                     stiffness=2.0 * np.abs(p["F_hyst"]) / delta)


TERM = Term(
    name="hysteresis", kind="screw", n_states=1,
    parameters=(
        Parameter("F_hyst", "N", Prior("loguniform", 0.001, 2.0, "force"),
                  "saturation force of the pre-sliding branch"),
        Parameter("delta_hyst", "m", Prior("loguniform", 1e-4, 1.0, "z"),
                  "pre-sliding displacement F_hyst / (bristle stiffness)"),
        Parameter("c_hyst", "N s/m", Prior("loguniform", 1e-3, 100.0, "force/v"),
                  "damping of the bristles while they deflect (LuGre's sigma_1)"),
    ),
    equation="Dahl / LuGre: h' = (F_hyst / delta_hyst) (w - |w| h / F_hyst), "
             "f = h + c_hyst (w - |w| h / F_hyst)",
    description="pre-sliding friction with memory and bristle damping (Dahl, LuGre)",
    force=force, state_rates=state_rates, rate_bound=rate_bound,
    displacement_update=displacement_update,
    # at 1e-4 of the RMS displacement the law is a sign law: a posterior piled there, or a
    # pre-sliding displacement the record does not resolve, asks for dry friction: one that
    # holds (sticking_friction), or a sign law (Coulomb's)
    unprobed=True,
    limits=(("delta_hyst", "lower", "sticking_friction"),
            ("delta_hyst", "lower", "coulomb_friction")),
    resolved=("delta_hyst",),
    probe=Probe("F_hyst", lambda d: 0.1 * d.force,
                shapes=lambda d: [{"delta_hyst": f * d.z, "c_hyst": c * d.force / d.v}
                                  for f in (0.001, 0.01, 0.1)
                                  for c in BRISTLE_DAMPING_SHAPES]),
    source=__file__)
