"""A dead zone (backlash) between the mass and the screw-side inertia J = M - m.

States: d, the relative displacement of the mass and the screw side, and d'. The coupling
force is F_b = k_backlash dz(d, gap) + c_b d' while in contact (compressive only), dz the
dead-zone function, c_b at damping ratio BACKLASH_ZETA on the reduced mass m J / (m + J).
The mass obeys m z'' = -m y'' - k z - (mass forces) - F_b and the screw side
J r'' = F_b - c_m r' - f(r'), d = z - r.

The contact's damping: without it (a Hunt-Crossley law, damping ~ penetration) the contact
rang and chattered; at zero clearance the coupling was an undamped mode, and the
log-likelihood of a record of the baseline itself fell by thousands at the library's
stiffness (measured).

Priors:

- gap_backlash: axial play of a ball nut: a micrometre when preloaded to a millimetre when worn
- k_backlash: the contact's resonance on the reduced mass, log-uniform from the analysed
  band's top to 8 x above it. Below the band's top it would ring inside the band (a mode that
  the record shows as one); far above it the band-limited record cannot tell a stiffer contact
  (a ball nut's 1e7-1e9 N/m) from one at 8 x, and each step up costs sub-steps. A compliant
  mount or a worn nut puts it anywhere between: with a normal prior about 6 x bounded at 4 x,
  the literature generator's backlash (its contact at 2.8 x the band's top) fitted on the
  bound, 25 nats below the posterior 5 % inside, and was not sampled (December 2026)
"""

from __future__ import annotations

import numpy as np

from harvester.model.priors import DeviceScale, Prior
from harvester.model.terms import Motion, Parameter, Probe, RateBound, Term

#: Damping ratio of the contact (Kelvin-Voigt, on the reduced mass m J / (m + J)).
BACKLASH_ZETA = 0.5


def force(d, dd, M, m, gap_backlash, k_backlash):
    """Coupling force F_b (N) at relative displacement d (m) and velocity dd (m/s)."""
    j_eq = max(M - m, 1e-6)
    c_b = 2.0 * BACKLASH_ZETA * np.sqrt(k_backlash * m * j_eq / (m + j_eq))
    if d > gap_backlash:
        return max(k_backlash * (d - gap_backlash) + c_b * dd, 0.0)
    if d < -gap_backlash:
        return min(k_backlash * (d + gap_backlash) + c_b * dd, 0.0)
    return 0.0


def rate_bound(p: dict, motion: Motion) -> RateBound:
    """Eight times the contact's natural frequency on the reduced mass: the contact switches
    on and off and RK4 drops to first order at each touch (x4 left 1.2 % error in z'' through
    a 20 Hz low-pass in a rattling case, x8 0.3 %)."""
    m = np.maximum(np.abs(motion.m_osc), 1e-3)
    j = np.maximum(motion.mass - m, 1e-3)
    reduced = m * j / (m + j)
    return RateBound(rate=8.0 * np.sqrt(np.abs(p["k_backlash"]) / reduced))


#: The contact resonance sqrt(k_backlash / mu) / 2 pi (mu the reduced mass m J / (m + J)) as
#: multiples of the analysed band's upper edge: the prior's log-uniform range.
CONTACT_BAND = (1.0, 8.0)


def contact_stiffness(d: DeviceScale) -> float:
    """mu (2 pi f_high)^2 (N/m): the stiffness whose contact resonance sits at the band's
    edge; the prior is in multiples of it."""
    mu = d.m * (d.M - d.m) / d.M if d.M > d.m > 0 else 0.25 * d.M
    return mu * (2.0 * np.pi * d.f_high) ** 2


TERM = Term(
    name="backlash", kind="coupling", n_states=2,
    parameters=(
        Parameter("gap_backlash", "m", Prior("loguniform", 1e-6, 1e-3),
                  "half dead zone in the screw-nut coupling"),
        Parameter("k_backlash", "N/m",
                  Prior("loguniform", CONTACT_BAND[0] ** 2, CONTACT_BAND[1] ** 2,
                        contact_stiffness),
                  "axial contact stiffness of the screw-nut coupling"),
    ),
    equation="coupling force F_b = k_backlash dz(d, gap) + c_b d' in contact (compressive "
             "only), c_b at damping ratio 0.5 on m J / (m + J); J r'' = F_b - c_m r' - f(r')",
    description="dead zone between the mass and the screw-side inertia",
    force=force, rate_bound=rate_bound,
    probe=Probe("gap_backlash", lambda d: 0.0, reference="zero", amount_is_shape=True,
                shapes=lambda d: [{"gap_backlash": g} for g in (2e-6, 1e-5)]),
    source=__file__)
