"""Dry friction of a contact fixed to the ground: f = F_ground sgn(x'), x' = z' + y' the
mass's own velocity, sgn regularised as tanh(x' / V_EPS), beside whatever acts between the
base and the mass (a screw, a guide). A base-excited frame whose contact is fixed to the
ground (Marino and Cicirello 2023) has it alone; the diagnosis's ground/base choice
(``diagnosis.prepare.topology``) rewrites such a record whole, and this term is the share of
a device's friction that the choice cannot split off: a guide on the frame beside a screw on
the base. With a force input the base is the ground, the term is the baseline's own
friction, and it is not a candidate (``diagnosis.prepare.redundant``).

Priors:

- F_ground: from a thousandth of the damping force the motion shows to twice it: a contact
  on the ground beside the base's friction may carry a small share of the device's friction
  (the literature generator's record as base_disp -> rel_disp, 2.8 % of a 0.17 N friction at
  half the noise RMS: F_ground 4.4 mN, which a hundredth, 4.0 mN, cut off), and up to all
  of it (the frame of Marino and Cicirello)
"""

from __future__ import annotations

import numpy as np

from harvester.model import fastmath as fm
from harvester.model.priors import Prior
from harvester.model.terms import V_EPS, Motion, Parameter, Probe, RateBound, Term


def force(x_dot, F_ground):
    """f = F_ground tanh(x' / V_EPS) (N), x' the mass's absolute velocity (m/s). Coulomb's
    law, written here rather than imported: a kernel's cache key hashes its terms' own files
    (``codegen._dependencies``), so a law imported from another file could go stale."""
    return F_ground * fm.tanh(x_dot / V_EPS)


def rate_bound(p: dict, motion: Motion) -> RateBound:
    """d f / d z' <= F_ground / V_EPS, doubled for margin."""
    return RateBound(damping=2.0 * np.abs(p["F_ground"]) / V_EPS)


TERM = Term(
    name="ground_friction", kind="ground",
    parameters=(Parameter("F_ground", "N", Prior("loguniform", 0.001, 2.0, "force"),
                          "friction force of a contact fixed to the ground"),),
    equation="f = F_ground sgn(z' + y'), sgn regularised as tanh(x' / 1 mm/s)",
    description="dry friction on the ground (a contact on the mass's own velocity)",
    force=force, rate_bound=rate_bound,
    probe=Probe("F_ground", lambda d: 1.0), source=__file__)
