"""Intervals for correlated residuals against exact answers: least squares with noise low-passed
as the study's records are, where the estimate's covariance is known in closed form."""

import numpy as np
import pytest
from scipy import signal

from harvester.inference.correlated_residuals import (Adjustment, adjustment_matrix, lag_window,
                                                      prior_precision, sandwich)

N = 2000
FS, CUTOFF = 256.0, 20.0


def lowpassed(rng, n, cutoff=CUTOFF):
    sos = signal.butter(8, cutoff, fs=FS, output="sos")
    return signal.sosfiltfilt(sos, rng.standard_normal(n + 400))[200:-200]


@pytest.fixture(scope="module")
def regression():
    """Two smooth regressors (below 8 Hz) and the exact covariance of the least-squares
    estimate under noise e = low-passed white: (X^T X)^-1 X^T R X (X^T X)^-1, R from the
    filter's own autocovariance."""
    rng = np.random.default_rng(1)
    x = np.column_stack([lowpassed(rng, N, 8.0), lowpassed(rng, N, 3.0)])
    sos = signal.butter(8, CUTOFF, fs=FS, output="sos")
    impulse = signal.sosfiltfilt(sos, np.r_[np.zeros(300), 1.0, np.zeros(300)])
    acf = np.correlate(impulse, impulse, "full")[impulse.size - 1:]
    lags = np.abs(np.subtract.outer(np.arange(N), np.arange(N)))
    r = np.where(lags < acf.size, acf[np.minimum(lags, acf.size - 1)], 0.0)
    xtx_inv = np.linalg.inv(x.T @ x)
    exact = xtx_inv @ x.T @ r @ x @ xtx_inv
    return x, exact, acf[0]


def test_sandwich_matches_the_exact_covariance_where_eq10_falls_short(regression):
    """Over 200 noise draws, the sandwich's sds are within 15 % of the exact ones on average,
    while eq. (10)'s (sigma^2 (X^T X)^-1) are more than 2 x too small, and the adjusted 95 %
    intervals cover the truth 87-99 % of the time (measured: sd ratios 0.97, 0.97; eq. (10)'s
    0.38; coverage 95.5 % and 90.5 %, the slower regressor's window a little short)."""
    x, exact, var = regression
    rng = np.random.default_rng(2)
    ratios, naive, cover = [], [], []
    for _ in range(200):
        e = lowpassed(rng, N)
        beta = np.linalg.lstsq(x, e, rcond=None)[0]  # the truth is 0
        r = e - x @ beta
        _, lag = lag_window(r)
        h, v = sandwich(x, r, lag)
        cov = np.linalg.inv(h) @ v @ np.linalg.inv(h)
        ratios.append(np.sqrt(np.diag(cov) / np.diag(exact)))
        naive.append(np.sqrt(np.diag(np.linalg.inv(h)) / np.diag(exact)))
        cover.append(np.abs(beta) < 1.96 * np.sqrt(np.diag(cov)))
    assert np.mean(ratios, axis=0) == pytest.approx([1.0, 1.0], abs=0.15)
    assert np.all(np.mean(naive, axis=0) < 0.5)
    assert np.all((np.mean(cover, axis=0) > 0.87) & (np.mean(cover, axis=0) < 0.99))


def test_white_residuals_leave_the_posterior_unchanged():
    """Over 20 draws of white residuals the adjusted sds average eq. (10)'s within 5 % (one
    draw scatters by about 10 %: the taper's 50 lags of sampled autocovariance)."""
    rng = np.random.default_rng(3)
    x = np.column_stack([lowpassed(rng, N, 8.0), np.ones(N)])
    taus, ratios = [], []
    for _ in range(20):
        r = 0.1 * rng.standard_normal(N)
        tau, lag = lag_window(r)
        h, v = sandwich(x, r, lag)
        post = np.linalg.inv(h)
        mat = adjustment_matrix(post, h, v)
        taus.append(tau)
        ratios.append(np.sqrt(np.diag(mat @ post @ mat.T) / np.diag(post)))
    assert np.mean(taus) == pytest.approx(1.0, abs=0.1)
    assert np.mean(ratios, axis=0) == pytest.approx([1, 1], abs=0.05)


def test_the_prior_part_of_the_posterior_is_kept():
    """A posterior twice as precise as the likelihood (prior = likelihood) with V = 4 H: the
    adjusted precision is the prior's H plus H V^-1 H = H / 4, covariance 0.8 H^-1."""
    h = np.diag([4.0, 9.0])
    mat = adjustment_matrix(np.linalg.inv(2.0 * h), h, 4.0 * h, prior_precision=h)
    assert mat @ np.linalg.inv(2.0 * h) @ mat.T == pytest.approx(np.linalg.inv(1.25 * h))


def test_prior_curvature_of_each_family():
    """Normal: 1 / sd^2; log-normal at its median: (1 + 0 ...) from ln x's; log-uniform: its
    curvature is negative, so none; a parameter without a prior: none."""
    from harvester.model.priors import PriorSpec
    priors = {"a": PriorSpec("a", 100.0, 5.0, ""), "b": PriorSpec.log_normal("b", 2.0, 0.5, ""),
              "c": PriorSpec.log_uniform("c", 1.0, 100.0, "")}
    prec = np.diag(prior_precision(priors, ["a", "b", "c", "d"], np.array([90.0, 2.0, 10.0, 1.0])))
    # log-normal: -(d^2/dx^2)[-(ln x - ln 2)^2 / (2 s^2) - ln x] at x = 2 is (1/s^2 - 1) / x^2
    assert prec == pytest.approx([1 / 25.0, (1 / 0.25 - 1.0) / 4.0, 0.0, 0.0], rel=1e-4)


def test_adjustment_round_trips_and_scales_about_its_center():
    adj = Adjustment(("a", "b"), (1.0, 2.0), ((2.0, 0.0), (0.0, 3.0)), 5.5, 28, (2.0, 3.0))
    again = Adjustment.from_json(adj.to_json())
    assert again == adj
    assert again.apply(np.array([[2.0, 2.0], [1.0, 3.0]])) == pytest.approx(
        np.array([[3.0, 2.0], [1.0, 5.0]]))


@pytest.fixture(scope="module")
def tanh_problem():
    """The study's tanh problem on the bundled training record (as tests/test_identify_study)."""
    from pathlib import Path

    import yaml

    from harvester.data.daq import read_raw_record, to_accelerations
    from harvester.data.signals import filter_recording
    from harvester.inference.problems import make_problem
    root = Path(__file__).resolve().parents[1]
    cfg = yaml.safe_load((root / "config/config.yaml").read_text())
    raw, meta = read_raw_record(root / "data/raw/training.csv", root / "data/raw/training.json")
    pre, rig = cfg["preprocess"], cfg["rig"]
    rec = filter_recording(to_accelerations(raw, meta), pre["lowpass_hz"], pre["filter_order"])
    start = pre["training_lead_in"]
    return make_problem(rec, "tanh", {"M": rig["M"], "m": rig["m"], "k": rig["k"]},
                        window=(start, start + pre["training_samples"]),
                        output_filter=(pre["lowpass_hz"], pre["filter_order"]))


def _draws(problem, rng, fixed=None):
    """400 draws of eq. (10)'s Laplace posterior at the study's posterior mean (its curvature
    from the output's Jacobian), sigma at its mean; ``fixed``: a parameter held constant."""
    from harvester.inference.correlated_residuals import output_jacobian
    center = np.array([105.4, 12.16, 81.7])
    r, jac = output_jacobian(problem, center, np.array([0.1, 0.005, 0.1]), 0.0953)
    cov = np.linalg.inv(jac.T @ jac / np.mean(r ** 2))
    theta = rng.multivariate_normal(center, cov, 400)
    if fixed is not None:
        theta[:, fixed] = center[fixed]
    return np.column_stack([theta, np.full(400, 0.0953)])


def test_the_study_record_widens_and_what_cannot_be_adjusted_is_said(tanh_problem, caplog,
                                                                     monkeypatch):
    """On the low-passed record the intervals widen about 2.4 x (the study's posterior:
    2.33-2.44 x); draws that do not vary, and a curvature that is singular, give no
    adjustment and a warning instead of an error after a long TMCMC."""
    import harvester.inference.correlated_residuals as cr
    rng = np.random.default_rng(4)
    adj = cr.correlation_adjustment(tanh_problem, _draws(tanh_problem, rng))
    assert adj is not None and adj.names == ("c_m", "F_c", "beta")
    assert all(1.8 < f < 3.0 for f in adj.inflation), adj.inflation
    assert cr.correlation_adjustment(tanh_problem, _draws(tanh_problem, rng, 1)) is None
    assert "F_c do not vary" in caplog.text

    def flat(problem, center, steps, sigma):
        r, jac = output_jacobian(problem, center, steps, sigma)
        jac[:, 1] = 0.0
        return r, jac
    output_jacobian = cr.output_jacobian
    draws = _draws(tanh_problem, rng)
    monkeypatch.setattr(cr, "output_jacobian", flat)
    assert cr.correlation_adjustment(tanh_problem, draws) is None
    assert "singular" in caplog.text


def test_the_bread_is_the_sum_of_squares_curvature():
    """For residuals linear in theta, SSE'' = 2 X^T X exactly; for y - a exp(b t) it is
    Gauss-Newton's 2 J^T J plus the residuals' own curvature (checked against the closed
    form)."""
    from harvester.inference.correlated_residuals import sse_curvature
    rng = np.random.default_rng(5)
    x = rng.standard_normal((200, 2))
    y = x @ np.array([1.0, -2.0]) + rng.standard_normal(200)

    class Linear:
        def residuals(self, theta):
            return y[None, :] - theta[:, :2] @ x.T

    hess = sse_curvature(Linear(), np.array([1.0, -2.0]), np.array([0.1, 0.1]), 1.0)
    assert hess == pytest.approx(2.0 * x.T @ x, rel=1e-8)
    t = np.linspace(0.0, 1.0, 100)
    obs = 2.0 * np.exp(0.5 * t) + 0.3 * np.sin(9.0 * t)  # a misfit the model cannot take

    class Exponential:
        def residuals(self, theta):
            return obs[None, :] - theta[:, :1] * np.exp(theta[:, 1:2] * t[None, :])

    a, b = 2.0, 0.5
    e = np.exp(b * t)
    r = obs - a * e
    ja, jb = -e, -a * t * e  # d r / d(a, b)
    exact = 2.0 * np.array([[ja @ ja, ja @ jb], [ja @ jb, jb @ jb]]) + 2.0 * np.array(
        [[0.0, r @ (-t * e)], [r @ (-t * e), r @ (-a * t * t * e)]])
    hess = sse_curvature(Exponential(), np.array([a, b]), np.array([1e-3, 1e-3]), 1.0)
    assert hess == pytest.approx(exact, rel=1e-4)


def test_a_posterior_cut_by_its_bound_is_not_rescaled():
    """EMPS's c_quad (mean 32, sd 31, bound 0) is cut; c_m (407 +- 8.5, bound 0) and an
    unbounded offset are not."""
    from harvester.inference.correlated_residuals import cut_by_bound
    from harvester.model.priors import PriorSpec
    priors = {"c_m": PriorSpec("c_m", 200.0, 100.0, ""), "c_quad": PriorSpec("c_quad", 0.0, 50.0,
                                                                             ""),
              "F_offset": PriorSpec("F_offset", 0.0, 10.0, "", -np.inf)}
    names = ["c_m", "c_quad", "F_offset"]
    assert cut_by_bound(priors, names, np.array([407.0, 32.3, -3.2]),
                        np.array([8.5, 30.7, 0.75])) == ["c_quad"]
