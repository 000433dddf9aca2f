"""Diagnosis of missing physics: detection calibrated on effect-free recordings, concealed
effects found and named, locations, ranking, the measurement chain and the tempering.

Fast versions: MAP baselines (no TMCMC), 10-20 s recordings, 200 noise replicates. The
statistical checks over many seeds are in test_diagnosis_calibration.py (slow).
"""

from __future__ import annotations

import logging
from types import SimpleNamespace

import numpy as np
import pytest

from harvester.diagnosis import DiagnosisSettings, quick_detect
from harvester.diagnosis.name.verdict import decide_verdict
from harvester.inference.map_fit import ChainProblem, chain_problem
from harvester.diagnosis.detect.scores import estimate_temper
from harvester.diagnosis.name.rank import rank
from harvester.diagnosis.detect.signatures import candidate_terms
from harvester.diagnosis.detect.spectral import filter_cutoff
from harvester.synthetic.measured import TABLE1_KNOWN, TANH_TABLE5, measured_recording
from harvester.inference.problems import make_problem
from harvester.inference.likelihood import DAQ_OVERSAMPLE
from harvester.model.structures import Layout
from harvester.inference.priors import PriorSpec
from harvester.inference.priors import default_prior
from harvester.synthetic.scenarios import ScenarioSettings, make_scenario
from harvester.data.signals import lowpass
from harvester.model.simulate import substeps

pytestmark = pytest.mark.filterwarnings("ignore::UserWarning", "ignore::RuntimeWarning")

FS = 256.0
PRIORS = {"c_m": PriorSpec("c_m", 170.0, 50.0, "N s/m"), "F_c": PriorSpec("F_c", 8.4, 5.0, "N"),
          "beta": PriorSpec("beta", 100.0, 100.0, "s/m"),
          "sigma": PriorSpec("sigma", 0.07, 0.03, "m/s^2")}


@pytest.fixture(autouse=True)
def _quiet():
    logging.getLogger("harvester").setLevel(logging.WARNING)
    yield


def run_detection(df, baseline="tanh", seed=0):
    """MAP baseline (Laplace posterior) after a 1 s lead-in, then the calibrated detection."""
    settings = DiagnosisSettings(bootstrap=200, artifact_components=30, seed=seed)
    return quick_detect(df, baseline, TABLE1_KNOWN, PRIORS, settings)


# --------------------------------------------------------------------------- building blocks


def test_filter_cutoff_finds_a_preprocessing_lowpass_and_nothing_else():
    y = np.random.default_rng(0).standard_normal(20 * 256)
    assert filter_cutoff(y, FS) is None
    for cut in (12.0, 20.0, 40.0):
        found = filter_cutoff(lowpass(y, FS, cut, 8), FS)
        assert found is not None and 0.85 * cut < found <= 1.02 * cut


def test_a_low_pass_given_as_none_is_not_looked_for_and_a_shared_roll_off_is_noted(tmp_path):
    """``recording_lowpass``: a given cut-off is kept, 0 means none (nothing looked for), None
    looks; ``shared_roll_off`` notes an input falling where the output's low-pass was found
    (an excitation's band edge looks like a filter in both channels), not an input falling two
    octaves higher; a sidecar may say ``filtered_at_hz: 0``, not a negative cut-off."""
    from harvester.data.errors import DataError
    from harvester.data.sidecar import read_sidecar
    from harvester.diagnosis.detect.spectral import recording_lowpass, shared_roll_off
    rng = np.random.default_rng(1)
    u, y = rng.standard_normal((2, 20 * 256))
    y20 = lowpass(y, FS, 20.0, 8)
    found, none = recording_lowpass(None, u, y20, FS)
    assert found is not None and 17.0 < found <= 20.4 and none is None
    assert recording_lowpass(0.0, u, y20, FS) == (None, None)
    assert recording_lowpass(25.0, u, y20, FS) == (25.0, None)
    note = shared_roll_off(lowpass(u, FS, 20.0, 8), found, FS)
    assert note is not None and "filtered_at_hz: 0" in note
    assert recording_lowpass(None, lowpass(u, FS, 20.0, 8), y20, FS) == (found, note)
    assert shared_roll_off(lowpass(u, FS, 80.0, 8), found, FS) is None
    assert shared_roll_off(u, None, FS) is None
    (tmp_path / "r.yaml").write_text("filtered_at_hz: 0\n")
    assert read_sidecar(tmp_path / "r.csv").filtered_at_hz == 0.0
    (tmp_path / "r.yaml").write_text("filtered_at_hz: -5\n")
    with pytest.raises(DataError, match="filtered_at_hz.*positive"):
        read_sidecar(tmp_path / "r.csv")


def test_chain_problem_below_its_cutoff_is_eq10_and_tempering_scales_it():
    # a record low-passed at 20 Hz, given as unfiltered: the chain's cut-off is then the DAQ's
    # anti-alias edge (0.8 x Nyquist) and its low-pass at 0.8 x that leaves eq. (10) alone
    df, _ = measured_recording(("tanh_friction",), {**TABLE1_KNOWN, **TANH_TABLE5}, 6.0, 1)
    plain = make_problem(df, "tanh", TABLE1_KNOWN, window=(256, 1200))
    theta = np.array([[109.5, 11.86, 88.35, 0.05], [150.0, 9.0, 60.0, 0.08]])
    chained = chain_problem(plain, 1.0, None)
    assert chained.oversample == DAQ_OVERSAMPLE > 1   # the chain samples z'' as a DAQ does
    assert chained.band_hz == pytest.approx(0.8 * 0.8 * FS / 2)
    plain = plain.replace(oversample=DAQ_OVERSAMPLE)
    np.testing.assert_allclose(chained.loglike(theta), plain.loglike(theta), rtol=1e-4)
    half = chain_problem(plain, 0.5, None)
    np.testing.assert_allclose(half.loglike(theta), 0.5 * chained.loglike(theta), rtol=1e-10)
    # through a 20 Hz chain the true parameters leave a residual at the noise level
    filtered = chain_problem(plain, 1.0, 19.0)
    assert isinstance(filtered, ChainProblem)
    r = filtered.residuals(theta[:1])[0]
    assert np.std(r) < 0.05


def test_the_likelihood_leaves_out_the_recording_filters_transition_band():
    # noise-free friction record, low-passed at 20 Hz as the rig does: at the true parameters
    # the residual is the chain's error alone, most of it where the data went through the
    # filter twice and the model once (between ANALYSIS_FRACTION x 20 Hz and 20 Hz)
    vals = {**TABLE1_KNOWN, **TANH_TABLE5, "beta": 1000.0}
    df, _ = measured_recording(("tanh_friction",), vals, 12.0, 2, noise_m_s2=0.0,
                               base_noise_m_s2=0.0)
    plain = make_problem(df, "tanh", TABLE1_KNOWN, window=(256, 256 * 11))
    truth = np.array([[vals["c_m"], vals["F_c"], vals["beta"], 0.05]])
    rms = {f: np.std(chain_problem(plain, 1.0, 20.0, 8, band_fraction=f).residuals(truth)[0])
           for f in (1.0, None)}
    assert chain_problem(plain, 1.0, 20.0, 8).band_hz == pytest.approx(16.0)
    assert rms[None] < 0.7 * rms[1.0]   # 0.014 and 0.023 m/s^2 when written


def test_quick_detect_without_priors_uses_the_librarys():
    # priors=None: the library's priors, sigma's scaled to the MAP's residual (as documented)
    df, _ = measured_recording(("tanh_friction",), {**TABLE1_KNOWN, **TANH_TABLE5}, 8.0, 2)
    det, _ = quick_detect(df, "tanh", TABLE1_KNOWN, None,
                          DiagnosisSettings(bootstrap=50, artifact_components=10))
    assert 0.0 < det.p_value <= 1.0 and det.sigma > 0.0


def test_tempering_is_the_share_of_independent_samples_of_band_limited_noise():
    rng = np.random.default_rng(3)
    noise = lowpass(rng.standard_normal(30 * 256), FS, 20.0, 8)
    lam = estimate_temper(noise, (256, 29 * 256), FS, 18.0)
    assert lam == pytest.approx(2 * 20.0 / FS, rel=0.3)
    white = rng.standard_normal(30 * 256)
    # white noise: about 1 (a little less: the densest tenth of the band sets lambda)
    assert 0.6 < estimate_temper(white, (256, 29 * 256), FS, 115.0) <= 1.0


# --------------------------------------------------------------------------- detection


@pytest.fixture(scope="module")
def null_detections():
    """Recordings of the baseline itself (tanh, Table 5), both sensors noisy, 20 Hz chain."""
    out = []
    for seed in range(4):
        df, _ = measured_recording(("tanh_friction",), {**TABLE1_KNOWN, **TANH_TABLE5}, 12.0,
                                   300 + seed)
        out.append(run_detection(df, seed=seed)[0])
    return out


def test_no_false_alarm_on_effect_free_recordings(null_detections):
    # calibrated at 5 %: four clean recordings should rarely flag; and never strongly
    ps = np.array([d.p_value for d in null_detections])
    assert np.sum(ps < 0.05) <= 1
    assert np.all(ps > 0.005)
    # the standardised scores of single-shape, signed effects are ~N(0, 1) under the null
    z = np.array([d.z[c.index] for d in null_detections for c in d.candidates
                  if d.signatures[c.index].signed])
    assert abs(np.mean(z)) < 0.8 and 0.4 < np.std(z) < 1.6


@pytest.mark.parametrize("effect", ["end_stop", "unmodelled_mode", "asymmetric_friction"])
def test_concealed_effect_below_noise_is_detected_and_named(effect):
    # generated in another functional form than the library's (harvester.synthetic.scenarios)
    sc = make_scenario(effect, 0.5, 11, ScenarioSettings(duration_s=16.0), masking=False)
    assert sc.truth["contribution_ratio"] == pytest.approx(0.5, rel=0.01)
    det, state = run_detection(sc.recording, seed=1)
    assert det.significant, f"{effect}: p = {det.p_value}"
    ranked = rank(det, state, PRIORS)
    top = [r.effect for r in ranked[:2]]
    family = {"end_stop": {"end_stop", "cubic_stiffness"}, "unmodelled_mode": {"unmodelled_mode"},
              "asymmetric_friction": {"asymmetric_friction"}}[effect]
    assert family & set(top), f"{effect}: ranked {top}"


def test_linear_baseline_on_friction_data_names_friction_and_conflicts_with_prior():
    # at the default settings (400 replicates, whose rank could not say less than 1/401), the
    # replicates' tail resolves the p-value below the unexplained verdict's bar: with no
    # effect accepted, the verdict is missing physics that the library does not explain
    df, _ = measured_recording(("tanh_friction",), {**TABLE1_KNOWN, **TANH_TABLE5}, 12.0, 5)
    settings = DiagnosisSettings()
    det, state = quick_detect(df, "linear", TABLE1_KNOWN, PRIORS, settings)
    assert det.family_tail["library"].method == "tail"
    assert det.p_value < settings.unexplained_alpha < 1 / (settings.bootstrap + 1)
    assert decide_verdict(det.p_value, False, settings.unexplained_alpha) == "missing_physics"
    # damping driven far above the prior by the missing friction
    assert any(c.conflict and c.parameter == "c_m" for c in det.conflicts)
    ranked = rank(det, state, PRIORS)
    assert ranked[0].effect in {"tanh_friction", "coulomb_friction", "stribeck_friction",
                                "hysteresis"}
    # locations: every family reports shares that add up
    shares = np.exp(det.window_stats.observed)
    assert shares.sum() == pytest.approx(1.0, rel=1e-6)
    assert det.band_energy.sum() > 0 and np.all(det.band_explained >= 0)


@pytest.mark.parametrize("fs", [1024.0, 400.0])
def test_a_fast_sampled_recording_is_resampled_to_its_band_and_diagnosed_alike(fs):
    # the same concealed end stop recorded at 1024 Hz (simulated at 256 Hz, every 4th sample)
    # and at 400 Hz (no integer factor: resampled by a ratio to 12.8 x the found cut-off)
    settings = ScenarioSettings(duration_s=16.0, fs=fs, oversample=4)
    sc = make_scenario("end_stop", 0.5, 11, settings, masking=False)
    det, state = run_detection(sc.recording, seed=1)
    if fs == 1024.0:
        assert state.problem.dt == pytest.approx(1.0 / 256.0)
    else:
        rate, cut = 1.0 / state.problem.dt, state.problem.lowpass_hz
        assert 12.8 * cut <= rate <= fs / 1.25 and (fs / rate) % 1 > 0.01, (rate, cut)
    assert det.significant, f"p = {det.p_value}"
    top = [r.effect for r in rank(det, state, PRIORS)[:2]]
    assert {"end_stop", "cubic_stiffness"} & set(top), top


def test_backlash_contact_prior_puts_the_contact_resonance_above_the_band():
    """The contact resonates between the band's top and 8 x above it (log-uniform)."""
    from dataclasses import replace as dc_replace

    from harvester.model.priors import REFERENCE_DEVICE
    from harvester.model.terms import term
    device = dc_replace(REFERENCE_DEVICE, f_high=18.0)
    spec = term("backlash").parameters[1].prior_on(device)
    known = dict(TABLE1_KNOWN)
    mu = known["m"] * (known["M"] - known["m"]) / known["M"]
    assert spec.family == "loguniform"
    assert np.sqrt(spec.lower / mu) / (2 * np.pi) == pytest.approx(18.0)
    assert np.sqrt(spec.upper / mu) / (2 * np.pi) == pytest.approx(8 * 18.0)
    # and it costs fewer sub-steps than a ball nut's 1e7 N/m
    layout = Layout.of(("backlash",))
    row = {**known, "c_m": 109.5, "gap_backlash": 1e-5}
    cost = [substeps(layout, np.array([[{**row, "k_backlash": k}[n]
                                        for n in layout.parameter_names]]), 1 / 256.0)[0]
            for k in (spec.mean, 1e7)]
    assert cost[0] < cost[1] / 2


def test_the_dissipative_force_is_the_power_the_base_puts_in():
    """c_eq sigma_v from the base's power input matches the simulated dissipation (viscous
    plus tanh friction) on a noisy low-passed recording, without knowing the split."""
    from harvester.diagnosis.detect.signatures import dissipative_force
    from harvester.synthetic.measured import base_excitation
    from harvester.model.simulate import simulate

    rng = np.random.default_rng(3)
    y = base_excitation(int(40 * FS), FS, rng, peak=4.0)
    values = {**TABLE1_KNOWN, **TANH_TABLE5, "c_m": 60.0, "F_c": 20.0, "beta": 300.0}
    layout = Layout.of(("tanh_friction",))
    sim = simulate(layout, np.array([values[p] for p in layout.parameter_names]), y, 1.0 / FS)
    v = sim.rel_vel[0]
    truth = np.mean((values["c_m"] * v + values["F_c"] * np.tanh(values["beta"] * v)) * v)
    truth /= np.sqrt(np.mean(v**2))
    measured = lowpass(y + 0.04 * rng.standard_normal(y.size), FS, 20.0, 8)
    estimate = dissipative_force(measured, v, values["m"])
    assert estimate == pytest.approx(truth, rel=0.03)
    assert dissipative_force(measured, np.zeros_like(v), values["m"]) is None


def test_candidate_priors_follow_the_device_from_the_papers_rig():
    """On the reference device's scales a term's priors are its defaults; on a device with 4x
    the dissipative force, 3x the velocity and twice M and k they follow the device."""
    from dataclasses import replace as dc_replace

    from harvester.diagnosis.name.fits import candidate_priors
    from harvester.model.priors import REFERENCE_DEVICE

    rig = REFERENCE_DEVICE
    for effect, name in (("coulomb_friction", "F_coulomb"), ("stribeck_friction", "v_stribeck"),
                         ("inertia_error", "dM"), ("end_stop", "k_stop")):
        assert candidate_priors(effect, rig)[name] == default_prior(name)
    other = dc_replace(rig, v=3 * rig.v, force=4 * rig.force, M=2 * rig.M, k=2 * rig.k)
    for effect, name, ratio in (("coulomb_friction", "F_coulomb", 4.0),
                                ("stribeck_friction", "F_stribeck", 4.0),
                                ("stribeck_friction", "v_stribeck", 3.0),
                                ("tanh_friction", "beta", 1.0 / 3.0),
                                ("hysteresis", "F_hyst", 4.0),
                                ("inertia_error", "dM", 2.0), ("end_stop", "k_stop", 2.0)):
        a, b = candidate_priors(effect, rig)[name], candidate_priors(effect, other)[name]
        c = a.scaled(ratio)
        assert b.family == c.family
        assert (b.mean, b.sd, b.lower, b.upper) == pytest.approx(
            (c.mean, c.sd, c.lower, c.upper), rel=1e-12), (effect, name)
    quad = candidate_priors("quadratic_damping", other)["c_quad"]
    assert quad.upper * other.v**2 == pytest.approx(
        4 * candidate_priors("quadratic_damping", rig)["c_quad"].upper * rig.v**2)

def _result(effect, delta, se=0.3, accepted=True):
    from harvester.diagnosis.name.results import CandidateResult
    return CandidateResult(effect, None, delta, se, 3.0 + 2 * se, accepted)


def test_a_rival_the_budget_left_unsampled_that_could_reach_the_name_makes_a_tie():
    """skips.budget_rivals: the literature generator's LuGre record as force -> rel_disp
    named a mode (+97.8 nats) while hysteresis, its best fit's bound +104.7, was left
    unsampled by the budget: the mode is not named alone. A rival whose bound cannot reach
    the name less the margin, one of the same physics, or one skipped for another reason
    leaves the name standing."""
    from harvester.diagnosis.name.results import ConfirmSettings
    from harvester.diagnosis.name.skips import BUDGET_REASON, STOPPED_REASON, budget_rivals
    cs = ConfirmSettings()

    def screened(effect, bound, skipped):
        s = _screened(effect, bound)
        s.skipped = skipped
        return s

    mode = [_result("unmodelled_mode", 97.8, se=0.05)]
    fitted = {"hysteresis": screened("hysteresis", 104.7, BUDGET_REASON)}
    assert budget_rivals(mode, fitted, cs) == ["hysteresis"] and not mode[0].named
    stopped = [_result("unmodelled_mode", 97.8, se=0.05)]
    fitted = {"hysteresis": screened("hysteresis", 95.0, f"{STOPPED_REASON} (chain 0)")}
    assert budget_rivals(stopped, fitted, cs) == ["hysteresis"]
    kept = [_result("unmodelled_mode", 97.8, se=0.05)]
    fitted = {"inertia_error": screened("inertia_error", 87.3, BUDGET_REASON),
              "hysteresis": screened("hysteresis", 104.7, "its best fit has F_hyst on its "
                                     "lower bound"),
              "coulomb_friction": screened("coulomb_friction", 1.4, BUDGET_REASON)}
    assert budget_rivals(kept, fitted, cs) == [] and kept[0].named
    same = [_result("coulomb_friction", 50.0, se=0.05)]
    fitted = {"sticking_friction": screened("sticking_friction", 60.0, BUDGET_REASON)}
    assert budget_rivals(same, fitted, cs) == [] and same[0].named


def test_a_term_whose_limits_fit_far_worse_is_told_from_them():
    """limits.apart_from_limits: hysteresis unresolved (1.08 um below the 8.3 um the record
    resolves) and piled on its lower bound is accepted where its limits, both screened, fall
    short of it by more than the naming margin (the Bouc-Wen friction as base_disp ->
    rel_disp: +212.3 against +15.1 and +1.7); not where one comes within the margin (the
    frame's stand-in bristle), was not screened, or failed; an edge of another parameter
    still leaves it untrusted."""
    from harvester.diagnosis.name.results import ConfirmSettings
    from harvester.diagnosis.name.limits import apart_from_limits
    cs = ConfirmSettings()

    def hysteresis(delta=212.3, edges=None):
        r = _result("hysteresis", delta, se=0.2, accepted=False)
        r.unresolved = {"delta_hyst": (1.08e-6, 8.28e-6)}
        r.at_prior_edge = dict(edges or {"delta_hyst": "lower"})
        return r

    limits = {"sticking_friction": _screened("sticking_friction", 15.1),
              "coulomb_friction": _screened("coulomb_friction", 1.7)}
    told = hysteresis()
    assert apart_from_limits(told, limits, cs) == {"sticking_friction": 15.1,
                                                  "coulomb_friction": 1.7}
    assert told.accepted and not told.unshown and not told.untrusted_edges
    assert told.at_limit == {}  # its limits are not sampled in its place
    close = hysteresis()
    near = {**limits, "sticking_friction": _screened("sticking_friction", 209.0)}
    assert apart_from_limits(close, near, cs) == {} and not close.accepted and close.unshown
    alone = hysteresis()
    assert apart_from_limits(alone, {"coulomb_friction": limits["coulomb_friction"]}, cs) == {}
    failed = {**limits, "coulomb_friction": _screened("coulomb_friction", 1.7, failed=True)}
    assert apart_from_limits(hysteresis(), failed, cs) == {}
    other = hysteresis(edges={"delta_hyst": "lower", "F_hyst": "lower"})
    assert apart_from_limits(other, limits, cs) and not other.accepted
    assert other.untrusted_edges == {"F_hyst": "lower"}
    assert apart_from_limits(_result("cubic_stiffness", 50.0), limits, cs) == {}
    resolved = hysteresis()  # piled on the bound of a displacement the record resolves
    resolved.unresolved = {}
    assert apart_from_limits(resolved, limits, cs) == {} and resolved.untrusted_edges


def test_a_best_fit_on_a_limit_its_limits_fall_short_of_is_sampled_in_its_turn():
    """limits.mark_apart: hysteresis's best fit on delta_hyst's lower bound, its posterior
    to pile there, is not held back as pulled where its limits' bounds fall short of its
    Laplace gain by log(1/alpha) and the bound lies below what the record resolves; a bound
    of another parameter, one above the resolution, a limit within reach, or a record whose
    noise floor is not measured still pulls it."""
    from harvester.diagnosis.name.results import ConfirmSettings
    from harvester.diagnosis.name.limits import mark_apart
    from harvester.diagnosis.name.skips import sampling_order
    # a record that resolves 8.28 um of displacement (rel_disp, the floor at an 81.9 Hz band)
    cs = ConfirmSettings(noise_floor=8.28e-6)
    problem = SimpleNamespace(output_type=SimpleNamespace(order=0), band_hz=81.9)

    def hysteresis(on_bound, gain=213.2, delta=1.08e-6):
        s = _screened("hysteresis", 222.3)
        s.laplace_gain, s.on_bound, s.problem = gain, on_bound, problem
        s.names, s.theta = ("F_hyst", "delta_hyst"), np.array([0.0129, delta])
        return s

    limits = {"sticking_friction": _screened("sticking_friction", 15.1),
              "coulomb_friction": _screened("coulomb_friction", 1.7)}
    fitted = {"hysteresis": hysteresis({"delta_hyst": ("lower", 40.0)}), **limits}
    mark_apart(fitted, cs)
    assert fitted["hysteresis"].apart == ("delta_hyst",) and not fitted["hysteresis"].pulled
    assert sampling_order(["hysteresis", "coulomb_friction"], fitted)[1] == set()
    other = {"hysteresis": hysteresis({"F_hyst": ("lower", 40.0)}), **limits}
    mark_apart(other, cs)
    assert other["hysteresis"].pulled == {"F_hyst": ("lower", 40.0)}
    near = {"hysteresis": hysteresis({"delta_hyst": ("lower", 40.0)}, gain=16.0), **limits}
    mark_apart(near, cs)
    assert near["hysteresis"].apart == () and near["hysteresis"].pulled
    seen = {"hysteresis": hysteresis({"delta_hyst": ("lower", 40.0)}, delta=2e-5), **limits}
    mark_apart(seen, cs)  # a bound above the resolution: the prior cuts what the record holds
    assert seen["hysteresis"].apart == ()
    unmeasured = {"hysteresis": hysteresis({"delta_hyst": ("lower", 40.0)}), **limits}
    mark_apart(unmeasured, ConfirmSettings())
    assert unmeasured["hysteresis"].apart == ()


def test_a_catch_all_leading_the_screen_has_the_laws_with_memory_fitted_before_it():
    """rank.behind_catch_all: where a mass error or a mode leads a round's screen (the first
    that did not fail), hysteresis and the hysteretic spring, whose probes can miss a loop the
    record holds, are screened with the limits they stand for; not where another term leads,
    nor twice, nor where the structure cannot take them."""
    from harvester.diagnosis.name.rank import behind_catch_all
    allowed = set(candidate_terms(()))
    more = behind_catch_all(["unmodelled_mode", "inertia_error"], set(), {"unmodelled_mode",
                            "inertia_error"}, allowed)
    assert more[:2] == ["hysteresis", "hysteretic_spring"]
    assert set(more[2:]) == {"sticking_friction", "coulomb_friction"} & allowed
    assert behind_catch_all(["end_stop", "inertia_error"], {"end_stop"}, set(), allowed)[0] \
        == "hysteresis"  # a failed fit does not lead
    assert behind_catch_all(["stribeck_friction", "unmodelled_mode"], set(), set(),
                            allowed) == []
    done = {"inertia_error", "hysteresis", "hysteretic_spring", "sticking_friction",
            "coulomb_friction"}
    assert behind_catch_all(["inertia_error"], set(), done, allowed) == []
    assert behind_catch_all(["inertia_error"], set(), {"inertia_error"},
                            allowed - {"hysteresis", "hysteretic_spring"}) == []


def test_an_effect_is_named_alone_only_beyond_the_threshold_of_every_different_rival():
    from harvester.diagnosis.name.confirm import mark_ties
    from harvester.diagnosis.name.results import ConfirmSettings
    cs = ConfirmSettings()
    # a physically different rival 2 nats behind: a tie, both ways
    results = [_result("unmodelled_mode", 20.0), _result("inertia_error", 18.0)]
    mark_ties(results, cs)
    assert not results[0].named and results[0].indistinguishable_from == ["inertia_error"]
    assert results[1].indistinguishable_from == ["unmodelled_mode"]
    # the same physics in another form does not tie; a rival 10 nats behind does not either
    results = [_result("coulomb_friction", 20.0), _result("tanh_friction", 19.5),
               _result("stribeck_friction", 10.0)]
    mark_ties(results, cs)
    assert results[0].named
    # a rival that was not accepted still ties when within the threshold
    results = [_result("end_stop", 5.0), _result("cubic_stiffness", 3.5, accepted=False)]
    mark_ties(results, cs)
    assert not results[0].named


def test_separating_experiments_are_the_recordings_own_scaled_and_a_sweep():
    from harvester.diagnosis.name.separate import proposed_experiments
    u = np.random.default_rng(0).standard_normal(2048)
    exps = proposed_experiments(u, 1 / 256.0, 16.0)
    assert [e.name for e in exps] == ["twice_amplitude", "half_amplitude", "sine_sweep"]
    np.testing.assert_allclose(exps[0].base_acc, 2 * u)
    sweep = exps[2].base_acc
    assert sweep.size == u.size
    assert np.sqrt(np.mean(sweep[256:-256] ** 2)) == pytest.approx(np.std(u), rel=0.05)


def test_a_posterior_is_piled_against_a_bound_only_when_the_bound_cuts_it():
    from harvester.diagnosis.detect.scores import at_prior_edge
    from harvester.inference.priors import PriorSpec

    rng = np.random.default_rng(0)
    wide = PriorSpec("k_cubic", 0.0, 4e7, "N/m^3", lower=-2.85e6)
    # a narrow posterior far inside the prior (165 of its own sds above the bound), although
    # near the bound on the prior's scale: not piled
    assert at_prior_edge(wide, 9.9e5 + 2.3e4 * rng.standard_normal(400)) is None
    # a posterior squeezed against the bound: piled
    assert at_prior_edge(wide, -2.85e6 + np.abs(2e5 * rng.standard_normal(400))) == "lower"
    log_uniform = PriorSpec.log_uniform("mass_mode", 0.01, 10.0, "kg")
    assert at_prior_edge(log_uniform, 0.01 * np.exp(np.abs(0.05 * rng.standard_normal(400)))) \
        == "lower"
    assert at_prior_edge(log_uniform, np.exp(0.3 * rng.standard_normal(400))) is None


def test_chains_are_enlarged_only_where_a_decision_lies_within_their_range():
    from harvester.diagnosis.name.confirm import _straddles

    # acceptance at baseline + 3; a tie boundary at best - 3 and best + 3
    decisions = (103.0, 497.0, 503.0)
    assert _straddles(np.array([101.5, 102.9]), decisions, 1.0)       # near acceptance
    assert not _straddles(np.array([60.0, 61.2]), decisions, 1.0)     # far below: rejected
    assert not _straddles(np.array([300.0, 301.5]), decisions, 1.0)   # accepted, far behind
    assert _straddles(np.array([495.0, 496.5]), decisions, 1.0)       # a possible tie


# --------------------------------------------------------------------------- the MAP screen


@pytest.fixture(scope="module")
def concealed_mode():
    """A 16 s record with a secondary mode at half the noise RMS, its MAP baseline as the
    nested fit (the evidence stand-in: its likelihood at the posterior mean), the scales."""
    from harvester.diagnosis.name.fits import ModelFit
    from harvester.diagnosis.run import default_priors
    from harvester.diagnosis.name.screen import max_loglike
    from harvester.diagnosis.detect.signatures import motion_scale
    from harvester.inference.priors import priors_for
    from harvester.model.structures import structure

    sc = make_scenario("unmodelled_mode", 0.5, 11, ScenarioSettings(duration_s=16.0),
                       masking=False)
    det, state = run_detection(sc.recording, seed=1)
    problem = state.problem
    specs = {**default_priors(structure("tanh"), float(state.theta[-1])), **PRIORS}
    stand_in = max_loglike(problem, state.samples.mean(axis=0))
    nested = ModelFit(structure("tanh"), problem, state.samples, np.array([stand_in]),
                      priors=priors_for(problem, specs))
    return sc, det, nested, specs, motion_scale(state, problem.window, det.frame.f_high)


def test_max_loglike_is_the_likelihood_at_its_best_sigma(concealed_mode):
    from harvester.diagnosis.name.screen import max_loglike
    _, _, nested, _, _ = concealed_mode
    theta = nested.samples.mean(axis=0)
    best = max_loglike(nested.problem, theta)
    sigmas = theta[-1] * np.linspace(0.5, 1.5, 41)
    rows = np.column_stack([np.tile(theta[:-1], (len(sigmas), 1)), sigmas])
    assert best >= nested.problem.loglike(rows).max() - 1e-9
    assert best == pytest.approx(nested.problem.loglike(rows).max(), abs=0.05)


def test_the_screen_puts_a_concealed_mode_first_at_its_frequency(concealed_mode):
    from harvester.diagnosis.name.screen import screen
    sc, det, nested, specs, scale = concealed_mode
    out = screen(nested, ["inertia_error", "cubic_stiffness", "unmodelled_mode"], specs, scale,
                 det)
    first, *others = out.candidates
    assert first.effect == "unmodelled_mode" and not first.failed
    f_mode = dict(zip(first.names, first.theta))["f_mode"]
    assert f_mode == pytest.approx(sc.truth["shape"]["f_mode"], rel=0.02)
    # every candidate contains the baseline, so none fits worse than it
    assert all(s.max_loglike >= out.nested_loglike - 1e-6 for s in out.candidates)
    assert first.bound > max(s.bound for s in others) + 20.0


def test_a_modes_fit_starts_at_its_scanned_shape_inside_the_prior(concealed_mode):
    # an unfiltered record's band puts the frequency prior's lower end above the scan's first
    # value: the scan keeps what lies inside, and the fit starts at the whole scanned shape
    from harvester.diagnosis.name.fits import candidate_priors, scan_factor
    from harvester.diagnosis.name.screen import scanned_start
    sc, det, nested, specs, scale = concealed_mode
    priors = {**candidate_priors("unmodelled_mode", scale, nested.problem.known), **specs,
              "f_mode": PriorSpec.log_uniform("f_mode", 2.0, 80.0, "Hz")}
    scan = scan_factor("unmodelled_mode", det, priors)
    assert scan is not None and min(scan.centres) > 2.0
    heaviest = scan.centres[int(np.argmax(scan.weights))]
    assert heaviest == pytest.approx(sc.truth["shape"]["f_mode"], rel=0.2)
    names = list(nested.structure.with_term("unmodelled_mode").free_parameters)
    row = np.full(len(names), np.nan)
    scanned_start(row, names, priors, "unmodelled_mode", det, "f_mode", heaviest)
    at = [i for i, g in enumerate(det.signatures)
          if g.effect == "unmodelled_mode" and g.shape["f_mode"] == heaviest]
    shape = det.signatures[max(at, key=lambda i: det.z[i])].shape
    got = dict(zip(names, row))
    assert all(got[k] == pytest.approx(v) for k, v in shape.items())
    score = next(c for c in det.candidates if c.effect == "unmodelled_mode")
    assert got["mass_mode"] == pytest.approx(score.strength)


def _screened(effect, bound, failed=False):
    from harvester.diagnosis.name.screen import Screened
    return Screened(effect, (), np.zeros(1), 0.0, bound, bound + 30.0, failed, 0, 0.0)


def test_a_candidate_is_sampled_unless_its_evidence_bound_rules_it_out():
    from harvester.diagnosis.name.results import ConfirmSettings
    from harvester.diagnosis.name.skips import skip_reason
    cs = ConfirmSettings()  # acceptance at log(20) = 3.0 nats plus two standard errors
    assert skip_reason(None, [], cs, 3) is None                      # not screened: sampled
    assert skip_reason(_screened("end_stop", 2.0), [], cs, 3) is not None   # cannot pass
    # a failed fit's bound means nothing: its importance estimate decides (test below)
    assert "nothing supports it" in skip_reason(_screened("end_stop", 2.0, failed=True), [],
                                                cs, 3)
    best = [_result("hysteresis", 400.0, se=0.5)]
    # a rival whose best fit cannot reach the accepted gain minus the naming margin
    assert "hysteresis gained 400.0" in skip_reason(_screened("unmodelled_mode", 390.0), best,
                                                    cs, 3)
    assert skip_reason(_screened("unmodelled_mode", 398.0), best, cs, 3) is None  # may tie
    assert skip_reason(_screened("inertia_error", 398.0), best * 3, cs, 3) is not None  # top


def test_acceptance_shares_alpha_among_the_candidates_the_round_could_name():
    # effect-free record s7 of the literature grid: an offset force gained +3.41 nats, over
    # the per-candidate threshold 3.3, in a round that could have named any of 11 effects
    from types import SimpleNamespace


    from harvester.diagnosis.name.confirm import judge


    from harvester.diagnosis.name.results import ConfirmSettings


    from harvester.diagnosis.name.skips import skip_reason
    from harvester.inference.priors import PriorSpec

    one, family = ConfirmSettings(), ConfirmSettings(family=11)
    assert family.acceptance_base == pytest.approx(np.log(11 / 0.05))
    assert family.base_threshold == one.base_threshold == pytest.approx(np.log(20.0))
    prior = PriorSpec("F_offset", 0.0, 1.0, "N", lower=-np.inf)
    samples = np.random.default_rng(0).normal(0.0, 0.1, (400, 1))

    def fit(log_evidence):
        return SimpleNamespace(log_evidence=log_evidence, log_evidence_se=0.05, names=["F_offset"],
                               priors={"F_offset": prior}, samples=samples)

    base = fit(0.0)
    assert judge("offset_force", fit(3.41), base, one).accepted
    assert not judge("offset_force", fit(3.41), base, family).accepted
    assert judge("offset_force", fit(6.0), base, family).accepted
    # a screened candidate that cannot reach the family's threshold is not sampled
    assert skip_reason(_screened("offset_force", 4.5), [], one, 3) is None
    assert "below the acceptance threshold 5.7" in skip_reason(_screened("offset_force", 4.5),
                                                               [], family, 3)


def test_a_candidate_piled_where_it_stands_for_another_term_brings_that_term_in():
    # Karnopp's stick on the literature generator: the Dahl term's pre-sliding displacement
    # piled at its lower bound, where the law is Coulomb's
    from types import SimpleNamespace

    from harvester.diagnosis.name.limits import limit_candidates
    from harvester.model.structures import structure

    tanh = structure("tanh")
    piled = SimpleNamespace(effect="hysteresis", at_prior_edge={"delta_hyst": "lower"})
    piled.at_limit = piled.at_prior_edge
    # there the law is dry friction: the one that holds first (Karnopp's stick is one)
    assert limit_candidates("hysteresis", piled.at_prior_edge, tanh, ["hysteresis"]) == [
        "sticking_friction"]
    assert limit_candidates("hysteresis", piled.at_prior_edge, tanh,
                            ["hysteresis", "sticking_friction"]) == []
    # beside a term the sticking integrator does not take (backlash), Coulomb's law
    assert limit_candidates("hysteresis", piled.at_prior_edge, structure("tanh+backlash"),
                            ["hysteresis"]) == ["coulomb_friction"]
    other_side = SimpleNamespace(effect="hysteresis", at_prior_edge={"delta_hyst": "upper"})
    assert limit_candidates("hysteresis", other_side.at_prior_edge, tanh, ["hysteresis"]) == []
    # a mode's modal mass is part of the stated masses: far above the band it is no mass error
    mode = SimpleNamespace(effect="unmodelled_mode", at_prior_edge={"f_mode": "upper"})
    assert limit_candidates("unmodelled_mode", mode.at_prior_edge, tanh,
                            ["unmodelled_mode"]) == []
    # and the term it becomes is that term's physics, not a rival explanation of it
    from harvester.diagnosis.name.limits import becomes

    other_side.at_limit, mode.at_limit = other_side.at_prior_edge, mode.at_prior_edge
    assert becomes(piled, "coulomb_friction") and becomes(piled, "sticking_friction")
    assert not becomes(piled, "cubic_stiffness")
    assert not becomes(other_side, "coulomb_friction")
    assert not becomes(mode, "inertia_error")


def test_a_trusted_importance_estimate_rules_out_what_the_bound_cannot():
    from harvester.diagnosis.name.results import ConfirmSettings
    from harvester.diagnosis.name.skips import skip_reason
    from harvester.inference.importance import ImportanceEstimate
    cs = ConfirmSettings()
    mode = _screened("unmodelled_mode", 7.9)  # the bound alone would sample it
    mode.importance = ImportanceEstimate(5817.7, 0.2, 0.3, 400.0, 1000)
    mode.importance_gain, mode.importance_gain_se = -4.5, 0.25
    assert skip_reason(mode, [], cs, 3) is None  # not trusted: sampled
    mode.importance_trusted = True
    assert "importance sampling" in skip_reason(mode, [], cs, 3)
    mode.importance_gain = 2.0  # 2.0 + 2 x 0.25 + 1 may still pass 3.0 + margin: sampled
    assert skip_reason(mode, [], cs, 3) is None


def test_a_failed_fit_is_sampled_only_where_a_trusted_importance_estimate_leaves_it_open():
    from harvester.diagnosis.name.results import ConfirmSettings
    from harvester.diagnosis.name.skips import skip_reason
    from harvester.inference.importance import ImportanceEstimate
    cs = ConfirmSettings()
    stop = _screened("backlash", -300.0, failed=True)  # its bound means nothing
    assert "nothing supports it" in skip_reason(stop, [], cs, 3)  # and no estimate either
    # in a round the family's test did not open, nothing supports it
    assert "single effects' scores" in skip_reason(stop, [], cs, 3, single_scores=True)
    # nor once another candidate is accepted
    from types import SimpleNamespace
    mode = SimpleNamespace(effect="unmodelled_mode", accepted=True, contradicted=[], unresolved={},
                           unshown=False)

    def estimate():
        raise AssertionError("estimated after another candidate was accepted")

    stop.pending = estimate  # neither estimated nor sampled: the next round screens it again
    assert "unmodelled_mode was accepted" in skip_reason(stop, [mode], cs, 3)
    stop.pending = None
    stop.importance = ImportanceEstimate(4035.0, 0.3, 0.5, 200.0, 1000)
    stop.importance_gain, stop.importance_gain_se = -360.0, 0.3
    assert "nothing supports it" in skip_reason(stop, [], cs, 3)  # not trusted
    stop.importance_trusted = True
    assert "at most" in skip_reason(stop, [], cs, 3)  # trusted, and it rules the fit out
    stop.importance_gain = 12.0  # trusted, and the optimiser had missed: sampled
    assert skip_reason(stop, [], cs, 3) is None


class _TwoBasins:
    """A stand-in problem whose sum of squares has two basins in its one parameter a:
    r = (a^2 - 1, 0.3 (a - 1)), the best at a = 1 (SSE 0) and a local one near a = -1 (SSE
    about 0.36)."""

    class structure:  # noqa: N801 (the attribute fit_map reads)
        free_parameters = ("a",)
        name = "two_basins"

    parameter_names = ("a", "sigma")
    temper = 1.0
    n_data = 2
    measured_chain = np.zeros(2)

    def residuals(self, theta: np.ndarray) -> np.ndarray:
        a = np.atleast_2d(theta)[:, 0]
        return np.column_stack([a * a - 1.0, 0.3 * (a - 1.0)])

    def predicted(self, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return -self.residuals(theta), np.ones(len(np.atleast_2d(theta)), dtype=bool)


def test_map_solves_from_several_starts_keep_the_best_end() -> None:
    """``fit_map(solves=k)`` runs least squares from the k best starts and keeps the best end:
    the best start (a = -1.0, SSE 0.36) lies in the worse basin, the second (a = 0.5, SSE
    0.585) in the better one; one solve stays at a = -1, two reach a = 1."""
    from harvester.inference.map_fit import fit_map
    priors = {"a": PriorSpec("a", 0.0, 2.0, "-", lower=-np.inf)}
    starts = np.array([[-1.0], [0.5]])
    one = fit_map(_TwoBasins(), priors, n_starts=0, start=starts, solves=1).theta[0]
    two = fit_map(_TwoBasins(), priors, n_starts=0, start=starts, solves=2).theta[0]
    assert one < -0.9
    assert abs(two - 1.0) < 1e-3


class _Level:
    """A stand-in problem with two parameters: a level a that the n data put at ``truth``
    (residuals truth - a plus a fixed pattern of RMS ``noise``), and b, which the data see
    only through ``b_effect`` b (zero: a direction the record cannot see)."""

    class structure:  # noqa: N801 (the attributes fit_map reads)
        free_parameters = ("a", "b")
        name = "level"

    parameter_names = ("a", "b", "sigma")
    temper = 1.0

    def __init__(self, truth: float, noise: float, n: int, b_effect: float = 0.0):
        self.truth, self.n_data, self.b_effect = truth, n, b_effect
        self.pattern = noise * np.sqrt(2.0) * np.sin(np.arange(n) * 0.7)
        self.measured_chain = np.zeros(n)

    def residuals(self, theta: np.ndarray) -> np.ndarray:
        theta = np.atleast_2d(theta)
        shift = self.truth - theta[:, :1] - self.b_effect * theta[:, 1:2]
        return shift + self.pattern[None, :]

    def residual_sums(self, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        sse = np.sum(self.residuals(theta) ** 2, axis=1)
        return sse, np.ones(len(sse), dtype=bool)

    def predicted(self, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return -self.residuals(theta), np.ones(len(np.atleast_2d(theta)), dtype=bool)


def _exact_draws(problem: "_Level", spec: PriorSpec, b: float, n: int = 4000) -> np.ndarray:
    """Exact posterior draws of a (b fixed; flat prior in ln a, sigma profiled as fit_map
    does) by the inverse of its distribution function on a fine grid."""
    u = np.linspace(spec.bounds[0], spec.bounds[1], 20001)
    a = np.exp(u)
    sse = np.sum(problem.residuals(np.column_stack([a, np.full_like(a, b)])) ** 2, axis=1)
    logp = -0.5 * problem.temper * problem.n_data * np.log(sse)
    cdf = np.cumsum(np.exp(logp - logp.max()))
    return a[np.searchsorted(cdf / cdf[-1], (np.arange(n) + 0.5) / n)]


def test_a_map_on_a_bound_is_reported_only_where_the_posterior_must_pile_there() -> None:
    """``bound_pull``: a level the data put at 2 with a log-uniform prior up to 1 has its MAP
    on the upper bound, the posterior falling 23 nats over 5 % of the prior's width inside
    (the closed form's): reported, and the exact
    posterior piles there (``at_prior_edge``). With 5 data points of noise 3 the MAP is on
    the same bound but the posterior spreads over the prior: not reported, and the exact
    posterior does not pile. b, which the data barely see, drifts to a bound without a slope:
    never reported. A level inside its prior is not on a bound."""
    from harvester.inference.map_fit import PILE_NATS, bound_pull, fit_map
    from harvester.diagnosis.detect.scores import EDGE_SHARE, at_prior_edge
    priors = {"a": PriorSpec.log_uniform("a", 0.1, 1.0, "-"),
              "b": PriorSpec.log_uniform("b", 0.1, 1.0, "-")}
    for truth, noise, n, piles in ((2.0, 0.1, 200, True), (2.0, 3.0, 5, False)):
        problem = _Level(truth, noise, n, b_effect=1e-9)
        point = fit_map(problem, priors, n_starts=8, start=np.array([[0.5, 0.99]]))
        assert point.theta[0] == pytest.approx(1.0, rel=1e-3)  # on the upper bound
        found = bound_pull(problem, priors, point, ("a", "b"), EDGE_SHARE)
        pulled = {n: v for n, v in found.items() if v[1] > PILE_NATS}
        exact = at_prior_edge(priors["a"], _exact_draws(problem, priors["a"], point.theta[1]))
        assert ("a" in pulled) is piles and (exact == "upper") is piles
        assert "b" not in pulled
        if piles:  # the slope in ln a at a = 1 is n (truth - 1) / (noise^2 + (truth - 1)^2)
            slope = n * (truth - 1.0) / (noise**2 + (truth - 1.0) ** 2)
            assert pulled["a"][0] == "upper"
            assert pulled["a"][1] == pytest.approx(slope * EDGE_SHARE * np.log(10.0), rel=0.02)
    inside = _Level(0.5, 0.1, 200)
    point = fit_map(inside, priors, n_starts=8)
    assert bound_pull(inside, priors, point, ("a", "b"), EDGE_SHARE) == {}


def test_a_candidate_pulled_against_a_bound_is_sampled_last_and_only_to_tie() -> None:
    """A candidate whose best fit lies on a bound its posterior must pile against cannot be
    named (``judge`` does not trust it): it is sampled after the others, and only where a
    candidate accepted before it leaves a tie to make."""
    from harvester.diagnosis.name.results import ConfirmSettings
    from harvester.diagnosis.name.skips import sampling_order, skip_reason
    cs = ConfirmSettings()
    mode, asym, cubic = (_screened("unmodelled_mode", 167.0), _screened("asymmetric_friction",
                                                                         93.0),
                         _screened("cubic_stiffness", 50.0))
    mode.on_bound = {"zeta_mode": ("lower", 40.0)}
    asym.on_bound = {"v_asym": ("upper", 12.0)}
    cubic.on_bound = {"k_cubic": ("lower", 1.0)}  # on its bound, but the posterior need not pile
    fitted = {s.effect: s for s in (mode, asym, cubic)}
    order, pulled = sampling_order([s.effect for s in (mode, asym, cubic)], fitted)
    assert order == ["cubic_stiffness", "unmodelled_mode", "asymmetric_friction"]
    assert pulled == {"unmodelled_mode", "asymmetric_friction"}
    assert "pile" in skip_reason(mode, [], cs, 3)                      # nothing to tie with
    assert "pile" in skip_reason(mode, [_result("cubic", 48.0, accepted=False)], cs, 3)
    assert skip_reason(mode, [_result("cubic_stiffness", 166.0)], cs, 3) is None  # may tie
    assert "gained" in skip_reason(asym, [_result("cubic_stiffness", 166.0)], cs, 3)
    mode.failed = True  # a failed fit's bound means nothing: its own rule decides
    assert "pile" not in (skip_reason(mode, [], cs, 3) or "")


def test_draws_of_a_trusted_importance_estimate_follow_the_exact_posterior() -> None:
    """``Screened.importance_draws``, which judges a candidate pulled against a bound in
    place of TMCMC (``confirm.judged_by_importance``): on the level whose posterior piles
    against its prior's upper bound, the estimate is trusted, its draws pile there as the
    exact posterior's do, and their mean and sd of ln a match the exact ones."""
    from types import SimpleNamespace

    from harvester.inference.map_fit import fit_map
    from harvester.diagnosis.name.confirm import judged_by_importance
    from harvester.diagnosis.detect.scores import at_prior_edge
    from harvester.diagnosis.name.screen import Screened, importance_evidence
    specs = {"a": PriorSpec.log_uniform("a", 0.1, 1.0, "-"),
             "b": PriorSpec.log_uniform("b", 0.1, 1.0, "-"),
             "sigma": PriorSpec.log_uniform("sigma", 1e-3, 10.0, "-")}
    problem = _Level(2.0, 0.1, 200, b_effect=1e-9)
    point = fit_map(problem, specs, n_starts=8, start=np.array([[0.5, 0.5]]))
    rng = np.random.default_rng(1)
    nested = SimpleNamespace(names=("b", "sigma"), samples=np.column_stack(
        [np.exp(rng.uniform(np.log(0.1), 0.0, 400)), np.full(400, 1.0)]))
    est = importance_evidence(problem, specs, point, nested, seed=0)
    assert est.reliable
    screened = Screened("level", problem.parameter_names, point.theta, 0.0, 10.0, 20.0, False,
                        0, 0.0, problem=problem, specs=specs)
    screened.importance = est
    draws = screened.importance_draws(2000, seed=0)
    exact = np.log(_exact_draws(problem, specs["a"], 0.5))
    got = np.log(draws[:, 0])
    assert at_prior_edge(specs["a"], draws[:, 0]) == "upper"
    assert abs(got.mean() - exact.mean()) < 0.2 * exact.std()
    assert got.std() == pytest.approx(exact.std(), rel=0.3)
    assert np.allclose(draws[:, 2], np.sqrt(np.sum(problem.residuals(draws) ** 2, axis=1)
                                            / problem.n_data))
    # where the estimate is not trusted, TMCMC decides, even for a MAP on a bound
    screened.on_bound = {"a": ("upper", 22.7)}
    assert not screened.importance_trusted
    assert judged_by_importance(None, "level", screened, None, 0) is None
    assert judged_by_importance(None, "level", None, None, 0) is None  # not screened
