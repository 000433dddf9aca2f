"""Hardening (or softening) spring: f = k_cubic z^3 (Duffing).

Priors:

- k_cubic: hardening or softening; at the RMS displacement the cubic force is within about the
  linear spring's (at 3 x it, nine times); softening no further than keeps the tangent stiffness
  k + 3 k_cubic z^2 positive up to 2.2 x the RMS displacement (97 % of a Gaussian motion):
  beyond it the recorded device would have buckled
"""

from __future__ import annotations

import numpy as np

from harvester.model.priors import Prior
from harvester.model.terms import Motion, Parameter, Probe, RateBound, Term


#: Largest softening, in units of k / z_rms^2: k + 3 k_cubic (2.2 z_rms)^2 > 0.
SOFTENING_LIMIT = 1.0 / (3.0 * 2.2**2)


def force(z, k_cubic):
    """f = k_cubic z^3 (N), z the mass's displacement (m)."""
    return k_cubic * z * z * z


def rate_bound(p: dict, motion: Motion) -> RateBound:
    """d f / d z = 3 k_cubic z^2 <= 3 k_cubic z_bound^2."""
    return RateBound(stiffness=3.0 * np.abs(p["k_cubic"]) * motion.z_bound**2)


TERM = Term(
    name="cubic_stiffness", kind="mass",
    parameters=(Parameter("k_cubic", "N/m^3",
                          Prior("normal", 0.0, 1.0, "k/z^2", lower=-SOFTENING_LIMIT),
                          "cubic stiffness coefficient"),),
    equation="f = k_cubic z^3", description="hardening/softening spring",
    force=force, rate_bound=rate_bound,
    probe=Probe("k_cubic", lambda d: 1.0 / d.z**3, signed=True), source=__file__)
