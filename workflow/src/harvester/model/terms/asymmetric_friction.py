"""Direction-dependent friction: the sliding friction differs between the two directions of
motion (a gravity preload on a vertical screw, a worn nut):

    f = F_asym tanh(w / v_asym)^2,

half the difference of the down- and up-going friction, switching over its own transition
velocity v_asym so that it can follow a smooth sliding law as well as a sign law. A refinement
of a sliding friction law (``SLIDING_FRICTION``). Under motion that is one-sided for long
stretches it acts as a constant force (``offset_force``) there.

Priors:

- F_asym: either direction may be the stronger; the difference rarely exceeds the damping force
  the motion shows
- v_asym: its transition velocity over the same decades as a sliding law's
"""

from __future__ import annotations

import numpy as np

from harvester.model import fastmath as fm
from harvester.model.priors import Prior
from harvester.model.terms import (SLIDING_FRICTION, Motion, Parameter, Probe, RateBound,
                                   Term)


def force(w, F_asym, v_asym):
    """f = F_asym tanh(w / v_asym)^2 (N)."""
    t = fm.tanh(w / v_asym)
    return F_asym * t * t


def rate_bound(p: dict, motion: Motion) -> RateBound:
    """d f / d w <= 0.77 F_asym / v_asym, taken as F_asym / v_asym."""
    return RateBound(damping=np.abs(p["F_asym"]) / np.maximum(np.abs(p["v_asym"]), 1e-7))


TERM = Term(
    name="asymmetric_friction", kind="screw",
    parameters=(
        Parameter("F_asym", "N", Prior("normal", 0.0, 0.5, "force", lower=None),
                  "half the difference of down- and up-going friction"),
        Parameter("v_asym", "m/s", Prior("loguniform", 0.01, 3.0, "v"),
                  "transition velocity of the direction-dependent part"),
    ),
    equation="f = F_asym tanh(w / v_asym)^2",
    description="direction-dependent friction (gravity preload on a vertical screw)",
    force=force, rate_bound=rate_bound, refines=SLIDING_FRICTION,
    probe=Probe("F_asym", lambda d: 0.1 * d.force, signed=True,
                shapes=lambda d: [{"v_asym": f * d.v} for f in (0.03, 0.3)]),
    source=__file__)
