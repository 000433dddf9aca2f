"""Transitional MCMC (Ching & Chen, 2007) as a PyMC SMC kernel, with batched likelihood calls.

Green et al. (2015) sample the posterior of each friction model with TMCMC and use its estimate
of the evidence P(D|M) (their eq. 11) to compare model structures (eq. 7, 12). TMCMC walks from
the prior to the posterior through tempered densities

    f_j(theta) ∝ p(theta | M) * p(D | theta, M) ** beta_j,      0 = beta_0 < beta_1 < ... = 1.

One stage of `TMCMC` (the order in which PyMC's ``sample_smc`` calls the methods):

``update_beta_and_weights``
    Choose beta_{j+1} by bisection so that the plausibility weights
    w_k = L(theta_k) ** (beta_{j+1} - beta_j) have coefficient of variation ``target_cov``
    (Ching & Chen: 100 %), capped at 1. The evidence gains the factor S_j = mean(w), so
    log_evidence = sum_j log S_j, computed in log space with logsumexp.
``resample``
    Draw N particles with probabilities w_k / sum(w). ``resampling="multinomial"`` (default) is
    Ching & Chen's choice: each particle is picked a multinomial number of times.
    ``"systematic"`` (PyMC's default) has lower resampling variance; both are unbiased.
``tune``
    Proposal covariance = proposal_scale**2 * the weighted sample covariance of the stage's
    particles (weights of this stage, computed before resampling; Ching & Chen's beta = 0.2).
``mutate``
    Metropolis moves of every particle, targeting f_{j+1}, in the model's value-variable
    (unconstrained) space: random-walk moves (covariance proposal_scale^2 x the stage's; where
    the mixture below has several components, each particle's own component's, with the
    Hastings term, ``component_steps``) in turn with independent moves proposed from a
    Gaussian mixture fitted to the stage, until the population has forgotten where the
    resampling put it: at least ``mcmc_steps`` moves, then more until the mean over
    dimensions of |corr(start, now)| across particles falls below ``correlation_threshold``,
    at most ``max_mcmc_steps`` (PyMC's SMC kernels count their steps on the same correlation;
    Betz, Papaioannou and Straub 2016 on why TMCMC's fixed chains leave the population
    correlated). At the last stage the moves also go on while the population's mean log
    posterior still rises (``still_rising``), up to FINAL_MOVES_FACTOR x ``max_mcmc_steps``:
    the posterior samples and the bridge estimate of the evidence read that population. Each
    move evaluates prior and likelihood of ALL N proposals in one call of a
    compiled, vectorised function.
``sample_stats``
    Per-stage statistics (``stats_dtypes_shapes``) and a progress line on the logger
    ``harvester.inference.tmcmc`` at INFO.

Tempering from a reference. With ``reference`` (`Reference`) the walk starts from a
distribution q that puts part of the population where other evidence (a residual's spectrum,
a nested model's posterior) places some free variables, instead of the prior, and follows
the geometric path

    f_j(theta) ∝ q(theta) ** (1 - beta_j) * (p(theta | M) * p(D | theta, M)) ** beta_j,

whose plausibility weights are w_k = (p L / q)(theta_k) ** (beta_{j+1} - beta_j). q is a
normalised density, so the same product of mean weights estimates the evidence, and the last
stage (beta = 1) targets the posterior as before. q = (1 - share) prior + share g is a
defensive mixture (``harvester.inference.reference``), so that the weights p / q stay below
1 / (1 - share). This is the reference-distribution path of stepping-stone sampling (Fan et
al. 2011): a model that nests another can start where the other's posterior lies, and a
posterior peak narrower than a few prior draws can hit (a resonance's frequency) can be found,
without changing the prior, the posterior or the evidence.

Precision of the evidence. Each stage's factor S_j = mean(w) is a mean over particles that
are not independent: the resampling made copies (families) and the Metropolis moves only
partly separate them. Its variance is estimated per stage as a cluster sample's, the
families the clusters (``stage_log_variance``): var(log S_j) ~ F / (F - 1) sum_f
(W_f - n_f mean(w))^2 / (N mean(w))^2, W_f the family's summed weight, n_f its size, F the
number of families; the first stage's particles are independent prior draws. A chain's
``log_evidence_se`` is the square root of the sum over stages; the benchmark
(``benchmarks/bench_tmcmc.py``) compares it with the spread of independent chains.

A NaN log-likelihood or log-prior is treated as -inf: such particles get zero weight and such
proposals are rejected, so one failed simulation never stops a run. If every particle of a stage
has zero likelihood the run stops with `TMCMCError`.

Use `run_tmcmc` for an `arviz.InferenceData` with tidy statistics (per-chain `log_evidence`,
tempering schedule, acceptance rates, likelihood evaluations, wall time).

Reference: J. Ching and Y.-C. Chen (2007), "Transitional Markov chain Monte Carlo method for
Bayesian model updating, model class selection, and model averaging", J. Eng. Mech. 133(7),
816-832.
"""

from __future__ import annotations

import logging
import time
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import arviz as az
import numpy as np
import pymc as pm
import pytensor
import pytensor.tensor as pt
import xarray as xr
from pymc.blocking import DictToArrayBijection
from pymc.logprob.utils import CheckParameterValue
from pymc.model import Model, modelcontext
from pymc.pytensorf import compile as pm_compile
from pymc.pytensorf import floatX, join_nonshared_inputs, make_shared_replacements
from pymc.smc.kernels import SMC_KERNEL, SMCSettings, SMCStats, systematic_resampling
from pymc.vartypes import discrete_types
from pytensor import shared
from pytensor.compile.mode import Mode
from pytensor.graph.basic import Variable
from pytensor.graph.replace import vectorize_graph
from pytensor.graph.traversal import toposort
from pytensor.tensor.random.type import RandomGeneratorType
from scipy.special import logsumexp

from harvester.inference.posterior import per_chain_stage_lists
from harvester.inference.reference import Reference

__all__ = [
    "Reference",
    "TMCMC",
    "TMCMCError",
    "FinishedChain",
    "OutOfTime",
    "compile_population_logp",
    "mean_abs_correlation",
    "next_beta",
    "plausibility_log_weights",
    "run_tmcmc",
    "stage_log_variance",
    "still_rising",
    "tidy_sample_stats",
    "weighted_covariance",
    "weights_cov",
]

logger = logging.getLogger("harvester.inference.tmcmc")

RESAMPLING_SCHEMES = ("multinomial", "systematic")
#: The independent proposals' covariances are the fitted mixture's widened by this factor.
IMH_WIDEN = 1.2
#: Independent proposals accepting less than this share are dropped for the rest of a stage.
IMH_MIN_ACCEPT = 0.05
#: At the last stage (beta = 1) the moves go on, up to this many times ``max_mcmc_steps``,
#: while the population's mean log posterior still rises by more than its standard error over
#: SETTLE_WINDOW moves (``still_rising``): the population that the posterior summaries and the
#: bridge estimate of the evidence read must have settled, not only decorrelated (a Dahl
#: friction's population decorrelated with its mean 17 nats below its best particle).
FINAL_MOVES_FACTOR = 3
SETTLE_WINDOW = 3
#: How the graphs TMCMC needs are compiled (the population's prior and likelihood, PyMC's
#: initial points and prior draws): with every rewrite but elementwise fusion, run by NumPy
#: implementations, so that no C compiler runs. A cold PyTensor cache spent 18 s in gcc (27
#: C modules) on the tanh model before its first stage; a population of 1000 particles
#: costs the same (312 against 301 ms per call with the likelihood), because each op works
#: on a whole column of particles. Fused ops would evaluate element by element in Python
#: (621 ms), hence no fusion.
COMPILE_MODE = Mode(linker="py", optimizer="fast_run").excluding("fusion")
#: The base class compiles one-particle prior and likelihood functions that this kernel never
#: calls (it evaluates populations, ``compile_population_logp``): compiled without rewrites.
UNUSED_MODE = Mode(linker="py", optimizer=None)


class TMCMCError(RuntimeError):
    """TMCMC cannot continue (no particle has a finite likelihood, or a degenerate population)."""


class OutOfTime(RuntimeError):
    """TMCMC stopped at its ``deadline`` (a caller's time budget): the chain, the stage and the
    tempering exponent it had reached; no posterior and no evidence."""

    def __init__(self, chain: int, stage: int, beta: float):
        self.chain, self.stage, self.beta = chain, stage, float(beta)
        super().__init__(f"TMCMC stopped at its deadline: chain {chain}, stage {stage}, "
                         f"beta {self.beta:.3g}")


@dataclass(frozen=True)
class FinishedChain:
    """A chain that reached beta = 1 (``TMCMC(keep=...)``): its final population, its
    per-stage statistics (one dict a stage, as ``TMCMC.sample_stats`` returns them), its
    settings, and PyMC's layout of the model's variables in a particle."""

    chain: int
    tempered_posterior: np.ndarray
    stats: list[dict]
    settings: dict
    var_info: dict
    variables: list


# --------------------------------------------------------------------------------------------
# The algorithm's formulas, as plain functions of the population arrays
# --------------------------------------------------------------------------------------------


def plausibility_log_weights(likelihood_logp: np.ndarray, dbeta: float) -> np.ndarray:
    """log w_k = (beta_new - beta_old) * log L_k, with log L = -inf giving log w = -inf."""
    with np.errstate(invalid="ignore"):
        return np.where(np.isneginf(likelihood_logp), -np.inf, dbeta * likelihood_logp)


def weights_cov(log_weights: np.ndarray) -> float:
    """Coefficient of variation std(w) / mean(w) of weights given in log space."""
    top = np.max(log_weights)
    if not np.isfinite(top):
        return np.inf
    w = np.exp(log_weights - top)
    return float(np.std(w) / np.mean(w))


def next_beta(
    likelihood_logp: np.ndarray,
    old_beta: float,
    target_cov: float = 1.0,
    rtol: float = 1e-8,
    max_iter: int = 200,
) -> tuple[float, np.ndarray]:
    """Next tempering exponent and its unnormalised log plausibility weights (Ching & Chen).

    Bisection on dbeta in (0, 1 - old_beta] for cov(w) = target_cov; cov(w) grows with dbeta.
    If even beta = 1 gives cov(w) <= target_cov, beta = 1 (the last stage).
    """
    remaining = 1.0 - old_beta
    log_w = plausibility_log_weights(likelihood_logp, remaining)
    if weights_cov(log_w) <= target_cov:
        return 1.0, log_w
    low, high = 0.0, remaining
    for _ in range(max_iter):
        mid = 0.5 * (low + high)
        if weights_cov(plausibility_log_weights(likelihood_logp, mid)) > target_cov:
            high = mid
        else:
            low = mid
        if high - low <= rtol * high:
            break
    # ``high`` > 0 always, so beta never stalls (a population with many -inf likelihoods can
    # need a step of almost zero: that stage only removes them).
    new_beta = min(old_beta + high, 1.0)
    return new_beta, plausibility_log_weights(likelihood_logp, new_beta - old_beta)


def stage_log_variance(log_weights: np.ndarray, families: np.ndarray) -> float:
    """Variance of log mean(w) for weights of particles grouped in families (cluster sample).

    var(mean w) = F / (F - 1) sum_f (W_f - n_f mean(w))^2 / N^2 with W_f the summed weight of
    family f, n_f its size and F the number of families; var(log mean w) = var(mean w) /
    mean(w)^2 (delta method). Independent particles are families of one.
    """
    top = np.max(log_weights)
    if not np.isfinite(top):
        return np.inf
    w = np.exp(log_weights - top)
    n = w.size
    labels, index = np.unique(families, return_inverse=True)
    n_families = labels.size
    if n_families < 2:
        return np.inf
    totals = np.bincount(index, weights=w, minlength=n_families)
    sizes = np.bincount(index, minlength=n_families)
    mean = w.mean()
    var = n_families / (n_families - 1.0) * np.sum((totals - sizes * mean) ** 2) / n**2
    return float(var / mean**2)


def still_rising(means: Sequence[float], se: float, window: int = SETTLE_WINDOW) -> bool:
    """Whether a population's mean log density (one entry per move, the first before any)
    rose by more than ``se`` over the last ``window`` moves: not yet settled."""
    return len(means) <= window or means[-1] - means[-1 - window] > se


def mean_abs_correlation(start: np.ndarray, now: np.ndarray) -> float:
    """Mean over dimensions of |Pearson correlation| between two populations' coordinates
    (particles paired by row); dimensions that do not vary in either count as 0."""
    a = start - start.mean(axis=0)
    b = now - now.mean(axis=0)
    norm = np.sqrt(np.sum(a * a, axis=0) * np.sum(b * b, axis=0))
    with np.errstate(invalid="ignore", divide="ignore"):
        rho = np.where(norm > 0, np.abs(np.sum(a * b, axis=0)) / norm, 0.0)
    return float(np.mean(rho))


@dataclass(frozen=True)
class GaussianMixture:
    """A mixture of Gaussians in the particles' (value-variable) space: weights (K,), means
    (K, d), Cholesky factors of the covariances (K, d, d)."""

    weights: np.ndarray
    means: np.ndarray
    chols: np.ndarray

    def log_density(self, x: np.ndarray) -> np.ndarray:
        """log of the mixture's density at each row of x."""
        return logsumexp(self._weighted_log_densities(x), axis=0)

    def component_of(self, x: np.ndarray) -> np.ndarray:
        """Index of the component most responsible for each row of x."""
        comps = self._weighted_log_densities(x)
        comps[~np.isfinite(comps)] = -np.inf
        return np.argmax(comps, axis=0)

    def _weighted_log_densities(self, x: np.ndarray) -> np.ndarray:
        """log(weight x density) of each component at each row of x, (K, rows)."""
        x = np.atleast_2d(x)
        d = x.shape[1]
        comps = []
        for w, mu, chol in zip(self.weights, self.means, self.chols):
            z = np.linalg.solve(chol, (x - mu).T)
            logdet = 2.0 * np.sum(np.log(np.diag(chol)))
            comps.append(np.log(w) - 0.5 * (np.sum(z * z, axis=0) + logdet
                                            + d * np.log(2.0 * np.pi)))
        return np.array(comps)

    def draw(self, rng: np.random.Generator, n: int) -> np.ndarray:
        """n draws (rows)."""
        k = rng.choice(len(self.weights), size=n, p=self.weights)
        z = rng.standard_normal((n, self.means.shape[1]))
        return self.means[k] + np.einsum("nij,nj->ni", self.chols[k], z)


def _weighted_only(x: np.ndarray, weights: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The rows of x with positive weight, where a row is not finite (a particle of zero
    likelihood may lie outside the transformed space); else x and weights as they are, so
    that the sums keep their order."""
    if np.isfinite(x).all():
        return x, weights
    keep = weights > 0
    return x[keep], weights[keep]


def fit_gaussian_mixture(x: np.ndarray, weights: np.ndarray, components: int,
                         rng: np.random.Generator, iterations: int = 50,
                         widen: float = 1.0) -> GaussianMixture:
    """Weighted EM fit of a Gaussian mixture with up to ``components`` components to the
    weighted particles, the number chosen by BIC (each component needs 5 d effective
    particles); covariances multiplied by ``widen``^2 (a proposal with lighter tails than
    its target would stick at the target's tail points). Particles of weight zero do not
    count (``_weighted_only``)."""
    x, weights = _weighted_only(x, weights)
    w = weights / weights.sum()
    n_eff = 1.0 / np.sum(w**2)
    d = x.shape[1]
    best, best_bic = None, np.inf
    for k in range(1, components + 1):
        if k > 1 and n_eff < 5 * d * k:
            break
        mix, loglike = _em(x, w, k, rng, iterations)
        n_par = k * (d + d * (d + 1) / 2) + k - 1
        bic = -2.0 * n_eff * loglike + n_par * np.log(n_eff)
        if bic < best_bic:
            best, best_bic = mix, bic
    return GaussianMixture(best.weights, best.means, best.chols * widen)


def _em(x: np.ndarray, w: np.ndarray, k: int, rng: np.random.Generator, iterations: int
        ) -> tuple[GaussianMixture, float]:
    """EM for a k-component mixture; returns it and the weighted mean log-likelihood."""
    n, d = x.shape
    # jitter per coordinate: parameters may differ by decades in scale (a stiffness in N/m^3
    # beside a noise sd in m/s^2), and one shared jitter would swamp the small ones
    floor = 1e-9 * _variance_floor(weighted_covariance(x, w))
    means = x[rng.choice(n, size=k, replace=False, p=w)]
    covs = np.array([weighted_covariance(x, w) for _ in range(k)])
    pis = np.full(k, 1.0 / k)
    loglike = -np.inf
    for _ in range(iterations):
        chols = np.array([_cholesky_with_jitter(c + floor) for c in covs])
        comp = np.array([GaussianMixture(np.ones(1), means[j:j + 1], chols[j:j + 1])
                         .log_density(x) + np.log(pis[j]) for j in range(k)])
        total = logsumexp(comp, axis=0)
        new = float(np.sum(w * total))
        resp = np.exp(comp - total) * w  # (k, n)
        mass = resp.sum(axis=1)
        if np.any(mass < 1e-6):
            break
        pis, means = mass / mass.sum(), (resp @ x) / mass[:, None]
        covs = np.array([weighted_covariance(x, resp[j]) for j in range(k)])
        if new - loglike < 1e-6 * abs(new):
            loglike = new
            break
        loglike = new
    chols = np.array([_cholesky_with_jitter(c + floor) for c in covs])
    return GaussianMixture(pis, means, chols), loglike


def weighted_covariance(particles: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """Sum_k w_k (theta_k - mean)(theta_k - mean)^T with normalised weights (Ching & Chen).
    Particles of weight zero do not count (``_weighted_only``)."""
    particles, weights = _weighted_only(particles, weights)
    weights = weights / weights.sum()
    mean = weights @ particles
    centred = particles - mean
    return np.atleast_2d((centred * weights[:, None]).T @ centred)


def component_steps(mixture: GaussianMixture, x: np.ndarray, z: np.ndarray, scale: float
                    ) -> tuple[np.ndarray, np.ndarray]:
    """Random-walk steps from rows of x, each with the covariance (times scale^2) of the
    mixture component that x most likely belongs to, and the Hastings term
    log q(x | x') - log q(x' | x) of each (x' = x + step: its component may differ).

    One covariance for a population in several clusters (a mode's frequency in two places,
    half the particles still at the prior while the other half sit at a MAP) is the spread
    between the clusters, and steps that size from inside a tight cluster are nearly all
    rejected; each cluster's own covariance keeps the moves the size of the cluster."""
    chols = mixture.chols * scale
    k_from = mixture.component_of(x)
    step = np.einsum("nij,nj->ni", chols[k_from], z)
    k_to = mixture.component_of(x + step)
    return step, _step_log_density(chols[k_to], -step) - _step_log_density(chols[k_from], step)


def _step_log_density(chols: np.ndarray, step: np.ndarray) -> np.ndarray:
    """log N(step; 0, L L^T) per row, L = chols[row] (the 2 pi term left out: it cancels)."""
    u = np.linalg.solve(chols, step[..., None])[..., 0]
    logdet = np.sum(np.log(np.abs(np.diagonal(chols, axis1=1, axis2=2))), axis=1)
    return -0.5 * np.sum(u * u, axis=1) - logdet


def _variance_floor(cov: np.ndarray) -> np.ndarray:
    """Diagonal matrix of each coordinate's variance, at least 1e-12 x their mean (a
    coordinate the population no longer spreads in keeps a jitter of its own)."""
    var = np.diag(cov)
    return np.diag(np.maximum(var, 1e-12 * max(float(np.mean(var)), 1e-300)))


def _cholesky_with_jitter(cov: np.ndarray) -> np.ndarray:
    """Cholesky factor, adding a growing diagonal jitter (relative to each coordinate's
    variance) if the covariance is degenerate."""
    diag = _variance_floor(cov)
    jitter = 0.0
    for _ in range(12):
        try:
            return np.linalg.cholesky(cov + jitter * diag)
        except np.linalg.LinAlgError:
            jitter = 1e-10 if jitter == 0.0 else jitter * 10.0
    raise TMCMCError(f"the proposal covariance is not positive definite:\n{cov}")



# --------------------------------------------------------------------------------------------
# Compiling prior and likelihood of a PyMC model for a whole population
# --------------------------------------------------------------------------------------------


def _checks_per_particle(outputs: Sequence[Variable], check_bounds: bool) -> list[Variable]:
    """Turn PyMC's parameter checks into ``switch(cond, logp, -inf)`` before vectorising.

    PyMC does this rewrite when compiling, but ``vectorize_graph`` first turns a check into one
    condition ``all()``-reduced over the batch, so a single particle with an invalid parameter
    would set every particle's logp to -inf. Rewriting first keeps the check per particle.
    """
    memo: dict[Variable, Variable] = {}
    for node in toposort(outputs):
        inputs = [memo.get(inp, inp) for inp in node.inputs]
        if isinstance(node.op, CheckParameterValue) and node.op.can_be_replaced_by_ninf:
            logp, *conds = inputs
            if check_bounds:
                cond = pt.all([pt.all(c) for c in conds])
                new = pt.switch(cond, logp, -np.inf).astype(node.outputs[0].dtype)
            else:
                new = logp
            memo[node.outputs[0]] = new
        elif any(new is not old for new, old in zip(inputs, node.inputs)):
            new_node = node.clone_with_new_inputs(inputs, strict=False)
            memo.update(zip(node.outputs, new_node.outputs))
    return [memo.get(out, out) for out in outputs]


def compile_population_logp(model: Model, compile_kwargs: dict | None = None):
    """Compile ``f(particles[N, P]) -> (prior_logp[N], likelihood_logp[N])`` for ``model``.

    Prior is ``model.varlogp`` (with the Jacobians of the value-variable transforms) and
    likelihood is ``model.datalogp`` (observed variables and Potentials), as in PyMC's SMC.
    Rows are the raveled value variables in ``model.value_vars`` order (PyMC's
    ``join_nonshared_inputs``); the per-particle graph is vectorised with ``vectorize_graph``, so
    each call evaluates every particle at once, and a `harvester.inference.batched.BatchedLogLike`
    in the graph gets the whole matrix in one call. Compiled in ``COMPILE_MODE`` unless
    ``compile_kwargs`` say otherwise.
    """
    value_vars = model.value_vars
    discrete = [v.name for v in value_vars if v.dtype in discrete_types]
    if discrete:
        raise TypeError(f"TMCMC needs continuous free variables; {discrete} are discrete")
    point = model.initial_point(random_seed=0)  # only the shapes are used
    shared_replacements = make_shared_replacements(point, value_vars, model)
    outputs, joined = join_nonshared_inputs(
        point=point,
        outputs=[model.varlogp, model.datalogp],
        inputs=value_vars,
        shared_inputs=shared_replacements,
    )
    outputs = _checks_per_particle(outputs, model.check_bounds)
    particles = pt.matrix("particles", dtype=joined.dtype)
    batched = vectorize_graph(outputs, replace={joined: particles})
    kwargs = {"on_unused_input": "ignore", "mode": COMPILE_MODE, **(compile_kwargs or {})}
    with model:
        fn = pm_compile([particles], batched, **kwargs)
    fn.trust_input = True
    return fn


def _reference_transforms(model: Model, names: Sequence[str], value_vars: Sequence[Variable]):
    """Per covered variable: (column in the raveled particles, value -> model, model -> value).

    The particles hold the value variables (PyMC's transformed space, e.g. log(x - lower) for
    a truncated prior); the reference's densities are in the model's own units.
    """
    point = model.initial_point(random_seed=0)
    offsets, start = {}, 0
    for v in value_vars:
        offsets[v] = start
        start += int(np.size(point[v.name]))
    out = []
    for name in names:
        try:
            rv = model[name]
        except KeyError:
            raise ValueError(f"the reference's variable {name!r} is not in the model") from None
        value = model.rvs_to_values[rv]
        if value not in offsets:
            raise ValueError(f"{name!r} is not a free variable of the model")
        if np.size(point[value.name]) != 1:
            raise ValueError(f"the reference's variable {name!r} must be a scalar")
        transform = model.rvs_to_transforms.get(rv)
        if transform is None:
            out.append((offsets[value], lambda a: np.asarray(a, dtype=float),
                        lambda a: np.asarray(a, dtype=float)))
            continue
        u = pt.dvector("u")
        back = pytensor.function([u], transform.backward(u, *rv.owner.inputs))
        fwd = pytensor.function([u], transform.forward(u, *rv.owner.inputs))
        out.append((offsets[value],
                    lambda a, f=back: np.asarray(f(np.asarray(a, dtype=float))),
                    lambda a, f=fwd: np.asarray(f(np.asarray(a, dtype=float)))))
    return out


# --------------------------------------------------------------------------------------------
# The kernel
# --------------------------------------------------------------------------------------------


class TMCMC(SMC_KERNEL):
    """Transitional MCMC (Ching & Chen, 2007) SMC kernel with batched likelihood evaluations.

    Use as ``pm.sample_smc(draws, kernel=TMCMC, proposal_scale=0.2, target_cov=1.0,
    mcmc_steps=2, ...)`` or through `run_tmcmc`.

    Parameters
    ----------
    proposal_scale : float, default 0.2
        Ching & Chen's beta: the Metropolis proposal covariance is proposal_scale**2 times the
        weighted sample covariance of the current stage.
    target_cov : float, default 1.0
        Coefficient of variation of the plausibility weights that sets each tempering step
        (Ching & Chen: 100 %). Smaller values give more, gentler stages.
    mcmc_steps : int, default 2
        Fewest Metropolis moves per particle per stage.
    max_mcmc_steps : int or None, default 30
        Most moves per stage; the moves go on until the population decorrelates
        (``correlation_threshold``). None: exactly ``mcmc_steps`` (Ching & Chen's fixed
        chains).
    correlation_threshold : float, default 0.1
        Stop moving once the mean over dimensions of |corr(start, now)| across particles is
        below this.
    independent_moves : bool, default True
        Alternate random-walk moves with independent Metropolis-Hastings moves proposed from a
        Gaussian mixture fitted (weighted EM, components by BIC) to the stage's particles,
        covariances widened by IMH_WIDEN (PyMC's IMH kernel proposes from one Gaussian). False:
        random-walk moves only, as Ching & Chen.
    mixture_components : int, default 3
        Most components of that mixture.
    target_accept : float or None, default None
        None keeps ``proposal_scale`` fixed (Ching & Chen). A value (e.g. 0.25) adapts the scale
        after every stage, scale <- scale * exp(2 (acceptance - target_accept)), as in Betz,
        Papaioannou and Straub (2016): with a fixed 0.2 the particles cannot follow a posterior
        that lies far in the prior's tail (acceptance stays near 0.9 and the population
        collapses before it arrives). The scale used is recorded per stage.
    resampling : {"multinomial", "systematic"}, default "multinomial"
        Multinomial is Ching & Chen's scheme; systematic has lower variance.
    reference : Reference or None, default None
        Temper from this reference distribution instead of the prior (module docstring). None
        gives Ching & Chen's path, unchanged to the last bit.
    deadline : float or None, default None
        Wall-clock time (``time.time()``, s) past which the run stops with `OutOfTime`,
        checked before each stage and each Metropolis move (a caller's time budget); at
        beta = 1, whose evidence is complete, it only ends the last stage's settling moves
        once ``mcmc_steps`` are made. None: no deadline.
    keep : list or None, default None
        Where each chain that reaches beta = 1 is appended as a `FinishedChain` (its final
        population, per-stage statistics and settings), so that `run_tmcmc` can return the
        chains a deadline let finish when it stops a later one (chains run sequentially).
    log : logging.Logger or callable(str) or None, default None
        Where the per-stage progress line goes; None means the logger ``harvester.inference.tmcmc`` at
        INFO. A callable must be picklable by cloudpickle if ``cores > 1``. The chain number in
        the line is right when chains run sequentially (``cores=1``); with parallel chains each
        process reports chain 0.
    **kwargs
        Passed to `pymc.smc.kernels.SMC_KERNEL` (``draws``, ``model``, ``random_seed``,
        ``compile_kwargs``; ``threshold`` is not used by TMCMC).
    """

    # Per-stage statistics, all scalars (PyMC's declaration, in this order):
    #   log_marginal_likelihood  NaN in every stage but the last, which holds the log evidence
    #   beta, accept_rate        tempering exponent; acceptance of the Metropolis moves
    #   log_mean_weight          log S_j = log mean(w): this stage's factor of the evidence
    #   weights_cov              achieved coefficient of variation of the weights
    #   log_weight_variance      variance of log S_j (families of the last resampling as
    #                            clusters)
    #   mcmc_steps, correlation  Metropolis moves made (int) and the correlation with the
    #                            start they left
    #   imh_accept_rate          acceptance of the independent (mixture) proposals
    #   ess                      effective sample size of the weights
    #   n_evals, wall_time       particle likelihood evaluations (int) and wall time (s) in
    #                            the stage; the first also counts the initial (prior) population
    #   proposal_scale           the Metropolis proposal's scale
    stats_dtypes_shapes: dict[str, tuple[type, list]] = {
        name: (int if name in ("mcmc_steps", "n_evals") else float, [])
        for name in ("log_marginal_likelihood", "beta", "accept_rate", "log_mean_weight",
                     "weights_cov", "log_weight_variance", "mcmc_steps", "correlation",
                     "imh_accept_rate", "ess", "n_evals", "wall_time", "proposal_scale")
    }

    def __init__(
        self,
        *args,
        proposal_scale: float = 0.2,
        target_cov: float = 1.0,
        mcmc_steps: int = 2,
        max_mcmc_steps: int | None = 30,
        correlation_threshold: float = 0.1,
        independent_moves: bool = True,
        mixture_components: int = 3,
        target_accept: float | None = None,
        resampling: str = "multinomial",
        reference: Reference | None = None,
        deadline: float | None = None,
        keep: list | None = None,
        log: logging.Logger | Callable[[str], None] | None = None,
        **kwargs,
    ):
        if proposal_scale <= 0:
            raise ValueError(f"proposal_scale must be positive, got {proposal_scale}")
        if target_cov <= 0:
            raise ValueError(f"target_cov must be positive, got {target_cov}")
        if int(mcmc_steps) < 1:
            raise ValueError(f"mcmc_steps must be at least 1, got {mcmc_steps}")
        if max_mcmc_steps is not None and int(max_mcmc_steps) < int(mcmc_steps):
            raise ValueError(f"max_mcmc_steps ({max_mcmc_steps}) must be at least mcmc_steps "
                             f"({mcmc_steps})")
        if not 0.0 < correlation_threshold < 1.0:
            raise ValueError(f"correlation_threshold must be in (0, 1), got "
                             f"{correlation_threshold}")
        if resampling not in RESAMPLING_SCHEMES:
            raise ValueError(f"resampling must be one of {RESAMPLING_SCHEMES}, got {resampling!r}")
        compile_kwargs = kwargs.pop("compile_kwargs", None) or {}
        super().__init__(*args, compile_kwargs={**compile_kwargs, "mode": UNUSED_MODE},
                         **kwargs)
        if target_accept is not None and not 0.0 < target_accept < 1.0:
            raise ValueError(f"target_accept must be in (0, 1) or None, got {target_accept}")
        self.proposal_scale = float(proposal_scale)
        self.initial_scale = float(proposal_scale)
        self.target_accept = target_accept
        self.target_cov = float(target_cov)
        self.mcmc_steps = int(mcmc_steps)
        self.max_mcmc_steps = int(mcmc_steps if max_mcmc_steps is None else max_mcmc_steps)
        self.correlation_threshold = float(correlation_threshold)
        self.independent_moves = bool(independent_moves)
        self.mixture_components = int(mixture_components)
        self.mixture: GaussianMixture | None = None
        self.resampling = resampling
        self.deadline = deadline
        self.keep = keep
        self._chain_stats: list[dict] = []
        self.log = log
        model = modelcontext(kwargs.get("model"))
        self.population_logp_func = compile_population_logp(model, compile_kwargs)
        self.reference = reference
        if reference is not None:
            self._reference_columns = _reference_transforms(model, reference.names,
                                                            self.variables)
        self.chain = -1  # counts initialisations; the chain number when chains run sequentially
        self._reset_stage_state()

    # ---- setup -------------------------------------------------------------------------------

    def _reset_stage_state(self) -> None:
        self.log_mean_weight = np.nan
        self.log_weight_variance = np.nan
        self.steps_used = 0
        self.correlation = np.nan
        self.imh_acc_rate = np.nan
        self.families = np.arange(self.draws)  # independent prior draws
        self.weights_cov = np.nan
        self.ess = np.nan
        self.acc_rate = np.nan
        self.scale_used = np.nan
        self.stage_particles: np.ndarray | None = None
        self.proposal_chol: np.ndarray | None = None
        self.n_evals = 0
        self._stage_clock = time.perf_counter()

    def set_rng(self, rng: np.random.Generator) -> None:
        """As the base class, for the batched function too (a logp graph rarely holds RNGs)."""
        super().set_rng(rng)
        fn = self.population_logp_func
        rngs = [v for v in fn.get_shared() if isinstance(v.type, RandomGeneratorType)]
        if rngs:
            swap = {old: shared(new, borrow=True) for old, new in zip(rngs, rng.spawn(len(rngs)))}
            self.population_logp_func = fn.copy(swap=swap)

    def _initialize_kernel(self) -> None:
        """Initial population and its prior and likelihood, evaluated in ONE batched call.

        The base class says this method should not be overridden, but it evaluates the
        particles one at a time (N calls of the likelihood). The population is built exactly as
        the base class does (``start`` or prior draws, raveled in ``value_vars`` order).
        """
        self.chain += 1
        self._reset_stage_state()
        self._chain_stats = []
        self.proposal_scale = self.initial_scale
        init = self.start if self.start else self.initialize_population()
        population = [
            DictToArrayBijection.map({v.name: init[v.name][i] for v in self.variables}).data
            for i in range(self.draws)
        ]
        self.tempered_posterior = np.ascontiguousarray(floatX(np.array(population)))
        note = ""
        if self.reference is not None:
            # a share of the particles takes the variable from g instead of the prior
            from_g = self.rng.random(self.draws) < self.reference.share
            drawn = self.reference.draw(self.rng, int(from_g.sum()))
            for k, (col, _, to_value) in enumerate(self._reference_columns):
                self.tempered_posterior[from_g, col] = to_value(drawn[:, k])
            note = (f"; {int(from_g.sum())} start from the reference for "
                    f"{', '.join(self.reference.names)}")
        self.reference_log_ratio = self._log_ratio(self.tempered_posterior)
        self.prior_logp, self.likelihood_logp = self.evaluate(self.tempered_posterior)
        n_dead = int(np.sum(np.isneginf(self.likelihood_logp)))
        self._say(
            f"TMCMC chain {self.chain}: {self.draws} particles, {self.tempered_posterior.shape[1]}"
            f" dimensions; {n_dead} initial particles have zero likelihood{note}"
        )

    def _log_ratio(self, particles: np.ndarray) -> np.ndarray:
        """log q / prior of each particle (zeros without a reference)."""
        if self.reference is None:
            return np.zeros(len(particles))
        x = np.column_stack([to_model(np.asarray(particles[:, col], dtype=float))
                             for col, to_model, _ in self._reference_columns])
        return np.asarray(self.reference.log_ratio(x), dtype=float)

    def evaluate(self, particles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Log prior and log likelihood of every particle (one batched call); NaN -> -inf."""
        n = len(particles)
        prior_logp, likelihood_logp = self.population_logp_func(
            np.ascontiguousarray(particles, dtype=self.tempered_posterior.dtype)
        )
        prior_logp = np.array(np.broadcast_to(prior_logp, (n,)), dtype=float)
        likelihood_logp = np.array(np.broadcast_to(likelihood_logp, (n,)), dtype=float)
        prior_logp[np.isnan(prior_logp)] = -np.inf
        likelihood_logp[np.isnan(likelihood_logp)] = -np.inf
        self.n_evals += n
        return prior_logp, likelihood_logp

    # ---- one stage ---------------------------------------------------------------------------

    def past_deadline(self) -> bool:
        return self.deadline is not None and time.time() > self.deadline

    def check_time(self) -> None:
        """`OutOfTime` where the deadline has passed."""
        if self.past_deadline():
            raise OutOfTime(self.chain, self.iteration, self.beta)

    def update_beta_and_weights(self) -> None:
        """Next beta for cov(w) = target_cov; weights; evidence factor S_j = mean(w)."""
        self.check_time()
        self.iteration += 1
        alive = np.isfinite(self.likelihood_logp)
        if not alive.any():
            raise TMCMCError(
                f"TMCMC chain {self.chain}, stage {self.iteration} (beta={self.beta:.4g}): all "
                f"{self.draws} particles have log-likelihood -inf or NaN, so the plausibility "
                "weights are all zero. The likelihood is zero wherever the prior puts the "
                "particles: check the data, the prior ranges and the likelihood function."
            )
        # log (p L / q) = log L - log (q / p): the log-likelihood itself without a reference
        self.beta, log_w = next_beta(self.likelihood_logp - self.reference_log_ratio, self.beta,
                                     self.target_cov)
        log_sum = logsumexp(log_w)
        self.log_mean_weight = float(log_sum - np.log(self.draws))
        self.log_weight_variance = stage_log_variance(log_w, self.families)
        self.log_marginal_likelihood += self.log_mean_weight
        self.weights = np.exp(log_w - log_sum)
        self.weights /= self.weights.sum()
        self.weights_cov = weights_cov(log_w)
        self.ess = float(1.0 / np.sum(self.weights**2))

    def resample(self) -> None:
        """Draw N particles with probabilities w (multinomial or systematic)."""
        self.stage_particles = self.tempered_posterior  # weighted population, used by tune()
        if self.resampling == "multinomial":
            self.resampling_indexes = self.rng.choice(self.draws, size=self.draws, p=self.weights)
        else:
            self.resampling_indexes = systematic_resampling(self.weights, self.rng)
        self.tempered_posterior = self.tempered_posterior[self.resampling_indexes]
        self.families = self.resampling_indexes.copy()
        self.prior_logp = self.prior_logp[self.resampling_indexes]
        self.likelihood_logp = self.likelihood_logp[self.resampling_indexes]
        self.reference_log_ratio = self.reference_log_ratio[self.resampling_indexes]
        self.tempered_posterior_logp = self._tempered(self.prior_logp, self.likelihood_logp,
                                                      self.reference_log_ratio)

    def _tempered(self, prior_logp: np.ndarray, likelihood_logp: np.ndarray,
                  log_ratio: np.ndarray) -> np.ndarray:
        """log f_beta = log p + beta log L + (1 - beta) log (q / p)."""
        out = prior_logp + self.beta * likelihood_logp
        return out if self.reference is None else out + (1.0 - self.beta) * log_ratio

    def tune(self) -> None:
        """Proposal covariance: proposal_scale**2 * weighted covariance of the stage."""
        cov = self.proposal_scale**2 * weighted_covariance(self.stage_particles, self.weights)
        if not np.all(np.isfinite(cov)):
            raise TMCMCError(
                f"TMCMC chain {self.chain}, stage {self.iteration}: the weighted sample "
                "covariance is not finite (a particle has an infinite coordinate)"
            )
        self.proposal_chol = _cholesky_with_jitter(cov)
        self.mixture = None
        if self.independent_moves:
            self.mixture = fit_gaussian_mixture(self.stage_particles, self.weights,
                                                self.mixture_components, self.rng,
                                                widen=IMH_WIDEN)
            self.mixture_logq = self.mixture.log_density(self.tempered_posterior)

    def mutate(self) -> None:
        """Metropolis moves of all particles (one batched evaluation each) until the population
        decorrelates from its start (``mcmc_steps`` .. ``max_mcmc_steps``) and, at the last
        stage, until its mean log posterior settles (``still_rising``, up to
        FINAL_MOVES_FACTOR x ``max_mcmc_steps``): independent proposals from a Gaussian
        mixture fitted to the stage (``independent_moves``) and random-walk proposals in turn;
        the independent ones are dropped for the rest of the stage when they accept under
        IMH_MIN_ACCEPT."""
        n = self.tempered_posterior.shape[0]
        start = self.tempered_posterior.copy()
        accepted = steps = rw_steps = imh_accepted = imh_steps = 0
        use_imh = self.mixture is not None
        settle = self.beta >= 1.0 and self.max_mcmc_steps > self.mcmc_steps
        limit = self.max_mcmc_steps * (FINAL_MOVES_FACTOR if settle else 1)
        means = [self._logp_mean_se()[0]]
        while steps < limit:
            if self.beta >= 1.0 and steps >= self.mcmc_steps and self.past_deadline():
                # at beta = 1 the evidence is complete: the deadline ends the settling moves
                self._say(f"TMCMC chain {self.chain}: the last stage's moves stopped at the "
                          f"deadline after {steps}")
                break
            if self.beta < 1.0:
                self.check_time()
            if use_imh and steps % 2 == 0:
                got = self._independent_move()
                imh_accepted += got
                imh_steps += 1
                use_imh = got >= IMH_MIN_ACCEPT * n
            else:
                accepted += self._move()
                rw_steps += 1
            steps += 1
            means.append(self._logp_mean_se()[0])
            if steps >= self.mcmc_steps:
                self.correlation = mean_abs_correlation(start, self.tempered_posterior)
                decorrelated = self.correlation < self.correlation_threshold
                if (decorrelated or steps >= self.max_mcmc_steps) and not (
                        settle and still_rising(means, self._logp_mean_se()[1])):
                    break
        self.steps_used = steps
        self.acc_rate = accepted / (n * rw_steps) if rw_steps else np.nan
        self.imh_acc_rate = imh_accepted / (n * imh_steps) if imh_steps else np.nan
        self.scale_used = self.proposal_scale
        if self.target_accept is not None and rw_steps:
            factor = np.exp(2.0 * (self.acc_rate - self.target_accept))
            self.proposal_scale = float(np.clip(self.proposal_scale * factor, 1e-3, 5.0))

    def _logp_mean_se(self) -> tuple[float, float]:
        """Mean tempered log density of the population's finite particles, and its
        standard error."""
        logp = self.tempered_posterior_logp[np.isfinite(self.tempered_posterior_logp)]
        return float(np.mean(logp)), float(np.std(logp) / np.sqrt(max(logp.size, 1)))

    def _independent_move(self) -> int:
        """One independent Metropolis-Hastings move of every particle, proposed from the
        stage's mixture; returns how many accepted."""
        n = self.tempered_posterior.shape[0]
        proposal = floatX(self.mixture.draw(self.rng, n))
        logq = self.mixture.log_density(proposal)
        prior_logp, likelihood_logp = self.evaluate(proposal)
        ref_ratio = self._log_ratio(proposal)
        with np.errstate(invalid="ignore"):
            proposal_logp = self._tempered(prior_logp, likelihood_logp, ref_ratio)
            proposal_logp[np.isnan(proposal_logp)] = -np.inf
            log_ratio = (proposal_logp - self.tempered_posterior_logp) + (self.mixture_logq
                                                                          - logq)
        accept = np.isfinite(proposal_logp) & (np.log(self.rng.random(n)) < log_ratio)
        self._take(accept, proposal, prior_logp, likelihood_logp, ref_ratio, proposal_logp)
        self.mixture_logq[accept] = logq[accept]
        return int(accept.sum())

    def _take(self, accept, proposal, prior_logp, likelihood_logp, ref_ratio, proposal_logp):
        """Replace the accepted particles and their densities by the proposal's."""
        self.tempered_posterior[accept] = proposal[accept]
        self.prior_logp[accept] = prior_logp[accept]
        self.likelihood_logp[accept] = likelihood_logp[accept]
        self.reference_log_ratio[accept] = ref_ratio[accept]
        self.tempered_posterior_logp[accept] = proposal_logp[accept]

    def _move(self) -> int:
        """One random-walk Metropolis move of every particle; returns how many accepted.
        Where the stage's mixture has several components, each particle steps with its own
        component's covariance (:func:`component_steps`), with the Hastings correction."""
        n, d = self.tempered_posterior.shape
        z = self.rng.standard_normal((n, d))
        if self.mixture is not None and len(self.mixture.weights) > 1:
            step, log_q_ratio = component_steps(self.mixture, self.tempered_posterior, z,
                                                self.proposal_scale / IMH_WIDEN)
        else:
            step, log_q_ratio = z @ self.proposal_chol.T, 0.0
        proposal = floatX(self.tempered_posterior + step)
        prior_logp, likelihood_logp = self.evaluate(proposal)
        ref_ratio = self._log_ratio(proposal)
        with np.errstate(invalid="ignore"):
            proposal_logp = self._tempered(prior_logp, likelihood_logp, ref_ratio)
            proposal_logp[np.isnan(proposal_logp)] = -np.inf
            log_ratio = proposal_logp - self.tempered_posterior_logp + log_q_ratio
        accept = np.isfinite(proposal_logp) & (np.log(self.rng.random(n)) < log_ratio)
        self._take(accept, proposal, prior_logp, likelihood_logp, ref_ratio, proposal_logp)
        if self.mixture is not None:
            self.mixture_logq[accept] = self.mixture.log_density(proposal[accept])
        return int(accept.sum())

    def sample_stats(self) -> SMCStats:
        now = time.perf_counter()
        stats = {
            "log_marginal_likelihood": self.log_marginal_likelihood if self.beta == 1 else np.nan,
            "beta": self.beta,
            "accept_rate": self.acc_rate,
            "log_mean_weight": self.log_mean_weight,
            "weights_cov": self.weights_cov,
            "log_weight_variance": self.log_weight_variance,
            "mcmc_steps": self.steps_used,
            "correlation": self.correlation,
            "imh_accept_rate": self.imh_acc_rate,
            "ess": self.ess,
            "n_evals": self.n_evals,
            "wall_time": now - self._stage_clock,
            "proposal_scale": self.scale_used,
        }
        self.n_evals = 0
        self._stage_clock = now
        self._chain_stats.append(stats)
        if self.beta >= 1.0 and self.keep is not None:
            self.keep.append(FinishedChain(self.chain, self.tempered_posterior.copy(),
                                           list(self._chain_stats), self.sample_settings(),
                                           self.var_info, list(self.variables)))
        self._say(
            f"TMCMC chain {self.chain} stage {self.iteration}: beta={self.beta:.4g} "
            f"(cov(w)={self.weights_cov:.2f}, ESS={self.ess:.0f}/{self.draws}), "
            f"accept={self.acc_rate:.2f} (scale {self.scale_used:.3g}, independent "
            f"{self.imh_acc_rate:.2f}), "
            f"{self.steps_used} moves (corr {self.correlation:.2f}), "
            f"log_evidence={self.log_marginal_likelihood:.3f}, "
            f"{stats['n_evals']} evals in {stats['wall_time']:.2f} s"
        )
        return stats

    def sample_settings(self) -> SMCSettings:
        return {
            "_n_draws": self.draws,
            "_n_tune": self.mcmc_steps,
            "kernel": "TMCMC",
            "proposal_scale": self.initial_scale,
            "target_cov": self.target_cov,
            "mcmc_steps": self.mcmc_steps,
            "max_mcmc_steps": self.max_mcmc_steps,
            "correlation_threshold": self.correlation_threshold,
            "target_accept": -1.0 if self.target_accept is None else self.target_accept,
            "resampling": self.resampling,
        }

    def _say(self, message: str) -> None:
        if self.log is None:
            logger.info(message)
        elif isinstance(self.log, logging.Logger):
            self.log.info(message)
        else:
            self.log(message)


# --------------------------------------------------------------------------------------------
# Running it and reading the results
# --------------------------------------------------------------------------------------------

#: Per-stage statistics copied into run_tmcmc's sample_stats, with dims (chain, stage).
STAGE_STATS = ("beta", "accept_rate", "log_mean_weight", "weights_cov", "ess", "n_evals",
               "wall_time", "proposal_scale", "log_weight_variance", "mcmc_steps",
               "correlation", "imh_accept_rate")


def _ragged_to_matrix(rows: list[np.ndarray]) -> np.ndarray:
    out = np.full((len(rows), max(len(r) for r in rows)), np.nan)
    for i, row in enumerate(rows):
        out[i, : len(row)] = row
    return out


def tidy_sample_stats(sample_stats: xr.Dataset, chains: int, wall_time: float) -> xr.Dataset:
    """PyMC's SMC sample_stats (ragged object arrays) -> numeric arrays with a ``stage`` dim.

    ``log_evidence`` (chain): final log evidence of each chain. Per stage (chain, stage), NaN
    after a chain's last stage: ``beta`` (the tempering schedule), ``accept_rate``,
    ``log_mean_weight``, ``weights_cov``, ``ess``, ``n_evals``, ``wall_time``,
    ``log_marginal_likelihood`` (running sum of ``log_mean_weight``). Per chain: ``n_stages``,
    ``n_evals_total``, ``wall_time_total``. Attributes keep PyMC's settings and add
    ``wall_time_s`` (whole run).
    """
    raw = {name: per_chain_stage_lists(sample_stats[name].values, chains)
           for name in STAGE_STATS if name in sample_stats}
    chain = np.arange(chains)
    data = {
        name: (("chain", "stage"), _ragged_to_matrix(rows)) for name, rows in raw.items()
    }
    running = [np.cumsum(rows) for rows in raw["log_mean_weight"]]
    data["log_marginal_likelihood"] = (("chain", "stage"), _ragged_to_matrix(running))
    data["log_evidence"] = (("chain",), np.array([r[-1] for r in running]))
    if "log_weight_variance" in raw:
        data["log_evidence_se"] = (("chain",), np.array(
            [float(np.sqrt(np.sum(v))) for v in raw["log_weight_variance"]]))
    data["n_stages"] = (("chain",), np.array([len(r) for r in running]))
    data["n_evals_total"] = (("chain",), np.array([np.sum(r) for r in raw["n_evals"]], dtype=int))
    data["wall_time_total"] = (("chain",), np.array([np.sum(r) for r in raw["wall_time"]]))
    stages = data["beta"][1].shape[1]
    attrs = {k: v for k, v in sample_stats.attrs.items()}
    attrs["wall_time_s"] = float(wall_time)
    return xr.Dataset(data, coords={"chain": chain, "stage": np.arange(1, stages + 1)},
                      attrs=attrs)


def run_tmcmc(
    model: Model,
    draws: int = 1000,
    chains: int = 4,
    seed: int | Sequence[int] | None = None,
    *,
    cores: int = 1,
    progressbar: bool = False,
    idata_kwargs: dict | None = None,
    **kernel_kwargs,
) -> az.InferenceData:
    """Sample ``model`` with `TMCMC` and return InferenceData with tidy TMCMC statistics.

    ``kernel_kwargs`` go to `TMCMC` (``proposal_scale``, ``target_cov``, ``mcmc_steps``,
    ``resampling``, ``reference``, ``deadline``, ``log``). ``idata.sample_stats`` is replaced
    by `tidy_sample_stats`: ``log_evidence`` per chain, the tempering schedule ``beta`` (chain, stage), acceptance
    rates, likelihood evaluations and wall times; numeric only, so it can be saved to netCDF.
    """
    start = time.perf_counter()
    keep = [] if kernel_kwargs.get("deadline") is not None and cores == 1 and chains > 1 \
        else None
    cut = None
    with warnings.catch_warnings(), pytensor.config.change_flags(mode=COMPILE_MODE):
        # PyMC packs SMC stats as (1 chain, n chains) arrays; tidy_sample_stats redoes them.
        warnings.filterwarnings("ignore", message="More chains", category=UserWarning)
        try:
            idata = pm.sample_smc(
                draws=draws,
                kernel=TMCMC,
                model=model,
                chains=chains,
                cores=cores,
                random_seed=seed,
                progressbar=progressbar,
                compute_convergence_checks=False,
                idata_kwargs=idata_kwargs,
                **({} if keep is None else {"keep": keep}),
                **kernel_kwargs,
            )
        except OutOfTime as stop:
            if not keep:
                raise
            cut = stop
            idata = finished_idata(keep, model, idata_kwargs, time.perf_counter() - start)
    wall_time = time.perf_counter() - start
    done = chains if cut is None else len(keep)
    idata.sample_stats = tidy_sample_stats(idata.sample_stats, done, wall_time)
    if cut is not None:
        idata.sample_stats.attrs.update(chains_cut=chains - done, cut=str(cut),
                                        cut_stage=cut.stage, cut_beta=cut.beta)
        logger.warning("%s; kept the %d chain(s) that finished before it", cut, done)
    return idata


def finished_idata(keep: Sequence[FinishedChain], model: Model, idata_kwargs: dict | None,
                   seconds: float) -> az.InferenceData:
    """InferenceData of the chains a deadline let finish (``TMCMC(keep=...)``), built as
    ``pm.sample_smc`` builds it from its chains (PyMC 5.28's own helpers)."""
    from pymc.backends.base import MultiTrace
    from pymc.smc.sampling import _build_trace_from_kernel_state, _save_sample_stats
    traces = [_build_trace_from_kernel_state(k.tempered_posterior, k.var_info, k.variables, i,
                                             model) for i, k in enumerate(keep)]
    stats = [{name: [row[name] for row in k.stats] for name in k.stats[0]} for k in keep]
    _, idata = _save_sample_stats([dict(k.settings) for k in keep], stats, len(keep),
                                  MultiTrace(traces), True, seconds, idata_kwargs, model)
    return idata
