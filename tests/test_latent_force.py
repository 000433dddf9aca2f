"""The missing force as a latent force (diagnosis.size.latent): the Matern state space, the terms'
forces along a path (the library's laws), and the force recovered within its bands on records
with a known added force (the library's simulator, and an integrator written here)."""

from __future__ import annotations

import logging

import numpy as np
import pytest
from scipy import signal

import pandas as pd

from latent_records import C_M, FS, linear_state, recording, rk4_record
from harvester.inference.map_fit import ChainProblem, baseline_state
from harvester.diagnosis.size.latent import latent_force, through_response
from harvester.diagnosis.size.views import binned, effect_force, views
from harvester.diagnosis.size.shapes import describe
from harvester.data.signals import butterworth_sos, lowpass
from harvester.inference.state_space import (discretise, filtered_noise, kalman_filter,
                                             kalman_loglik, matern, rts_smoother)
from harvester.model.term_forces import model_force
from harvester.inference.likelihood import DAQ_OVERSAMPLE
from harvester.model.simulate import simulate
from harvester.model.structures import Layout, structure
from harvester.synthetic.measured import TABLE1_KNOWN, measured_recording

pytestmark = pytest.mark.filterwarnings("ignore::UserWarning", "ignore::RuntimeWarning")


@pytest.fixture(autouse=True)
def _quiet():
    logging.getLogger("harvester").setLevel(logging.WARNING)
    yield


def _library_record(terms, values, seconds=16.0, seed=1):
    """A record of the library's simulator (no base sensor noise), the truth's states."""
    df, _ = measured_recording(terms, values, seconds, seed, base_noise_m_s2=0.0)
    layout = Layout.of(terms)
    sim = simulate(layout, np.array([values[p] for p in layout.parameter_names]),
                   df["base_acc"].to_numpy(), 1.0 / FS, oversample=8)
    return df, sim


def _state(df, baseline, theta, window_end_s=0.5):
    n = len(df)
    problem = ChainProblem(structure(baseline), df["base_acc"].to_numpy(),
                           df["rel_acc"].to_numpy(), 1.0 / FS, dict(TABLE1_KNOWN),
                           (int(FS), n - int(window_end_s * FS)), lowpass_hz=20.0,
                           oversample=DAQ_OVERSAMPLE)
    state = baseline_state(problem, np.append(theta, 1.0)[None, :])
    state.theta[-1] = float(np.std(state.residual[problem.samples]))
    return state


def _check(lf, truth, coverage=(0.85, 1.0), rel_error=0.3):
    err = lf.force - truth
    inside = np.mean(np.abs(err) < 2.0 * lf.sd)
    assert coverage[0] <= inside <= coverage[1], inside
    assert np.sqrt(np.mean(err**2)) < rel_error * np.sqrt(np.mean(truth**2))
    return inside


def test_the_state_space_is_the_matern_process():
    """Stationary variance s_f^2 and derivative variance lam^2 s_f^2 (3/2); the discrete
    noise keeps the stationary covariance: Q = P_inf - Phi P_inf Phi^T."""
    F, q, P = matern("matern32", 0.3, 2.0)
    assert P[0, 0] == pytest.approx(4.0) and P[1, 1] == pytest.approx(4.0 * 3 / 0.09)
    F, q, P = matern("matern52", 0.3, 2.0)
    W = np.zeros((3, 3))
    W[-1, -1] = q
    d = discretise(F, np.zeros(3), W, 0.01)
    assert np.allclose(d.Q, P - d.Phi @ P @ d.Phi.T, atol=1e-9 * np.abs(P).max())
    # the drive's first-order hold: a constant input over a step of x' = -x + d
    d = discretise(np.array([[-1.0]]), np.array([1.0]), np.zeros((1, 1)), 0.5)
    assert d.G0[0] + d.G1[0] == pytest.approx(1.0 - np.exp(-0.5))


def test_the_filter_and_the_compiled_likelihood_agree():
    """The path-storing filter (numpy, covariances copied once their cycle repeats) and the
    compiled likelihood (gain frozen once steady) give the same marginal likelihood; the
    smoother's means lie closer to the signal than the data."""
    F, q, P = matern("matern32", 0.05, 1.0)
    W = np.zeros((2, 2))
    W[-1, -1] = q
    d = discretise(F, np.zeros(2), W, 1.0 / FS)
    rng = np.random.default_rng(0)
    y = np.sin(np.arange(2000) / 20.0) + 0.3 * rng.standard_normal(2000)
    H, drive = np.array([1.0, 0.0]), np.zeros(2000)
    measured = np.arange(2000) % 4 == 0
    mf, Pf, mp, Pp, ll = kalman_filter(d.Phi, d.G0, d.G1, d.Q, H, 0.0, 0.09, drive, y,
                                       measured, np.zeros(2), P)
    assert ll == pytest.approx(kalman_loglik(d.Phi, d.G0, d.G1, d.Q, H, 0.0, 0.09, drive, y,
                                             4, np.zeros(2), P), abs=1e-6)
    ms, J, C = rts_smoother(d.Phi, mf, Pf, mp, Pp)
    assert np.std(ms[:, 0] - np.sin(np.arange(2000) / 20.0)) < 0.25  # the noise: 0.3


def test_the_chains_noise_as_a_state_space_has_the_zero_phase_filters_spectrum():
    """White noise through sosfiltfilt (20 Hz, order 8, 256 Hz) has the autocovariance of the
    cascade run twice forward; the state space's, c A^k P c, is that, normalised to unit
    variance, to round-off."""
    sos = butterworth_sos(FS, 20.0, 8)
    A, c, P = filtered_noise(sos)
    h = signal.sosfilt(np.concatenate([sos, sos]), np.r_[1.0, np.zeros(4000)])
    acov = np.correlate(h, h, "full")[h.size - 1:][:60]
    model, x = [], P @ c
    for _ in range(60):
        model.append(c @ x)
        x = A @ x
    assert model[0] == pytest.approx(1.0, abs=1e-9)
    assert np.allclose(model, acov / acov[0], atol=1e-9)


def _disp_state(extra, seconds=12.0):
    """A z record of ``extra`` under the linear baseline at the truth, its noise level (the
    sensor's through the chain) known, as a recording's own floor gives it."""
    truth = rk4_record(extra, seconds)
    state = linear_state(recording(truth, "rel_disp"))
    p = state.problem
    noise = float(np.std((p.measured_chain - p.chain(truth["z"]))[slice(*p.window)]))
    return state, truth, noise


def test_a_displacement_record_with_its_noise_given_is_measured_at_every_sample():
    """With its noise level given, a z record's band-limited noise is a state space and every
    sample is measured: no force where none was added; a 2 N Coulomb friction recovered
    within its bands (measured: error 0.19 N RMS on 1.86 N, 81 % inside; every 8th sample
    measured with white noise: 0.20 N, 93 %: the bands narrower, 0.13 N against 0.18 N)."""
    state, _, noise = _disp_state(lambda z, v, t: 0.0)
    lf = latent_force(state, noise=noise, draws=40)
    assert lf.noise_in_band and lf.stride == 1
    assert describe(lf).sentence.startswith("no missing force"), describe(lf).sentence
    state, truth, noise = _disp_state(lambda z, v, t: 2.0 * np.tanh(v / 1e-3))
    lf = latent_force(state, noise=noise, draws=40)
    w = slice(*state.problem.window)
    _check(lf, state.problem.chain(truth["f"])[w], coverage=(0.75, 1.0), rel_error=0.15)


def test_terms_forces_close_eq1_along_a_simulated_path():
    """Along the simulator's own path, M z'' + c_m z' + k z + sum_T X_T = -m y'' (the terms'
    laws reused, masses of an inertia term included)."""
    terms = ("tanh_friction", "cubic_stiffness", "inertia_error")
    values = {**TABLE1_KNOWN, "c_m": 60.0, "F_c": 5.0, "beta": 200.0, "k_cubic": 3e5,
              "dM": 0.8, "m_share": 0.5}
    layout = Layout.of(terms)
    y = np.sin(2 * np.pi * 1.3 * np.arange(2048) / FS) * 3.0
    sim = simulate(layout, np.array([values[p] for p in layout.parameter_names]), y, 1 / FS)
    z, v, a = sim.rel_disp, sim.rel_vel, sim.rel_acc
    lhs = values["M"] * a + model_force(layout, values, z, v, a, y, 1 / FS)
    assert np.max(np.abs(lhs[0] + values["m"] * y)) < 1e-6 * np.max(np.abs(values["m"] * y))


def test_a_coulomb_force_is_recovered_within_its_bands():
    """Linear baseline at the true c_m on a record of linear + Coulomb friction (6 N; the
    library's simulator): the band-limited truth lies within +-2 sd at about the nominal
    rate (0.99 measured on 16 s), the error is a fifth of the force."""
    values = {**TABLE1_KNOWN, "c_m": 60.0, "F_coulomb": 6.0}
    df, sim = _library_record(("coulomb_friction",), values)
    state = _state(df, "linear", [60.0])
    lf = latent_force(state)
    w = slice(*state.problem.window)
    truth = state.problem.chain(6.0 * np.tanh(sim.rel_vel[0] / 1e-3))[w]
    _check(lf, truth)
    assert lf.to_dict()["rms_N"] == pytest.approx(np.sqrt(np.mean(truth**2)), rel=0.1)


def test_the_posterior_mean_sees_a_force_through_the_smoothers_response():
    """The smoother is linear: its posterior mean of a force is W * f plus noise. On the 6 N
    Coulomb record (4.8 N RMS through the band) it lies 0.44 N RMS from W * f against 0.83 N
    from the banded f (measured); from z'' a static force is not seen (W's sum about 0)."""
    truth = rk4_record(lambda z, v, t: 6.0 * np.tanh(v / 1e-3), 12.0)
    state = linear_state(recording(truth, "rel_acc"))
    lf = latent_force(state, draws=20)
    w = slice(*state.problem.window)
    seen = state.problem.chain(through_response(truth["f"], lf.response))[w]
    banded = state.problem.chain(truth["f"])[w]
    err = lambda x: np.sqrt(np.mean((lf.force - x) ** 2))  # noqa: E731
    assert err(seen) < 0.65 * err(banded), (err(seen), err(banded))
    assert abs(lf.response.sum()) < 0.05 * np.max(lf.response) * lf.stride


def test_a_missing_cubic_spring_under_a_friction_baseline():
    """Baseline linear + tanh friction at its truth, record with a cubic spring too: the
    friction is taken out along joint draws of the path, the cubic force remains. The noise
    is given (the sensor's, through the chain, as an independent floor would give it): the
    marginal likelihood alone takes the cubic force's bursts for noise up to the baseline's
    sigma (the bands then widen: the default keeps its coverage, loses precision). A term's
    force inherits its slope x the velocity's uncertainty (about 1.6 mm/s from z''): a
    sharper law (beta = 100 s/m) left 0.7 N of error on 1 N, this one 0.6 N on 1.4 N."""
    values = {**TABLE1_KNOWN, "c_m": 60.0, "F_c": 4.0, "beta": 30.0, "k_cubic": 1e7}
    df, sim = _library_record(("tanh_friction", "cubic_stiffness"), values)
    state = _state(df, "linear+tanh_friction", [60.0, 4.0, 30.0])
    lf = latent_force(state, draws=60, noise=0.04 * np.sqrt(16.0 / 128.0))
    w = slice(*state.problem.window)
    truth = state.problem.chain(1e7 * sim.rel_disp[0] ** 3)[w]
    _check(lf, truth, rel_error=0.5)  # 0.43 measured
    assert describe(lf).best.name == "odd in z"
    default = latent_force(state, draws=60)
    _check(default, truth, rel_error=1.0)


def test_a_displacement_record_is_smoothed_in_its_own_unit():
    """rel_disp (m) measured: a slow drift of the force, invisible in z'', is recovered."""
    truth = rk4_record(lambda z, v, t: 0.25 * t - 2.0, 16.0)
    state = linear_state(recording(truth, "rel_disp"))
    lf = latent_force(state)
    w = slice(*state.problem.window)
    _check(lf, state.problem.chain(truth["f"])[w], rel_error=0.1)
    assert lf.output_kind == "rel_disp"


def test_no_missing_force_gives_nothing_beyond_its_band():
    """The baseline is the truth: f's RMS stays within its sd and the description says so."""
    state = linear_state(recording(rk4_record(lambda z, v, t: 0.0, 12.0), "rel_acc"))
    lf = latent_force(state)
    assert lf.rms_N < 2.0 * np.mean(lf.sd) + 0.05
    assert describe(lf).sentence.startswith("no missing force")


def test_noise_band_limited_below_nyquist_is_not_read_as_force():
    """An effect-free z'' record whose noise went through a low-pass at 0.32 x the sample rate
    (the band the likelihood gives an unfiltered record; fs / (2 band) = 1.56): measured at
    every sample, the noise's stop band makes it predictable from its past, and the marginal
    likelihood traded it for a force at the shortest length scale (the literature grid's
    payload record: noise 0.013 against its floor of 0.089 m/s^2, a force 26 x the truth's).
    Measured every second sample, where the noise is close to white, it is noise."""
    truth = rk4_record(lambda z, v, t: 0.0, 12.0)
    rng = np.random.default_rng(3)
    band = 0.32 * FS
    noisy = lowpass(truth["a"] + 0.05 * rng.standard_normal(truth["a"].size), FS, band, 8)
    df = pd.DataFrame({"time": np.arange(noisy.size) / FS, "base_acc": truth["y"],
                       "rel_acc": noisy})
    n = len(df)
    problem = ChainProblem(structure("linear"), df["base_acc"].to_numpy(),
                           df["rel_acc"].to_numpy(), 1.0 / FS, dict(TABLE1_KNOWN),
                           (int(FS), n - int(0.5 * FS)), lowpass_hz=band,
                           oversample=DAQ_OVERSAMPLE)
    state = baseline_state(problem, np.array([[C_M, 1.0]]))
    in_band = float(np.std(state.residual[problem.samples]))
    state.theta[-1] = in_band
    lf = latent_force(state, draws=40)
    assert lf.stride == 2
    assert lf.noise_sd > 0.8 * in_band, (lf.noise_sd, in_band)
    assert describe(lf).sentence.startswith("no missing force"), describe(lf).sentence


def test_views_and_the_named_effect_beside_the_latent_force():
    """Binned against z' the missing Coulomb force is a sign law whose bands hold +-F; the
    improved model (linear + Coulomb at the truth) takes the shape of the latent force."""
    truth = rk4_record(lambda z, v, t: 6.0 * np.tanh(v / 1e-3), 12.0)
    state = linear_state(recording(truth, "rel_acc"))
    lf = latent_force(state)
    v = binned(lf, "z'", bins=12)
    assert v.lower[-1] < 6.0 < v.upper[-1] + 0.5 and v.lower[0] - 0.5 < -6.0 < v.upper[0]
    assert set(views(lf)) == {"z", "z'", "time", "input"}
    ef = effect_force(lf, structure("linear+coulomb_friction"), np.array([60.0, 6.0, 0.1]),
                      state.problem.known, "coulomb_friction")
    assert ef.share > 0.6 and ef.rms_N == pytest.approx(lf.rms_N, rel=0.25)
    wrong = effect_force(lf, structure("linear+cubic_stiffness"), np.array([60.0, 1e6]),
                         state.problem.known, "cubic_stiffness")
    assert wrong.share < 0.2


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(4))
def test_coverage_over_seeds_on_40_s_records(seed):
    """40 s records of linear + Coulomb (6 N, the library's simulator), linear baseline at the
    truth, default settings: +-2 sd holds the band-limited truth at 0.96-1.0 of the samples
    (conservative), the error a fifth of the force or less."""
    values = {**TABLE1_KNOWN, "c_m": 60.0, "F_coulomb": 6.0}
    df, sim = _library_record(("coulomb_friction",), values, seconds=41.5, seed=10 + seed)
    state = _state(df, "linear", [60.0])
    lf = latent_force(state)
    w = slice(*state.problem.window)
    _check(lf, state.problem.chain(6.0 * np.tanh(sim.rel_vel[0] / 1e-3))[w], (0.93, 1.0), 0.22)
