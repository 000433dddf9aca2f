"""Bridge-sampling evidence against cases with exact answers."""

import numpy as np
import pytest
from scipy import integrate, stats

from harvester.inference.evidence import (bridge_log_evidence, chains_bridge_log_evidence,
                                effective_count)


def linear_gaussian(seed: int, d: int = 4, n: int = 40, s0: float = 2.0, noise: float = 0.5):
    """y = A theta + e, theta ~ N(0, s0^2 I): exact log Z, posterior mean and covariance."""
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, d))
    y = A @ rng.normal(0.0, s0, d) + rng.normal(0.0, noise, n)
    log_z = stats.multivariate_normal(np.zeros(n), s0**2 * A @ A.T + noise**2 * np.eye(n)
                                      ).logpdf(y)
    prec = A.T @ A / noise**2 + np.eye(d) / s0**2
    cov = np.linalg.inv(prec)
    mean = cov @ A.T @ y / noise**2

    def log_target(theta):
        theta = np.atleast_2d(theta)
        r = y[None, :] - theta @ A.T
        loglike = -0.5 * np.sum(r * r, axis=1) / noise**2 - n * np.log(noise * np.sqrt(2 * np.pi))
        return loglike + stats.norm(0.0, s0).logpdf(theta).sum(axis=1)

    return log_target, log_z, mean, cov


def resampled_posterior(rng, mean, cov, n: int = 300) -> np.ndarray:
    """n rows as a resampled SMC population holds them: ~n/2 distinct draws, duplicated."""
    distinct = rng.multivariate_normal(mean, cov, n // 2)
    return distinct[rng.integers(0, len(distinct), n)]


def test_the_bridge_estimate_recovers_a_conjugate_models_evidence():
    errors, ses = [], []
    for seed in range(40):
        log_target, log_z, mean, cov = linear_gaussian(seed)
        rng = np.random.default_rng(1000 + seed)
        est = bridge_log_evidence(log_target, resampled_posterior(rng, mean, cov), rng)
        errors.append(est.log_evidence - log_z)
        ses.append(est.se)
    errors, ses = np.array(errors), np.array(ses)
    assert np.max(np.abs(errors)) < 0.15
    assert np.max(ses) < 0.1
    # the stated error is honest: standardised errors centred (no bias from fitting the
    # proposal on the estimator's samples: -3.5 before the split) and about unit-wide
    z = errors / ses
    assert abs(np.mean(z)) < 0.6
    assert 0.6 < np.std(z) < 1.5


def test_a_posterior_piled_against_a_prior_bound():
    """One parameter with a prior truncated at 0 whose posterior sits at the bound (an added
    effect the data do not need): the bridge still agrees with quadrature."""
    prior = stats.truncnorm(0.0, np.inf, loc=0.0, scale=3.0)
    data_mean, data_sd = -0.4, 0.5  # the likelihood peaks below the bound

    def log_target(theta):
        t = np.atleast_2d(theta)[:, 0]
        return prior.logpdf(t) + stats.norm(data_mean, data_sd).logpdf(t)

    exact = np.log(integrate.quad(lambda t: np.exp(log_target(np.array([[t]]))[0]), 0, 20)[0])
    post = stats.truncnorm((0 - data_mean) / data_sd, np.inf, loc=data_mean, scale=data_sd)
    rng = np.random.default_rng(3)
    samples = post.rvs(size=(400, 1), random_state=rng)
    est = bridge_log_evidence(log_target, samples, rng)
    assert abs(est.log_evidence - exact) < max(4 * est.se, 0.05)


def test_chains_that_disagree_widen_the_stated_error():
    """Two chains, one of whose populations has not settled (drawn from a posterior too
    narrow): the pooled estimate's error is at least the chains' scatter over sqrt(2), and
    wider than the formula's alone."""
    log_target, log_z, mean, cov = linear_gaussian(7)
    rng = np.random.default_rng(11)
    good = resampled_posterior(rng, mean, cov)
    narrow = resampled_posterior(rng, mean, 0.3 * cov)
    est = chains_bridge_log_evidence(log_target, [good, narrow], rng)
    a, b = est.chain_log_evidence
    assert est.se >= abs(a - b) / 2 - 1e-12
    assert est.se > 3 * est.formula_se
    # settled chains: the formula's error stands
    fine = chains_bridge_log_evidence(
        log_target, [resampled_posterior(rng, mean, cov) for _ in range(2)], rng)
    assert abs(fine.log_evidence - log_z) < 4 * fine.se


def test_a_chain_that_missed_the_mode_is_left_out():
    """A chain whose population sits far from the posterior's mass (stuck in a minor mode)
    estimates a far smaller evidence on its own; it is left out and the others' pooled
    estimate stands."""
    log_target, log_z, mean, cov = linear_gaussian(9)
    rng = np.random.default_rng(5)
    good = [resampled_posterior(rng, mean, cov) for _ in range(2)]
    stuck = resampled_posterior(rng, mean + 8.0 * np.sqrt(np.diag(cov)), 0.2 * cov)
    est = chains_bridge_log_evidence(log_target, [*good, stuck], rng, missed_mode_nats=5.0)
    assert len(est.chain_log_evidence) == 2
    assert abs(est.log_evidence - log_z) < 4 * est.se


def test_the_effective_count_discounts_duplicates():
    x = np.repeat(np.arange(10.0)[:, None], 3, axis=0)
    assert effective_count(x) == pytest.approx(10.0)
    assert effective_count(np.arange(12.0)[:, None]) == pytest.approx(12.0)


def test_too_few_samples_is_an_error():
    with pytest.raises(ValueError, match="distinct posterior rows"):
        bridge_log_evidence(lambda t: np.zeros(len(t)), np.zeros((3, 4)),
                            np.random.default_rng(0))


@pytest.mark.slow  # 4 TMCMC chains on a device record
@pytest.mark.filterwarnings("ignore::UserWarning", "ignore::RuntimeWarning")
def test_the_diagnosis_evidence_agrees_with_tmcmc_and_is_more_precise():
    """On a tanh-device record, the bridge estimate from TMCMC's final population lies within
    TMCMC's own chain-to-chain scatter of its pooled estimate, and its stated error is
    smaller than that scatter."""
    from harvester.inference.map_fit import chain_problem
    from harvester.diagnosis.name.confirm import fit_structure
    from harvester.diagnosis.name.results import ConfirmSettings
    from harvester.synthetic.measured import TABLE1_KNOWN, TANH_TABLE5, measured_recording
    from harvester.inference.problems import make_problem
    from harvester.inference.priors import PriorSpec
    from harvester.model.structures import structure

    rec, _ = measured_recording(("tanh_friction",), {**TABLE1_KNOWN, **TANH_TABLE5}, 7.0, 5)
    base = structure("tanh")
    raw = make_problem(rec, base, TABLE1_KNOWN, window=(256, len(rec) - 128))
    problem = chain_problem(raw, 0.1, 20.0, 8)
    priors = {"c_m": PriorSpec("c_m", 110.0, 50.0, "N s/m"),
              "F_c": PriorSpec("F_c", 10.0, 5.0, "N"),
              "beta": PriorSpec("beta", 100.0, 100.0, "s/m"),
              "sigma": PriorSpec("sigma", 0.02, 0.02, "m/s^2")}
    fit = fit_structure(problem, base, priors,
                        ConfirmSettings(particles=150, chains=4, seed=2))
    chains = fit.log_evidence_chains
    assert fit.bridge is not None and fit.log_evidence == fit.bridge.log_evidence
    assert fit.bridge.se < 0.5
    spread = max(np.std(chains, ddof=1), 0.5)
    assert abs(fit.bridge.log_evidence - fit.tmcmc_log_evidence) < 3 * spread + 1.0


# ---------------------------------------------------------------- importance sampling


def _normal_prior(s0: float, d: int):
    """A N(0, s0^2) prior per coordinate as ``MixtureProposal`` takes it."""
    return (lambda u: stats.norm(0.0, s0).logpdf(u),
            lambda rng, n: rng.normal(0.0, s0, (n, d)))


def test_importance_sampling_recovers_a_conjugate_models_evidence_within_its_error():
    from harvester.inference.importance import (Component, MixtureProposal,
                                                importance_log_evidence)
    z = []
    for seed in range(20):
        log_target, log_z, mean, cov = linear_gaussian(seed)
        proposal = MixtureProposal(*_normal_prior(2.0, 4),
                                   (Component((0, 1, 2, 3), mean, 1.5**2 * cov, 0.9),), 0.1)
        est = importance_log_evidence(log_target, proposal, 1000, np.random.default_rng(seed))
        assert est.reliable and est.se < 0.1
        z.append((est.log_evidence - log_z) / est.se)
    assert np.max(np.abs(z)) < 4.0
    assert abs(np.mean(z)) < 3.0 / np.sqrt(len(z))


def test_importance_sampling_says_when_its_proposal_misses_the_posterior():
    from harvester.inference.importance import (Component, MixtureProposal,
                                                importance_log_evidence)
    log_target, log_z, mean, cov = linear_gaussian(3)
    # a component far from the posterior: the prior's few lucky draws carry all the weight
    proposal = MixtureProposal(*_normal_prior(2.0, 4),
                               (Component((0, 1), -mean[:2], 0.01 * np.eye(2), 0.9),), 0.1)
    est = importance_log_evidence(log_target, proposal, 1000, np.random.default_rng(0))
    assert not est.reliable and est.pareto_k > 0.7


def test_a_mixture_proposal_is_a_normalised_density_and_draws_from_it():
    from harvester.inference.importance import Component, MixtureProposal
    proposal = MixtureProposal(*_normal_prior(1.0, 2),
                               (Component((0,), np.array([1.5]), np.array([[0.04]]), 0.5),
                                Component((0, 1), np.array([-1.0, 0.5]),
                                          np.array([[0.3, 0.1], [0.1, 0.2]]), 0.3)), 0.2)
    grid = np.linspace(-7.0, 7.0, 561)
    uu, vv = np.meshgrid(grid, grid, indexing="ij")
    dens = np.exp(proposal.log_density(np.column_stack([uu.ravel(), vv.ravel()])))
    assert integrate.trapezoid(integrate.trapezoid(dens.reshape(uu.shape), grid), grid) == \
        pytest.approx(1.0, abs=1e-4)
    draws = proposal.draw(np.random.default_rng(1), 40_000)
    assert draws[:, 0].mean() == pytest.approx(0.2 * 0 + 0.5 * 1.5 + 0.3 * -1.0, abs=0.02)


def test_the_sigma_marginal_likelihood_matches_quadrature():
    from harvester.inference.likelihood import gaussian_loglike, sigma_marginal_loglike
    prior = stats.truncnorm(-0.07 / 0.03, np.inf, loc=0.07, scale=0.03)
    n, temper = 2000, 0.7
    sse = np.array([n * 0.05**2, n * 0.09**2, np.nan])
    got = sigma_marginal_loglike(sse, n, temper, prior.logpdf)
    for s, g in zip(sse[:2], got[:2]):
        peak = temper * gaussian_loglike(s, n, np.sqrt(s / n))
        f = lambda sg: np.exp(temper * gaussian_loglike(s, n, sg) + prior.logpdf(sg) - peak)  # noqa: E731
        hat = np.sqrt(s / n)
        exact = np.log(integrate.quad(f, 0.8 * hat, 1.2 * hat, points=[hat])[0]) + peak
        assert g == pytest.approx(exact, abs=1e-6)
    assert got[2] == -np.inf


def test_an_adapted_proposal_recovers_the_evidence_a_misplaced_one_cannot_state():
    from harvester.inference.importance import (Component, MixtureProposal,
                                                importance_log_evidence)
    log_target, log_z, mean, cov = linear_gaussian(5)
    sd = np.sqrt(np.diag(cov))
    # narrow and off the posterior's centre: heavy-tailed weights
    proposal = MixtureProposal(*_normal_prior(2.0, 4),
                               (Component((0, 1, 2, 3), mean + 1.5 * sd, 0.3 * cov, 0.9),), 0.1)
    first = importance_log_evidence(log_target, proposal, 1000, np.random.default_rng(0))
    assert not first.reliable
    est = importance_log_evidence(log_target, proposal, 1000, np.random.default_rng(0), adapt=2)
    assert est.reliable
    assert est.log_evidence == pytest.approx(log_z, abs=4.0 * est.se + 0.05)


def test_a_component_with_a_covariance_that_is_not_positive_definite_still_draws():
    # a Laplace covariance from a Hessian that is not positive definite at a fit's end
    from harvester.inference.importance import Component

    comp = Component((0, 1), np.zeros(2), np.array([[1.0, 1.2], [1.2, 1.0]]), 0.5)
    dist = comp.distribution()
    draws = dist.rvs(size=200, random_state=np.random.default_rng(0))
    assert np.isfinite(dist.logpdf(draws)).all()
