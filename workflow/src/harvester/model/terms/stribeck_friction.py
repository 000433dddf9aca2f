"""Stribeck effect: the excess of breakaway over sliding friction, fading as sliding
speeds up: f = F_stribeck exp(-(w / v_stribeck)^2) sgn(w).

A refinement of a sliding friction law (``SLIDING_FRICTION``): meaningless without one.
"""

from __future__ import annotations

import numpy as np

from harvester.model import fastmath as fm
from harvester.model.terms import SLIDING_FRICTION, V_EPS, Motion, Parameter, RateBound, Term


def force(w, F_stribeck, v_stribeck):
    """f = F_stribeck exp(-(w / v_stribeck)^2) tanh(w / V_EPS) (N)."""
    r = w / v_stribeck
    return F_stribeck * fm.exp(-r * r) * fm.tanh(w / V_EPS)


def rate_bound(p: dict, motion: Motion) -> RateBound:
    """The sign's slope F / V_EPS plus the decay's 2 F / v_stribeck."""
    a = np.abs(p["F_stribeck"])
    return RateBound(damping=a / V_EPS + 2.0 * a / np.maximum(np.abs(p["v_stribeck"]), 1e-6))


TERM = Term(
    name="stribeck_friction", kind="screw",
    parameters=(
        Parameter("F_stribeck", "N", 2.0, 2.0, 0.0, "excess of breakaway over sliding friction"),
        Parameter("v_stribeck", "m/s", 0.02, 0.02, 1e-4, "Stribeck velocity"),
    ),
    equation="f = F_stribeck exp(-(w / v_stribeck)^2) sgn(w)",
    description="Stribeck effect: friction falls from breakaway as sliding speeds up",
    force=force, rate_bound=rate_bound, refines=SLIDING_FRICTION, source=__file__)
