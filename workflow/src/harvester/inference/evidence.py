"""Model evidence from posterior samples by bridge sampling (Meng & Wong 1996).

TMCMC estimates the evidence of eq. (11) as a product of stage means; its error comes from
every stage and, with few particles and few Metropolis moves, from how far each stage's
population is from its tempered density (two chains of the same 4-parameter model differed
by 5.7 nats with 150 particles on a 30 s record). Bridge sampling re-estimates the same
integral, Z = int p(theta) L(theta) dtheta, from the final posterior population alone:

    Z = E_q[ p L alpha ] / E_post[ q alpha ],

q a Gaussian fitted to the posterior samples, alpha the optimal bridge function
1 / (s1 p L + s2 Z q), solved by the fixed-point iteration of Meng & Wong (1996, eq. 4.1).
It needs N2 more likelihood evaluations (draws from q), fewer than one TMCMC stage, and its
relative mean squared error (Fruhwirth-Schnatter 2004, eq. 15; Gronau et al. 2017) is
estimated from the same evaluations, the posterior samples' share counted by their
effective number (resampled populations hold duplicates). With several chains the error is
also read off the chains' own estimates (``chains_bridge_log_evidence``): the formula trusts
the population to be a posterior sample, which a short TMCMC run need not give.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

import numpy as np
from scipy.special import logsumexp

from harvester.inference.priors import PriorSpec

#: Iterations of the fixed point, and its tolerance on log Z.
MAX_ITER = 1000
TOL = 1e-10


@dataclass(frozen=True)
class BridgeEstimate:
    """log Z with its standard error (nats) and what it used: ``formula_se`` from the relative
    MSE; with several chains, ``chain_log_evidence`` holds each chain's own estimate and
    ``se`` is the larger of the formula's and the chains' scatter over sqrt(chains)."""

    log_evidence: float
    se: float
    n_posterior: int
    n_effective: float
    n_proposal: int
    iterations: int
    formula_se: float = float("nan")
    chain_log_evidence: tuple[float, ...] = ()

    def to_dict(self) -> dict:
        return {"log_evidence": self.log_evidence, "se": self.se,
                "formula_se": self.formula_se,
                "chain_log_evidence": list(self.chain_log_evidence),
                "n_posterior": self.n_posterior, "n_effective": self.n_effective,
                "n_proposal": self.n_proposal}


def effective_count(samples: np.ndarray) -> float:
    """N^2 / sum(c_k^2), c_k the multiplicities of the distinct rows (N for distinct rows)."""
    _, counts = np.unique(np.asarray(samples), axis=0, return_counts=True)
    return float(counts.sum() ** 2 / np.sum(counts.astype(float) ** 2))


def gaussian_logpdf(x: np.ndarray, mean: np.ndarray, chol: np.ndarray) -> np.ndarray:
    """Log density of N(mean, L L^T) at the rows of x."""
    z = np.linalg.solve(chol, (x - mean).T)
    half_logdet = np.sum(np.log(np.diag(chol)))
    d = len(mean)
    return -0.5 * np.sum(z * z, axis=0) - half_logdet - 0.5 * d * np.log(2.0 * np.pi)


def _cholesky(cov: np.ndarray) -> np.ndarray:
    """Cholesky factor with jitter on the correlation matrix (parameters of a diagnosis span
    sigma ~ 0.02 to contact stiffnesses ~ 1e6: a jitter scaled by the mean variance, as
    ``tmcmc``'s proposal uses, would swamp the small ones)."""
    scale = np.sqrt(np.maximum(np.diag(cov), 1e-300))
    corr = cov / np.outer(scale, scale)
    for jitter in (0.0, 1e-10, 1e-8, 1e-6, 1e-4):
        try:
            return scale[:, None] * np.linalg.cholesky(corr + jitter * np.eye(len(cov)))
        except np.linalg.LinAlgError:
            continue
    raise np.linalg.LinAlgError("posterior sample covariance is not positive definite")


def bridge_iterate(l1: np.ndarray, l2: np.ndarray) -> tuple[float, int]:
    """log r solving Meng & Wong's fixed point; l1 = log(pL/q) at the posterior samples, l2
    at the proposal draws (-inf allowed where pL = 0)."""
    n1, n2 = len(l1), len(l2)
    ls1, ls2 = np.log(n1 / (n1 + n2)), np.log(n2 / (n1 + n2))
    log_r = float(np.median(l1[np.isfinite(l1)]))
    for it in range(1, MAX_ITER + 1):
        num = logsumexp(l2 - np.logaddexp(ls1 + l2, ls2 + log_r)) - np.log(n2)
        den = logsumexp(-np.logaddexp(ls1 + l1, ls2 + log_r)) - np.log(n1)
        new = float(num - den)
        if abs(new - log_r) < TOL:
            return new, it
        log_r = new
    return log_r, MAX_ITER


def relative_mse(l1: np.ndarray, l2: np.ndarray, log_z: float, n1_eff: float) -> float:
    """Fruhwirth-Schnatter's (2004) relative MSE of the bridge estimate (nats^2 for small
    errors): var(f1) / (N2 mean(f1)^2) + var(f2) / (N1_eff mean(f2)^2)."""
    n1, n2 = len(l1), len(l2)
    s1, s2 = n1 / (n1 + n2), n2 / (n1 + n2)
    # f1 = p_g / (s1 p_g + s2 q_g) at the proposal draws, f2 = q_p / (s1 p_p + s2 q_p) at the
    # posterior samples, with p = pL / Z: both in [0, 1 / s], computed from the log ratios
    with np.errstate(over="ignore"):
        f1 = 1.0 / (s1 + s2 * np.exp(log_z - l2))
        f2 = 1.0 / (s1 * np.exp(l1 - log_z) + s2)
    f1 = np.where(np.isfinite(l2), f1, 0.0)
    f2 = np.where(np.isfinite(l1), f2, 1.0 / s2)
    return float(np.var(f1) / (n2 * np.mean(f1) ** 2) + np.var(f2) / (n1_eff * np.mean(f2) ** 2))


def split_samples(x: np.ndarray, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """(rows to fit q on, rows for the estimator): the distinct rows split at random in two
    halves, each row with all its duplicates. Fitting q on the
    samples the estimator uses makes q too tight and log Z low by about d / N (measured:
    -0.07 nats, 3.5 stated standard errors, for d = 4 and 150 distinct of 300 rows)."""
    _, first, inverse = np.unique(x, axis=0, return_index=True, return_inverse=True)
    inverse = inverse.reshape(-1)
    to_fit = rng.permutation(len(first))[: len(first) // 2]
    mask = np.isin(inverse, to_fit)
    return x[mask], x[~mask]


def bridge_log_evidence(log_target: Callable[[np.ndarray], np.ndarray], samples: np.ndarray,
                        rng: np.random.Generator, n_proposal: int | None = None
                        ) -> BridgeEstimate:
    """Bridge-sampling estimate of log Z = log int exp(log_target) from posterior ``samples``.

    ``log_target``: log prior density (normalised) + log-likelihood at the rows of an array,
    -inf where the prior or the simulation fails (evaluated at the estimator's half of the
    samples and at the proposal draws only); ``samples``: rows drawn from the normalised
    target (duplicates allowed); ``n_proposal``: draws from the fitted Gaussian (default: as
    many as the estimator's half of the samples).
    """
    x = np.asarray(samples, dtype=float)
    if x.ndim != 2 or len(np.unique(x, axis=0)) < 2 * x.shape[1] + 4:
        raise ValueError(f"need at least 2 d + 4 distinct posterior rows of d parameters "
                         f"(half fit the proposal), got {x.shape}")
    fit, x = split_samples(x, rng)
    t1 = np.asarray(log_target(x), dtype=float)
    mean = fit.mean(axis=0)
    chol = _cholesky(np.cov(fit, rowvar=False).reshape(x.shape[1], x.shape[1]))
    n2 = int(n_proposal or len(x))
    draws = mean + rng.standard_normal((n2, x.shape[1])) @ chol.T
    t2 = np.asarray(log_target(draws), dtype=float)
    t1 = np.where(np.isnan(t1), -np.inf, t1)
    t2 = np.where(np.isnan(t2), -np.inf, t2)
    if not np.any(np.isfinite(t1)):
        raise ValueError("the target is -inf at every posterior sample")
    l1 = t1 - gaussian_logpdf(x, mean, chol)
    l2 = t2 - gaussian_logpdf(draws, mean, chol)
    log_z, iterations = bridge_iterate(l1, l2)
    n_eff = effective_count(x)
    se = float(np.sqrt(max(relative_mse(l1, l2, log_z, n_eff), 0.0)))
    return BridgeEstimate(log_z, se, len(x), n_eff, n2, iterations, formula_se=se)


def chains_bridge_log_evidence(log_target: Callable[[np.ndarray], np.ndarray],
                               chains: Sequence[np.ndarray], rng: np.random.Generator,
                               missed_mode_nats: float = np.inf) -> BridgeEstimate:
    """The bridge estimate from the pooled chains, its error checked against the chains'.

    Each chain is estimated on its own first; a chain whose own estimate lies more than
    ``missed_mode_nats`` below the best chain's missed the posterior's main mode (its rows
    carry the wrong weight) and is left out. The rest are pooled. The relative MSE assumes
    the rows are draws from the posterior; a population that has not settled (few
    particles, few Metropolis moves, a posterior piled against a bound) breaks that, and the
    formula then understates the error (measured: per-chain estimates scattering by 0.9 nats
    with a stated 0.08, 4 chains of 150 particles of the tanh model with Coulomb friction).
    So ``se`` is the larger of the pooled formula's and sd(chain estimates) / sqrt(chains).
    """
    own: list[float | None] = []
    for rows in chains if len(chains) > 1 else []:
        try:
            own.append(bridge_log_evidence(log_target, rows, rng).log_evidence)
        except (ValueError, np.linalg.LinAlgError):
            own.append(None)
    found = [e for e in own if e is not None]
    keep = list(chains)
    if found:
        best = max(found)
        keep = [rows for rows, e in zip(chains, own) if e is None or e >= best - missed_mode_nats]
        found = [e for e in found if e >= best - missed_mode_nats]
    pooled = bridge_log_evidence(log_target, np.vstack(keep), rng)
    scatter = float(np.std(found, ddof=1) / np.sqrt(len(found))) if len(found) > 1 else 0.0
    return replace(pooled, se=max(pooled.formula_se, scatter), chain_log_evidence=tuple(found))


def log_target(loglike: Callable[[np.ndarray], np.ndarray], priors: Sequence[PriorSpec]
               ) -> Callable[[np.ndarray], np.ndarray]:
    """theta -> sum of the priors' log densities (truncated Gaussians, normalised) + log L,
    the integrand of eq. (11) in logs; columns of theta in the order of ``priors``."""
    def target(theta: np.ndarray) -> np.ndarray:
        theta = np.atleast_2d(theta)
        lp = np.sum([spec.logpdf(theta[:, j]) for j, spec in enumerate(priors)], axis=0)
        out = np.full(len(theta), -np.inf)
        ok = np.isfinite(lp)
        if np.any(ok):
            out[ok] = lp[ok] + np.asarray(loglike(theta[ok]), dtype=float)
        return out
    return target
