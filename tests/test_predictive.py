"""Likelihood (eq. 10), posterior predictive bounds and validation metrics."""

import numpy as np
import pandas as pd
import pytest
from scipy.signal import butter, sosfilt

from harvester.inference.problems import make_problem
from harvester.model.simulate import acquired
from harvester.inference.predictive import (NOMINAL_OUTSIDE, PredictiveBand, load_band, mlpd,
                                  posterior_predictive, save_band, validation_rows)

FS = 256.0
KNOWN = {"M": 12.8, "m": 8.0, "k": 250.0}
TRUE = np.array([109.5, 11.86, 88.35, 0.1])  # c_m, F_c, beta, sigma


def recording(n=3000, seed=0, noise=0.1):
    rng = np.random.default_rng(seed)
    y = sosfilt(butter(4, 15.0, fs=FS, output="sos"), rng.standard_normal(n))
    y *= 4.0 / np.abs(y).max()
    df = pd.DataFrame({"time": np.arange(n) / FS, "base_acc": y, "rel_acc": np.zeros(n)})
    clean = make_problem(df, "tanh", KNOWN).simulate(TRUE).rel_acc[0]
    df["rel_acc"] = clean + noise * rng.standard_normal(n)
    return df, clean


def test_loglike_is_eq10_and_fails_to_minus_inf():
    df, clean = recording(800)
    p = make_problem(df, "tanh", KNOWN, window=(100, 700))
    # the record meets the model through the model's acquisition filter (its noise above the
    # anti-alias edge is not compared)
    observed = acquired(df["rel_acc"].to_numpy(), 1.0 / FS, p.oversample)[100:700]
    np.testing.assert_array_equal(p.observed, observed)
    r = observed - clean[100:700]
    expected = -300 * np.log(2 * np.pi * 0.01) - 0.5 * np.sum(r**2) / 0.01
    ll = p.loglike(np.array([TRUE, [109.5, 11.86, 88.35, -1.0], [np.nan, 1, 1, 0.1]]))
    assert ll[0] == pytest.approx(expected, rel=1e-10)
    assert ll[1] == -np.inf and ll[2] == -np.inf


def test_true_model_gives_nominal_predictive_coverage():
    df, clean = recording(6000, seed=3)
    p = make_problem(df, "tanh", KNOWN)
    rng = np.random.default_rng(4)
    theta = TRUE + rng.normal(0, [1.0, 0.05, 1.0, 0.0005], size=(50, 4))
    band = posterior_predictive(p, theta, df["base_acc"].to_numpy(), df["time"].to_numpy())
    rows = {r["bounds"]: r for r in validation_rows("tanh", "training", df["rel_acc"].to_numpy(), band)}
    pred = rows["predictive"]
    for k in (1, 2, 3):
        assert pred[f"outside_{k}sigma"] == pytest.approx(NOMINAL_OUTSIDE[k], abs=0.02)
    # parameter-only bounds are far too narrow here: most samples fall outside
    assert rows["parameter"]["outside_3sigma"] > 0.5
    assert pred["mlpd"] == pytest.approx(-0.5 * np.log(2 * np.pi * 0.01) - 0.5, abs=0.05)
    assert pred["nrmse"] == pytest.approx(0.1 / np.std(df["rel_acc"]), rel=0.1)


def test_bounds_contain_mean_and_coverage_counts_samples():
    t = np.arange(5) / FS
    responses = np.array([[0.0, 1.0, 2.0, 3.0, 4.0], [0.2, 1.2, 2.2, 3.2, 4.2]])
    band = PredictiveBand(t, responses, np.array([0.1, 0.1]))
    for kind in ("parameter", "predictive"):
        sd = band.sd(kind)
        assert np.all(band.mean - 3 * sd <= band.mean) and np.all(band.mean + 3 * sd >= band.mean)
    measured = band.mean + np.array([0.0, 0.5, 0.0, -0.5, 0.0])
    rows = validation_rows("m", "training", measured, band)
    par = [r for r in rows if r["bounds"] == "parameter"][0]
    # parameter sd = 0.1414; 0.5 is outside 1, 2 and 3 sd: 2 of 5 samples
    assert par["outside_1sigma"] == par["outside_3sigma"] == pytest.approx(0.4)
    assert np.isfinite(mlpd(measured, band, "predictive"))


def test_band_file_round_trip(tmp_path):
    band = PredictiveBand(np.arange(3.0), np.ones((2, 3)), np.array([0.1, 0.2]))
    save_band(tmp_path / "b.npz", band, np.zeros(3), "tanh", "unseen")
    back, measured, model, data = load_band(tmp_path / "b.npz")
    np.testing.assert_allclose(back.responses, band.responses)
    assert (model, data) == ("tanh", "unseen") and measured.shape == (3,)
