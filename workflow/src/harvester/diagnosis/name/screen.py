"""Screen candidate effects by their best fit before sampling them: how much evidence each
can gain, and the order in which they are sampled.

Two ceilings on the log Bayes factor of the nested model plus one effect against the nested
model, both from the candidate's posterior mode (``map_fit.fit_map``; sigma^2 = SSE / n
maximises eq. (10) over sigma) under the same tempered likelihood (``map_fit.ChainProblem``)
as the nested model's sampled evidence:

* strict: for a prior that integrates to one, Z = int L pi <= max L, so the gain is at most
  max log L_candidate - log Z_nested. It exceeds the true gain by the nested model's Occam
  factor as well as the candidate's (tens of nats), too loose to rule out anything in a
  second round.
* ``bound``: the gain in log L plus the log prior density of the parameters both models
  share (sigma among them), each at its best fit, plus GAIN_SLACK. In the Laplace picture
  log Z = max log L + log pi(theta_hat) + 1/2 log det(2 pi Sigma), and the candidate's last
  two terms are the shared parameters' (at fixed added ones) plus those of the added
  parameters, log(pi(phi_hat) sqrt(det 2 pi Sigma_phi)), which is not positive while their
  posterior is no wider than their prior (an added parameter the data leave at its prior
  costs nothing, and gains nothing). So the evidence gain does not exceed that gain, to
  within the Laplace picture's error, which GAIN_SLACK allows for. The shared prior counts:
  a candidate that moves the parameters back from a prior conflict (friction added to a
  linear model whose damping had run far above its prior) gains that as evidence too.

A candidate whose ``bound`` lies below the acceptance threshold cannot be accepted, and one
whose bound lies below the best accepted gain minus the naming margin cannot tie with it
(``skips.skip_reason``): neither needs TMCMC. The bound misleads where the MAP misses the
best fit: the fit starts from the best of the nested posterior's mean joined with prior draws
of the added parameters and, for a start shape (a mode's frequency), the detection's scan; a
fit below the nested model's best (impossible at the optimum of a model that contains the
nested one; possible where the added term's smallest admissible size already costs, as for a
log-uniform amplitude) is marked ``failed``, and its bound is not used. Each candidate's
Laplace log evidence (``map_fit.laplace_log_evidence``) minus the nested model's is reported
beside it.

The bound ignores the added parameters' Occam factor, so it cannot rule out a candidate
whose best fit gains a few nats by fitting noise (a sharp resonance at a noise peak), yet
whose evidence is lower than the nested model's. For those the screen also estimates each
candidate's evidence by importance sampling (``harvester.inference.importance``) from a
defensive mixture in the prior coordinates: the MAP with its Laplace covariance, the nested
model's posterior with the added parameters at their prior (where the effect is absent), and
the prior (adapted twice at most to its weighted draws where the draws' Pareto k says the
estimate does not hold). Where the weights' Pareto k says the estimate holds, a candidate whose estimated
gain plus ``mc_sigmas`` standard errors plus IMPORTANCE_SLACK lies below the acceptance
threshold is not sampled (``Screened.importance_ceiling``). The same estimate of the nested
model against its sampled evidence checks the estimator on every round: where the two
disagree by more than IMPORTANCE_SLACK plus two standard errors, no candidate is ruled out by
it in that round.

The linearised ranking (``rank``) chooses which candidates are fitted; ``bound`` orders them.
On grid records the two disagreed on 2 of 3 (``benchmarks/bench_ranking.py``).
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace

import numpy as np

from harvester.inference.map_fit import (PILE_NATS, FitStopped, PointFit, PriorCoordinates,
                                          bound_pull, chain_problem, fit_map)
from harvester.diagnosis.name.fits import ModelFit, candidate_priors, scan_factor
from harvester.diagnosis.detect.scores import EDGE_SHARE, Detection
from harvester.inference.importance import (Component, ImportanceEstimate, MixtureProposal,
                                            importance_log_evidence, resample)
from harvester.inference.likelihood import sigma_marginal_loglike
from harvester.inference.priors import PriorSpec, priors_for
from harvester.model.priors import DeviceScale
from harvester.model.terms import term

log = logging.getLogger("harvester.diagnosis")

#: Prior draws of the added parameters joined with the nested posterior's mean as starts.
ADDED_STARTS = 24
#: Scanned values of a start shape (heaviest first) joined with the nested mean as starts.
SCAN_STARTS = 3
#: Least-squares solves of each candidate's MAP, from its best starts; the best end is kept.
#: One solve stopped linear + hysteresis on the frame at 450 g in a mode whose TMCMC stayed
#: 24 nats below the one the second start reaches (docs/measurements.md); a third solve
#: found nothing more there and on the paper's records, at 1.5 x the simulations.
MAP_SOLVES = 2
#: Nats allowed for the MAP's distance from the best fit and for the Laplace picture's error
#: in ``bound``.
GAIN_SLACK = 1.0
#: Draws of each importance-sampling estimate; the mixture's weights (MAP, nested posterior
#: with the added parameters' prior, prior) and the widening of its Gaussians' sds.
IMPORTANCE_DRAWS = 1000
IMPORTANCE_WEIGHTS = (0.45, 0.45, 0.1)
IMPORTANCE_WIDEN = 1.2
#: Adaptations of the mixture to its weighted draws where the first estimate is not reliable.
IMPORTANCE_ADAPT = 2
#: Nats allowed for the importance-sampling estimate's bias (a low tail the draws missed).
IMPORTANCE_SLACK = 1.0


def above_band(effect: str, names, value: Callable[[str], float],
               band_top: Callable[[], float]) -> dict[str, tuple[float, float]]:
    """The term's resonance frequencies (``Term.in_band``) among ``names`` whose ``value``
    (a best fit's, a posterior's median) lies above the top of the band the likelihood
    compares (``band_top``, asked only for a term that has such frequencies):
    name -> (value, band top), Hz."""
    at = {n: float(value(n)) for n in term(effect).in_band if n in names}
    if not at:
        return {}
    band = float(band_top())
    return {n: (x, band) for n, x in at.items() if x > band}


@dataclass
class Screened:
    """One candidate's best fit and the most evidence it can gain over the nested model."""

    effect: str
    names: tuple[str, ...]
    theta: np.ndarray  # the MAP (free parameters..., sigma)
    max_loglike: float  # tempered log L at the MAP, sigma profiled (nats)
    bound: float  # gain in log L + shared log prior over the nested model's + GAIN_SLACK
    strict_bound: float  # max log L - the nested model's log evidence (nats)
    failed: bool  # the fit fell below the nested model's best (``fit_value``)
    simulations: int
    seconds: float
    laplace_gain: float = float("nan")  # Laplace log evidence minus the nested model's (nats)
    skipped: str | None = None  # why it was not sampled (None: sampled, or not reached)
    sampled: bool = False
    point: PointFit | None = field(default=None, repr=False)  # the MAP, its Laplace covariance
    importance: ImportanceEstimate | None = None  # its log evidence by importance sampling
    importance_gain: float = float("nan")  # that minus the nested model's (nats)
    importance_gain_se: float = float("nan")
    importance_trusted: bool = False  # reliable, and the round's check of the nested passed
    #: makes the estimate on first use (:meth:`importance_ceiling`); None once made
    pending: Callable[[], None] | None = field(default=None, repr=False)
    #: added parameters whose MAP lies on a bound of their prior (``map_fit.bound_pull``):
    #: {name: (side, nats the posterior falls over EDGE_SHARE of the width from it)}
    on_bound: dict[str, tuple[str, float]] = field(default_factory=dict)
    #: the candidate's problem and priors, as its fit and its estimate used them
    problem: object = field(default=None, repr=False)
    specs: dict[str, PriorSpec] = field(default_factory=dict, repr=False)
    #: the likelihood's smoothness about the MAP (``smoothness.Smoothness``), checked before
    #: TMCMC (``confirm.rough``); None where it was not
    smooth: object = None
    #: parameters on a bound where the term becomes its limits, which the round's screens
    #: tell it from (``limits.mark_apart``): a posterior piled there is still judged
    apart: tuple[str, ...] = ()

    @property
    def pulled(self) -> dict[str, tuple[str, float]]:
        """Those of ``on_bound`` whose posterior must pile against the bound (a fall above
        PILE_NATS), but for a bound where the term becomes limits it is told from
        (``apart``)."""
        return {n: v for n, v in self.on_bound.items()
                if v[1] > PILE_NATS and n not in self.apart}

    def importance_draws(self, n: int, seed: int) -> np.ndarray:
        """n draws of the candidate's posterior from its importance-sampling estimate
        (``importance.resample``): rows (free parameters..., sigma), sigma at sqrt(SSE / n) of
        each row, where eq. (10)'s likelihood peaks over sigma whatever its tempering."""
        coords = PriorCoordinates.of(self.problem, self.specs)
        theta = coords.theta(resample(self.importance, n, np.random.default_rng(seed)))
        unique, inverse = np.unique(theta, axis=0, return_inverse=True)
        sse, ok = self.problem.residual_sums(np.column_stack([unique, np.ones(len(unique))]))
        sigma = np.sqrt(np.where(ok, sse, np.nan) / self.problem.n_data)
        return np.column_stack([theta, sigma[np.ravel(inverse)]])

    @property
    def beyond_band(self) -> dict[str, tuple[float, float]]:
        """The term's resonance frequencies (``Term.in_band``) whose best fit lies above the
        band the likelihood compares: name -> (MAP, band top), Hz. The confirmation would not
        name the term with its posterior there (``limits.beyond_band``), so its sampling
        would buy no name."""
        if self.problem is None:
            return {}
        return above_band(self.effect, self.names,
                          lambda n: self.theta[self.names.index(n)],
                          lambda: self.problem.band_hz)

    def pull_phrase(self, bounds: dict[str, tuple[str, float]] | None = None) -> str:
        """``bounds`` (default ``pulled``) in words, for logs and the reasons a candidate
        was not sampled."""
        return ", ".join(f"{n} on its {side} bound, the posterior {drop:.1f} nats lower "
                         f"{EDGE_SHARE:.0%} of the prior's width inside"
                         for n, (side, drop) in (self.pulled if bounds is None
                                                 else bounds).items())

    def importance_ceiling(self, mc_sigmas: float) -> float | None:
        """The most evidence the importance-sampling estimate lets this candidate gain
        (gain + mc_sigmas se + IMPORTANCE_SLACK, nats); None where it is not trusted. The
        estimate is made here, on first use: only candidates the bound leaves open pay its
        thousand-odd simulations."""
        if self.pending is not None:
            job, self.pending = self.pending, None
            job()
        if not self.importance_trusted:
            return None
        return self.importance_gain + mc_sigmas * self.importance_gain_se + IMPORTANCE_SLACK

    def importance_phrase(self) -> str:
        """The estimate in words, for logs and the reasons a candidate was not sampled."""
        if self.importance is None:
            return "no importance-sampling estimate (no prior of sigma)"
        est = self.importance
        return (f"importance sampling puts its evidence gain at {self.importance_gain:.2f} +- "
                f"{self.importance_gain_se:.2f} nats (Pareto k {est.pareto_k:.2f}, ESS "
                f"{est.ess:.0f} of {est.draws}{'' if self.importance_trusted else ', not trusted'})")

    def to_dict(self) -> dict:
        added = term(self.effect).parameter_names
        return {"effect": self.effect, "max_log_likelihood": self.max_loglike,
                "evidence_gain_bound": self.bound,
                "evidence_gain_strict_bound": self.strict_bound, "map_failed": self.failed,
                "laplace_evidence_gain": self.laplace_gain,
                "map": {n: float(v) for n, v in zip(self.names, self.theta) if n in added},
                "simulations": self.simulations, "seconds": self.seconds,
                "importance_sampling": None if self.importance is None else {
                    **self.importance.to_dict(), "evidence_gain": self.importance_gain,
                    "evidence_gain_se": self.importance_gain_se,
                    "trusted": self.importance_trusted},
                "map_on_bound": {n: {"side": side, "drop_nats": drop,
                                     "posterior_must_pile": drop > PILE_NATS}
                                 for n, (side, drop) in self.on_bound.items()},
                "smoothness": None if self.smooth is None else self.smooth.to_dict(),
                "map_beyond_band_hz": {n: {"map": x, "band_top": b}
                                       for n, (x, b) in self.beyond_band.items()},
                "sampled": self.sampled, "skipped": self.skipped}


@dataclass
class Screen:
    """The screened candidates of one round, largest bound first (failed fits last)."""

    candidates: list[Screened] = field(default_factory=list)
    nested_loglike: float = float("nan")  # the nested model's best: its MAP or posterior mean
    nested_value: float = float("nan")  # its best log L plus log prior (``fit_value``)
    nested_laplace: float = float("nan")  # the nested model's Laplace log evidence
    #: the nested model's log evidence by importance sampling, the check of the estimator
    nested_importance: ImportanceEstimate | None = None
    importance_check: bool = False  # that estimate agrees with the nested model's sampled one
    unscreened: list[str] = field(default_factory=list)  # not fitted: the time budget ran out
    stopped: str | None = None  # the effect whose MAP fit the budget ended mid-way

    @property
    def order(self) -> list[str]:
        return [s.effect for s in self.candidates]


def max_loglike(problem, theta: np.ndarray) -> float:
    """The tempered log-likelihood at ``theta`` (free parameters, sigma ignored) with sigma
    at its maximum, sqrt(SSE / n) (nats; -inf where the simulation fails)."""
    return _profiled(problem, theta)[0]


def _profiled(problem, theta: np.ndarray) -> tuple[float, float]:
    """(max log L over sigma, that sigma) at the free parameters of ``theta``: one
    simulation (:func:`profiled_rows`)."""
    free = np.asarray(theta, dtype=float)[:len(problem.structure.free_parameters)]
    ll, sigma = profiled_rows(problem, free[None, :])
    return float(ll[0]), float(sigma[0])


def profiled_rows(problem, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(max log L over sigma, that sigma) per row of free parameters, one batch of
    simulations (``Problem.profiled_loglike``); -inf and nan where a simulation fails."""
    theta = np.atleast_2d(np.asarray(theta, dtype=float))
    sse, ok = problem.residual_sums(np.column_stack([theta, np.ones(len(theta))]))
    good = ok & np.isfinite(sse) & (sse > 0.0)
    ll, sigma = np.full(len(theta), -np.inf), np.full(len(theta), np.nan)
    ll[good] = problem.profiled_loglike(sse[good])
    sigma[good] = np.sqrt(sse[good] / problem.n_data)
    return ll, sigma


def fit_value(problem, theta: np.ndarray, priors: Mapping[str, PriorSpec],
              names: tuple[str, ...]) -> tuple[float, float]:
    """(max log L over sigma, that plus the log prior densities of ``names`` (sigma among
    them) at ``theta``): what ``Screened.bound`` compares, the likelihood and the prior of
    the parameters both models share (a candidate that moves them back from a prior
    conflict gains that too)."""
    ll, sigma = _profiled(problem, theta)
    values = dict(zip(problem.parameter_names, [*np.asarray(theta)[:-1], sigma]))
    return ll, ll + float(sum(priors[n].logpdf(values[n]) for n in names))


def screen(nested: ModelFit, effects: list[str], priors: Mapping[str, PriorSpec],
           scale: DeviceScale, detection: Detection | None = None, seed: int = 0,
           stop: Callable[[], bool] | None = None) -> Screen:
    """Each effect's MAP on the nested model's data and likelihood and its bounds, sorted by
    ``bound`` (failed fits last). ``stop``: asked before each effect's fit and each of its
    simulations; once it says so (the time budget is spent) the fit under way ends
    (``Screen.stopped``) and the effects left are not fitted (``Screen.unscreened``)."""
    nested_mean = nested.samples.mean(axis=0)
    point = fit_map(nested.problem, nested.priors, seed=seed, start=nested_mean[:-1])
    names = nested.names
    fits = [fit_value(nested.problem, th, nested.priors, names)
            for th in (nested_mean, point.theta)]
    out = Screen(nested_loglike=max(ll for ll, _ in fits),
                 nested_value=max(v for _, v in fits),
                 nested_laplace=point.log_evidence_laplace)
    check_estimator(out, nested, point, seed)
    return screen_more(out, nested, effects, priors, scale, detection, seed, stop)


def screen_more(out: Screen, nested: ModelFit, effects: list[str],
                priors: Mapping[str, PriorSpec], scale: DeviceScale,
                detection: Detection | None = None, seed: int = 0,
                stop: Callable[[], bool] | None = None) -> Screen:
    """``effects`` screened into ``out`` (a round's ``Screen`` on ``nested``), as
    :func:`screen` does, its candidates sorted again by bound."""
    nested_mean = nested.samples.mean(axis=0)
    for i, effect in enumerate(effects):
        if stop is not None and stop():
            out.unscreened += list(effects[i:])
            log.info("not screened, the time budget is spent: %s", ", ".join(effects[i:]))
            break
        try:
            out.candidates.append(_screen_one(nested, effect, priors, scale, detection, seed,
                                              nested_mean, out, stop))
        except FitStopped:
            out.unscreened, out.stopped = out.unscreened + list(effects[i:]), effect
            log.info("%s: its MAP fit stopped, the time budget is spent; not screened: %s",
                     effect, ", ".join(effects[i:]))
            break
    out.candidates.sort(key=lambda s: (s.failed, -s.bound))
    log.info("screened by MAP (nested: log evidence %.1f, best log L %.1f, Laplace %.1f): %s",
             nested.log_evidence, out.nested_loglike, out.nested_laplace, "; ".join(
                 f"{s.effect} {'failed' if s.failed else f'gain <= {s.bound:.1f}'} (Laplace "
                 f"{s.laplace_gain:+.1f}, {s.seconds:.1f} s)" for s in out.candidates))
    return out


def check_estimator(out: Screen, nested: ModelFit, point: PointFit, seed: int) -> None:
    """The importance-sampling estimate of the nested model's evidence against its sampled
    one: the round trusts the estimator only where they agree within IMPORTANCE_SLACK plus
    two standard errors."""
    est = importance_evidence(nested.problem, nested.priors, point, nested, seed)
    out.nested_importance = est
    if est is None:
        return
    gap = est.log_evidence - nested.log_evidence
    allowed = IMPORTANCE_SLACK + 2.0 * float(np.hypot(est.se, nested.log_evidence_se))
    out.importance_check = bool(est.reliable and abs(gap) <= allowed)
    log.info("importance sampling of %s: log evidence %.2f +- %.2f (Pareto k %.2f, ESS %.0f "
             "of %d) against %.2f sampled: %s", nested.structure.name, est.log_evidence,
             est.se, est.pareto_k, est.ess, est.draws, nested.log_evidence,
             "trusted this round" if out.importance_check else "not trusted this round")


def importance_evidence(problem, specs: Mapping[str, PriorSpec], point: PointFit,
                        nested: ModelFit, seed: int) -> ImportanceEstimate | None:
    """log evidence of ``problem`` (tempered eq. (10), sigma integrated out) by importance
    sampling from the mixture of ``_components`` and the prior, in prior coordinates; None
    without a prior of sigma."""
    if "sigma" not in specs:
        return None
    coords = PriorCoordinates.of(problem, specs)
    comps = _components(coords, problem.structure.free_parameters, point, nested)
    scale = (1.0 - IMPORTANCE_WEIGHTS[2]) / max(sum(c.weight for c in comps), 1e-300)
    comps = tuple(replace(c, weight=c.weight * scale) for c in comps)
    proposal = MixtureProposal(coords.log_prior, coords.draw, comps,
                               1.0 - sum(c.weight for c in comps))
    sigma_logpdf = specs["sigma"].logpdf

    def log_target(u: np.ndarray) -> np.ndarray:
        lp = coords.log_prior(u).sum(axis=1)
        out = np.full(len(u), -np.inf)
        ok = np.isfinite(lp)
        if ok.any():
            theta = np.column_stack([coords.theta(u[ok]), np.ones(int(ok.sum()))])
            sse, good = problem.residual_sums(theta)
            out[ok] = lp[ok] + sigma_marginal_loglike(np.where(good, sse, np.nan),
                                                      problem.n_data, problem.temper,
                                                      sigma_logpdf)
        return out

    return importance_log_evidence(log_target, proposal, IMPORTANCE_DRAWS,
                                   np.random.default_rng(seed), adapt=IMPORTANCE_ADAPT)


def _components(coords: PriorCoordinates, names: tuple[str, ...], point: PointFit,
                nested: ModelFit) -> list[Component]:
    """The mixture's Gaussians in u: the MAP with its Laplace covariance, and the nested
    posterior over the parameters it shares (the others from their prior); sds widened by
    IMPORTANCE_WIDEN. One that is not finite or not positive definite is left out."""
    out = []
    u_map = coords.u(point.theta[:-1])
    d = coords.dtheta_du(u_map)
    cov = np.asarray(point.cov, dtype=float) / np.outer(d, d) * IMPORTANCE_WIDEN**2
    out.append(Component(tuple(range(len(names))), u_map, cov, IMPORTANCE_WEIGHTS[0]))
    shared = [j for j, n in enumerate(names) if n in nested.names]
    sub = PriorCoordinates(tuple(coords.specs[j] for j in shared))
    u_nested = sub.u_rows(nested.samples[:, [nested.names.index(names[j]) for j in shared]])
    u_nested = u_nested[np.all(np.isfinite(u_nested), axis=1)]
    if len(u_nested) > 2 * len(shared):
        cov = np.atleast_2d(np.cov(u_nested, rowvar=False)) * IMPORTANCE_WIDEN**2
        out.append(Component(tuple(shared), u_nested.mean(axis=0), cov,
                             IMPORTANCE_WEIGHTS[1]))
    return [c for c in out if _usable(c)]


def _usable(c: Component) -> bool:
    if not (np.all(np.isfinite(c.mean)) and np.all(np.isfinite(c.cov))):
        return False
    try:
        c.distribution()
    except (ValueError, np.linalg.LinAlgError):
        return False
    return True


def _screen_one(nested: ModelFit, effect: str, priors: Mapping[str, PriorSpec],
                scale: DeviceScale, detection: Detection | None, seed: int,
                nested_mean: np.ndarray, so_far: Screen,
                stop: Callable[[], bool] | None = None) -> Screened:
    """One candidate's MAP and bounds against the nested model (``so_far``: its best
    likelihood and Laplace evidence); ``stop`` ends its MAP fit (:class:`FitStopped`)."""
    clock = time.perf_counter()
    p = nested.problem
    problem = chain_problem(p, p.temper, p.lowpass_hz, p.filter_order,
                            structure=nested.structure.with_term(effect))
    specs = {**candidate_priors(effect, scale, p.known), **priors}
    starts = _starts(problem, specs, nested, nested_mean, effect, detection, seed)
    fit = fit_map(problem, specs, seed=seed, start=starts, solves=MAP_SOLVES, stop=stop)
    ll, value = fit_value(problem, fit.theta, {**specs, **nested.priors}, nested.names)
    gain = value - so_far.nested_value
    out = Screened(effect, problem.parameter_names, fit.theta, ll, gain + GAIN_SLACK,
                   ll - nested.log_evidence, not gain >= -GAIN_SLACK, fit.n_simulations,
                   0.0, fit.log_evidence_laplace - so_far.nested_laplace, point=fit,
                   problem=problem, specs=specs)
    out.on_bound = bound_pull(problem, specs, fit, term(effect).parameter_names, EDGE_SHARE)
    out.seconds = time.perf_counter() - clock

    def estimate() -> None:
        clock = time.perf_counter()
        est = importance_evidence(problem, specs, fit, nested, seed)
        if est is not None:
            out.importance = est
            out.importance_gain = est.log_evidence - nested.log_evidence
            out.importance_gain_se = float(np.hypot(est.se, nested.log_evidence_se))
            out.importance_trusted = bool(so_far.importance_check and est.reliable)
        out.seconds += time.perf_counter() - clock
        log.info("%s: %s (%.1f s)", effect, out.importance_phrase(),
                 time.perf_counter() - clock)

    out.pending = estimate
    return out


def _starts(problem, specs: Mapping[str, PriorSpec], nested: ModelFit, nested_mean: np.ndarray,
            effect: str, detection: Detection | None, seed: int) -> np.ndarray:
    """Rows of free parameters: the nested posterior's mean for the shared parameters, the
    added ones from prior draws and, for a start shape, at the scan's heaviest values."""
    names = problem.structure.free_parameters
    coords = PriorCoordinates.of(problem, specs)
    rng = np.random.default_rng(seed)
    u = rng.standard_normal((ADDED_STARTS, len(names)))
    low, high = coords.bounds()
    flat = coords.penalty == 0.0
    u[:, flat] = rng.uniform(np.maximum(low, -3.0), np.minimum(high, 3.0),
                             u.shape)[:, flat]
    rows = coords.theta(np.clip(u, low + 1e-6, high - 1e-6))
    shared = {n: float(v) for n, v in zip(nested.names, nested_mean)}
    for j, n in enumerate(names):
        if n in shared:
            rows[:, j] = shared[n]
    scan = scan_factor(effect, detection, priors_for(problem, specs, names))
    if scan is not None:
        heaviest = np.asarray(scan.centres)[np.argsort(scan.weights)[::-1][:SCAN_STARTS]]
        extra = np.repeat(rows[:1], len(heaviest), axis=0)
        for row, value in zip(extra, heaviest):
            scanned_start(row, names, specs, effect, detection, scan.name, value)
        rows = np.vstack([extra, rows])
    return rows


def scanned_start(row: np.ndarray, names: list[str], specs: Mapping[str, PriorSpec],
                  effect: str, detection: Detection, name: str, value: float) -> None:
    """Set ``row`` where the detection's best signature with ``name`` = ``value`` lies: its
    whole shape (a mode's damping and drive beside its frequency) and the strength the score
    estimates, inside the prior. A sharp mode (zeta 0.02 at 11.4 Hz) started at its scanned
    frequency with a damping drawn from the prior was fitted at 228 Hz instead."""
    idx = [i for i, sig in enumerate(detection.signatures)
           if sig.effect == effect and sig.shape.get(name) == value]
    best = max(idx, key=lambda i: detection.z[i])
    sig = detection.signatures[best]
    score = next((c for c in detection.candidates if c.effect == effect), None)
    start = {**sig.shape, sig.strength: score.strength if score and score.strength > 0
             else sig.amount}
    for key, v in start.items():  # fit_map's start moves a bound value just inside
        if key in names:
            row[names.index(key)] = np.clip(v, specs[key].lower, specs[key].upper)
