"""Screen candidate effects by their best fit before sampling them: how much evidence each
can gain, and the order in which they are sampled.

Two ceilings on the log Bayes factor of the nested model plus one effect against the nested
model, both from the candidate's posterior mode (``baseline.fit_map``; sigma^2 = SSE / n
maximises eq. (10) over sigma) under the same tempered likelihood (``baseline.ChainProblem``)
as the nested model's sampled evidence:

* strict: for a prior that integrates to one, Z = int L pi <= max L, so the gain is at most
  max log L_candidate - log Z_nested. It exceeds the true gain by the nested model's Occam
  factor as well as the candidate's (tens of nats), too loose to rule out anything in a
  second round.
* ``bound``: the likelihood gain, max log L_candidate - max log L_nested, plus GAIN_SLACK. In
  the Laplace picture log Z = max log L - Occam, and the candidate's Occam factor is the
  nested one's (its shared parameters at fixed added ones) plus that of the added
  parameters, -log(pi(phi_hat) sqrt(det 2 pi Sigma_phi)), which is not negative while their
  posterior is no wider than their prior (an added parameter the data leave at its prior
  costs nothing, and gains nothing). So the evidence gain does not exceed the likelihood
  gain, to within the Laplace picture's error, which GAIN_SLACK allows for.

A candidate whose ``bound`` lies below the acceptance threshold cannot be accepted, and one
whose bound lies below the best accepted gain minus the naming margin cannot tie with it
(``confirm.skip_reason``): neither needs TMCMC. The bound misleads where the MAP misses the
best fit: the fit starts from the best of the nested posterior's mean joined with prior draws
of the added parameters and, for a start shape (a mode's frequency), the detection's scan; a
fit below the nested model's best likelihood (impossible at the optimum of a model that
contains the nested one) is marked ``failed`` and never screened out. Each candidate's
Laplace log evidence (``baseline.laplace_log_evidence``) minus the nested model's is reported
beside it.

The linearised ranking (``rank``) chooses which candidates are fitted; ``bound`` orders them.
On grid records the two disagreed on 2 of 3 (``benchmarks/bench_ranking.py``).
"""

from __future__ import annotations

import logging
import time
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from harvester.diagnosis.baseline import PointFit, PriorCoordinates, chain_problem, fit_map
from harvester.diagnosis.confirm import ModelFit, candidate_priors, scan_factor
from harvester.diagnosis.detect import Detection
from harvester.inference.priors import PriorSpec, priors_for
from harvester.model.priors import DeviceScale
from harvester.model.terms import term

log = logging.getLogger("harvester.diagnosis")

#: Prior draws of the added parameters joined with the nested posterior's mean as starts.
ADDED_STARTS = 24
#: Scanned values of a start shape (heaviest first) joined with the nested mean as starts.
SCAN_STARTS = 3
#: Nats allowed between the MAP's likelihood and the largest one (the MAP trades a little
#: likelihood for prior density where the prior is not flat), and for the Laplace picture's
#: error in ``bound``.
GAIN_SLACK = 1.0


@dataclass
class Screened:
    """One candidate's best fit and the most evidence it can gain over the nested model."""

    effect: str
    names: tuple[str, ...]
    theta: np.ndarray  # the MAP (free parameters..., sigma)
    max_loglike: float  # tempered log L at the MAP, sigma profiled (nats)
    bound: float  # likelihood gain over the nested model's best + GAIN_SLACK (nats)
    strict_bound: float  # max log L - the nested model's log evidence (nats)
    failed: bool  # the fit fell below the nested model's best likelihood
    simulations: int
    seconds: float
    laplace_gain: float = float("nan")  # Laplace log evidence minus the nested model's (nats)
    skipped: str | None = None  # why it was not sampled (None: sampled, or not reached)
    sampled: bool = False
    point: PointFit | None = field(default=None, repr=False)  # the MAP, its Laplace covariance

    def to_dict(self) -> dict:
        added = term(self.effect).parameter_names
        return {"effect": self.effect, "max_log_likelihood": self.max_loglike,
                "evidence_gain_bound": self.bound,
                "evidence_gain_strict_bound": self.strict_bound, "map_failed": self.failed,
                "laplace_evidence_gain": self.laplace_gain,
                "map": {n: float(v) for n, v in zip(self.names, self.theta) if n in added},
                "simulations": self.simulations, "seconds": self.seconds,
                "sampled": self.sampled, "skipped": self.skipped}


@dataclass
class Screen:
    """The screened candidates of one round, largest bound first (failed fits last)."""

    candidates: list[Screened] = field(default_factory=list)
    nested_loglike: float = float("nan")  # the nested model's best: its MAP or posterior mean
    nested_laplace: float = float("nan")  # the nested model's Laplace log evidence

    @property
    def order(self) -> list[str]:
        return [s.effect for s in self.candidates]


def max_loglike(problem, theta: np.ndarray) -> float:
    """The tempered log-likelihood at ``theta`` (free parameters, sigma ignored) with sigma
    at its maximum, sqrt(SSE / n) (nats; -inf where the simulation fails)."""
    row = np.append(np.asarray(theta, dtype=float)[:len(problem.structure.free_parameters)],
                    1.0)[None, :]
    sse, ok = problem.residual_sums(row)
    if not ok[0] or not np.isfinite(sse[0]) or sse[0] <= 0.0:
        return -np.inf
    row[0, -1] = np.sqrt(sse[0] / problem.n_data)
    return float(problem.loglike(row)[0])


def screen(nested: ModelFit, effects: list[str], priors: Mapping[str, PriorSpec],
           scale: DeviceScale, detection: Detection | None = None, seed: int = 0) -> Screen:
    """Each effect's MAP on the nested model's data and likelihood and its bounds, sorted by
    ``bound`` (failed fits last)."""
    nested_mean = nested.samples.mean(axis=0)
    point = fit_map(nested.problem, nested.priors, seed=seed, start=nested_mean[:-1])
    out = Screen(nested_loglike=max(max_loglike(nested.problem, nested_mean),
                                    max_loglike(nested.problem, point.theta)),
                 nested_laplace=point.log_evidence_laplace)
    for effect in effects:
        out.candidates.append(_screen_one(nested, effect, priors, scale, detection, seed,
                                          nested_mean, out))
    out.candidates.sort(key=lambda s: (s.failed, -s.bound))
    log.info("screened by MAP (nested: log evidence %.1f, best log L %.1f, Laplace %.1f): %s",
             nested.log_evidence, out.nested_loglike, out.nested_laplace, "; ".join(
                 f"{s.effect} {'failed' if s.failed else f'gain <= {s.bound:.1f}'} (Laplace "
                 f"{s.laplace_gain:+.1f}, {s.seconds:.1f} s)" for s in out.candidates))
    return out


def _screen_one(nested: ModelFit, effect: str, priors: Mapping[str, PriorSpec],
                scale: DeviceScale, detection: Detection | None, seed: int,
                nested_mean: np.ndarray, so_far: Screen) -> Screened:
    """One candidate's MAP and bounds against the nested model (``so_far``: its best
    likelihood and Laplace evidence)."""
    clock = time.perf_counter()
    p = nested.problem
    problem = chain_problem(p, p.temper, p.lowpass_hz, p.filter_order,
                            structure=nested.structure.with_term(effect))
    specs = {**candidate_priors(effect, scale, p.known), **priors}
    starts = _starts(problem, specs, nested, nested_mean, effect, detection, seed)
    fit = fit_map(problem, specs, seed=seed, start=starts)
    ll = max_loglike(problem, fit.theta)
    return Screened(effect, problem.parameter_names, fit.theta, ll,
                    ll - so_far.nested_loglike + GAIN_SLACK, ll - nested.log_evidence,
                    not ll >= so_far.nested_loglike - GAIN_SLACK, fit.n_simulations,
                    time.perf_counter() - clock,
                    fit.log_evidence_laplace - so_far.nested_laplace, point=fit)


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
        j = names.index(scan.name)
        heaviest = np.asarray(scan.centres)[np.argsort(scan.weights)[::-1][:SCAN_STARTS]]
        extra = np.repeat(rows[:1], len(heaviest), axis=0)
        extra[:, j] = heaviest
        rows = np.vstack([extra, rows])
    return rows
