"""Hyperbolic tangent friction, the paper's M2 (Table 4): f = F_c tanh(beta w).

A smooth sliding friction: F_c is the sliding force (N), 1 / beta (m/s) the velocity over
which it reverses. beta -> inf is Coulomb friction.

Priors:

- F_c: a sliding friction from a hundredth of the damping force the motion shows to twice it
  (friction is part of that force)
- beta: the transition velocity 1 / beta from 3 x the RMS velocity (friction almost viscous) to
  1/100 of it: below, a recording's velocity resolution (noise x sample time, about 1/100 of the
  RMS velocity on a shaker record) cannot tell it from a sign law, and each decade costs ten
  times the integrator's steps
"""

from __future__ import annotations

import numpy as np

from harvester.model import fastmath as fm
from harvester.model.priors import Prior
from harvester.model.terms import Motion, Parameter, Probe, RateBound, Term


def force(w, F_c, beta):
    """f = F_c tanh(beta w) (N), w the screw-side velocity (m/s)."""
    return F_c * fm.tanh(beta * w)


def rate_bound(p: dict, motion: Motion) -> RateBound:
    """d f / d w <= F_c beta (at w = 0)."""
    return RateBound(damping=np.abs(p["F_c"]) * np.abs(p["beta"]))


TERM = Term(
    name="tanh_friction", kind="screw",
    parameters=(
        Parameter("F_c", "N", Prior("loguniform", 0.01, 2.0, "force"), "friction force amplitude"),
        Parameter("beta", "s/m", Prior("loguniform", 1.0 / 3.0, 100.0, "1/v"),
                  "steepness at velocity reversal"),
    ),
    equation="f = F_c tanh(beta w)", description="hyperbolic tangent friction (Table 4)",
    force=force, rate_bound=rate_bound, alike=("coulomb_friction",),
    probe=Probe("F_c", lambda d: 1.0,
                shapes=lambda d: [{"beta": b / d.v} for b in (1.0, 3.0, 10.0, 30.0)]),
    source=__file__)
