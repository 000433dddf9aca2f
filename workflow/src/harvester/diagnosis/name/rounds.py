"""Rounds of detect -> rank -> confirm: the diagnosis adds one effect at a time.

Each round detects and locates the mismatch of the current structure (``detect``), ranks the
library's effects by how much of it each explains (``rank``), fits the best ``screen`` of them
and their rivals (``rank.rivals``) by MAP for a bound on the evidence each can gain
(``screen``), samples the best few by that bound by TMCMC, skipping those the bound rules
out, judges them by evidence (``confirm``), and adopts the best accepted one. It stops when
nothing is detected, nothing is worth sampling, nothing sampled is accepted, the time budget
is spent (``budget``; what it cut is kept on the round), or after ``settings.rounds``
additions.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field, replace

import numpy as np

from harvester.diagnosis.prepare.analysis import Analysis, BaselineStart
from harvester.inference.map_fit import BaselineState, baseline_state
from harvester.diagnosis.name.budget import Unfinished, spent
from harvester.diagnosis.name.confirm import confirm, fit_structure
from harvester.diagnosis.name.results import CandidateResult
from harvester.diagnosis.name.fits import ModelFit
from harvester.diagnosis.detect.floor import problem_floor
from harvester.diagnosis.detect.scores import Detection, detect
from harvester.diagnosis.name.rank import (RankedCandidate, behind_catch_all, limit_rivals,
                                           rank, rivals, to_confirm)
from harvester.diagnosis.name.screen import Screen, screen, screen_more
from harvester.diagnosis.name.simulable import withdraw_divergent
from harvester.diagnosis.name.sensor import SensorReading, hold_against_sensor
from harvester.diagnosis.prepare.settings import DiagnosisSettings
from harvester.diagnosis.detect.signatures import candidate_terms, motion_scale
from harvester.model.priors import DeviceScale
from harvester.model.structures import ModelStructure

log = logging.getLogger("harvester.diagnosis")


@dataclass
class Round:
    """One pass of detect -> rank -> confirm on the current structure."""

    structure: str
    detection: Detection
    state: BaselineState
    ranked: list[RankedCandidate]
    confirmed: list[CandidateResult] = field(default_factory=list)
    scale: DeviceScale | None = None  # the scales the candidates' priors were read on
    screen: Screen | None = None  # the candidates' best fits, in the order they were sampled
    unfinished: list[Unfinished] = field(default_factory=list)  # what the budget cut
    seconds: dict[str, float] = field(default_factory=dict)  # detect, screen, confirm
    sensor: SensorReading | None = None  # held against the output's sensor (name.sensor)

    @property
    def accepted(self) -> CandidateResult | None:
        acc = [r for r in self.confirmed if r.accepted]
        return acc[0] if acc else None


@dataclass
class Current:
    """Where the rounds stand: the structure, its fit (None until sampled), its posterior
    samples and the priors so far."""

    structure: ModelStructure
    fit: ModelFit | None
    samples: np.ndarray
    priors: dict


def run_rounds(analysis: Analysis, start: BaselineStart, settings: DiagnosisSettings,
               nominated: tuple[str, ...] = ()
               ) -> tuple[list[Round], ModelFit | None, bool, list[str]]:
    """(rounds, the baseline's fit (sampled here if the start had none and a round needed it),
    whether a detected mismatch is left unexplained, notes). ``nominated``: effects the first
    round screens beside its ranking's (the missing force's, ``verdict.nominated_terms``)."""
    now = Current(analysis.structure, start.fit, start.samples, dict(start.priors))
    rounds, notes, unexplained = [], [], False
    floor = problem_floor(start.detection_problem)  # what a term's displacement must exceed
    baseline_fit = start.fit
    for r in range(settings.rounds + 1):
        rnd = detect_round(analysis, start, now, settings, r)
        rounds.append(rnd)
        if rnd.state.note:  # its state read at a sample, not the mean (map_fit.representative)
            notes.append(f"round {r + 1}: {rnd.state.note}")
        det = rnd.detection
        # a candidate whose own score is significant is screened even where the family's
        # maximum is not: the evidence, not the detection, decides what is named
        chosen = to_confirm(rnd.ranked, det, settings.screen)
        extra = [e for e in nominated if r == 0 and e not in {c.effect for c in chosen}]
        if r == settings.rounds or not (det.significant or det.conflict or chosen or extra):
            break
        if not chosen and not extra:
            unexplained = unexplained or det.significant
            if det.significant:
                notes.append(f"round {r + 1}: mismatch detected (p = {det.p_value:.3g}) but no "
                             "library effect explains enough of it to be worth sampling")
            break
        if now.fit is None:  # the baseline's own sampling: never cut by the budget
            now.fit = fit_structure(start.fit_problem, now.structure, now.priors,
                                    replace(settings.confirmation(), deadline=None))
            baseline_fit = baseline_fit or now.fit
        effects = [c.effect for c in chosen + rivals(rnd.ranked, chosen)]
        effects += [e for e in extra if e not in effects]
        effects += limit_rivals(effects, set(candidate_terms(now.structure.terms,
                                                             settings.candidates)))
        if spent(settings):
            unexplained = unexplained or det.significant
            notes.append(cut_round(rnd, effects, r, settings))
            break
        best, said = sample_round(rnd, now, effects, analysis, start, settings, floor, r)
        notes += said + rough_notes(rnd, r)
        if best is None:
            unexplained = unexplained or det.significant
            notes += undecided_notes(rnd, r, settings)
            break
        now = Current(best.fit.structure, best.fit, best.fit.samples,
                      {**best.fit.priors, **now.priors})
        unexplained = unexplained and not det.significant
    return rounds, baseline_fit, unexplained, notes


def sample_round(rnd: Round, now: Current, effects: list[str], analysis: Analysis,
                 start: BaselineStart, settings: DiagnosisSettings, floor, r: int
                 ) -> tuple[CandidateResult | None, list[str]]:
    """The round's screen and confirmation of ``effects`` on the current structure, a name
    whose posterior diverges over the record withdrawn (``simulable``) and the round held
    against a resonance of the output's sensor (``sensor``): (the accepted candidate or
    None, notes)."""
    det = rnd.detection
    begun = time.perf_counter()
    scale = rnd.scale = motion_scale(rnd.state, analysis.window, det.frame.f_high)
    rnd.screen = screen(now.fit, effects, now.priors, scale, det, settings.seed + r,
                        stop=lambda: spent(settings))
    effects, behind = screen_behind_catch_all(rnd, now, effects, scale, settings, r)
    rnd.unfinished += [Unfinished(f"round {r + 1}", now.fit.structure.with_term(e).name,
                                  "MAP fit stopped" if e == rnd.screen.stopped
                                  else "not screened") for e in rnd.screen.unscreened]
    rnd.seconds["screen"] = time.perf_counter() - begun
    # the acceptance shares alpha among every candidate the round could name
    confirmation = replace(settings.confirmation(), family=len(det.candidates),
                           noise_floor=None if floor is None else floor.rms)
    rnd.confirmed = confirm(now.fit, effects, now.priors, confirmation, scale,
                            seed_offset=1000 * (r + 1), detection=det, screen=rnd.screen,
                            top=settings.top, unfinished=rnd.unfinished,
                            where=f"round {r + 1}")

    def chain(structure):
        return analysis.chain(start.detection_problem, start.temper, structure=structure)
    # a name whose posterior diverges over the record is withdrawn (name.simulable)
    notes = withdraw_divergent(rnd.confirmed, chain, confirmation)
    rnd.sensor, said = hold_against_sensor(rnd, chain, analysis.f_high, confirmation)
    rnd.seconds["confirm"] = time.perf_counter() - begun - rnd.seconds["screen"]
    return rnd.accepted, behind + notes + said


def screen_behind_catch_all(rnd: Round, now: Current, effects: list[str], scale,
                            settings: DiagnosisSettings, r: int
                            ) -> tuple[list[str], list[str]]:
    """Where a catch-all term leads the round's screen, the laws with memory and their
    limits fitted into it (``rank.behind_catch_all``): (the round's effects with them, a
    note saying so, or none)."""
    fitted = rnd.screen
    more = [] if fitted.unscreened else behind_catch_all(
        fitted.order, {s.effect for s in fitted.candidates if s.failed}, set(fitted.order),
        set(candidate_terms(now.structure.terms, settings.candidates)))
    if not more:
        return effects, []
    leader = fitted.order[0]
    log.info("%s leads the screen and can stand for what is not fitted: %s screened before "
             "it is judged", leader, ", ".join(more))
    screen_more(fitted, now.fit, more, now.priors, scale, rnd.detection, settings.seed + r,
                stop=lambda: spent(settings))
    return effects + more, [f"round {r + 1}: {leader} led the screen; {', '.join(more)}, "
                            "which the detection's scores cannot see, screened beside it "
                            "(a catch-all term is judged against them)"]


def cut_round(rnd: Round, effects: list[str], r: int, settings: DiagnosisSettings) -> str:
    """Record a round the spent budget did not start (``rnd.unfinished``); its note."""
    rnd.unfinished.append(Unfinished(f"round {r + 1}", ", ".join(effects),
                                     "neither screened nor sampled"))
    return f"round {r + 1}: not run, the time budget was spent"


def undecided_notes(rnd: Round, r: int, settings: DiagnosisSettings) -> list[str]:
    """Why a round named nothing: the budget ran out, or nothing gained enough evidence
    where a mismatch was detected."""
    det = rnd.detection
    if rnd.unfinished:
        return [f"round {r + 1}: not decided, the time budget ran out before its candidates "
                "were sampled"]
    if det.significant:
        return [f"round {r + 1}: mismatch detected (p = {det.p_value:.3g}); no candidate "
                "sampled gained enough evidence"]
    return []


def detect_round(analysis: Analysis, start: BaselineStart, now: Current,
                 settings: DiagnosisSettings, r: int) -> Round:
    """Detection, location and ranking of the current structure's mismatch."""
    begun = time.perf_counter()
    problem = analysis.chain(start.detection_problem, start.temper, structure=now.structure)
    state = baseline_state(problem, now.samples)
    candidates = candidate_terms(now.structure.terms, settings.candidates)
    ds = settings.detection()
    det = detect(state, analysis.window, now.priors, candidates,
                 replace(ds, seed=ds.seed + r), time=analysis.time)
    rnd = Round(now.structure.name, det, state, rank(det, state, now.priors))
    rnd.seconds["detect"] = time.perf_counter() - begun
    return rnd


def rough_rivals(rnd: Round) -> list:
    """The round's candidates (``screen.Screened``) that were not sampled because their
    likelihood jumps (``confirm.rough``) while their best fit, by Laplace, gains more than
    every candidate accepted: the round's names stand against what could be sampled, not
    against them."""
    best = rnd.accepted
    return [s for s in (rnd.screen.candidates if rnd.screen is not None else [])
            if s.smooth is not None and s.smooth.rough and not s.sampled
            and (best is None or s.laplace_gain > best.delta_log_evidence)]


def rough_notes(rnd: Round, r: int) -> list[str]:
    """:func:`rough_rivals` of round ``r`` (from 0) in words."""
    best = rnd.accepted
    than = "" if best is None else f", above {best.effect}'s {best.delta_log_evidence:+.1f}"
    return [f"round {r + 1}: {s.effect} fits better at its best fit (Laplace "
            f"{s.laplace_gain:+.1f} nats{than}) but was not sampled: {s.smooth.phrase()}; "
            "the round's names stand against the candidates that could be sampled"
            for s in rough_rivals(rnd)]
