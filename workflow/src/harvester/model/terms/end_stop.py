"""An end stop beyond a clearance: f = k_stop (|z| - gap_stop)_+ sgn(z).

A force that acts only where the displacement exceeds the clearance, unlike a cubic spring,
which acts everywhere; it stands for linear, Hertzian ((|z| - g)^1.5) and Hunt-Crossley
contacts, whose differences lie in the first micrometres of contact.

Priors:

- gap_stop: a clearance the motion reaches: from a tenth of its largest displacement to that
  displacement itself (a stop met at the peaks alone: the literature generator's linear stop,
  0.04 % of the time in contact at 0.99 x the largest |z|, lay beyond the old bound of five RMS
  displacements)
- k_stop: from a rubber bumper as soft as the spring to a steel stop 1e5 x stiffer (contact
  stiffnesses of steel parts: 1e6-1e9 N/m)
"""

from __future__ import annotations

import numpy as np

from harvester.model.priors import Prior
from harvester.model.terms import Motion, Parameter, Probe, RateBound, Term


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
        Parameter("gap_stop", "m", Prior("loguniform", 0.1, 1.0, "z_max"),
                  "clearance before contact"),
        Parameter("k_stop", "N/m", Prior("loguniform", 1.0, 1e5, "k"), "contact stiffness"),
    ),
    equation="f = k_stop (|z| - gap_stop)_+ sgn(z)", description="end stop beyond a clearance",
    force=force, rate_bound=rate_bound,
    probe=Probe("k_stop", lambda d: 1.0 / d.z,
                shapes=lambda d: [{"gap_stop": d.z_quantiles[q]}
                                  for q in (0.5, 0.75, 0.9, 0.97, 0.99, 0.999)],
                start_shape="gap_stop"),
    source=__file__)
