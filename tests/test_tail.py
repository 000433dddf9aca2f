"""The tail p-value (inference.tail) against exact answers: the maximum of independent
chi-square(1) scores, whose distribution is known in closed form."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from harvester.inference.tail import gpd_sample, pwm_fit, rank_p, tail_p

#: Squared scores per replicate (the detection's statistic is the largest of many).
SCORES = 40


def exact_sf(x: float) -> float:
    """P(max of SCORES chi-square(1) > x)."""
    return float(-np.expm1(SCORES * stats.chi2.logcdf(x, 1)))


def draws(rng: np.random.Generator, count: int) -> np.ndarray:
    return np.max(rng.standard_normal((count, SCORES)) ** 2, axis=1)


def test_pwm_recovers_a_known_generalised_pareto():
    rng = np.random.default_rng(0)
    for xi, scale in ((0.0, 2.0), (0.2, 1.0), (-0.2, 3.0)):
        xi_hat, s_hat = pwm_fit(gpd_sample(rng, xi, scale, 20000))
        assert xi_hat == pytest.approx(xi, abs=0.03)
        assert s_hat == pytest.approx(scale, rel=0.05)


def test_tail_p_reaches_below_the_rank_floor_near_the_exact_value():
    """400 replicates: the rank cannot go below 1/401; the tail p-value reaches the exact one's
    order (measured on 200 sets: at p = 3e-4 its ratio to the exact one spans 0.38-6.3 from
    the 5 % to the 95 % quantile, median 1.5), rarely far below it."""
    rng = np.random.default_rng(1)
    for x in (20.0, 25.0):
        exact = exact_sf(x)
        ratios = np.array([tail_p(x, draws(rng, 400), seed=i).p / exact for i in range(100)])
        assert 0.5 < np.median(ratios) < 5.0, (x, np.median(ratios))
        assert np.mean(ratios < 1 / 3) <= 0.1, (x, np.mean(ratios < 1 / 3))
    res = tail_p(30.0, draws(rng, 400))
    assert res.method == "tail" and res.p < 0.1 * (1 / 401)


def test_tail_p_holds_its_nominal_rate_under_the_null():
    """An observed value drawn like the replicates: P(p < a) <= a within its binomial
    interval, for a = 0.01 and 0.002 (3000 records)."""
    rng = np.random.default_rng(2)
    n = 3000
    p = np.array([tail_p(float(draws(rng, 1)[0]), draws(rng, 400), seed=i).p
                  for i in range(n)])
    for a in (0.01, 0.002):
        k = int(np.sum(p < a))
        assert k <= stats.binom.ppf(0.99, n, a), (a, k)


def test_rank_used_where_replicates_reach_the_observation():
    reps = np.arange(400, dtype=float)
    res = tail_p(200.0, reps)
    assert res.method == "rank" and res.p == rank_p(200.0, reps) == pytest.approx(201 / 401)
    assert tail_p(-np.inf, reps).p == 1.0


def test_too_few_replicates_keep_the_rank_and_say_why():
    res = tail_p(100.0, np.arange(60, dtype=float))
    assert res.method == "rank" and res.p == pytest.approx(1 / 61)
    assert "too few" in res.note
