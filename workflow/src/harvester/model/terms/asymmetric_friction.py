"""Direction-dependent friction: f = F_asym sgn(w)^2, half the difference of the down- and
up-going friction (a gravity preload on a vertical screw).

A refinement of a sliding friction law (``SLIDING_FRICTION``).
"""

from __future__ import annotations

import numpy as np

from harvester.model import fastmath as fm
from harvester.model.terms import SLIDING_FRICTION, V_EPS, Motion, Parameter, RateBound, Term


def force(w, F_asym):
    """f = F_asym tanh(w / V_EPS)^2 (N)."""
    t = fm.tanh(w / V_EPS)
    return F_asym * t * t


def rate_bound(p: dict, motion: Motion) -> RateBound:
    """d f / d w <= F_asym / V_EPS, doubled for margin."""
    return RateBound(damping=2.0 * np.abs(p["F_asym"]) / V_EPS)


TERM = Term(
    name="asymmetric_friction", kind="screw",
    parameters=(Parameter("F_asym", "N", 0.0, 2.0, None,
                          "half the difference of down- and up-going friction"),),
    equation="f = F_asym sgn(w)^2",
    description="direction-dependent friction (gravity preload on a vertical screw)",
    force=force, rate_bound=rate_bound, refines=SLIDING_FRICTION, source=__file__)
