"""Hardening (or softening) spring: f = k_cubic z^3.
"""

from __future__ import annotations

import numpy as np

from harvester.model.terms import Motion, Parameter, RateBound, Term


def force(z, k_cubic):
    """f = k_cubic z^3 (N), z the mass's displacement (m)."""
    return k_cubic * z * z * z


def rate_bound(p: dict, motion: Motion) -> RateBound:
    """d f / d z = 3 k_cubic z^2 <= 3 k_cubic z_bound^2."""
    return RateBound(stiffness=3.0 * np.abs(p["k_cubic"]) * motion.z_bound**2)


TERM = Term(
    name="cubic_stiffness", kind="mass",
    parameters=(Parameter("k_cubic", "N/m^3", 0.0, 2000.0, None,
                          "cubic stiffness coefficient"),),
    equation="f = k_cubic z^3", description="hardening/softening spring",
    force=force, rate_bound=rate_bound, source=__file__)
