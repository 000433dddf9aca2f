"""Where a candidate stands for another term, or the record does not show its physics.

A term's posterior may pile against a bound of its prior where the term becomes another
(``Term.limits``: a pre-sliding displacement of nothing is friction that sticks, a mode far
above the band a mass); a displacement it rests on may lie below what the record resolves
(``Term.resolved``, :func:`unresolved`); a resonance it declares may lie above the band the
likelihood compares (``Term.in_band``, :func:`beyond_band`). Such a candidate is taken at its
limit and the terms it stands for are sampled in its place (:func:`limit_candidates`),
unless the record tells it from them by its force (:func:`apart_from_limits`,
:func:`mark_apart`). ``diagnosis.name.confirm`` judges and names; this module says what a
result stands for.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping

import numpy as np

from harvester.diagnosis.detect.signatures import candidate_terms
from harvester.diagnosis.name.fits import ModelFit
from harvester.diagnosis.name.results import CandidateResult, ConfirmSettings
from harvester.diagnosis.name.screen import above_band
from harvester.model.structures import ModelStructure
from harvester.model.terms import term

log = logging.getLogger("harvester.diagnosis")


def limit_candidates(effect: str, edges: Mapping[str, str], structure: ModelStructure,
                     order: list[str], candidates: tuple[str, ...] | None = None) -> list[str]:
    """The terms a candidate stands for where its posterior piled, or its best fit lies,
    against a bound (``edges``: name -> side; ``Term.limits``), that the structure can take
    (of ``candidates``, None: any) and the round has not listed: sampled next, in its place
    (unscreened, so always)."""
    allowed = set(candidate_terms(structure.terms, candidates))
    out = []
    for name, side in edges.items():
        other = next((o for o in term(effect).limit_terms(name, side) if o in allowed), None)
        if other and other not in order and other not in out:
            log.info("%s: %s at its %s limit, where the term stands for %s: sampling %s too",
                     effect, name, side, other, other)
            out.append(other)
    return out


def apart_from_limits(result: CandidateResult, fitted: Mapping, settings: ConfirmSettings
                      ) -> dict[str, float]:
    """Where the candidate stands for other terms at a displacement the record does not
    resolve (:func:`unresolved`, ``Term.limits``: a pre-sliding displacement of nothing is
    friction that sticks, or a sign law), whether the record still tells it from them: each
    of those terms screened this round (``fitted``: effect -> Screened) with a usable best fit
    whose evidence bound falls short of the candidate's gain by more than the naming margin
    (log(1/alpha) + mc_sigmas of its standard error). The law is then not its limit: its
    force, not its displacement, tells it apart, and that displacement is an upper bound,
    not a value; a posterior piled against the prior's bound there (below the resolution) is
    no reason to distrust it, a pile of any other parameter is. Sets ``result.limits_short``
    (term -> bound) and, where nothing else holds it back, accepts it. On the literature
    generator's Bouc-Wen friction as base_disp -> rel_disp (pre-sliding 1.7 um, the record
    resolving 8.3 um) hysteresis gained +212.3 nats, piled at 1.08 um, its limits' best fits
    +15.1 (sticking) and +1.7 (Coulomb): taken as its limit, neither could be named. On the
    frame the sticking law's best fit comes within it where the bristle is a stand-in; on
    EMPS a hysteretic spring piled on its yield displacement's bound (1.58 mm, resolved)
    stands for the position loop and is not waived. Returns ``limits_short``."""
    limits = tuple(sorted({o for n in result.unresolved
                           for o in term(result.effect).limit_terms(n, "lower")}))
    least = result.delta_log_evidence - settings.base_threshold \
        - settings.mc_sigmas * result.delta_se
    if not _short(limits, fitted, least):
        return {}
    result.limits_short = {o: float(fitted[o].bound) for o in limits}
    result.accepted = result.passes()
    log.info("%s: its limits' best fits (%s) fall short of its %+.1f nats: the record tells "
             "it from them", result.effect, ", ".join(f"{e} {b:+.1f}" for e, b in
                                                     result.limits_short.items()),
             result.delta_log_evidence)
    return result.limits_short


def mark_apart(fitted: Mapping, settings: ConfirmSettings) -> None:
    """Set ``Screened.apart`` on each screened candidate (``fitted``: effect -> Screened)
    whose best fit lies on a bound where its term becomes other terms (``Term.limits``), each
    of them screened with a usable fit whose evidence bound falls short of the candidate's
    Laplace gain by more than log(1/alpha): its posterior may pile there and it is still
    judged (:func:`apart_from_limits`), so it is sampled in its turn, not last or never. Only
    a displacement the record must resolve (``Term.resolved``) whose best fit lies below the
    resolution (``settings.noise_floor``; none where it is not measured)."""
    for s in fitted.values():
        if s.failed or settings.noise_floor is None or s.problem is None:
            continue
        least = s.laplace_gain - settings.base_threshold
        floor = _resolution(s.problem, settings.noise_floor)
        s.apart = tuple(n for n, (side, _) in s.on_bound.items()
                        if n in term(s.effect).resolved
                        and s.theta[s.names.index(n)] < floor
                        and _short(term(s.effect).limit_terms(n, side), fitted, least))


def _short(limits: tuple[str, ...], fitted: Mapping, least: float) -> bool:
    """Whether every one of ``limits`` was screened with a usable best fit whose evidence
    bound lies below ``least``."""
    screens = [fitted.get(o) for o in limits]
    return bool(limits) and all(x is not None and not x.failed and x.bound is not None
                                and x.bound < least for x in screens)


def resolution(fit: ModelFit, noise_floor: float) -> float:
    """The smallest displacement (m) the record tells from its noise: the recording's own
    noise floor (RMS over the likelihood's band, output units, ``detect.floor``: measured
    where the model has no say, so that a model's misfit does not set it) carried to a
    displacement at the top of that band (floor / (2 pi f)^order: the displacement itself,
    or its second derivative). Below it a displacement of the model leaves nothing in the
    record but the noise."""
    return _resolution(fit.problem, noise_floor)


def _resolution(problem, noise_floor: float) -> float:
    """:func:`resolution` on a likelihood's problem (``map_fit.ChainProblem``)."""
    order = problem.output_type.order
    return float(noise_floor) / (2.0 * np.pi * problem.band_hz) ** order


def unresolved(effect: str, fit: ModelFit, noise_floor: float | None
               ) -> dict[str, tuple[float, float]]:
    """The term's displacements (``Term.resolved``: a pre-sliding displacement) whose
    posterior median lies below what the record resolves (:func:`resolution`): name ->
    (median, resolution), m. Such a term is a stand-in for its limit (a bristle of 0.1 um on
    lasers that see 5 um is a contact that holds), not its own physics. None checked where
    the record's noise floor is not measured (``noise_floor`` None)."""
    names = [n for n in term(effect).resolved if n in fit.names]
    if not names or noise_floor is None:
        return {}
    floor = resolution(fit, noise_floor)
    medians = {n: float(np.median(fit.samples[:, fit.names.index(n)])) for n in names}
    return {n: (x, floor) for n, x in medians.items() if x < floor}


def beyond_band(effect: str, fit: ModelFit) -> dict[str, tuple[float, float]]:
    """The term's resonance frequencies (``Term.in_band``) whose posterior median lies above
    the band the likelihood compares (``ChainProblem.band_hz``): name -> (median, band top),
    Hz. The record holds no peak there, only what the resonance's skirt does at the band's
    top; on the literature generator's records recorded as base_disp -> rel_acc, whose base
    acceleration is derived through a filter at 102 Hz, a mode was fitted at 83-109 Hz above
    the 81.9 Hz band on four of the eight effects (dead zone, ground friction, Dahl,
    backlash), and named on two (December 2026, 3289362): the filter's edge, not a part of the
    device."""
    return above_band(effect, fit.names,
                      lambda n: np.median(fit.samples[:, fit.names.index(n)]),
                      lambda: fit.problem.band_hz)


def becomes(result: CandidateResult, effect: str) -> bool:
    """Whether ``result``'s posterior piles against a bound where its term becomes
    ``effect`` (``Term.limits``): a mode pushed far above the band is the mass error."""
    return any(effect in term(result.effect).limit_terms(name, side)
               for name, side in result.at_limit.items())
