"""What the diagnosis concludes: the verdict, the effects it names, and the ties it cannot
break.

An effect is *named* only when it is accepted by evidence and every physically different
candidate trails it by more than the acceptance threshold (``confirm.mark_ties``); otherwise
the verdict lists the tie: what each candidate would mean physically, and which experiment
would separate them with the expected evidence gap (``separate``). A wrong name misleads more
than no name.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field

from harvester.diagnosis.confirm import CandidateResult, ModelFit
from harvester.diagnosis.rounds import Round
from harvester.diagnosis.separate import Separation, separations
from harvester.diagnosis.settings import DiagnosisSettings

log = logging.getLogger("harvester.diagnosis")

#: Rivals of a tie whose separating experiments are computed (the closest first).
TIE_RIVALS = 2


def decide_verdict(p_value: float, accepted: bool, unexplained_alpha: float) -> str:
    """"missing_physics" when an added effect is confirmed by evidence, or when the
    detection's p-value is below ``unexplained_alpha`` although nothing explains it; else
    "adequate".

    The detection at ``alpha`` only screens: on data the baseline explains, it fires in about
    alpha of recordings, and a verdict on it alone would cry wolf at that rate. Evidence
    acceptance is calibrated by itself (``confirm``: P(B > 1/alpha) <= alpha under the
    baseline), so the false-alarm rate is at most P(accepted) + unexplained_alpha. The
    detection's replicate p-value cannot fall below 1 / (bootstrap + 1): the default 0.001
    needs 1000 replicates, so with fewer the verdict rests on evidence alone. (Measured: on
    8 s analysed records of the baseline itself, 2 of 5 reached the smallest p-value of 200
    and 300 replicates: the replicate null is too light-tailed there to trust a lone
    detection.) Either way ``unexplained_mismatch`` in diagnosis.json reports a significant
    detection that no effect explains.
    """
    return "missing_physics" if accepted or p_value < unexplained_alpha else "adequate"


@dataclass
class Tie:
    """Candidates the recording cannot tell apart: what each implies, and the experiments
    that would (best first)."""

    effects: list[str]
    implies: dict[str, str]
    separations: list[Separation] = field(default_factory=list)

    def to_dict(self) -> dict:
        return {"effects": self.effects, "implies": self.implies,
                "separating_experiments": [s.to_dict() for s in self.separations],
                "recommended": self.separations[0].experiment if self.separations else None}


@dataclass
class Conclusion:
    """The verdict, the effects named (each alone), the ties, whether a detected mismatch is
    left unexplained, notes, and the improved model's fit (the last accepted)."""

    verdict: str
    missing: list[str]
    ties: list[Tie]
    unexplained: bool
    notes: list[str]
    improved_fit: ModelFit | None


def conclude(rounds: list[Round], unexplained: bool, settings: DiagnosisSettings,
             f_high: float) -> Conclusion:
    """The conclusion from the rounds (module docstring)."""
    first, last = rounds[0].detection, rounds[-1].detection
    accepted = [rnd.accepted for rnd in rounds if rnd.accepted is not None]
    missing = [a.effect for a in accepted if a.named]
    ties = [tie_of(rnd.accepted, rnd, f_high) for rnd in rounds
            if rnd.accepted is not None and not rnd.accepted.named]
    notes = []
    if accepted and last.significant:
        unexplained = True
        notes.append(f"after adding {', '.join(a.effect for a in accepted)} a mismatch remains "
                     f"(p = {last.p_value:.3g})")
    verdict = decide_verdict(first.p_value, bool(accepted), settings.unexplained_alpha)
    if first.significant and not accepted and verdict == "adequate":
        notes.append(f"weak mismatch (p = {first.p_value:.3g}) that no library effect explains "
                     f"by evidence; below the bar for an unexplained verdict "
                     f"(p < {settings.unexplained_alpha:g})")
    if verdict == "adequate" and first.conflict:
        notes.append("prior-posterior conflict on " + ", ".join(
            c.parameter for c in first.conflicts if c.conflict) + " that no library effect "
            "resolves: check the initial modelling and priors")
    for rnd in rounds:
        for r in rnd.confirmed:
            if r.at_prior_edge:
                notes.append(f"{r.effect}: the posterior of {', '.join(r.at_prior_edge)} piles "
                             "against its prior's bound; the candidate is not trusted")
    return Conclusion(verdict, missing, ties, bool(unexplained), notes,
                      accepted[-1].fit if accepted else None)


def tie_of(best: CandidateResult, rnd: Round, f_high: float) -> Tie:
    """The tie around ``best`` in its round, with separating experiments against its
    closest rivals (TIE_RIVALS)."""
    results = {r.effect: r for r in rnd.confirmed}
    rivals = [e for e in best.indistinguishable_from if e in results][:TIE_RIVALS]
    effects = [best.effect, *best.indistinguishable_from]
    tie = Tie(effects, {e: results[e].implies() for e in effects if e in results})
    for rival in rivals:
        try:
            tie.separations += separations({best.effect: best.fit,
                                            rival: results[rival].fit}, f_high)
        except (RuntimeError, ValueError) as err:
            log.warning("separating %s from %s failed: %s", best.effect, rival, err)
    tie.separations.sort(key=lambda s: -s.decisive if s.decisive == s.decisive else 0.0)
    log.info("tie: %s; %s", " / ".join(effects),
             f"best separated by {tie.separations[0].experiment}" if tie.separations else
             "no separating experiment computed")
    return tie
