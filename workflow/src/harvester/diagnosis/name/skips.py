"""Which screened candidates are sampled, in what order, and what the time budget left.

A candidate's best fit (``diagnosis.name.screen``) bounds the evidence it can gain; one that
can neither be accepted nor tie with the best accepted is not sampled (:func:`skip_reason`),
one whose best fit lies on a bound its posterior must pile against comes last
(:func:`sampling_order`), and a rival the budget left unsampled that could have reached the
name makes a tie (:func:`budget_rivals`). ``diagnosis.name.confirm`` runs the sampling.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping

import numpy as np

from harvester.diagnosis.name.fits import BRIDGE_MIN_SE
from harvester.diagnosis.name.results import CandidateResult, ConfirmSettings
from harvester.model.terms import same_physics

log = logging.getLogger("harvester.diagnosis")

#: Why a candidate the time budget left was not sampled, or why its sampling stopped.
BUDGET_REASON = "the time budget ran out before it"


STOPPED_REASON = "not finished within the time budget"


def sampling_order(order: list[str], fitted: Mapping) -> tuple[list[str], set[str]]:
    """``order`` with the candidates whose best fit lies on a bound their posterior must pile
    against (``Screened.pulled``, of ``fitted``: effect -> Screened) moved behind the others,
    each group in its order; and the set of those."""
    pulled = {e for e in order if e in fitted and fitted[e].pulled and not fitted[e].failed}
    return [e for e in order if e not in pulled] + [e for e in order if e in pulled], pulled


def skip_reason(screened, results: list[CandidateResult], settings: ConfirmSettings,
                top: int | None, nested_se: float = BRIDGE_MIN_SE,
                single_scores: bool = False, estimate: bool = True) -> str | None:
    """Why a screened candidate (``diagnosis.name.screen.Screened``) need not be sampled: ``top``
    candidates were sampled already, or its evidence bound (``Screened.bound``) or its
    importance-sampling ceiling (``Screened.importance_ceiling``, where trusted) lies below the
    acceptance threshold (``acceptance_base`` plus mc_sigmas times the root sum of squares of
    the nested model's standard error and BRIDGE_MIN_SE), or below the best accepted gain minus
    the naming margin (log(1/alpha) + mc_sigmas standard errors of that gain): it can then
    neither be accepted nor tie with the best. A candidate whose fit failed (fell below the
    nested model's: an optimiser that missed, or an effect whose smallest admissible size
    already costs) is sampled only where a trusted importance-sampling estimate, which does
    not rest on the fit, leaves it open: nothing else supports it, and its sampling is where
    stiff contacts spend a quarter of an hour (the backlash on the literature grid, never
    accepted). In a round opened by single effects' scores (``single_scores``: the family's
    test not significant, no conflict), or once another candidate was accepted, it is not
    even estimated. A candidate whose best fit lies on a bound its posterior must pile
    against (``Screened.pulled``) would not be trusted (``confirm.judge``), so it cannot be
    named; it is sampled only where a candidate accepted before it leaves it a tie to make.
    One whose best fit puts a resonance above the likelihood's band
    (``Screened.beyond_band``) would not be named either (``limits.beyond_band``): on the
    literature generator's Bouc-Wen records a mode's TMCMC at 104-218 Hz above the 81.9 Hz
    band spent the time budget before the other candidates were sampled. None: sample it
    (always where it was not screened). ``estimate`` False: the reasons that need no
    importance-sampling estimate only (the time budget is spent)."""
    if screened is None:
        return None
    if top is not None and len([r for r in results
                                if not (r.contradicted or r.unshown)]) >= top:
        return f"the round's {top} best by their fits were sampled"
    if screened.pulled and not screened.failed and not any(r.accepted for r in results):
        return (f"its best fit has {screened.pull_phrase()}: its posterior would pile there "
                "and not be trusted, and no candidate was accepted for it to tie with")
    above = screened.beyond_band
    if above and not screened.failed:
        at = ", ".join(f"{n} at {x:.1f} Hz" for n, (x, _) in above.items())
        band = max(b for _, b in above.values())
        return (f"its best fit puts {at}, above the {band:.1f} Hz band the likelihood "
                "compares: a resonance the record does not show, which is not named")
    least = settings.acceptance_base + settings.mc_sigmas * float(np.hypot(nested_se,
                                                                           BRIDGE_MIN_SE))
    if screened.failed:  # its bound means nothing; a trusted estimate still does
        return _failed_fit_reason(screened, results, settings, least, single_scores, estimate)
    return _fitted_reason(screened, results, settings, least, estimate)


def _failed_fit_reason(screened, results: list[CandidateResult], settings: ConfirmSettings,
                       least: float, single_scores: bool, estimate: bool = True) -> str | None:
    """:func:`skip_reason` for a candidate whose fit fell below the nested model's: only a
    trusted importance-sampling estimate, and only in a round opened by the family's test
    with nothing accepted yet, can leave it open (``least``: the acceptance threshold)."""
    if single_scores:
        return ("its fit fell below the nested model's, and the round was opened by single "
                "effects' scores, not by the family's test")
    accepted = [r.effect for r in results if r.accepted]
    if accepted:  # not estimated either (100 s for a stiff contact): the next round
        return (f"its fit fell below the nested model's and {accepted[0]} was accepted; "
                "the next round screens it again")
    if not estimate:
        return None
    ceiling = screened.importance_ceiling(settings.mc_sigmas)
    if ceiling is None:
        return (f"its fit fell below the nested model's and {screened.importance_phrase()}"
                ": nothing supports it (the next round screens it again)")
    if ceiling < least:
        return (f"its fit fell below the nested model's; {screened.importance_phrase()}, "
                f"at most {ceiling:.1f}, below the acceptance threshold {least:.1f}")
    return None


def _fitted_reason(screened, results: list[CandidateResult], settings: ConfirmSettings,
                   least: float, estimate: bool = True) -> str | None:
    """:func:`skip_reason` for a candidate with a usable fit: its evidence bound, then its
    trusted importance-sampling ceiling, against the acceptance threshold ``least`` and the
    best accepted gain less the naming margin."""
    if screened.bound < least:
        return (f"its best fit gains at most {screened.bound:.1f} nats of evidence, below the "
                f"acceptance threshold {least:.1f}")
    accepted = [r for r in results if r.accepted]
    floor = -np.inf
    if accepted:
        best = max(accepted, key=lambda r: r.delta_log_evidence)
        floor = best.delta_log_evidence - settings.base_threshold \
            - settings.mc_sigmas * best.delta_se
        if screened.bound < floor:
            return (f"its best fit gains at most {screened.bound:.1f} nats of evidence; "
                    f"{best.effect} gained {best.delta_log_evidence:.1f}")
    if not estimate:
        return None
    ceiling = screened.importance_ceiling(settings.mc_sigmas)
    if ceiling is not None and ceiling < max(least, floor):
        return (f"{screened.importance_phrase()}, at most {ceiling:.1f}, below "
                + (f"the acceptance threshold {least:.1f}" if floor <= least else
                   f"{best.effect}'s {best.delta_log_evidence:.1f} less the naming margin"))
    return None


def budget_rivals(results: list[CandidateResult], fitted: Mapping, settings: ConfirmSettings
                  ) -> list[str]:
    """The best accepted candidate is not named alone where the time budget left a screened
    rival of other physics unsampled (or stopped its TMCMC) whose best fit could reach it: its
    evidence bound at least the best's gain less the naming margin, so that sampled it could
    tie or lead (``skip_reason`` would have sampled it). Such rivals are recorded as
    indistinguishable from it, the evidence on them not in; a candidate whose best fit failed
    or puts a resonance above the band is not one. On the literature generator's LuGre record
    as force -> rel_disp a mode was named (+97.8 nats) while hysteresis, its bound +104.7,
    was left unsampled by the budget. Returns the rivals added. ``results`` best first."""
    accepted = [r for r in results if r.accepted]
    if not accepted:
        return []
    best = accepted[0]
    least = best.delta_log_evidence - settings.base_threshold \
        - settings.mc_sigmas * best.delta_se
    added = []
    for s in fitted.values():
        cut = s.skipped is not None and (s.skipped == BUDGET_REASON
                                         or s.skipped.startswith(STOPPED_REASON))
        if cut and not s.failed and not s.beyond_band and s.bound >= least \
                and not same_physics(s.effect, best.effect) \
                and s.effect not in best.indistinguishable_from:
            best.indistinguishable_from.append(s.effect)
            added.append(s.effect)
    if added:
        log.info("%s not named alone: the time budget left %s unsampled, whose best fits "
                 "could reach its evidence", best.effect, ", ".join(added))
    return added
