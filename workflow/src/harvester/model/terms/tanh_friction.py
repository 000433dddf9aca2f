"""Hyperbolic tangent friction, the paper's M2 (Table 4): f = F_c tanh(beta w).

A smooth sliding friction: F_c is the sliding force (N), 1 / beta (m/s) the velocity over
which it reverses. beta -> inf is Coulomb friction.
"""

from __future__ import annotations

import numpy as np

from harvester.model import fastmath as fm
from harvester.model.terms import Motion, Parameter, RateBound, Term


def force(w, F_c, beta):
    """f = F_c tanh(beta w) (N), w the screw-side velocity (m/s)."""
    return F_c * fm.tanh(beta * w)


def rate_bound(p: dict, motion: Motion) -> RateBound:
    """d f / d w <= F_c beta (at w = 0)."""
    return RateBound(damping=np.abs(p["F_c"]) * np.abs(p["beta"]))


TERM = Term(
    name="tanh_friction", kind="screw",
    parameters=(
        Parameter("F_c", "N", 8.4, 5.0, 0.0, "friction force amplitude"),
        Parameter("beta", "s/m", 100.0, 100.0, 0.0, "steepness at velocity reversal"),
    ),
    equation="f = F_c tanh(beta w)", description="hyperbolic tangent friction (Table 4)",
    force=force, rate_bound=rate_bound, source=__file__)
