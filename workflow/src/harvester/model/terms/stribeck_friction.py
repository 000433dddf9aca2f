"""Stribeck effect: the excess of breakaway over sliding friction, fading as sliding speeds
up (Armstrong-Helouvry, Dupont and Canudas de Wit 1994):

    f = F_stribeck exp(-|w / v_stribeck|^delta_stribeck) sgn(w),

the exponent covering the literature's exponential (1) and Gaussian (2) decays; the sign
switches over a tenth of the Stribeck velocity, so that the excess is reached at low speed
whatever the device's scale. A refinement of a sliding friction law (``SLIDING_FRICTION``):
meaningless without one.

Priors:

- F_stribeck: breakaway exceeds sliding friction by a hundredth to twice the damping force the
  motion shows
- v_stribeck: the Stribeck velocity from 1/100 of the RMS velocity to 3 x it: Stribeck
  velocities span 1e-5 to 1e-1 m/s (Armstrong-Helouvry et al. 1994), and below 1/100 of the RMS
  velocity (a shaker record's velocity resolution, as for the tanh law's transition) the excess
  cannot be resolved; above 3 x it, it is viscous-like
- delta_stribeck: the decay's exponent: 1 (exponential) and 2 (Gaussian) are the literature's
  forms
"""

from __future__ import annotations

import numpy as np

from harvester.model import fastmath as fm
from harvester.model.priors import Prior
from harvester.model.terms import (SLIDING_FRICTION, Motion, Parameter, Probe, RateBound,
                                   Term)

#: The sign's transition as a share of the Stribeck velocity.
SIGN_SHARE = 0.1


def force(w, F_stribeck, v_stribeck, delta_stribeck):
    """f = F_stribeck exp(-|w / v_s|^delta) tanh(w / (0.1 v_s)) (N)."""
    r = abs(w / v_stribeck)
    decay = fm.exp(-fm.exp(delta_stribeck * fm.log(r + 1e-300)))
    return F_stribeck * decay * fm.tanh(w / (SIGN_SHARE * v_stribeck))


def rate_bound(p: dict, motion: Motion) -> RateBound:
    """The sign's slope F / (0.1 v_s) plus the decay's delta F / v_s."""
    a = np.abs(p["F_stribeck"])
    vs = np.maximum(np.abs(p["v_stribeck"]), 1e-6)
    return RateBound(damping=a / (SIGN_SHARE * vs) + np.abs(p["delta_stribeck"]) * a / vs)


TERM = Term(
    name="stribeck_friction", kind="screw",
    parameters=(
        Parameter("F_stribeck", "N", Prior("loguniform", 0.01, 2.0, "force"),
                  "excess of breakaway over sliding friction"),
        Parameter("v_stribeck", "m/s", Prior("loguniform", 1.0 / 100.0, 3.0, "v"),
                  "Stribeck velocity"),
        Parameter("delta_stribeck", "-", Prior("normal", 1.5, 0.5, lower=0.5, upper=3.0),
                  "exponent of the Stribeck decay"),
    ),
    equation="f = F_stribeck exp(-|w / v_stribeck|^delta_stribeck) sgn(w)",
    description="Stribeck effect: friction falls from breakaway as sliding speeds up",
    force=force, rate_bound=rate_bound, refines=SLIDING_FRICTION,
    probe=Probe("F_stribeck", lambda d: 1.0,
                shapes=lambda d: [{"v_stribeck": f * d.v} for f in (0.01, 0.03, 0.1, 0.3, 1.0)]),
    source=__file__)
