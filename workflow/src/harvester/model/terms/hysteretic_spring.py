"""A hysteretic spring (Bouc 1967, Wen 1976; exponent 1): a loop in the restoring force of the
spring itself, beside the linear spring k that holds at small amplitude,

    f = k_bw (s - x),    s' = w - (|w| s + e_bw w |s|) / d_bw,    x' = w,

x the spring's displacement and w its velocity (z' where no coupling), s the hysteretic
displacement (Bouc-Wen's z / alpha). At small amplitude s = x and f = 0: the sidecar's k is the
small-amplitude stiffness (k_L + alpha of a Bouc-Wen oscillator m y'' + c y' + k_L y + z = u,
z' = alpha y' - beta (gamma |y'| z + delta y' |z|), with k_bw = alpha, d_bw = 1 / (beta gamma),
e_bw = delta / gamma). Moving away from s = 0 the element's stiffness is k_bw (1 - (1 + e_bw)
|s| / d_bw), moving back k_bw (1 + (1 - e_bw) |s| / d_bw): the branches differ by 2 k_bw |s| /
d_bw, a loop that dissipates. e_bw > -1 saturates (s -> d_bw / (1 + e_bw), the spring softens:
e_bw = 0 is Dahl's law, the friction term ``hysteresis`` placed in the spring); e_bw < -1
hardens while moving away (the Bouc-Wen benchmark of Noel and Schoukens 2016: e_bw = -1.375,
d_bw = 1.25 mm). The law is rate-independent, as ``hysteresis``'s.

Priors:

- k_bw: the hysteretic element's stiffness from a hundredth of the linear spring k to k itself
  (the benchmark's alpha is half its small-amplitude stiffness)
- d_bw: the loop's yield displacement 1 / (beta gamma), from a tenth of the RMS displacement
  (below it the element saturates at once: a friction of level k_bw d_bw / (1 + e_bw)) to ten
  times it (above it the element is a linear spring over the record); a posterior piled at its
  lower bound stands for friction (``limits``: sticking, then Coulomb), which the diagnosis
  then samples in its place; on EMPS through the command line it had piled there alone
- e_bw: delta / gamma, normal about 0 (the symmetric forms of the literature, |delta| <= gamma)
  with sd 1, within [-2, 2]: below -1 the loading branch hardens as exp(|1 + e_bw| x / d_bw),
  which the prior's edges let grow e^10 over ten RMS displacements (the rate bound assumes
  at most e-fold, ``GROWTH_CAP``)
"""

from __future__ import annotations

import numpy as np

from harvester.model.priors import Prior
from harvester.model.terms import Motion, Parameter, Probe, RateBound, Term

#: The probe's shapes: yield displacements (x the RMS displacement) and e_bw.
PROBE_YIELD, PROBE_E = (0.3, 1.0, 3.0), (-1.0, 0.0)
#: Exponent at which the rate bound caps the hardening branch's growth: s grown e-fold over
#: its linear course. The Bouc-Wen benchmark's grows e^0.72 over its largest displacement
#: (2.4 mm); 8 sub-steps per sample there reproduce 64 to 0.009 x its noise sd.
GROWTH_CAP = 1.0


def force(w, s, x, k_bw, d_bw, e_bw):
    """f = k_bw (s - x) (N): the element's force less the linear spring's share of it."""
    return k_bw * (s - x)


def state_rates(w, s, x, k_bw, d_bw, e_bw):
    """s' = w - (|w| s + e_bw w |s|) / d_bw (m/s), x' = w."""
    return w - (abs(w) * s + e_bw * w * abs(s)) / d_bw, w


def _state_bound(d: np.ndarray, e: np.ndarray, z_bound: float) -> np.ndarray:
    """|s| along a monotone displacement of at most z_bound from s = 0 (m): d / (1 + e) where
    it saturates (e > -1), z_bound at e = -1, d / |1 + e| (exp(|1 + e| z_bound / d) - 1) where
    it hardens, its exponent capped at GROWTH_CAP (a step bound, not a bound on every
    path: z_bound is the generic 0.3 m per m/s, hundreds of yield displacements)."""
    g = (1.0 + e) / d
    with np.errstate(divide="ignore", invalid="ignore"):
        hard = np.expm1(np.minimum(-g * z_bound, GROWTH_CAP)) / np.maximum(-g, 1e-300)
        soft = np.minimum(1.0 / np.maximum(g, 1e-300), z_bound)
    return np.where(g > 0, soft, np.where(g < 0, hard, z_bound))


def rate_bound(p: dict, motion: Motion) -> RateBound:
    """The element's stiffness |k_bw (ds/dx - 1)| <= k_bw (1 + |e_bw|) |s| / d_bw, |s| by
    :func:`_state_bound`; the state's own rate (1 + |e_bw|) v_bound / d_bw (1/s)."""
    k, d, e = np.abs(p["k_bw"]), np.maximum(np.abs(p["d_bw"]), 1e-12), p["e_bw"]
    s = _state_bound(d, e, motion.z_bound)
    return RateBound(stiffness=k * (1.0 + np.abs(e)) * s / d,
                     rate=(1.0 + np.abs(e)) * motion.v_bound / d)


TERM = Term(
    name="hysteretic_spring", kind="screw", n_states=2,
    parameters=(
        Parameter("k_bw", "N/m", Prior("loguniform", 0.01, 1.0, "k"),
                  "stiffness of the hysteretic element (Bouc-Wen's alpha)"),
        Parameter("d_bw", "m", Prior("loguniform", 0.1, 10.0, "z"),
                  "yield displacement of the loop, 1 / (beta gamma)"),
        Parameter("e_bw", "1", Prior("normal", 0.0, 1.0, None, lower=-2.0, upper=2.0),
                  "shape of the loop, delta / gamma (< -1 hardens, > -1 saturates)"),
    ),
    equation="Bouc-Wen (exponent 1) in the spring: f = k_bw (s - x), "
             "s' = w - (|w| s + e_bw w |s|) / d_bw, x' = w",
    description="hysteretic spring (Bouc-Wen): a loop in the restoring force",
    force=force, state_rates=state_rates, rate_bound=rate_bound, alike=("hysteresis",),
    # a yield displacement of nothing: the element holds, then slides at k_bw d_bw / (1 + e_bw)
    unprobed=True,
    limits=(("d_bw", "lower", "sticking_friction"), ("d_bw", "lower", "coulomb_friction")),
    probe=Probe("k_bw", lambda d: 0.1 * d.k,
                shapes=lambda d: [{"d_bw": y * d.z, "e_bw": e}
                                  for y in PROBE_YIELD for e in PROBE_E]),
    source=__file__)
