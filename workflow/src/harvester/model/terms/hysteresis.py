"""Pre-sliding friction with memory (Dahl 1968): the friction force h follows
h' = k_hyst (w - |w| h / F_hyst), saturating at F_hyst while sliding.

k_hyst (N/m) is the bristle (pre-sliding) stiffness, F_hyst / k_hyst the pre-sliding
displacement.
"""

from __future__ import annotations

import numpy as np

from harvester.model.terms import Motion, Parameter, RateBound, Term


def force(w, h, F_hyst, k_hyst):
    """f = h (N), the Dahl state."""
    return h + 0.0 * w


def state_rates(w, h, F_hyst, k_hyst):
    """h' = k_hyst (w - |w| h / F_hyst) (N/s)."""
    return k_hyst * (w - abs(w) * h / F_hyst)


def rate_bound(p: dict, motion: Motion) -> RateBound:
    """The bristle stiffness k_hyst, and the relaxation rate k_hyst v_bound / F_hyst."""
    k = np.abs(p["k_hyst"])
    return RateBound(stiffness=k,
                     rate=k * motion.v_bound / np.maximum(np.abs(p["F_hyst"]), 1e-6))


TERM = Term(
    name="hysteresis", kind="screw", n_states=1,
    parameters=(
        Parameter("F_hyst", "N", 2.0, 2.0, 1e-3, "saturation force of the pre-sliding branch"),
        Parameter("k_hyst", "N/m", 2e4, 2e4, 1.0, "pre-sliding (bristle) stiffness"),
    ),
    equation="Dahl: h' = k_hyst (w - |w| h / F_hyst), f = h",
    description="pre-sliding friction with memory (Dahl model)",
    force=force, state_rates=state_rates, rate_bound=rate_bound, source=__file__)
