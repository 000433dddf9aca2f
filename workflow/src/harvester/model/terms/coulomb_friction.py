"""Coulomb (dry) friction: f = F_coulomb sgn(w), sgn regularised as tanh(w / V_EPS).

Priors:

- F_coulomb: a dry friction from a hundredth of the damping force the motion shows to twice it
"""

from __future__ import annotations

import numpy as np

from harvester.model import fastmath as fm
from harvester.model.priors import Prior
from harvester.model.terms import V_EPS, Motion, Parameter, Probe, RateBound, Term


def force(w, F_coulomb):
    """f = F_coulomb tanh(w / V_EPS) (N), w the screw-side velocity (m/s)."""
    return F_coulomb * fm.tanh(w / V_EPS)


def rate_bound(p: dict, motion: Motion) -> RateBound:
    """d f / d w <= F_coulomb / V_EPS, doubled for margin."""
    return RateBound(damping=2.0 * np.abs(p["F_coulomb"]) / V_EPS)


TERM = Term(
    name="coulomb_friction", kind="screw",
    parameters=(Parameter("F_coulomb", "N", Prior("loguniform", 0.01, 2.0, "force"),
                          "Coulomb friction force"),),
    equation="f = F_coulomb sgn(w), sgn regularised as tanh(w / 1 mm/s)",
    description="Coulomb (dry) friction", force=force, rate_bound=rate_bound,
    alike=("tanh_friction",),
    probe=Probe("F_coulomb", lambda d: 1.0), source=__file__)
