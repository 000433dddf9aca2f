"""A constant force on the mass (gravity on a tilted device, a cable, a sensor bias): f = F_offset.

Priors:

- F_offset: either sign, rarely more than the damping force the motion shows
"""

from __future__ import annotations

from harvester.model.priors import Prior
from harvester.model.terms import Motion, Parameter, Probe, RateBound, Term


def force(z, F_offset):
    """f = F_offset (N), whatever the displacement."""
    return F_offset + 0.0 * z


def rate_bound(p: dict, motion: Motion) -> RateBound:
    """A constant force adds no rate."""
    return RateBound()


TERM = Term(
    name="offset_force", kind="mass",
    parameters=(Parameter("F_offset", "N", Prior("normal", 0.0, 0.5, "force", lower=None),
                          "constant force (gravity, cable, bias)"),),
    equation="f = F_offset", description="constant force offset",
    force=force, rate_bound=rate_bound,
    probe=Probe("F_offset", lambda d: 0.1 * d.force, signed=True), source=__file__)
