"""Power prediction, design and calibration (harvester.power): excitations, BMA draws, the
power of a linear device against its closed form, optima, paired gains, coverage, the CLI."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest
from harvester.cli import main
from harvester.electrical import generator as gen
from harvester.power import design
from harvester.power.calibration import coverage_table
from harvester.power.excitations import jonswap, make_excitation, read_excitation
from harvester.power.predict import PARAMETERS, bma_draws, predict_power, with_change

KNOWN = {"M": 12.8, "m": 8.0, "k": 250.0}
G = gen.screw_ratio(0.02)
SEA = {"duration_s": 60.0, "tp_s": 3.0, "gamma": 3.3, "hs_m": 0.5, "band_hz": [0.1, 1.5],
       "peak_m_s2": 6.0}


def _posterior(n: int = 20, F_c: float = 11.86, L_s: float = 1e-3) -> pd.DataFrame:
    rng = np.random.default_rng(3)
    return pd.DataFrame({"c_m": 109.5 * (1 + 0.01 * rng.standard_normal(n)),
                         "F_c": F_c, "beta": 88.35, "K_e": 0.03, "R_s": 1.0, "L_s": L_s,
                         "sigma_acc": 0.02, "sigma_V": 0.003})


def test_jonswap_peaks_at_the_peak_period_and_the_record_at_the_peak_acceleration():
    f = np.linspace(0.05, 2.0, 4000)
    s = jonswap(f, 1.0, 4.0, 3.3)
    assert f[np.argmax(s)] == pytest.approx(0.25, abs=0.002)
    # m0 = H_s^2 / 16 (DNV-RP-C205: the normalisation A_gamma holds it to a few per cent)
    m0 = np.trapezoid(s, 2 * np.pi * f)
    assert m0 == pytest.approx(1.0 / 16.0, rel=0.05)
    exc = make_excitation("sea_state", SEA, 256.0, 7)
    assert np.max(np.abs(exc.base_acc)) == pytest.approx(6.0)
    spec = np.abs(np.fft.rfft(exc.base_acc)) ** 2
    freqs = np.fft.rfftfreq(exc.base_acc.size, exc.dt)
    assert spec[freqs > 1.6].sum() < 1e-12 * spec.sum()
    again = make_excitation("sea_state", SEA, 256.0, 7)
    np.testing.assert_array_equal(exc.base_acc, again.base_acc)


def test_white_noise_is_stationary_to_its_ends():
    spec = {"duration_s": 60.0, "band_hz": [0.5, 15.0], "peak_m_s2": 6.0}
    acc = make_excitation("white_noise", spec, 256.0, 3).base_acc
    assert np.max(np.abs(acc)) == pytest.approx(6.0)
    parts = np.array_split(acc, 6)
    rms = np.array([p.std() for p in parts])
    assert rms.max() / rms.min() < 1.2            # no filter transient at the ends
    assert 3.0 < 6.0 / acc.std() < 6.0            # a Gaussian's peak over 15 000 samples


def test_user_excitation_is_read_and_checked(tmp_path):
    good = tmp_path / "boat.csv"
    pd.DataFrame({"time": np.arange(10) / 100.0, "base_acc": 1.0}).to_csv(good, index=False)
    exc = read_excitation(good)
    assert exc.dt == pytest.approx(0.01) and exc.name == "boat"
    bad = tmp_path / "bad.csv"
    pd.DataFrame({"time": np.arange(3), "acc": 1.0}).to_csv(bad, index=False)
    with pytest.raises(ValueError, match="base_acc"):
        read_excitation(bad)


def test_bma_draws_follow_the_weights():
    post = {"resistive": _posterior(L_s=0.0), "inductive": _posterior()}
    rng = np.random.default_rng(0)
    draws = bma_draws(post, {"resistive": 0.0, "inductive": 1.0}, 50, rng)
    assert set(draws["structure"]) == {"inductive"} and len(draws) == 50
    mixed = bma_draws(post, {"resistive": 0.5, "inductive": 0.5}, 4000, rng)
    assert mixed["structure"].eq("resistive").mean() == pytest.approx(0.5, abs=0.03)
    halved = with_change(draws, {"F_c": 0.5})
    np.testing.assert_allclose(halved["F_c"], 0.5 * draws["F_c"])
    assert set(PARAMETERS) <= set(draws.columns)


def test_linear_device_power_matches_its_closed_form():
    """No friction, no inductance, harmonic base acceleration: z' is the linear oscillator's
    with damping c_m + c_e, and the load gets R_L / (R_s + R_L) of c_e z'^2."""
    fs, f0, A = 256.0, 0.8, 2.0
    t = np.arange(int(40 * fs)) / fs
    y_dd = A * np.sin(2 * np.pi * f0 * t)
    draws = _posterior(2, F_c=0.0, L_s=0.0).assign(structure="resistive")
    loads = np.array([0.5, 2.0, 8.0])
    pred = predict_power(draws, loads, y_dd, 1 / fs, KNOWN, G, lead_in_s=20.0)
    w = 2 * np.pi * f0
    for j, load in enumerate(loads):
        c_e = gen.electrical_damping(0.03, 1.0, 1 / load, G)
        c = draws["c_m"].to_numpy() + c_e
        v_amp = w * KNOWN["m"] * A / np.abs(KNOWN["k"] - KNOWN["M"] * w**2 + 1j * w * c)
        expected = 0.5 * v_amp**2 * c_e * load / (load + 1.0)
        np.testing.assert_allclose(pred.power[:, j], expected, rtol=2e-3)
    assert pred.failed == 0 and pred.energy.shape == (2, 3)
    split = predict_power(draws, loads, y_dd, 1 / fs, KNOWN, G, lead_in_s=20.0, window_s=5.0)
    assert split.windows.shape == (2, 3, 4) and split.per_record.shape == (8, 3)
    np.testing.assert_allclose(split.power, pred.power, rtol=1e-12)


def test_optimum_is_the_parabolas_vertex_and_the_gain_is_paired():
    loads = np.geomspace(0.25, 25.0, 13)
    x = np.log(loads)
    values = 5.0 - (x - np.log(1.7)) ** 2
    r, p = design.refined_argmax(loads, values)
    assert r == pytest.approx(1.7, rel=1e-9) and p == pytest.approx(5.0)
    assert design.refined_argmax(loads, x)[0] == loads[-1]   # at the grid's end
    rng = np.random.default_rng(0)
    base = np.outer(1 + 0.2 * rng.standard_normal(400), np.exp(values))
    gain = design.paired_gain(base, 1.1 * base, loads, 1.7, 0.9)
    assert gain["ratio_low"] == pytest.approx(1.1) and gain["ratio_high"] == pytest.approx(1.1)
    assert gain["probability_of_gain"] == 1.0
    table = design.curve(loads, base, 0.9, 0.05)
    best = design.optimal_loads(table, 0.05)
    assert best["expected"]["load_ohm"] == pytest.approx(1.7, rel=1e-3)


def test_coverage_counts_windows_inside():
    windows = pd.DataFrame({"record": ["a", "a", "b", "b"], "measured_W": [1.0] * 4,
                            "predicted_mean_W": [1.0, 2.0, 1.0, 1.0],
                            "inside_0.9": [True, False, True, True]})
    table = coverage_table(windows, [0.9])
    assert table.set_index("record").loc["all", "coverage"] == pytest.approx(0.75)
    assert table.set_index("record").loc["a", "windows"] == 2


def test_power_command_writes_the_curve_and_the_design(tmp_path):
    study = tmp_path / "electrical"
    study.mkdir()
    _posterior(8).to_csv(study / "samples_inductive.csv", index=False)
    (study / "weights.json").write_text(json.dumps({
        "weights": {"inductive": 1.0}, "device": {"known": KNOWN, "G": G}}))
    exc = tmp_path / "walk.csv"
    t = np.arange(int(8 * 128)) / 128.0
    pd.DataFrame({"time": t, "base_acc": 3 * np.sin(2 * np.pi * 0.7 * t)}).to_csv(exc,
                                                                                  index=False)
    out = tmp_path / "out"
    assert main(["power", str(exc), "--electrical", str(study), "--out", str(out),
                 "--draws", "8", "--loads", "0.5", "8", "5", "--record", "2",
                 "--no-figures"]) == 0
    curve = pd.read_csv(out / "curve.csv")
    assert len(curve) == 5 and (curve["mean_W"] > 0).all()
    # one record's band holds the parameters' (it adds the record-to-record spread)
    assert (curve["record_q0.05_W"] <= curve["q0.05_W"] + 1e-12).all()
    d = json.loads((out / "design.json").read_text())
    assert 0.5 <= d["optimum"]["expected"]["load_ohm"] <= 8
    assert d["gain_at_best_load"]["gain_W"] > 0  # less friction, more motion, more power
    assert d["records"] == 3 and d["record_s"] == pytest.approx(2.0)


def test_rule_power_excitation_writes_the_seeded_record(tmp_path):
    """Rule-level: Snakemake runs power_excitation from the config alone; the record is the
    library's for the config's seed, at the rig's DAQ rate."""
    import yaml
    from conftest import run_snakemake, small_config

    cfg = small_config()
    cfg["power"]["excitations"]["white_noise"]["duration_s"] = 4.0
    (tmp_path / "config.yaml").write_text(yaml.safe_dump(cfg))
    run_snakemake(tmp_path, "results/power/excitations/white_noise.csv")
    got = pd.read_csv(tmp_path / "results/power/excitations/white_noise.csv")
    spec = cfg["power"]["excitations"]["white_noise"]
    want = make_excitation("white_noise", spec, 256.0, cfg["power"]["seed"] + spec["seed_offset"])
    np.testing.assert_allclose(got["base_acc"], want.base_acc, rtol=1e-7, atol=1e-9)
    assert (tmp_path / "logs/power/excitation_white_noise.log").is_file()
