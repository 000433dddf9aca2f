"""A force periodic in the displacement: f = a_periodic sin(2 pi z / P_periodic)
+ b_periodic cos(2 pi z / P_periodic).

Not a library name: a shape of the missing force's dictionary (``diagnosis.size.shapes``'s
"periodic in z": cogging, a ball screw's or a gear's pitch, a magnetic detent) fitted as a
term of the model (``diagnosis.size.shape_terms``), along the model's own simulated z. The
smoother reads z from the record and, on an acceleration record of a small motion, knows it
only to a fraction of a millimetre (a cogging record of the literature generator: 86 um RMS
known to +-124 um, period 0.1 mm); the model's own z, driven by the recorded input, does not
carry that uncertainty. ``nameable=False``: the diagnosis never adds it as a candidate; it
describes what the library lacks.

Priors:

- a_periodic: either sign, about the force the motion shows (its damping force; a detent of
  the generator's cogging: 1.1 x it)
- b_periodic: as a_periodic (the pair sets the amplitude and the phase)
- P_periodic: from a fiftieth of the RMS displacement to twice it: at least two periods within
  +-2 RMS displacements, where a Gaussian motion spends 95 % of its time (a longer period is
  a stiffness or a cubic spring there), and at most fifty per RMS displacement
  (``shape_terms`` scans the band's part of it)
"""

from __future__ import annotations

import numpy as np

from harvester.model.priors import Prior
from harvester.model.terms import Motion, Parameter, Probe, RateBound, Term

TWO_PI = 2.0 * np.pi


def force(z, a_periodic, b_periodic, P_periodic):
    """f = a sin(2 pi z / P) + b cos(2 pi z / P) (N), z the mass's displacement (m)."""
    phase = TWO_PI * z / P_periodic
    return a_periodic * np.sin(phase) + b_periodic * np.cos(phase)


def rate_bound(p: dict, motion: Motion) -> RateBound:
    """d f / d z <= 2 pi (|a| + |b|) / P."""
    return RateBound(stiffness=TWO_PI * (np.abs(p["a_periodic"]) + np.abs(p["b_periodic"]))
                     / p["P_periodic"])


TERM = Term(
    name="periodic_force", kind="mass",
    parameters=(
        Parameter("a_periodic", "N", Prior("normal", 0.0, 1.0, "force", lower=None),
                  "amplitude of the sine part"),
        Parameter("b_periodic", "N", Prior("normal", 0.0, 1.0, "force", lower=None),
                  "amplitude of the cosine part"),
        Parameter("P_periodic", "m", Prior("loguniform", 0.02, 2.0, "z"),
                  "period in the displacement")),
    equation="f = a_periodic sin(2 pi z / P_periodic) + b_periodic cos(2 pi z / P_periodic)",
    description="force periodic in z (a shape fitted as a term; never a candidate name)",
    force=force, rate_bound=rate_bound,
    probe=Probe("a_periodic", lambda d: 0.1 * d.force, signed=True), nameable=False,
    source=__file__)
