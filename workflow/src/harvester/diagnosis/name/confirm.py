"""Confirm candidate effects by TMCMC on the augmented structures and select by evidence.

Each candidate is the baseline with one more term of the library
(``ModelStructure.with_term``), sampled by TMCMC (``identify``) under the same likelihood as
the baseline: eq. (10) through the measurement chain, tempered by lambda, the effective
share of independent samples (``map_fit.ChainProblem``), so that evidences are comparable and
not inflated by the correlation of the low-passed residuals.

Acceptance. For data from the baseline, the Bayes factor B of any alternative has
E[B] = 1 (over the baseline's prior predictive), so P(B > 1/alpha) <= alpha (Markov's
inequality). A round compares the family of N candidates the library offers the structure, and
the union bound gives P(any B_k > N/alpha) <= alpha: a candidate is accepted when delta log
evidence exceeds log(N/alpha) (5.4 nats for the tanh model's 11 candidates at alpha = 0.05;
``ConfirmSettings.acceptance_base``) plus ``mc_sigmas`` Monte Carlo standard errors of the
difference. Which of the N are sampled depends on the data, so the bound holds only over all N,
not over the few sampled. Each evidence
is TMCMC's re-estimated by bridge sampling from the final population (``bridge_evidence``),
whose standard error is its own; chains that disagree by more than ``agreement_nats`` are
sampled again with twice the particles. Naming (``mark_ties``): the best accepted candidate is
named only if every physically different rival trails it by more than log(1/alpha) plus its
Monte Carlo margin; otherwise they are reported together as a tie. A candidate whose
posterior implies a device the sidecar contradicts (``plausibility``: a mass error that pulls
M to three times the weighed mass) is not accepted, does not count among the ``top`` sampled
(the next is sampled in its place) and ties with none: the sidecar tells it apart.

Priors of the added terms: each parameter's prior as its term file states it, in the
device's own scales (``harvester.model.priors``: the damping force the motion shows, its RMS
velocity and displacement, M, k, the analysed band), read on this device's scales
(``signatures.motion_scale``). Scale parameters span their physically plausible decades
(log-uniform), with the reasoning beside each; the evidence pays for that breadth through
the Occam factor. Priors given by the caller always win.

Particles. A candidate's TMCMC gets ``particles`` x (its added parameters / 2), at least
``particles`` (``candidate_particles``): the secondary mode's four parameters hold a narrow
peak in f_mode that few prior draws hit.

Start. A candidate's TMCMC tempers from a reference distribution, not from the prior
(``harvester.inference.reference``, :func:`start_of`): half its initial particles at its MAP
with the Laplace covariance widened (``diagnosis.name.screen`` fitted it), as the baseline's
start; where it was not fitted, at the nested model's posterior (widened) for the shared
parameters and, for a ``Probe.start_shape`` (a mode's frequency), the detection's scan
(:func:`candidate_reference`). The other half come from the prior, which bounds the
importance weights. The prior, the posterior and the evidence are unchanged; what changes is
that the tempering no longer spends its first stages (and their resampling, which thins out
the added parameters' values at random) re-finding the likelihood's peak, so a narrow peak
(in f_mode) survives to the stages where its likelihood gain counts. A population that
collapsed all the same (:func:`collapsed`) is sampled again from the prior.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Mapping
from dataclasses import replace

import numpy as np

from harvester.inference.map_fit import ChainProblem, chain_problem
from harvester.diagnosis.detect.scores import Detection, at_prior_edge
from harvester.diagnosis.name.fits import (MISSED_MODE_NATS, ModelFit, candidate_priors,
                                           scan_factor)
from harvester.diagnosis.name.budget import OutOfTime, Unfinished, spent
from harvester.diagnosis.name.screen import Screen
from harvester.diagnosis.prepare.redundant import used_quantities
from harvester.diagnosis.name.plausibility import (Implied, contradictions, implied_device,
                                              measured_device)
from harvester.diagnosis.name.smoothness import smoothness
from harvester.model.priors import DeviceScale
from harvester.inference.evidence import BridgeEstimate, chains_bridge_log_evidence, log_target
from harvester.inference.identify import identify
from harvester.inference.posterior import posterior_theta, pooled_log_evidence, log_evidence
from harvester.model.terms import same_physics, term
from harvester.inference.priors import PriorSpec
from harvester.inference.priors import priors_for
from harvester.inference.reference import (REFERENCE_SHARE, REFERENCE_WIDEN, GaussianFactor,
                                           Reference, map_reference, support)
from harvester.model.structures import ModelStructure
from harvester.diagnosis.name.results import CandidateResult, ConfirmSettings
from harvester.diagnosis.name.limits import (apart_from_limits, becomes, beyond_band,
                                             limit_candidates, mark_apart, unresolved)
from harvester.diagnosis.name.skips import (BUDGET_REASON, STOPPED_REASON, budget_rivals,
                                            sampling_order, skip_reason)

log = logging.getLogger("harvester.diagnosis")


def candidate_particles(effect: str, particles: int) -> int:
    """Particles per chain for a candidate: ``particles`` x (added parameters / 2), at least
    ``particles``. Measured on one medium-grid record with a 6.6 Hz mode at zeta 0.04: with
    150 particles the two chains' log evidences differed by 12 nats (one missed the mode),
    with 300 by 6."""
    return int(particles * max(1.0, len(term(effect).parameters) / 2.0))


def candidate_reference(effect: str, nested: ModelFit, detection: Detection | None,
                        priors: Mapping[str, PriorSpec]) -> Reference | None:
    """Where the TMCMC of a candidate starts half its particles (``harvester.inference.
    reference``): the parameters it shares with the model it extends at that model's
    posterior (a Gaussian, sds widened by REFERENCE_WIDEN), a ``Probe.start_shape`` (a
    mode's frequency) where the detection's scan places it (:func:`scan_factor`), its other
    parameters from their priors. ``priors`` must be the ones the candidate's model is built
    with. The other half start from the prior, which bounds the weights.

    Started there the tempering needs a few stages, not a dozen, and skips the prior's
    stiffest corners. (With random-walk moves alone, an added term that trades off against
    the nested model's parameters, Coulomb friction against F_c, collapsed in 3 of 10 runs,
    commit e1e8381; a population that collapses all the same is sampled again from the prior,
    :func:`candidate_fit`.) None when the nested posterior is too small or degenerate."""
    scan = scan_factor(effect, detection, priors)
    if nested.samples is None or len(nested.samples) < 2 * len(nested.names):
        return None
    lowers, uppers = support(priors, nested.names)
    inside = np.all((nested.samples >= np.asarray(lowers)[None, :])
                    & (nested.samples < np.asarray(uppers)[None, :]), axis=1)
    try:
        gaussian = GaussianFactor.from_samples(tuple(nested.names), nested.samples[inside],
                                               lowers, REFERENCE_WIDEN, uppers)
    except ValueError as err:  # a degenerate posterior: the scan alone, or the prior
        log.warning("no Gaussian start for %s (%s)", effect, err)
        return None if scan is None else Reference({scan.name: priors[scan.name]}, (scan,),
                                                   REFERENCE_SHARE)
    factors = (gaussian,) if scan is None else (gaussian, scan)
    names = (*nested.names, *(() if scan is None else (scan.name,)))
    return Reference({n: priors[n] for n in names}, factors, REFERENCE_SHARE)


#: A final TMCMC stage accepting at least this share of its moves had collapsed onto copies
#: of a few particles (its moves have no size); a healthy one accepts 0.2-0.5.
COLLAPSED_ACCEPTANCE = 0.9


def collapsed(fit: ModelFit) -> bool:
    """Whether a chain's population collapsed onto copies of a few particles: its last stage
    accepted nearly every move, which happens when the proposal covariance, taken from the
    population, has shrunk to nothing (seen once in 16 candidates started from a reference
    at 100 particles: the early stages, their moves too wide for the reference's cloud while
    the prior's half was still alive, kept few distinct particles, and the last stage jumped
    to beta = 1 from them; bridge estimate 140 nats low)."""
    if fit.idata is None or "accept_rate" not in fit.idata.sample_stats:
        return False
    rates = fit.idata.sample_stats["accept_rate"].values
    last = [row[np.isfinite(row)][-1] for row in np.atleast_2d(rates) if np.isfinite(row).any()]
    return bool(any(r >= COLLAPSED_ACCEPTANCE for r in last))


def describe_start(ref: Reference) -> str:
    """One line for the log: what a candidate's reference is made of."""
    parts = []
    for f in ref.describe()["factors"]:
        if f["kind"] == "gaussian":
            parts.append("the nested model's posterior (" + ", ".join(f["variables"]) + ")")
        else:
            parts.append(f"the scan of {f['variable']} (heaviest at "
                         + ", ".join(f"{c:.3g}" for c in f["heaviest"]) + ")")
    return " and ".join(parts)


def fit_structure(problem: ChainProblem, structure: ModelStructure,
                  priors: Mapping[str, PriorSpec], settings: ConfirmSettings,
                  seed_offset: int = 0, reference: Reference | None = None,
                  decisions: tuple[float, ...] | None = None) -> ModelFit:
    """TMCMC of ``structure`` on the data, window, chain and tempering of ``problem``
    (from ``reference`` instead of the prior where given); sampled again with twice the
    particles while its chains disagree by more than ``settings.agreement_nats``, unless
    ``decisions`` (log evidences where the diagnosis's decision changes) are all outside the
    chains' range widened by that much: then no precision bought would change anything."""
    p = chain_problem(problem, problem.temper, problem.lowpass_hz, problem.filter_order,
                      structure=structure)
    used = priors_for(p, priors)
    enlarged: list[tuple[int, float]] = []
    run = settings
    for attempt in range(settings.enlargements + 1):
        # the candidates' intervals are not reported: no adjustment for correlated residuals
        idata = identify(p, priors, run.tmcmc(seed_offset + 7919 * attempt), reference,
                         adjust=False)
        ev = log_evidence(idata)
        spread = float(np.ptp(ev)) if len(ev) > 1 else 0.0
        if spread <= settings.agreement_nats or attempt == settings.enlargements:
            break
        if spent(settings):
            log.warning("%s: the chains differ by %.2f nats, but the time budget is spent: "
                        "not sampled again", structure.name, spread)
            break
        if decisions is not None and not _straddles(ev, decisions, settings.agreement_nats):
            log.info("%s: the chains differ by %.2f nats, but no decision lies within their "
                     "range: not sampled again", structure.name, spread)
            break
        log.warning("%s: the chains' log evidences differ by %.2f nats (more than %.1f) with "
                    "%d particles; sampled again with %d", structure.name, spread,
                    settings.agreement_nats, run.particles, 2 * run.particles)
        enlarged.append((run.particles, spread))
        run = replace(run, particles=2 * run.particles)
    samples = posterior_theta(idata)
    bridge = None
    if settings.bridge:
        bridge = bridge_evidence(p, used, samples, ev, settings.seed + seed_offset)
    log.info("%s: log evidence %s (TMCMC chains, pooled %.2f)%s", structure.name,
             ", ".join(f"{e:.2f}" for e in ev), pooled_log_evidence(ev),
             f"; bridge sampling {bridge.log_evidence:.2f} +- {bridge.se:.2f}" if bridge else "")
    if spread > settings.agreement_nats:
        log.warning("%s: the chains still differ by %.2f nats with %d particles", structure.name,
                    spread, run.particles)
    return ModelFit(structure, p, samples, ev, idata, used, bridge, reference, enlarged=enlarged)


def bridge_evidence(problem: ChainProblem, priors: Mapping[str, PriorSpec],
                    samples: np.ndarray, chain_evidence: np.ndarray, seed: int
                    ) -> BridgeEstimate | None:
    """Bridge-sampling log evidence (``harvester.inference.evidence.chains_bridge_log_evidence``) from
    the posterior samples of the chains whose own bridge estimate lies within
    MISSED_MODE_NATS of the best chain's (a chain stuck in a minor mode holds samples of the
    wrong weight; TMCMC's own chain estimates scatter by up to 6 nats without that, so they
    do not decide it); its error is the larger of the formula's and the chains' scatter.
    None where it fails."""
    chains = len(chain_evidence)
    rows = np.split(samples, chains) if chains > 1 else [samples]
    target = log_target(problem.loglike, [priors[n] for n in problem.parameter_names])
    try:
        return chains_bridge_log_evidence(target, rows, np.random.default_rng(seed),
                                          MISSED_MODE_NATS)
    except (ValueError, np.linalg.LinAlgError) as err:
        log.warning("bridge sampling failed (%s); TMCMC's evidence is used", err)
        return None


def _straddles(ev: np.ndarray, decisions: tuple[float, ...], margin: float) -> bool:
    """Whether any decision point lies within the chains' log evidences widened by margin."""
    low, high = float(np.min(ev)) - margin, float(np.max(ev)) + margin
    return any(low <= d <= high for d in decisions)


def candidate_fit(baseline: ModelFit, effect: str, priors: Mapping[str, PriorSpec],
                  settings: ConfirmSettings, scale: DeviceScale,
                  detection: Detection | None = None, seed_offset: int = 0,
                  decisions: tuple[float, ...] | None = None, point=None) -> ModelFit:
    """The baseline with one more term, sampled by TMCMC: its priors (the candidate's
    scaled to this device, ``priors`` winning), its particles (:func:`candidate_particles`)
    and its start (:func:`start_of`, sampled again from the prior if that population
    collapsed). ``point``: the candidate's MAP (``map_fit.PointFit``) where it was fitted."""
    structure = baseline.structure.with_term(effect)
    specs = {**candidate_priors(effect, scale, baseline.problem.known), **priors}
    run = replace(settings, particles=candidate_particles(effect, settings.particles))
    ref, where = start_of(effect, baseline, detection, specs, point) \
        if settings.reference else (None, "")
    log.info("%s: %d particles per chain%s", structure.name, run.particles,
             "" if ref is None else "; half the particles start from " + where)
    fit = fit_structure(baseline.problem, structure, specs, run, seed_offset=seed_offset,
                        reference=ref, decisions=decisions)
    if ref is not None and collapsed(fit):
        log.warning("%s: the population started from the reference collapsed; sampled "
                    "again from the prior", structure.name)
        fit = fit_structure(baseline.problem, structure, specs, run, seed_offset=seed_offset)
        fit.restarted = True
    return fit


def start_of(effect: str, baseline: ModelFit, detection: Detection | None,
             specs: Mapping[str, PriorSpec], point=None) -> tuple[Reference | None, str]:
    """(reference, what it is) for a candidate's TMCMC: its own MAP with the Laplace
    covariance (:func:`map_reference`) where the screen fitted it, as the baseline's starts;
    else the nested model's posterior and the detection's scan (:func:`candidate_reference`).
    With the MAP the tempering starts where the likelihood is, instead of at the added
    parameters' priors, and needs a few stages instead of a dozen or more."""
    names = baseline.names + term(effect).parameter_names
    used = priors_for(baseline.problem, specs, names)
    if point is not None:
        ref = map_reference(point, used)
        if ref is not None:
            return ref, "the candidate's MAP and its Laplace covariance"
    ref = candidate_reference(effect, baseline, detection, used)
    return ref, "" if ref is None else describe_start(ref)


def confirm(baseline: ModelFit, effects: list[str], priors: Mapping[str, PriorSpec],
            settings: ConfirmSettings, scale: DeviceScale, seed_offset: int = 0,
            detection: Detection | None = None, screen: Screen | None = None,
            top: int | None = None, unfinished: list[Unfinished] | None = None,
            where: str = "") -> list[CandidateResult]:
    """Sample each augmented structure; evidence against the baseline; acceptance.
    ``detection``: the round's detection, whose scans place the start of candidates with a
    ``Probe.start_shape`` (:func:`candidate_reference`). ``screen``: the candidates' best
    fits (``diagnosis.name.screen``); then they are sampled in its order, at most ``top`` of them,
    and one whose evidence bound rules it out is not sampled (``skips.skip_reason``). Those
    whose best fit lies on a bound their posterior must pile against (``Screened.pulled``)
    come last: they can only tie with a candidate accepted before them. Past the settings'
    deadline (``budget``) a candidate's TMCMC stops and no further one starts: each is
    appended to ``unfinished`` (``where``: the round, for its sentence)."""
    fitted = {s.effect: s for s in screen.candidates} if screen is not None else {}
    mark_apart(fitted, settings)
    order, pulled = sampling_order(list(screen.order if screen is not None else effects),
                                   fitted)
    single = detection is not None and not (detection.significant or detection.conflict)
    results, cut = [], unfinished if unfinished is not None else []
    i = -1
    while i + 1 < len(order):
        i += 1
        effect = order[i]
        screened = fitted.get(effect)
        late = bool(cut) or spent(settings)
        reason = skip_reason(screened, results, settings, top, baseline.log_evidence_se,
                             single, estimate=not late)
        if reason is None and late:
            reason = BUDGET_REASON
        if reason is not None:
            order[i + 1:i + 1] = _skip(screened, effect, reason, effect in pulled,
                                       baseline.structure, order, settings.candidates)
            if late and reason == BUDGET_REASON:
                cut.append(Unfinished(where, baseline.structure.with_term(effect).name,
                                      "not sampled"))
            continue
        log.info("confirming %s (%d of %d)", baseline.structure.with_term(effect).name, i + 1,
                 len(order))
        result = _sampled(baseline, effect, screened, priors, settings, scale, detection,
                          seed_offset + 101 * (i + 1), results, cut, where)
        if result is None:
            continue
        apart_from_limits(result, fitted, settings)
        results.append(result)
        order[i + 1:i + 1] = limit_candidates(effect, results[-1].at_limit,
                                              baseline.structure, order, settings.candidates)
    results.sort(key=lambda r: -r.delta_log_evidence)
    mark_ties(results, settings)
    if cut:
        budget_rivals(results, fitted, settings)
    return results


def _sampled(baseline: ModelFit, effect: str, screened, priors: Mapping[str, PriorSpec],
             settings: ConfirmSettings, scale: DeviceScale, detection: Detection | None,
             seed: int, results: list[CandidateResult], cut: list[Unfinished],
             where: str) -> CandidateResult | None:
    """One candidate's result (:func:`_confirm_one`) with its wall time, marked sampled on
    its screen; None where the deadline stopped it (appended to ``cut``) or its likelihood
    jumps and no estimate is trusted, each said on ``screened``."""
    begun = time.perf_counter()
    try:
        result = _confirm_one(baseline, effect, screened, priors, settings, scale, detection,
                              seed, results)
    except OutOfTime as stop:
        cut.append(Unfinished.stopped(where, baseline.structure.with_term(effect).name, stop))
        _skipped(screened, effect, f"{STOPPED_REASON} ({stop})")
        return None
    if result is None:
        _skipped(screened, effect, rough_reason(screened))
        return None
    result.seconds = time.perf_counter() - begun
    if screened is not None:
        screened.sampled = True
    return result


def _skip(screened, effect: str, reason: str, pulled: bool, structure: ModelStructure,
          order: list[str], allowed: tuple[str, ...] | None = None) -> list[str]:
    """Say why ``effect`` is not sampled; the terms it stands for at the bound its best fit
    lies on (where it is ``pulled``), to sample next in its place (of ``allowed``)."""
    _skipped(screened, effect, reason)
    if not pulled:
        return []
    edges = {n: side for n, (side, _) in screened.pulled.items()}
    return limit_candidates(effect, edges, structure, order, allowed)


def _skipped(screened, effect: str, reason: str) -> None:
    """Say (and record on the screened candidate) why ``effect`` was not sampled."""
    if screened is not None:
        screened.skipped = reason
    log.info("%s not sampled: %s", effect, reason)


def _confirm_one(baseline: ModelFit, effect: str, screened, priors: Mapping[str, PriorSpec],
                 settings: ConfirmSettings, scale: DeviceScale, detection: Detection | None,
                 seed: int, results: list[CandidateResult]) -> CandidateResult | None:
    """One candidate's result: judged on its importance-sampling estimate where that decides
    (:func:`judged_by_importance`, :func:`judged_rough`), else by TMCMC (:func:`candidate_fit`);
    None where its likelihood jumps and no estimate is trusted (not sampled). Raises
    ``OutOfTime`` past the settings' deadline."""
    result = judged_by_importance(baseline, effect, screened, settings, seed)
    if result is None and rough(screened):
        return judged_rough(baseline, effect, screened, settings, seed)
    if result is None:
        point = screened.point if screened is not None and not screened.failed else None
        fit = candidate_fit(baseline, effect, priors, settings, scale, detection, seed,
                            decisions(baseline, results, settings), point)
        result = judge(effect, fit, baseline, settings)
    return result


def judged_by_importance(baseline: ModelFit, effect: str, screened, settings: ConfirmSettings,
                         seed: int) -> CandidateResult | None:
    """The result of a candidate whose best fit lies on a bound of its prior
    (``Screened.on_bound``), judged on draws from its trusted importance-sampling estimate
    (``Screened.importance_draws``) instead of TMCMC where those draws pile against a bound:
    then the candidate cannot be named (:func:`judge`), only its evidence, for a tie, is at
    stake, and the estimate gives it. None (TMCMC decides) where the estimate is not
    trusted or its draws do not pile (and for a candidate not screened, or not on a bound)."""
    if screened is None or screened.failed or not screened.on_bound \
            or not screened.importance_trusted:
        return None
    result = _importance_result(baseline, effect, screened, settings, seed)
    if not result.at_prior_edge:
        log.info("%s: the draws of its importance-sampling estimate do not pile against a "
                 "bound: sampled by TMCMC", result.fit.structure.name)
        return None
    log.info("%s: judged on its importance-sampling estimate, not by TMCMC: its best fit "
             "has %s", result.fit.structure.name, screened.pull_phrase(screened.on_bound))
    return result


def _importance_result(baseline: ModelFit, effect: str, screened, settings: ConfirmSettings,
                       seed: int) -> CandidateResult:
    """:func:`judge` on draws from the candidate's importance-sampling estimate, its
    evidence that estimate's."""
    est, p = screened.importance, screened.problem
    chains = max(settings.chains, 1)
    samples = screened.importance_draws(chains * candidate_particles(effect, settings.particles),
                                        settings.seed + seed)
    fit = ModelFit(baseline.structure.with_term(effect), p, samples,
                   np.array([est.log_evidence]), None, priors_for(p, screened.specs),
                   importance=est)
    log.info("%s: %d draws of its importance-sampling estimate (log evidence %.2f +- %.2f, "
             "Pareto k %.2f, ESS %.0f of %d)", fit.structure.name, len(samples),
             est.log_evidence, est.se, est.pareto_k, est.ess, est.draws)
    return judge(effect, fit, baseline, settings)


def rough(screened) -> bool:
    """Whether a screened candidate's likelihood jumps about its best fit
    (``smoothness.smoothness``, made here on first use and kept on ``screened``): then
    TMCMC's random walk cannot sample it (:func:`judged_rough`). False for a candidate not
    screened or whose fit failed."""
    if screened is None or screened.failed or screened.point is None:
        return False
    if screened.smooth is None:
        screened.smooth = smoothness(screened.problem, screened.specs, screened.point,
                                     screened.on_bound)
        s = screened.smooth
        log.info("%s: smoothness about its best fit: %s (%d simulations, %.1f s)",
                 screened.effect, s.phrase(), s.simulations, s.seconds)
    return screened.smooth.rough


def judged_rough(baseline: ModelFit, effect: str, screened, settings: ConfirmSettings,
                 seed: int) -> CandidateResult | None:
    """A candidate whose likelihood jumps (:func:`rough`) judged on its importance-sampling
    estimate where that is trusted: an average of the likelihood over draws, which needs no
    random walk (its Pareto k says whether the draws found the jumps' peaks). None where the
    estimate is not trusted: the candidate is then not sampled (:func:`rough_reason`)."""
    screened.importance_ceiling(settings.mc_sigmas)  # makes the estimate
    if not screened.importance_trusted:
        return None
    log.info("%s: %s: judged on its importance-sampling estimate, not by TMCMC",
             effect, screened.smooth.phrase())
    return _importance_result(baseline, effect, screened, settings, seed)


def rough_reason(screened) -> str:
    """Why a candidate whose likelihood jumps was not sampled, in words."""
    return (f"{screened.smooth.phrase()}: a Metropolis random walk cannot sample it, and "
            f"{screened.importance_phrase()}; its best fit gains at most "
            f"{screened.bound:.1f} nats (Laplace {screened.laplace_gain:+.1f}), which no "
            "estimate here confirms")


def decisions(baseline: ModelFit, results: list[CandidateResult], settings: ConfirmSettings
              ) -> tuple[float, ...]:
    """Log evidences at which a candidate's fate changes: acceptance over the baseline (by
    ``acceptance_base``), and a tie with (or a lead over) the best accepted so far
    (``mark_ties``, by log(1/alpha))."""
    step = settings.base_threshold
    points = [baseline.log_evidence + settings.acceptance_base]
    accepted = [r.fit.log_evidence for r in results if r.accepted]
    if accepted:
        points += [max(accepted) - step, max(accepted) + step]
    return tuple(points)


def judge(effect: str, fit: ModelFit, baseline: ModelFit, settings: ConfirmSettings
          ) -> CandidateResult:
    """The candidate's evidence against the baseline and its acceptance: delta log evidence
    above ``acceptance_base`` (log(family/alpha)) plus mc_sigmas standard errors, and no added
    parameter piled against a bound of its prior (then the prior cut off what the data wanted:
    flagged, not trusted)."""
    delta = fit.log_evidence - baseline.log_evidence
    se = float(np.hypot(fit.log_evidence_se, baseline.log_evidence_se))
    threshold = settings.acceptance_base + settings.mc_sigmas * se
    edges = {}
    for name in term(effect).parameter_names:
        j = fit.names.index(name)
        side = at_prior_edge(fit.priors[name], fit.samples[:, j])
        if side is not None:
            edges[name] = side
    if edges:
        log.warning("%s: the posterior of %s piles against the prior's bound (%s): not trusted",
                    fit.structure.name, ", ".join(edges), ", ".join(edges.values()))
    device = candidate_device(effect, fit, settings)
    for d in contradictions(device):
        log.warning("%s: not named: %s", fit.structure.name, d.sentence())
    hidden = unresolved(effect, fit, settings.noise_floor)
    above = beyond_band(effect, fit)
    result = CandidateResult(effect, fit, float(delta), se, float(threshold), False,
                             at_prior_edge=edges, device=device, unresolved=hidden,
                             beyond_band=above)
    result.accepted = result.passes()
    if result.unshown:
        log.warning("%s: %s", fit.structure.name, result.unresolved_sentence())
    return result


def candidate_device(effect: str, fit: ModelFit, settings: ConfirmSettings) -> list[Implied]:
    """The stated device quantities (the fit's known M, m, k, with ``settings``'
    uncertainties) that ``effect``'s posterior implies (``plausibility``); none where its
    term declares none. Only those the recording's model uses: with a force input m is a
    placeholder, not a stated mass (``redundant.used_quantities``)."""
    if term(effect).device is None:
        return []
    known = fit.problem.known
    used = used_quantities(fit.problem.input_type.force_input)
    stated = measured_device(known, settings.device_sd, settings.device_relative_sd)
    return implied_device(effect, fit.structure, fit.samples, known,
                          {n: v for n, v in stated.items() if n in used})


def mark_ties(results: list[CandidateResult], settings: ConfirmSettings) -> None:
    """The best accepted candidate is named alone only if every physically different
    candidate (``harvester.model.terms.same_physics``; not one piled at the bound where it
    becomes the best's term, ``limits.becomes``) trails it by more than the naming margin
    (log(1/alpha) plus mc_sigmas standard errors of the gap: two named models, no family);
    the others within it are recorded as indistinguishable from it, both ways. ``results``
    best first."""
    accepted = [r for r in results if r.accepted]
    if not accepted:
        return
    best = accepted[0]
    for r in results:
        if r is best or same_physics(r.effect, best.effect) or becomes(r, best.effect) \
                or r.contradicted or r.unshown:  # the sidecar, the record tell it apart
            continue
        gap = best.delta_log_evidence - r.delta_log_evidence
        margin = settings.base_threshold + settings.mc_sigmas * np.hypot(best.delta_se,
                                                                         r.delta_se)
        if gap <= margin:
            r.indistinguishable_from.append(best.effect)
            best.indistinguishable_from.append(r.effect)
