"""An end stop beyond a clearance: f = k_stop (|z| - gap_stop)_+ sgn(z).
"""

from __future__ import annotations

import numpy as np

from harvester.model.terms import Motion, Parameter, RateBound, Term


def force(z, gap_stop, k_stop):
    """f = k_stop (|z| - gap_stop) sgn(z) beyond the clearance, else 0 (N)."""
    over = max(abs(z) - gap_stop, 0.0)
    return k_stop * over if z >= 0.0 else -k_stop * over


def rate_bound(p: dict, motion: Motion) -> RateBound:
    """The contact stiffness k_stop."""
    return RateBound(stiffness=np.abs(p["k_stop"]))


TERM = Term(
    name="end_stop", kind="mass",
    parameters=(
        Parameter("gap_stop", "m", 0.05, 0.03, 0.0, "clearance before contact"),
        Parameter("k_stop", "N/m", 5000.0, 3000.0, 0.0, "contact stiffness"),
    ),
    equation="f = k_stop (|z| - gap_stop)_+ sgn(z)", description="end stop beyond a clearance",
    force=force, rate_bound=rate_bound, source=__file__)
