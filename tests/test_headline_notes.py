"""The headline's notes on the paper's numbers that cannot all hold (``study.summary``)."""

import numpy as np
import pandas as pd
import pytest

from harvester.study.summary import COLUMNS, figure7_notes, what_cannot_hold, with_notes


def _posterior(c_m: float, sigma: float) -> pd.DataFrame:
    return pd.DataFrame({"parameter": ["c_m", "sigma"], "mean": [c_m, sigma]})


def test_the_notes_compute_the_paper_numbers_that_cannot_hold():
    posts = {"linear": _posterior(430.0, 0.25), "tanh": _posterior(110.0, 0.1)}
    notes = what_cannot_hold(posts, log_bf=1850.0, ensemble_ratio=0.03)
    # eq. (10) with the paper's own sigmas and N = 2000
    assert f"{2000 * np.log(0.1035 / 0.0956):.1f} nats" in notes["eq. (12)"]
    assert "158.8 nats" in notes["eq. (12)"] and "134.6 of them back" in notes["eq. (12)"]
    ours = 2000 * np.log(0.25 / 0.1)
    assert f"{1850.0 - ours:+.1f}" in notes["eq. (12)"]
    # misfit beyond the tanh model's: the paper's and ours
    table3 = notes["Table 3 (linear): posterior mean sigma"]
    assert "0.040 m/s^2" in table3 and f"{np.sqrt(0.25**2 - 0.1**2):.3f}" in table3
    # Gaussian residuals outside +-3 x 0.03 of their sd; 1.3 % needs 0.83 x
    share = notes["tanh, unseen data: share outside 3 sd (parameter"]
    assert "92.8%" in share and "needs 0.83 x" in share


def test_notes_land_on_the_rows_they_name_only():
    table = pd.DataFrame([{"quantity": q, "paper": 1.0, "ours": 2.0, "truth": np.nan,
                           "unit": "", "note": np.nan}
                          for q in ("eq. (12): log Bayes factor tanh / linear", "Table 1: M")],
                         columns=COLUMNS)
    out = with_notes(table, {"eq. (12)": "why"})
    assert out.note.tolist()[0] == "why" and pd.isna(out.note.tolist()[1])
    assert pd.isna(table.note).all()  # the table passed in is not changed
    assert pytest.approx(out.ours.tolist()) == [2.0, 2.0]


def test_figure7_notes_read_the_sticking_table():
    rows = pd.DataFrame([
        {"model": "linear", "nrmse_stuck": 0.83, "nrmse_moving": 0.28, "rms_stuck": 0.157,
         "rms_moving": 0.27, "rms_fastest_band": 0.52},
        {"model": "tanh", "nrmse_stuck": 0.51, "nrmse_moving": 0.10, "rms_stuck": 0.097,
         "rms_moving": 0.095, "rms_fastest_band": 0.1}])
    notes = figure7_notes(rows)
    assert "misses 83% of the record while the rig is stuck against 28%" in notes[
        "Figure 7: linear"] and "(0.52 in the fastest band, 0.157 stuck)" in notes[
        "Figure 7: linear"]
    assert "(0.097 and 0.095 m/s^2)" in notes["Figure 7: tanh"]
    assert figure7_notes(rows.iloc[:1]) == {}


def test_the_headline_notes_read_the_ensemble_from_the_unseen_band():
    """The parameter ensemble's sd over the residual's RMS, from the band: an ensemble of sd
    0.03 exactly about the record's mean, a residual of RMS 1 exactly."""
    from harvester.inference.predictive import PredictiveBand
    from harvester.study.summary import headline_notes
    rng = np.random.default_rng(0)
    t = np.arange(4000) / 256.0
    signal = np.sin(2 * np.pi * t)
    z = rng.standard_normal((400, t.size))
    z = (z - z.mean(axis=0)) / z.std(axis=0, ddof=1)
    band = PredictiveBand(t, signal + 0.03 * z, np.full(400, 1.0))
    r = rng.standard_normal(t.size)
    measured = signal + r / np.sqrt(np.mean(r ** 2))
    posts = {"linear": _posterior(430.0, 0.25), "tanh": _posterior(110.0, 0.1)}
    bayes = pd.DataFrame({"model": ["tanh"], "log_bayes_factor": [1850.0]})
    sticking = pd.DataFrame([
        {"model": m, "nrmse_stuck": 0.5, "nrmse_moving": 0.1, "rms_stuck": 0.1,
         "rms_moving": 0.1, "rms_fastest_band": 0.1} for m in ("linear", "tanh")])
    notes = headline_notes(posts, bayes, band, measured, sticking)
    assert "the parameter ensemble's sd is 0.030 x" in notes[
        "tanh, unseen data: share outside 3 sd (parameter"]
    assert set(notes) >= {"eq. (12)", "Figure 7: linear", "Figure 7: tanh"}
