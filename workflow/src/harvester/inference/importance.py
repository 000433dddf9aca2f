"""Evidence by importance sampling from a defensive Gaussian mixture, with its own check.

For a target L(u) p(u), p a prior that is a product over the coordinates u,

    Z = E_q[w],   w = L(u) p(u) / q(u),
    q(u) = a_0 p(u) + sum_k a_k N(u_S; m_k, C_k) p(u_rest),

each Gaussian component covering a subset S of the coordinates, the rest drawn from the
prior. The prior's share bounds the weights, w <= L / a_0 (Hesterberg 1995, defensive
importance sampling). log Z is estimated by log mean w, its standard error by the delta
method, sd(w) / (mean(w) sqrt(N)), and its reliability by the shape k of a generalised
Pareto distribution fitted to the largest weights (Vehtari, Simpson, Gelman, Yao and Gabry
2024, *Pareto smoothed importance sampling*, JMLR 25): below ``K_RELIABLE`` the estimate
converges at the usual rate and its stated error can be believed; above, it is not used.

No check sees a region of the posterior that the proposal never reaches: there log Z is
biased low. A user of the estimate must place components where the posterior can be (the
diagnosis's screen: a candidate's MAP, and the nested model's posterior with the added
parameters at their prior, where the added effect is absent).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace

import arviz as az
import numpy as np
from scipy import stats
from scipy.special import logsumexp

from harvester.inference.tmcmc import fit_gaussian_mixture

__all__ = ["Component", "ImportanceEstimate", "MixtureProposal", "importance_estimate",
           "importance_log_evidence", "resample"]

#: Pareto k below which an importance-sampling estimate is trusted (PSIS's threshold for
#: estimates of a mean, Vehtari et al. 2024, sec. 3).
K_RELIABLE = 0.7


@dataclass(frozen=True)
class Component:
    """N(mean, cov) over the coordinates ``columns``, with mixture weight ``weight``."""

    columns: tuple[int, ...]
    mean: np.ndarray
    cov: np.ndarray
    weight: float

    def distribution(self):
        """The normal, its covariance made positive definite: symmetrised, and eigenvalues
        below 1e-9 x the largest raised to that (a Laplace covariance from a Hessian that
        is not positive definite at a MAP fit's end has some below zero)."""
        cov = np.atleast_2d(np.asarray(self.cov, dtype=float))
        vals, vecs = np.linalg.eigh(0.5 * (cov + cov.T))
        vals = np.maximum(vals, 1e-9 * max(float(vals.max()), 1e-300))
        return stats.multivariate_normal(np.asarray(self.mean, dtype=float),
                                         (vecs * vals) @ vecs.T)


@dataclass(frozen=True)
class MixtureProposal:
    """q = prior_weight p + sum_k a_k (component k x p on the coordinates it leaves out).

    ``log_prior``: rows u (N, d) -> the prior's log density per coordinate (N, d), -inf
    outside its support; ``draw_prior``: (rng, n) -> n rows from the prior."""

    log_prior: Callable[[np.ndarray], np.ndarray]
    draw_prior: Callable[[np.random.Generator, int], np.ndarray]
    components: tuple[Component, ...]
    prior_weight: float

    def __post_init__(self) -> None:
        total = self.prior_weight + sum(c.weight for c in self.components)
        if not self.prior_weight > 0 or abs(total - 1.0) > 1e-9:
            raise ValueError(f"mixture weights must be positive with the prior's > 0 and sum "
                             f"to 1, got prior {self.prior_weight} and total {total}")

    def draw(self, rng: np.random.Generator, n: int) -> np.ndarray:
        """n rows of q."""
        weights = [self.prior_weight] + [c.weight for c in self.components]
        counts = rng.multinomial(n, weights)
        rows = [self.draw_prior(rng, int(counts[0]))]
        for c, k in zip(self.components, counts[1:]):
            part = self.draw_prior(rng, int(k))
            if k:
                part[:, list(c.columns)] = np.atleast_2d(
                    c.distribution().rvs(size=int(k), random_state=rng)).reshape(k, -1)
            rows.append(part)
        return np.vstack(rows)

    def log_density(self, u: np.ndarray) -> np.ndarray:
        """log q at rows u."""
        u = np.atleast_2d(u)
        lp = self.log_prior(u)
        terms = [np.log(self.prior_weight) + lp.sum(axis=1)]
        for c in self.components:
            rest = np.ones(u.shape[1], dtype=bool)
            rest[list(c.columns)] = False
            terms.append(np.log(c.weight) + c.distribution().logpdf(u[:, list(c.columns)])
                         + lp[:, rest].sum(axis=1))
        with np.errstate(invalid="ignore"):
            return logsumexp(np.column_stack(terms), axis=1)


@dataclass(frozen=True)
class ImportanceEstimate:
    """log Z (nats), its delta-method standard error, the Pareto k of the weights' tail,
    their effective sample size and the number of draws."""

    log_evidence: float
    se: float
    pareto_k: float
    ess: float
    draws: int
    #: the draws (rows of the proposal's coordinates) and their log weights, where kept
    u: np.ndarray | None = field(default=None, repr=False, compare=False)
    log_w: np.ndarray | None = field(default=None, repr=False, compare=False)

    @property
    def reliable(self) -> bool:
        return bool(np.isfinite(self.log_evidence) and self.pareto_k < K_RELIABLE)

    def to_dict(self) -> dict:
        return {"log_evidence": self.log_evidence, "se": self.se, "pareto_k": self.pareto_k,
                "ess": self.ess, "draws": self.draws, "reliable": self.reliable}


def importance_estimate(log_w: np.ndarray) -> ImportanceEstimate:
    """The estimate from log weights (-inf allowed: a draw outside the support or whose
    simulation failed)."""
    log_w = np.asarray(log_w, dtype=float)
    n = len(log_w)
    finite = np.isfinite(log_w)
    if finite.sum() < 2:
        return ImportanceEstimate(-np.inf, np.inf, np.inf, 0.0, n)
    top = log_w[finite].max()
    w = np.where(finite, np.exp(log_w - top), 0.0)
    mean = w.mean()
    se = float(w.std(ddof=1) / (mean * np.sqrt(n)))
    ess = float(w.sum() ** 2 / np.sum(w * w))
    return ImportanceEstimate(float(top + np.log(mean)), se, pareto_k(log_w), ess, n)


def smoothed_weights(est: ImportanceEstimate) -> tuple[np.ndarray, np.ndarray]:
    """(indices of ``est``'s draws with a finite weight, their Pareto-smoothed weights
    (ArviZ's PSIS), largest 1), so that a few large weights do not dominate."""
    keep = np.flatnonzero(np.isfinite(est.log_w))
    smoothed, _ = az.psislw(est.log_w[keep])
    return keep, np.exp(smoothed - smoothed.max())


def resample(est: ImportanceEstimate, n: int, rng: np.random.Generator) -> np.ndarray:
    """n rows of ``est``'s draws picked by their Pareto-smoothed weights: draws from the
    target as far as the estimate holds (its Pareto k)."""
    keep, w = smoothed_weights(est)
    return est.u[keep[rng.choice(len(keep), size=n, p=w / w.sum())]]


def pareto_k(log_w: np.ndarray) -> float:
    """Shape k of the generalised Pareto distribution fitted to the largest weights
    (ArviZ's PSIS); zero-weight draws enter as far below the smallest finite one."""
    log_w = np.asarray(log_w, dtype=float)
    finite = np.isfinite(log_w)
    floor = log_w[finite].min() - 50.0
    _, k = az.psislw(np.where(finite, log_w, floor))
    return float(np.asarray(k))


def importance_log_evidence(log_target: Callable[[np.ndarray], np.ndarray],
                            proposal: MixtureProposal, n: int, rng: np.random.Generator,
                            adapt: int = 0) -> ImportanceEstimate:
    """log Z of ``log_target`` (rows u -> log L + log p, -inf where it has no density) from
    n draws of ``proposal``; while the estimate is not reliable, at most ``adapt`` times, n
    new draws from the proposal joined with a Gaussian mixture fitted to the weighted draws
    (:func:`adapted`; population Monte Carlo, Cappe, Guillin, Marin and Robert 2004), the
    estimate then from the new draws alone."""
    est = _estimate(log_target, proposal, n, rng)
    for _ in range(adapt):
        if est.reliable or est.ess < 2.0:
            break
        proposal = adapted(proposal, est, rng)
        est = _estimate(log_target, proposal, n, rng)
    return est


def _estimate(log_target, proposal: MixtureProposal, n: int, rng: np.random.Generator
              ) -> ImportanceEstimate:
    u = proposal.draw(rng, n)
    log_q = proposal.log_density(u)
    with np.errstate(invalid="ignore"):
        log_w = np.asarray(log_target(u), dtype=float) - log_q
    log_w = np.where(np.isfinite(log_w), log_w, -np.inf)
    return replace(importance_estimate(log_w), u=u, log_w=log_w)


#: Share of an adapted proposal's non-prior weight that goes to the fitted mixture, its most
#: components and the widening of their sds.
ADAPT_SHARE, ADAPT_COMPONENTS, ADAPT_WIDEN = 0.6, 3, 2.0


def adapted(proposal: MixtureProposal, est: ImportanceEstimate,
            rng: np.random.Generator) -> MixtureProposal:
    """``proposal`` joined with a Gaussian mixture fitted to the draws of ``est`` (made
    from it) by their Pareto-smoothed weights (:func:`smoothed_weights`, so that a few large
    ones do not shrink it to a point; ``tmcmc.fit_gaussian_mixture``, sds widened by
    ADAPT_WIDEN), which takes ADAPT_SHARE of the weight that is not the prior's."""
    keep, w = smoothed_weights(est)
    u = est.u
    mix = fit_gaussian_mixture(u[keep], w, ADAPT_COMPONENTS, rng, widen=ADAPT_WIDEN)
    rest = 1.0 - proposal.prior_weight
    old = tuple(Component(c.columns, c.mean, c.cov, c.weight * (1.0 - ADAPT_SHARE))
                for c in proposal.components)
    columns = tuple(range(u.shape[1]))
    new = tuple(Component(columns, m, ch @ ch.T, float(a) * ADAPT_SHARE * rest)
                for a, m, ch in zip(mix.weights, mix.means, mix.chols))
    return MixtureProposal(proposal.log_prior, proposal.draw_prior, old + new,
                           proposal.prior_weight)
