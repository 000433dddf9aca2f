"""Stribeck excess of a dry friction that sticks: breakaway above the sliding level,

    f = [F_dry + F_break exp(-(|w| / v_break)^delta_break)] sgn(w)   sliding,
    |f| <= F_dry + F_break                                              stuck (w = 0),

so the contact holds up to the static level F_s = F_dry + F_break and, once broken away,
its friction falls towards the sliding level F_dry as it speeds up (Armstrong-Helouvry,
Dupont and Canudas de Wit 1994). A refinement of ``sticking_friction`` (meaningless without
it); the smooth counterpart is ``stribeck_friction``. v_break -> 0 is Karnopp's (1985) jump
from the static to the sliding level.

Priors:

- F_break: the static level exceeds the sliding one by a hundredth of the damping force the
  motion shows to twice it, as ``stribeck_friction``'s excess: static/sliding ratios of 1.2-2
  (the literature generator's Karnopp element) sit inside it for sliding levels from a tenth
  of that force up
- v_break: the Stribeck velocity from 1/100 of the RMS velocity to 3 x it: Stribeck
  velocities span 1e-5 to 1e-1 m/s (Armstrong-Helouvry et al. 1994); below 1/100 of the RMS
  velocity the decay is over within a recording's velocity resolution (a jump, Karnopp's), and
  the integrator's pieces below 5 v_break shorten with it; above 3 x it, it is viscous-like
- delta_break: the decay's exponent: 1 (exponential) and 2 (Gaussian) are the literature's
  forms; below 1 the decay's slope is infinite at breakaway
"""

from __future__ import annotations

from harvester.model import fastmath as fm
from harvester.model.priors import Prior
from harvester.model.terms import STICKING_FRICTION, Motion, Parameter, Probe, RateBound, Term

#: The decay's transition speed in Stribeck velocities: at 5 v_break the excess is exp(-5) of
#: F_break for delta = 1 (less for delta > 1).
TRANSITION_SPEEDS = 5.0
#: Beyond this many Stribeck velocities the excess is exp(-37) < 1e-16 of F_break (delta >= 1).
FLAT_RATIO = 37.0


def force(speed, F_break, v_break, delta_break):
    """The excess F_break exp(-(speed / v_break)^delta_break) (N) at a speed >= 0 (m/s);
    without its three elementary functions where they change nothing: at rest (F_break) and
    beyond FLAT_RATIO Stribeck velocities (0: below 1e-16 of F_break for delta >= 1)."""
    r = speed / v_break
    if r == 0.0:
        return F_break
    if r > FLAT_RATIO:
        return 0.0
    return F_break * fm.exp(-fm.exp(delta_break * fm.log(r)))


def static(F_break, v_break, delta_break):
    """The excess's share of the holding level: F_break (N)."""
    return F_break


def transition(F_break, v_break, delta_break):
    """(speed, slope): below TRANSITION_SPEEDS x v_break (m/s) the decay changes at up to
    delta F_break / v_break (N s/m; attained for delta = 1 at breakaway), the integrator's
    pieces cut to it there; above, the slope is below exp(-5) of that."""
    return TRANSITION_SPEEDS * v_break, delta_break * F_break / v_break


def rate_bound(p: dict, motion: Motion) -> RateBound:
    """Nothing beyond the transition (``transition``: the integrator refines below it)."""
    return RateBound()


TERM = Term(
    name="sticking_stribeck", kind="stick",
    parameters=(
        Parameter("F_break", "N", Prior("loguniform", 0.01, 2.0, "force"),
                  "excess of the static (breakaway) over the sliding level"),
        Parameter("v_break", "m/s", Prior("loguniform", 1.0 / 100.0, 3.0, "v"),
                  "Stribeck velocity of the sticking law"),
        Parameter("delta_break", "-", Prior("normal", 1.5, 0.5, lower=1.0, upper=3.0),
                  "exponent of the decay from breakaway"),
    ),
    equation="f = [F_dry + F_break exp(-(|w| / v_break)^delta_break)] sgn(w) sliding; "
             "w = 0 while |force needed| <= F_dry + F_break",
    description="Stribeck excess of a dry friction that sticks (breakaway above sliding)",
    force=force, static=static, transition=transition, rate_bound=rate_bound,
    refines=STICKING_FRICTION,
    alike=("stribeck_friction",),
    probe=Probe("F_break", lambda d: 0.1 * d.force,
                shapes=lambda d: [{"v_break": f * d.v} for f in (0.01, 0.1, 1.0)]),
    source=__file__)
