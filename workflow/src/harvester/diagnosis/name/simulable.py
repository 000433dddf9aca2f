"""A candidate accepted on the TMCMC window whose posterior cannot be simulated over the
record is not named.

TMCMC samples a candidate on the fit window (``settings.fit_seconds``, 10 s in the fast
settings), the detection reads the whole analysed record. A term can fit the first and
predict a device that the rest of the record contradicts: a softening cubic spring
(k_cubic -1.05e8 N/m^3 beside k 3065 N/m) leaves its well wherever |z| exceeds
sqrt(k / |k_cubic|) = 5.4 mm, which the 10 s window never reached and the 30 s record did:
every one of its 300 posterior draws diverged there (an effect-free literature record, seed 0,
its sidecar's k doubled; ``docs/measurements.md``). A model whose posterior, more likely than
not, sends the device out of its well where the record shows it stayed is contradicted by the
record: it is withdrawn, said in a note, and the round's next accepted candidate, if any,
takes its place (ties marked again without it).
"""

from __future__ import annotations

import logging
from collections.abc import Callable

import numpy as np

from harvester.diagnosis.name.confirm import mark_ties
from harvester.diagnosis.name.results import CandidateResult, ConfirmSettings
from harvester.inference.map_fit import ChainProblem
from harvester.model.structures import ModelStructure

log = logging.getLogger("harvester.diagnosis")

#: Below this share of its posterior draws simulable over the record, a candidate is
#: withdrawn: its posterior predicts, more likely than not, a motion the record did not show.
MIN_SIMULABLE_SHARE = 0.5


def simulable_share(problem: ChainProblem, samples: np.ndarray) -> float:
    """Share of the posterior draws (rows: free parameters..., sigma) whose simulation over
    ``problem``'s record stays finite (one batched simulation)."""
    samples = np.atleast_2d(np.asarray(samples, dtype=float))
    return float(np.mean(np.isfinite(problem.loglike(samples))))


def withdraw_divergent(results: list[CandidateResult],
                       problem_of: Callable[[ModelStructure], ChainProblem],
                       settings: ConfirmSettings) -> list[str]:
    """Withdraw (``accepted`` False) the round's accepted candidates, best first, whose
    posterior draws simulate over the record (``problem_of(structure)``) less often than
    MIN_SIMULABLE_SHARE, up to the first that holds; mark the ties again without them.
    Returns a note per withdrawn candidate."""
    notes, withdrawn = [], []
    for r in [r for r in results if r.accepted]:
        share = simulable_share(problem_of(r.fit.structure), r.fit.samples)
        if share >= MIN_SIMULABLE_SHARE:
            break
        withdrawn.append(r.effect)
        notes.append(f"{r.effect} was accepted on the sampled window ({r.delta_log_evidence:+.1f}"
                     f" nats) but only {100.0 * share:.0f} % of its posterior draws can be "
                     "simulated over the analysed record (the others diverge: the device it "
                     "implies leaves its equilibrium where the record shows it did not): "
                     "not named")
        log.warning("%s", notes[-1])
    withdraw(results, withdrawn, settings)
    return notes


def withdraw(results: list[CandidateResult], effects: list[str],
             settings: ConfirmSettings) -> None:
    """Set ``effects``' results not accepted and mark the round's ties again without them
    (``confirm.mark_ties``): a withdrawn candidate is no rival of the others."""
    if not effects:
        return
    for r in results:
        r.indistinguishable_from.clear()
        if r.effect in effects:
            r.accepted = False
    mark_ties(results, settings)
    for r in results:
        r.indistinguishable_from[:] = [e for e in r.indistinguishable_from if e not in effects]
        if r.effect in effects:
            r.indistinguishable_from.clear()
