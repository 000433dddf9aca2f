"""TMCMC kernel (harvester.inference.tmcmc) and the batched black-box likelihood Op (harvester.inference.batched).

Problems with exact answers (linear-Gaussian evidence, conjugate Normal mean), agreement with
PyMC's own SMC kernel, the Op's placement in ``datalogp`` and its one-call-per-batch contract,
robustness to NaN likelihoods, reproducibility. Sampling runs are small: each takes about a
second on one core after compilation.
"""

from __future__ import annotations

import logging

import numpy as np
import pymc as pm
import pytensor
import pytensor.tensor as pt
import pytest
from pytensor.graph.replace import vectorize_graph
from scipy.stats import multivariate_normal

from harvester.inference.batched import BatchedLogLike, loglike_potential
from harvester.inference.priors import PriorSpec
from harvester.inference.reference import GaussianFactor, Reference, ScanFactor
from harvester.inference.posterior import log_evidence
from harvester.inference.tmcmc import (
    TMCMC,
    OutOfTime,
    TMCMCError,
    compile_population_logp,
    fit_gaussian_mixture,
    weighted_covariance,
    next_beta,
    run_tmcmc,
    still_rising,
    weights_cov,
)

pytestmark = pytest.mark.filterwarnings("ignore::UserWarning", "ignore::RuntimeWarning")


@pytest.fixture(autouse=True)
def _quiet_pymc():
    pymc_logger = logging.getLogger("pymc")
    level = pymc_logger.level
    pymc_logger.setLevel(logging.ERROR)
    yield
    pymc_logger.setLevel(level)


# --------------------------------------------------------------------------------------------
# Problems with known answers
# --------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def linear_gaussian():
    """y = X w + noise, w ~ N(0, s0^2 I) in 3 dims, known noise: y ~ N(0, s0^2 X X^T + s^2 I)."""
    rng = np.random.default_rng(0)
    n, d, prior_sd, noise_sd = 20, 3, 1.0, 0.5
    X = rng.normal(size=(n, d))
    y = X @ rng.normal(scale=prior_sd, size=d) + rng.normal(scale=noise_sd, size=n)
    exact = multivariate_normal(np.zeros(n), prior_sd**2 * X @ X.T + noise_sd**2 * np.eye(n))
    with pm.Model() as model:
        w = pm.Normal("w", 0.0, prior_sd, shape=d)
        pm.Normal("y", pm.math.dot(X, w), noise_sd, observed=y)
    return model, float(exact.logpdf(y))


def test_log_evidence_linear_gaussian_default_settings(linear_gaussian):
    # The default kernel moves until the population decorrelates (Betz et al. 2016): one
    # chain's log evidence spreads by about 0.1 nats here, so the mean of 8 chains has a
    # standard error of about 0.04 nats (with Ching & Chen's fixed 2 moves it took 48 chains).
    model, exact = linear_gaussian
    idata = run_tmcmc(model, draws=1000, chains=8, seed=11)
    errors = log_evidence(idata) - exact
    assert abs(errors.mean()) < 0.2, errors
    assert np.all(np.abs(errors) < 2.5), errors
    assert np.all(idata.sample_stats["n_stages"].values >= 2)


def test_log_evidence_linear_gaussian_four_chains(linear_gaussian):
    # A wider proposal and more moves mix well: one chain's spread is about 0.1 nats, so the
    # mean of 4 chains has a standard error of about 0.05 nats.
    model, exact = linear_gaussian
    idata = run_tmcmc(model, draws=1000, chains=4, seed=12, proposal_scale=1.0, mcmc_steps=5)
    errors = log_evidence(idata) - exact
    assert abs(errors.mean()) < 0.2, errors


def test_posterior_of_normal_mean_with_known_sigma():
    y = np.array([1.2, 0.7, 2.1, 1.5, 0.9, 1.8, 1.1, 1.4])
    prior_mean, prior_sd, noise_sd = 0.0, 2.0, 0.8
    precision = 1 / prior_sd**2 + len(y) / noise_sd**2
    post_mean = (prior_mean / prior_sd**2 + y.sum() / noise_sd**2) / precision
    post_sd = precision**-0.5
    with pm.Model() as model:
        mu = pm.Normal("mu", prior_mean, prior_sd)
        pm.Normal("y", mu, noise_sd, observed=y)
    draws = run_tmcmc(model, draws=1000, chains=4, seed=3).posterior["mu"].values
    assert draws.shape == (4, 1000)
    # Resampled populations hold duplicates, so the effective sample size is well below 4000.
    assert abs(draws.mean() - post_mean) < 0.15 * post_sd
    assert abs(draws.std() / post_sd - 1) < 0.1


def test_agrees_with_pymc_imh_kernel():
    rng = np.random.default_rng(3)
    z = rng.normal(1.0, 0.7, size=15)
    with pm.Model() as model:
        mu = pm.Normal("mu", 0.0, 2.0)
        s = pm.HalfNormal("s", 1.0)  # log-transformed: moves happen in log(s)
        pm.Normal("z", mu, s, observed=z)
    ours = run_tmcmc(model, draws=1000, chains=4, seed=5)
    imh = pm.sample_smc(1000, model=model, chains=2, cores=1, random_seed=5,
                        progressbar=False, compute_convergence_checks=False)
    assert abs(log_evidence(ours).mean() - log_evidence(imh).mean()) < 0.3
    for name in ("mu", "s"):
        ref_sd = float(imh.posterior[name].std())
        diff = float(ours.posterior[name].mean() - imh.posterior[name].mean())
        assert abs(diff) < 0.3 * ref_sd, (name, diff, ref_sd)


# --------------------------------------------------------------------------------------------
# The tempering rule
# --------------------------------------------------------------------------------------------


def test_next_beta_hits_target_cov_and_caps_at_one():
    loglike = np.random.default_rng(0).normal(-50.0, 20.0, size=2000)
    beta, log_w = next_beta(loglike, 0.0, target_cov=1.0)
    assert 0 < beta < 1
    assert weights_cov(log_w) == pytest.approx(1.0, rel=1e-4)
    flat = np.full(100, -3.0)  # cov(w) = 0 for any step: go straight to the posterior
    assert next_beta(flat, 0.3)[0] == 1.0


def test_next_beta_with_zero_likelihood_particles():
    loglike = np.r_[np.full(60, -np.inf), np.random.default_rng(1).normal(-5, 1, size=40)]
    beta, log_w = next_beta(loglike, 0.0)
    assert beta > 0  # progress even when -inf particles alone give cov(w) > target
    assert np.all(np.isneginf(log_w[:60])) and np.all(np.isfinite(log_w[60:]))


# --------------------------------------------------------------------------------------------
# The batched black-box likelihood Op
# --------------------------------------------------------------------------------------------

DATA = np.array([0.3, -0.2, 0.5, 1.1, 0.8])


def normal_loglike(theta: np.ndarray) -> np.ndarray:
    """Rows (mu, log_sigma): Gaussian log-likelihood of DATA."""
    mu, sigma = theta[:, :1], np.exp(theta[:, 1:2])
    return (-0.5 * ((DATA - mu) / sigma) ** 2 - np.log(sigma) - 0.5 * np.log(2 * np.pi)).sum(1)


class CountingLogLike:
    """normal_loglike that records the shape of every call."""

    def __init__(self, fn=normal_loglike):
        self.fn = fn
        self.calls: list[tuple[int, ...]] = []

    def __call__(self, theta):
        self.calls.append(theta.shape)
        return self.fn(theta)


def op_model(fn, as_potential=False):
    with pm.Model() as model:
        mu = pm.Normal("mu", 0.0, 1.0)
        log_sigma = pm.Normal("log_sigma", -0.5, 0.5)
        loglike_potential("loglike", fn, [mu, log_sigma], as_potential=as_potential)
    return model


def reference_model():
    with pm.Model() as model:
        mu = pm.Normal("mu", 0.0, 1.0)
        log_sigma = pm.Normal("log_sigma", -0.5, 0.5)
        pm.Normal("y", mu, pt.exp(log_sigma), observed=DATA)
    return model


@pytest.mark.parametrize("as_potential", [False, True])
def test_op_model_has_the_same_logp_as_pm_normal(as_potential):
    model, reference = op_model(normal_loglike, as_potential), reference_model()
    for mu, log_sigma in [(0.0, 0.0), (0.4, -0.7), (-1.0, 0.3)]:
        point = {"mu": np.array(mu), "log_sigma": np.array(log_sigma)}
        for term in ("datalogp", "varlogp"):
            ours = model.compile_fn(getattr(model, term))(point)
            ref = reference.compile_fn(getattr(reference, term))(point)
            assert ours == pytest.approx(ref, rel=1e-12), term
    # Equal datalogp and varlogp: the likelihood is in datalogp (tempered by SMC), not the prior.
    assert (len(model.observed_RVs), len(model.potentials)) == ((0, 1) if as_potential else (1, 0))


def test_vectorized_op_is_one_call_not_a_blockwise_loop():
    counter = CountingLogLike()
    op = BatchedLogLike(counter, n_params=2)
    theta = pt.vector("theta")
    thetas = pt.matrix("thetas")
    batched = vectorize_graph(op(theta), replace={theta: thetas})
    assert isinstance(batched.owner.op, BatchedLogLike)
    rows = np.random.default_rng(0).normal(size=(7, 2))
    values = pytensor.function([thetas], batched)(rows)
    assert counter.calls == [(7, 2)]
    np.testing.assert_allclose(values, normal_loglike(rows))
    with pytest.raises(NotImplementedError, match="no gradient"):
        pytensor.grad(op(theta), theta)


def test_population_logp_calls_fn_once_per_batch():
    counter = CountingLogLike()
    model, reference = op_model(counter), reference_model()
    rows = np.random.default_rng(1).normal(size=(50, 2))
    prior, loglike = compile_population_logp(model)(rows)
    assert counter.calls == [(50, 2)]
    ref_prior, ref_loglike = compile_population_logp(reference)(rows)
    np.testing.assert_allclose(loglike, ref_loglike)
    np.testing.assert_allclose(prior, ref_prior)


def test_population_logp_needs_no_c_compiler_and_fuses_nothing():
    # a cold PyTensor cache cost 18 s of gcc per model; fused ops would run element by element
    from pytensor.link.basic import PerformLinker
    from pytensor.scalar import Composite
    with pm.Model() as model:
        mu = pm.TruncatedNormal("mu", 0.0, 2.0, lower=-3.0, upper=3.0)
        sigma = pm.LogNormal("sigma", 0.0, 1.0)
        pm.Normal("y", mu, sigma=sigma, observed=DATA)
    fn = compile_population_logp(model)
    assert isinstance(fn.maker.linker, PerformLinker)
    fused = [n for n in fn.maker.fgraph.toposort()
             if isinstance(getattr(n.op, "scalar_op", None), Composite)]
    assert not fused
    rows = np.random.default_rng(3).normal(size=(5, 2))
    prior, loglike = fn(rows)
    mu_v = 6.0 / (1.0 + np.exp(-rows[:, 0])) - 3.0  # interval transform back
    sd = np.exp(rows[:, 1])
    np.testing.assert_allclose(loglike, [np.sum(-0.5 * ((DATA - m) / s) ** 2 - np.log(s)
                                                - 0.5 * np.log(2 * np.pi))
                                         for m, s in zip(mu_v, sd)], rtol=1e-10)
    assert np.all(np.isfinite(prior))


def test_sampling_calls_fn_once_per_move():
    counter = CountingLogLike()
    model = op_model(counter)
    draws = 300
    idata = run_tmcmc(model, draws=draws, chains=2, seed=2, mcmc_steps=2)
    moves = idata.sample_stats["mcmc_steps"].values  # (chain, stage), adapted per stage
    total_moves = int(np.nansum(moves))
    assert len(counter.calls) == 2 + total_moves
    assert set(counter.calls) == {(draws, 2)}
    assert idata.sample_stats["n_evals_total"].values.tolist() == [
        int(draws * (1 + np.nansum(m))) for m in moves
    ]


def test_nan_likelihood_is_rejected_not_fatal():
    def loglike_nan_above_one(theta):
        out = normal_loglike(theta)
        out[theta[:, 0] > 1.0] = np.nan
        return out

    idata = run_tmcmc(op_model(loglike_nan_above_one), draws=300, chains=2, seed=4)
    assert np.all(idata.posterior["mu"].values <= 1.0)
    assert np.all(np.isfinite(log_evidence(idata)))
    op = BatchedLogLike(loglike_nan_above_one, 2)
    theta = pt.matrix("theta")
    values = pytensor.function([theta], op(theta))(np.array([[2.0, 0.0], [0.0, 0.0]]))
    assert np.isneginf(values[0]) and np.isfinite(values[1])


def test_zero_likelihood_everywhere_is_a_clear_error():
    model = op_model(lambda theta: np.full(len(theta), -np.inf))
    with pytest.raises(TMCMCError, match="all 100 particles have log-likelihood -inf"):
        run_tmcmc(model, draws=100, chains=1, seed=0)


def test_invalid_parameter_of_one_particle_does_not_poison_the_batch():
    # PyMC checks sigma > 0; vectorize_graph alone would all()-reduce the check over particles.
    with pm.Model() as model:
        sigma = pm.Normal("sigma", 1.0, 1.0)  # unconstrained on purpose
        pm.Normal("y", 0.0, sigma=sigma, observed=DATA)
    _, loglike = compile_population_logp(model)(np.array([[1.0], [-1.0], [2.0]]))
    assert np.isneginf(loglike[1]) and np.all(np.isfinite(loglike[[0, 2]]))


# --------------------------------------------------------------------------------------------
# Reproducibility and reporting
# --------------------------------------------------------------------------------------------


def test_same_seed_same_samples_and_evidence():
    model = reference_model()
    first = run_tmcmc(model, draws=300, chains=2, seed=21)
    second = run_tmcmc(model, draws=300, chains=2, seed=21)
    other = run_tmcmc(model, draws=300, chains=2, seed=22)
    for name in ("mu", "log_sigma"):
        np.testing.assert_array_equal(first.posterior[name].values, second.posterior[name].values)
    np.testing.assert_array_equal(log_evidence(first), log_evidence(second))
    assert not np.array_equal(first.posterior["mu"].values, other.posterior["mu"].values)


def test_run_tmcmc_statistics_and_progress_log(caplog):
    model = reference_model()
    with caplog.at_level(logging.INFO, logger="harvester.inference.tmcmc"):
        idata = run_tmcmc(model, draws=200, chains=2, seed=1)
    stats = idata.sample_stats
    assert stats["log_evidence"].dims == ("chain",)
    assert stats["beta"].dims == ("chain", "stage")
    for chain in range(2):
        beta = stats["beta"].values[chain]
        beta = beta[np.isfinite(beta)]
        assert np.all(np.diff(beta) > 0) and beta[-1] == 1.0
        running = stats["log_marginal_likelihood"].values[chain]
        assert running[np.isfinite(running)][-1] == stats["log_evidence"].values[chain]
    assert np.all((stats["accept_rate"].values[np.isfinite(stats["accept_rate"].values)] > 0))
    assert stats.attrs["wall_time_s"] > 0 and stats.attrs["kernel"] == "TMCMC"
    assert np.all(stats["n_evals_total"].values > 0)
    lines = [r.getMessage() for r in caplog.records if r.name == "harvester.inference.tmcmc"]
    assert any("stage 1: beta=" in line and "log_evidence=" in line for line in lines)
    # A callable also works as the progress sink.
    seen: list[str] = []
    pm.sample_smc(100, kernel=TMCMC, model=model, chains=1, cores=1, random_seed=0,
                  progressbar=False, compute_convergence_checks=False, log=seen.append)
    assert any("accept=" in line for line in seen)


def test_a_deadline_in_the_second_chain_keeps_the_first(monkeypatch):
    """Chains run one after another: a deadline that stops the second returns the first,
    the very chain the whole run gives (same seed), with the cut said; one that stops the
    first raises."""
    model = reference_model()
    whole = run_tmcmc(model, draws=200, chains=2, seed=5)
    monkeypatch.setattr(TMCMC, "past_deadline", lambda self: self.chain >= 1)
    kept = run_tmcmc(model, draws=200, chains=2, seed=5, deadline=1.0)
    assert kept.posterior.sizes["chain"] == 1
    for name in ("mu", "log_sigma"):
        np.testing.assert_array_equal(kept.posterior[name].values[0],
                                      whole.posterior[name].values[0])
    assert log_evidence(kept)[0] == log_evidence(whole)[0]
    stats = kept.sample_stats
    assert stats.attrs["chains_cut"] == 1 and "chain 1" in stats.attrs["cut"]
    assert stats["log_evidence_se"].shape == (1,)
    monkeypatch.setattr(TMCMC, "past_deadline", lambda self: True)
    with pytest.raises(OutOfTime):
        run_tmcmc(model, draws=200, chains=2, seed=5, deadline=1.0)


def test_discrete_free_variables_are_refused():
    with pm.Model() as model:
        pm.Poisson("k", 3.0)
        pm.Normal("x", 0, 1, observed=[0.1])
    with pytest.raises(TypeError, match="continuous"):
        run_tmcmc(model, draws=50, chains=1, seed=0)


@pytest.mark.slow
def test_log_evidence_linear_gaussian_spread_over_many_seeds(linear_gaussian):
    # Per-chain bias and spread with the default settings, 60 chains.
    model, exact = linear_gaussian
    errors = log_evidence(run_tmcmc(model, draws=1000, chains=60, seed=99)) - exact
    assert abs(errors.mean()) < 3 * errors.std() / np.sqrt(len(errors)) + 0.05
    assert errors.std() < 0.6


# --------------------------------------------------------------------------------------------
# Tempering from a reference distribution
# --------------------------------------------------------------------------------------------

#: A resonance's evidence in miniature: log L = G k(x) (1 - (m / m0 - 1)^2), k(x) a narrow
#: bump at the frequency x0; away from it the likelihood is flat (the baseline's), and at it a
#: parabola in the modal mass m. Few prior draws of x land on the bump.
PEAK = {"gain": 24.0, "x0": 6.57, "s": 0.03, "m0": 0.22}
PRIOR_X = {"mu": 8.0, "sigma": 6.0, "lower": 0.5}
PRIOR_M = {"mu": 0.5, "sigma": 0.5, "lower": 0.0}


def _peak_model():
    with pm.Model() as model:
        x = pm.TruncatedNormal("x", **PRIOR_X)
        m = pm.TruncatedNormal("m", **PRIOR_M)
        bump = pt.exp(-0.5 * ((x - PEAK["x0"]) / PEAK["s"]) ** 2)
        pm.Potential("peak", PEAK["gain"] * bump * (1.0 - (m / PEAK["m0"] - 1.0) ** 2))
    return model


def _peak_exact_log_evidence() -> float:
    """log(1 + E_prior[L - 1]) by quadrature on a fine grid over the bump (L = 1 elsewhere)."""
    from scipy import stats

    def prior(p, v):
        return stats.truncnorm.pdf(v, (p["lower"] - p["mu"]) / p["sigma"], np.inf,
                                   loc=p["mu"], scale=p["sigma"])

    x = np.linspace(PEAK["x0"] - 9 * PEAK["s"], PEAK["x0"] + 9 * PEAK["s"], 3001)
    m = np.linspace(0.0, 6.0, 6001)
    k = np.exp(-0.5 * ((x - PEAK["x0"]) / PEAK["s"]) ** 2)[:, None]
    q = (1.0 - (m / PEAK["m0"] - 1.0) ** 2)[None, :]
    excess = np.expm1(PEAK["gain"] * k * q) * prior(PRIOR_X, x)[:, None] * prior(PRIOR_M, m)
    return float(np.log1p(np.trapezoid(np.trapezoid(excess, m, axis=1), x)))


def _prior(p, name="x"):
    return PriorSpec(name, p["mu"], p["sigma"], "-", p["lower"])


def _reference(centres=(6.2, 7.4), weights=(0.6, 0.4), share=0.5, gaussian=None):
    factors = [ScanFactor("x", centres, (np.log(1.2),) * len(centres), weights, PRIOR_X["lower"])]
    if gaussian is not None:
        factors.append(gaussian)
    return Reference({"x": _prior(PRIOR_X), "m": _prior(PRIOR_M, "m")}, tuple(factors), share)


def _quad(f, lo, hi, points=None):
    from scipy import integrate

    return integrate.quad(lambda v: float(f(np.array([v]))[0]), lo, hi, points=points,
                          limit=400)[0]


def test_reference_densities_are_normalised_and_draws_follow_them():
    ref = _reference()
    scan = ref.factors[0]
    assert _quad(lambda v: np.exp(scan.log_density(v)), 0.5, 80, [6.2, 7.4]) == \
        pytest.approx(1.0, abs=1e-6)
    assert _quad(lambda v: np.exp(_prior(PRIOR_X).logpdf(v)), 0.5, 80) == \
        pytest.approx(1.0, abs=1e-6)
    # q = prior x ratio is a density, and the ratio never falls below 1 - share
    q = _quad(lambda v: np.exp(_prior(PRIOR_X).logpdf(v) + ref.log_ratio(v[:, None])),
              0.5, 80, [6.2, 7.4])
    assert q == pytest.approx(1.0, abs=1e-6)
    assert np.all(ref.log_ratio(np.linspace(0.6, 40, 200)[:, None]) >= np.log(0.5) - 1e-12)
    draws = ref.draw(np.random.default_rng(1), 20_000)[:, 0]
    assert draws.min() > 0.5
    expected = _quad(lambda v: np.exp(scan.log_density(v)), 5.0, 7.0)
    assert np.mean((draws > 5.0) & (draws < 7.0)) == pytest.approx(expected, abs=0.015)
    # a Gaussian factor cut by the support is normalised over the support
    g = GaussianFactor(("m",), (0.1,), ((0.04,),), (0.0,))
    assert _quad(lambda v: np.exp(g.log_density(v[:, None])), 0.0, 3.0) == \
        pytest.approx(1.0, abs=2e-3)
    assert g.draw(np.random.default_rng(2), 1000).min() >= 0.0
    with pytest.raises(ValueError, match="share"):
        _reference(share=1.0)
    with pytest.raises(ValueError, match="lower bound"):
        _reference(centres=(0.2,), weights=(1.0,))
    with pytest.raises(ValueError, match="distinct"):
        _reference(gaussian=GaussianFactor(("x",), (5.0,), ((1.0,),), (0.5,)))


def test_a_particle_of_weight_zero_does_not_spoil_the_proposal():
    """A particle with zero likelihood may have a coordinate outside the transformed space
    (inf): with weight zero it must not make the covariance or the mixture NaN."""
    x = np.random.default_rng(0).standard_normal((200, 3))
    w = np.random.default_rng(1).random(200)
    x[7], w[7] = (0.0, np.inf, -np.inf), 0.0
    np.testing.assert_allclose(weighted_covariance(x, w),
                               weighted_covariance(x[w > 0], w[w > 0]), rtol=1e-12)
    mix = fit_gaussian_mixture(x, w, 3, np.random.default_rng(2))
    assert np.isfinite(mix.means).all() and np.isfinite(mix.chols).all()


def test_reference_factors_stay_inside_an_upper_bound_and_are_normalised_there():
    """A prior with an upper bound (a log-uniform frequency): the factors' draws stay below it
    (above it PyMC's interval transform has no value) and their densities integrate to 1
    below it (mass above it would bias the evidence low)."""
    scan = ScanFactor("x", (2.0, 4.0, 6.0), (0.4, 0.4, 0.4), (1.0, 1.0, 1.0), 0.5, 6.5)
    assert _quad(lambda v: np.exp(scan.log_density(v)), 0.5, 6.5, [2.0, 4.0, 6.0]) == \
        pytest.approx(1.0, abs=1e-6)
    draws = scan.draw(np.random.default_rng(3), 20_000)[:, 0]
    assert draws.max() < 6.5 and np.isneginf(scan.log_density(np.array([6.5, 7.0]))).all()
    expected = _quad(lambda v: np.exp(scan.log_density(v)), 5.0, 6.5)
    assert np.mean(draws > 5.0) == pytest.approx(expected, abs=0.015)
    g = GaussianFactor(("m",), (0.9,), ((0.04,),), (0.0,), uppers=(1.0,))
    assert _quad(lambda v: np.exp(g.log_density(v[:, None])), 0.0, 1.0) == \
        pytest.approx(1.0, abs=2e-3)
    assert g.draw(np.random.default_rng(4), 1000).max() < 1.0
    with pytest.raises(ValueError, match="upper bound"):
        ScanFactor("x", (20.0,), (0.1,), (1.0,), 0.5, 6.5)


def _peak_loglike(theta: np.ndarray) -> np.ndarray:
    x, m = theta[:, 0], theta[:, 1]
    bump = np.exp(-0.5 * ((x - PEAK["x0"]) / PEAK["s"]) ** 2)
    return PEAK["gain"] * bump * (1.0 - (m / PEAK["m0"] - 1.0) ** 2)


def test_reference_finds_a_narrow_peak_the_prior_misses_and_keeps_the_evidence_exact():
    """As the diagnosis uses it: TMCMC from the reference, then the bridge estimate from its
    final population (harvester.inference.evidence)."""
    from harvester.inference.evidence import chains_bridge_log_evidence, log_target

    model = _peak_model()
    exact = _peak_exact_log_evidence()
    assert exact > 10.0  # the peak dominates the evidence
    settings = dict(draws=300, chains=2, seed=3, mcmc_steps=3, proposal_scale=0.8)
    prior_start = log_evidence(run_tmcmc(model, **settings))
    assert np.all(prior_start < exact - 10.0)  # both chains missed the peak: why it exists
    idata = run_tmcmc(model, **settings, reference=_reference())
    post = idata.posterior
    assert float(post["x"].mean()) == pytest.approx(PEAK["x0"], abs=0.02)
    assert float(post["m"].mean()) == pytest.approx(PEAK["m0"], abs=0.03)
    assert np.all(log_evidence(idata) > exact - 6.0)
    target = log_target(_peak_loglike, [_prior(PRIOR_X), _prior(PRIOR_M, "m")])
    rows = [np.column_stack([post["x"].values[c], post["m"].values[c]]) for c in range(2)]
    bridge = chains_bridge_log_evidence(target, rows, np.random.default_rng(0))
    assert bridge.log_evidence == pytest.approx(exact, abs=max(0.3, 3 * bridge.se))


@pytest.mark.slow  # 12 chains: a statistical check
def test_reference_path_keeps_a_conjugate_evidence_exact_over_seeds():
    """Normal means with truncated priors; both factors of the reference placed off the
    posterior, so the evidence must come right through the weights, not the placement."""
    from scipy import integrate, stats

    y = np.array([4.1, 3.6, 4.4, 3.9])
    u = np.array([0.9, 1.3])
    with pm.Model() as model:
        x = pm.TruncatedNormal("x", **PRIOR_X)
        m = pm.TruncatedNormal("m", **PRIOR_M)
        pm.Normal("y", x, 0.5, observed=y)
        pm.Normal("u", m, 0.3, observed=u)
    prior = stats.truncnorm((PRIOR_X["lower"] - PRIOR_X["mu"]) / PRIOR_X["sigma"], np.inf,
                            loc=PRIOR_X["mu"], scale=PRIOR_X["sigma"])
    prior_m = stats.truncnorm((PRIOR_M["lower"] - PRIOR_M["mu"]) / PRIOR_M["sigma"], np.inf,
                              loc=PRIOR_M["mu"], scale=PRIOR_M["sigma"])
    exact = np.log(integrate.quad(
        lambda v: prior.pdf(v) * np.prod(stats.norm.pdf(y, v, 0.5)), 0.5, 30, points=[4.0])[0])
    exact += np.log(integrate.quad(
        lambda v: prior_m.pdf(v) * np.prod(stats.norm.pdf(u, v, 0.3)), 0.0, 6, points=[1.1])[0])
    off = GaussianFactor(("m",), (0.6,), ((0.05,),), (0.0,))  # posterior: about 1.0 +- 0.2
    ev = log_evidence(run_tmcmc(model, draws=400, chains=12, seed=5, mcmc_steps=3,
                                proposal_scale=0.8,
                                reference=_reference((2.0, 9.0), (0.5, 0.5), gaussian=off)))
    err = ev - exact
    assert abs(err.mean()) < 3 * err.std() / np.sqrt(len(err)) + 0.03
    assert err.std() < 0.2


def test_without_a_reference_the_path_is_unchanged(linear_gaussian):
    model, _ = linear_gaussian
    a = run_tmcmc(model, draws=200, chains=1, seed=11)
    b = run_tmcmc(model, draws=200, chains=1, seed=11, reference=None)
    assert np.array_equal(log_evidence(a), log_evidence(b))
    assert np.array_equal(a.posterior["w"].values, b.posterior["w"].values)


def test_reference_needs_a_scalar_free_variable_of_the_model(linear_gaussian):
    model, _ = linear_gaussian
    with pytest.raises(ValueError, match="not in the model"):
        run_tmcmc(model, draws=50, chains=1, seed=0, reference=_reference())


# --------------------------------------------------------------------------------------------
# Adaptive moves and the stated precision of the evidence
# --------------------------------------------------------------------------------------------


def test_stage_variance_of_independent_particles_is_that_of_a_mean():
    from harvester.inference.tmcmc import stage_log_variance
    rng = np.random.default_rng(0)
    log_w = rng.normal(0.0, 0.8, 4000)
    w = np.exp(log_w)
    expected = np.var(w) / (len(w) * np.mean(w) ** 2)
    assert stage_log_variance(log_w, np.arange(len(w))) == pytest.approx(expected, rel=1e-3)


def test_stage_variance_grows_when_copies_share_their_weights():
    """Ten copies of each particle with one weight: the mean is no better than that of the
    particles' one-tenth, so the variance is ten times that of independent ones."""
    from harvester.inference.tmcmc import stage_log_variance
    rng = np.random.default_rng(1)
    base = rng.normal(0.0, 0.8, 400)
    log_w = np.repeat(base, 10)
    families = np.repeat(np.arange(400), 10)
    independent = stage_log_variance(log_w, np.arange(log_w.size))
    assert stage_log_variance(log_w, families) == pytest.approx(10 * independent, rel=0.05)


def test_mixture_fit_finds_two_separated_components():
    from harvester.inference.tmcmc import fit_gaussian_mixture
    rng = np.random.default_rng(2)
    x = np.vstack([rng.normal([-4.0, 0.0], 0.5, (300, 2)), rng.normal([4.0, 1.0], 1.0, (300, 2))])
    mix = fit_gaussian_mixture(x, np.ones(len(x)), 3, rng)
    assert len(mix.weights) == 2
    order = np.argsort(mix.means[:, 0])
    np.testing.assert_allclose(mix.means[order], [[-4.0, 0.0], [4.0, 1.0]], atol=0.2)
    draws = mix.draw(rng, 20000)
    assert np.mean(draws[:, 0] > 0) == pytest.approx(0.5, abs=0.03)
    grid = np.linspace(-8, 9, 400)
    xx, yy = np.meshgrid(grid, grid)
    density = np.exp(mix.log_density(np.column_stack([xx.ravel(), yy.ravel()])))
    assert density.sum() * (grid[1] - grid[0]) ** 2 == pytest.approx(1.0, abs=0.01)


def test_correlation_of_a_population_with_itself_and_with_a_shuffle():
    from harvester.inference.tmcmc import mean_abs_correlation
    rng = np.random.default_rng(3)
    x = rng.normal(size=(2000, 3))
    assert mean_abs_correlation(x, x) == pytest.approx(1.0)
    assert mean_abs_correlation(x, rng.permutation(x)) < 0.05


def test_the_last_stage_moves_on_while_the_mean_log_posterior_rises():
    """A population climbing by 1 nat per move against a standard error of 0.3 has not settled;
    one that rose 0.2 over the last three moves has; fewer moves than the window never has."""
    assert still_rising([0.0, 1.0, 2.0], se=0.3)
    assert still_rising([0.0, 1.0, 2.0, 3.0, 4.0], se=0.3)
    assert not still_rising([0.0, 4.0, 4.1, 4.2, 4.2], se=0.3)


@pytest.mark.slow  # 16 chains: a statistical check
def test_stated_evidence_errors_cover_the_spread_of_chains(linear_gaussian):
    """Default (adaptive) settings, 16 chains of 400 particles: each chain's error against the
    exact log evidence, over its stated standard error, spreads like a standard normal."""
    model, exact = linear_gaussian
    idata = run_tmcmc(model, draws=400, chains=16, seed=31)
    err = log_evidence(idata) - exact
    se = idata.sample_stats["log_evidence_se"].values
    z = err / se
    assert abs(err.mean()) < 3 * err.std() / np.sqrt(len(err)) + 0.05
    assert 0.5 < np.sqrt(np.mean(z**2)) < 2.0, (err, se)
    moves = idata.sample_stats["mcmc_steps"].values
    assert np.nanmax(moves) <= 30 and np.nanmin(moves) >= 2


def test_component_steps_leave_a_two_cluster_target_invariant():
    # Metropolis-Hastings with steps from each particle's own component, on a target made of
    # two clusters of very different sizes: exact draws stay exact draws (detailed balance
    # holds only with the Hastings term, since a step can land in the other component)
    from harvester.inference.tmcmc import GaussianMixture, component_steps

    means = np.array([[0.0, 0.0], [6.0, 1.0]])
    chols = np.array([np.diag([0.05, 0.1]), np.array([[1.5, 0.0], [0.9, 1.2]])])
    target = GaussianMixture(np.array([0.3, 0.7]), means, chols)
    proposal = GaussianMixture(np.array([0.5, 0.5]), means, chols * 1.2)
    rng = np.random.default_rng(4)
    x = target.draw(rng, 20000)
    logp = target.log_density(x)
    accepted = 0
    for _ in range(40):
        step, log_q = component_steps(proposal, x, rng.standard_normal(x.shape), 2.0)
        new_logp = target.log_density(x + step)
        accept = np.log(rng.random(len(x))) < new_logp - logp + log_q
        x[accept], logp[accept] = (x + step)[accept], new_logp[accept]
        accepted += accept.sum()
    assert accepted / (40 * len(x)) > 0.2
    small = target.component_of(x) == 0
    assert small.mean() == pytest.approx(0.3, abs=0.015)
    np.testing.assert_allclose(x[small].std(axis=0), [0.05, 0.1], rtol=0.05)
    np.testing.assert_allclose(x[~small].mean(axis=0), [6.0, 1.0], atol=0.06)
    np.testing.assert_allclose(np.cov(x[~small].T), chols[1] @ chols[1].T, atol=0.12)
