"""Concealed-effect scenarios: calibration of the contribution, effect-free records, concealment."""

from __future__ import annotations

import numpy as np
import pytest

from harvester.synthetic import scenarios as sc
from harvester.data.daq import read_recording
from harvester.data.fileio import read_json
from harvester.data.signals import lowpass

SETTINGS = sc.ScenarioSettings(duration_s=8.0, lead_in_s=1.0, seed=11)
EFFECTS = list(sc.FAMILIES)


@pytest.fixture(scope="module")
def at_half():
    """Every family at a contribution of half the noise RMS, seed 0."""
    return {e: sc.make_scenario(e, 0.5, 0, SETTINGS, masking=False) for e in EFFECTS}


def _independent_contribution(truth: dict) -> np.ndarray:
    """LP[z''(with) - z''(without)] recomputed from the truth's strength and shape alone."""
    fam = sc.FAMILIES[truth["effect"]]
    device = sc.Device(**truth["device"])
    exc, _, _ = sc.excitation(SETTINGS, truth["seed"])
    on = sc.device_acceleration(exc.y_fine, exc.fs_fine, device, fam.code, truth["strength"],
                                fam.shape_vector(truth["shape"]))
    off = sc.device_acceleration(exc.y_fine, exc.fs_fine, device)
    return lowpass(exc.decimate(on - off), SETTINGS.fs, SETTINGS.lowpass_hz,
                   SETTINGS.filter_order)


@pytest.mark.parametrize("effect", EFFECTS)
def test_calibration_hits_the_requested_ratio(at_half, effect):
    truth = at_half[effect].truth
    assert truth["contribution_ratio"] == pytest.approx(0.5, rel=0.01)
    c = _independent_contribution(truth)[SETTINGS.lead_in:]
    ratio = np.sqrt(np.mean(c**2)) / SETTINGS.noise_rms()
    assert ratio == pytest.approx(0.5, rel=0.05)
    assert truth["baseline"] == ("linear" if effect == "coulomb_friction" else "tanh")


def test_calibration_scales_with_the_ratio():
    for effect in ("stribeck_friction", "end_stop"):
        for r in (0.25, 1.0):
            t = sc.make_scenario(effect, r, 1, SETTINGS, masking=False).truth
            assert t["contribution_ratio"] == pytest.approx(r, rel=0.01)


def test_the_recording_carries_exactly_the_contribution(at_half):
    """Same seed: effect recording - effect-free recording = the calibrated contribution."""
    free = sc.make_scenario("none_tanh", 0.0, 0, SETTINGS, masking=False)
    for effect in ("hysteresis", "unmodelled_mode"):
        s = at_half[effect]
        diff = s.recording["rel_acc"].to_numpy() - free.recording["rel_acc"].to_numpy()
        np.testing.assert_allclose(diff, s.contribution, atol=1e-9)
        np.testing.assert_allclose(s.recording["base_acc"], free.recording["base_acc"])


@pytest.mark.parametrize("effect", ["none_tanh", "none_linear"])
def test_effect_free_scenarios_have_zero_contribution(effect):
    s = sc.make_scenario(effect, 0.0, 3, SETTINGS)
    assert np.all(s.contribution == 0.0)
    assert s.truth["contribution_ratio"] == 0.0 and "strength" not in s.truth
    assert s.truth["baseline"] == effect.split("_")[1]
    with pytest.raises(ValueError):
        sc.make_scenario(effect, 0.5, 3, SETTINGS)


def test_concealed_below_the_noise(at_half):
    """At half the noise RMS the contribution is below the realised noise, and the record-level
    concealment measures are what they say they are."""
    noise = SETTINGS.noise_rms()
    for effect, s in at_half.items():
        t = s.truth
        c = s.contribution[SETTINGS.lead_in:]
        assert np.sqrt(np.mean(c**2)) < t["noise_rms_realised"], effect
        assert t["peak_to_noise"] == pytest.approx(np.max(np.abs(c)) / noise)
        assert t["invisible"] == (t["peak_to_noise"] < sc.INVISIBLE_PEAK)
        assert 0.5 <= t["window_rms_to_noise"] < 2.0, effect  # no second of it above 2x noise
        assert 0.0 <= t["filter_removed_share"] < 1.0


def test_smooth_effects_are_invisible_at_a_quarter():
    """Effects spread over the record stay inside 3 noise RMS at r = 0.25 (the displacement
    effects, end stop and progressive spring, come in bursts and may not: see truth)."""
    for effect in ("stribeck_friction", "hysteresis", "inertia_error", "coulomb_friction",
                   "backlash"):
        t = sc.make_scenario(effect, 0.25, 0, SETTINGS, masking=False).truth
        assert t["invisible"], (effect, t["peak_to_noise"])


def test_noise_rms_is_the_recorded_channel_noise():
    free = sc.make_scenario("none_tanh", 0.0, 5, sc.ScenarioSettings(duration_s=30.0))
    assert free.truth["noise_rms_realised"] == pytest.approx(free.truth["noise_rms"], rel=0.05)
    # two 0.04 m/s^2 sensors, 20 Hz of the 128 Hz Nyquist band, order 8
    assert free.truth["noise_rms"] == pytest.approx(0.04 * np.sqrt(2 * 20 / 128), rel=0.05)


def test_masking_measures():
    t = sc.make_scenario("quadratic_damping", 0.5, 0, SETTINGS).truth
    # |w|^1.8 damping over the device's velocity range is nearly viscous: c_m absorbs most
    assert t["unabsorbed_to_noise"] < 0.25
    t = sc.make_scenario("backlash", 0.5, 0, SETTINGS).truth
    assert t["filter_removed_share"] > 0.5  # contact impacts lie mostly above 20 Hz
    assert t["zero_strength_ratio"] < 0.1  # the contact's compliance alone is negligible


@pytest.mark.parametrize("effect", ["coulomb_friction", "hysteresis", "backlash", "end_stop"])
def test_generator_is_converged_in_its_step(at_half, effect):
    truth = at_half[effect].truth
    fam = sc.FAMILIES[effect]
    device = sc.Device(**truth["device"])
    exc, _, _ = sc.excitation(SETTINGS, 0)
    shape = fam.shape_vector(truth["shape"])
    base = sc.SUBSTEPS.get(fam.code, 1)

    def contribution(substeps):
        on = sc.device_acceleration(exc.y_fine, exc.fs_fine, device, fam.code,
                                    truth["strength"], shape, substeps)
        off = sc.device_acceleration(exc.y_fine, exc.fs_fine, device, substeps=substeps)
        return lowpass(exc.decimate(on - off), 256.0, 20.0, 8)[SETTINGS.lead_in:]

    a, b = contribution(base), contribution(4 * base)
    assert np.sqrt(np.mean((a - b) ** 2)) < 0.03 * np.sqrt(np.mean(b**2))


def test_seeds_are_reproducible_and_shapes_drawn_per_seed():
    a = sc.make_scenario("unmodelled_mode", 0.5, 2, SETTINGS, masking=False)
    b = sc.make_scenario("unmodelled_mode", 0.5, 2, SETTINGS, masking=False)
    c = sc.make_scenario("unmodelled_mode", 0.5, 4, SETTINGS, masking=False)
    np.testing.assert_array_equal(a.recording.to_numpy(), b.recording.to_numpy())
    assert a.truth["shape"] == b.truth["shape"] != c.truth["shape"]
    assert 3.0 <= a.truth["shape"]["f_mode"] <= 18.0


def test_scenario_files(tmp_path, at_half):
    s = at_half["end_stop"]
    sc.write_scenario(s, tmp_path / "r.csv", tmp_path / "r.json")
    rec = read_recording(tmp_path / "r.csv")
    assert list(rec.columns) == ["time", "base_acc", "rel_acc"]
    np.testing.assert_allclose(rec["rel_acc"], s.recording["rel_acc"], rtol=1e-8, atol=1e-12)
    truth = read_json(tmp_path / "r.json")
    assert truth["effect"] == "end_stop" and truth["known"] == {"M": 12.8, "m": 8.0, "k": 250.0}
    assert truth["form"] != truth["library_form"]


def test_settings_from_the_study_config():
    import yaml

    from conftest import ROOT

    cfg = yaml.safe_load((ROOT / "config/config.yaml").read_text())
    s = sc.ScenarioSettings.from_config(cfg, duration_s=5.0)
    assert (s.fs, s.noise_m_s2, s.lowpass_hz, s.duration_s) == (
        cfg["rig"]["daq"]["sampling_rate_hz"], cfg["rig"]["sensors"]["noise_m_s2"],
        cfg["preprocess"]["lowpass_hz"], 5.0)
    dev = sc.Device.from_rig(cfg["rig"], "linear")
    assert dev.F_c == 0.0 and dev.c_m == cfg["rig"]["c_m"]
