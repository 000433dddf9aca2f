"""Dry friction that holds (Coulomb's law with a stuck state): while the contact slides,

    f = F_dry sgn(w),

and while it is stuck, w = 0 exactly and f is whatever force keeps it so, as long as that
stays within F_dry; the contact breaks away when the force it must supply exceeds F_dry. No
regularisation: the integrator switches between the stuck and the sliding equations at the
events, located within the step (``harvester.model.codegen``, the ``stick`` kind;
``docs/sticking-friction.md``). A breakaway level above the sliding one is the Stribeck
excess ``sticking_stribeck``, a refinement of this term. On the ground (``data.kinds.on_ground``)
w is the mass's absolute velocity; on the base, its velocity relative to the base.

Priors:

- F_dry: the sliding (and holding) level from a hundredth of the damping force the motion
  shows to twice it, as for ``coulomb_friction``: friction is part of that force, and a dry
  friction of more than twice it would hold the device still for most of the record
"""

from __future__ import annotations

from harvester.model.priors import Prior
from harvester.model.terms import Motion, Parameter, Probe, RateBound, Term


def force(speed, F_dry):
    """The sliding magnitude F_dry (N) at any speed (m/s)."""
    return F_dry + 0.0 * speed


def static(F_dry):
    """The holding level F_dry (N)."""
    return F_dry


def rate_bound(p: dict, motion: Motion) -> RateBound:
    """Nothing: the law is constant while sliding and the switches are events, not a slope."""
    return RateBound()


TERM = Term(
    name="sticking_friction", kind="stick",
    parameters=(Parameter("F_dry", "N", Prior("loguniform", 0.01, 2.0, "force"),
                          "sliding and holding level of a dry friction that sticks"),),
    equation="f = F_dry sgn(w) sliding; w = 0 while |force needed| <= F_dry",
    description="Coulomb (dry) friction that sticks", force=force, static=static,
    rate_bound=rate_bound, alike=("coulomb_friction",),
    probe=Probe("F_dry", lambda d: 0.1 * d.force), source=__file__)
