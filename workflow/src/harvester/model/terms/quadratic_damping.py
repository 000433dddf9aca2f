"""Velocity-squared (fluid-like) damping: f = c_quad w |w| (an orifice, air drag).

Priors:

- c_quad: at the RMS velocity the quadratic force is from a hundredth of the damping force the
  motion shows to twice it
"""

from __future__ import annotations

import numpy as np

from harvester.model.priors import Prior
from harvester.model.terms import Motion, Parameter, Probe, RateBound, Term


def force(w, c_quad):
    """f = c_quad w |w| (N)."""
    return c_quad * w * abs(w)


def rate_bound(p: dict, motion: Motion) -> RateBound:
    """d f / d w = 2 c_quad |w| <= 2 c_quad v_bound."""
    return RateBound(damping=2.0 * np.abs(p["c_quad"]) * motion.v_bound)


TERM = Term(
    name="quadratic_damping", kind="screw",
    parameters=(Parameter("c_quad", "N s^2/m^2", Prior("loguniform", 0.01, 2.0, "force/v^2"),
                          "quadratic damping coefficient"),),
    equation="f = c_quad w |w|", description="velocity-squared (fluid-like) damping",
    force=force, rate_bound=rate_bound, probe=Probe("c_quad", lambda d: 1.0 / d.v**2),
    source=__file__)
