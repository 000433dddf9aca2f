"""The missing force's periodic shape fitted as a term of the model (diagnosis.size.shape_terms):
records made here (``latent_records``, the force written outside the library) with a force
periodic in z get its period within 10 %; without it nothing stands; a fitted shape that
beats the named effects' model withholds their names and describes the force."""

from __future__ import annotations

import logging

import numpy as np
import pytest

from latent_records import FS, LOWPASS_HZ, linear_state, recording, rk4_record
from harvester.diagnosis.size.shape_terms import (BEAT_NATS, STAND_NATS, ShapeTermFit,
                                             period_grid, shape_term_fit)
from harvester.diagnosis.detect.signatures import motion_scale
from harvester.model.priors import PriorSpec

pytestmark = pytest.mark.filterwarnings("ignore::UserWarning", "ignore::RuntimeWarning")


@pytest.fixture(autouse=True)
def _quiet():
    logging.getLogger("harvester").setLevel(logging.WARNING)
    yield


def _fitted(force, seconds=10.0, peak=2.0):
    """The periodic shape fitted as a term to the tanh baseline (c_m, F_c, beta free) on a
    record of the linear device with ``force`` added, shaken at ``peak`` m/s^2."""
    from harvester.inference.map_fit import (ChainProblem, baseline_state, chain_problem,
                                              fit_map)
    from harvester.diagnosis.detect.scores import estimate_temper
    from harvester.inference.likelihood import DAQ_OVERSAMPLE
    from harvester.model.structures import structure
    from harvester.synthetic.measured import TABLE1_KNOWN
    df = recording(rk4_record(force, seconds, peak=peak), "rel_acc")
    window = (int(FS), len(df) - int(0.5 * FS))
    problem = ChainProblem(structure("tanh"), df["base_acc"].to_numpy(),
                           df["rel_acc"].to_numpy(), 1.0 / FS, dict(TABLE1_KNOWN), window,
                           output_kind="rel_acc", lowpass_hz=LOWPASS_HZ,
                           oversample=DAQ_OVERSAMPLE)
    priors = {"c_m": PriorSpec("c_m", 60.0, 20.0, "N s/m"),
              "F_c": PriorSpec("F_c", 6.0, 3.0, "N"),
              "beta": PriorSpec.log_uniform("beta", 10.0, 1e4, "s/m"),
              "sigma": PriorSpec("sigma", 0.02, 0.01, "m/s^2")}
    base = fit_map(problem, priors, seed=0)
    # tempered for the low-passed noise's correlation, as the diagnosis does
    temper = estimate_temper(base.residual, window, FS, LOWPASS_HZ)
    problem = chain_problem(problem, temper, LOWPASS_HZ, problem.filter_order)
    base = fit_map(problem, priors, seed=0, start=base.theta[:-1])
    state = baseline_state(problem, base.samples(20))
    start, stop = window
    return shape_term_fit(problem, priors, base.samples(4), state.rel_disp[start:stop],
                          state.rel_vel[start:stop], motion_scale(state, window, LOWPASS_HZ),
                          LOWPASS_HZ, None)


def _friction(z, v, t):
    return 6.0 * np.tanh(v / 1e-3)


def test_a_period_in_z_is_found_along_the_models_own_motion():
    """A 2 N detent of period 1 mm beside 6 N of friction (z about 0.8 mm RMS): period
    within 10 % (1.1 % measured), amplitude within 20 %, well beyond STAND_NATS; the
    sentence says so."""
    fit = _fitted(lambda z, v, t: _friction(z, v, t) + 2.0 * np.sin(2 * np.pi * z / 1e-3 + 0.7))
    assert fit.parameters["period_m"] == pytest.approx(1e-3, rel=0.1)
    assert fit.parameters["amplitude_N"] == pytest.approx(2.0, rel=0.2)
    assert fit.stands and fit.gain_nats > 3 * STAND_NATS  # 229 nats measured
    assert "a force periodic in z, period 1" in fit.sentence()
    assert fit.to_dict()["stands"] is True and fit.named is None and not fit.beats_names


def test_nothing_stands_without_the_force():
    """The same device without it: the shape gains less than STAND_NATS."""
    fit = _fitted(_friction)
    assert fit is not None and not fit.stands


def test_the_grid_keeps_within_the_band_and_the_prior():
    """Periods half a period over the span apart, none below v_rms / f_high (finer lies
    beyond the band) or outside the prior; none for a motion without span."""
    z = np.sin(np.linspace(0.0, 60.0, 6000)) * 1e-3
    v = np.full_like(z, 1e-3)
    specs = {"P_periodic": PriorSpec.log_uniform("P_periodic", 2e-5, 2e-3, "m")}
    grid = period_grid(z, v, 20.0, specs)
    span = float(np.subtract(*np.quantile(z, [0.99, 0.01])))
    assert grid.min() >= 1e-3 / 20.0 - 1e-12 and grid.max() <= 2e-3
    assert np.allclose(np.diff(span / grid[::-1]), -0.5) or np.allclose(
        np.diff(span / grid), 0.5)
    assert period_grid(np.zeros(10), v[:10], 20.0, specs).size == 0


def test_a_fitted_shape_that_beats_the_names_withholds_them():
    """A named cubic spring whose model a periodic force fitted as a term beats by more
    than BEAT_NATS is withheld; the headline says the fitted shape where the smoother read
    no force; within BEAT_NATS, the name stands."""
    from types import SimpleNamespace

    from harvester.diagnosis.size.missing_force import missing_force
    from harvester.diagnosis.prepare.settings import DiagnosisSettings
    from harvester.diagnosis.name.verdict import Conclusion, FitJudgement, judge, withheld_names
    out = missing_force(linear_state(recording(rk4_record(lambda z, v, t: 0.0 * z, 12.0))),
                        draws=20)
    assert not out.description.readable
    found = Conclusion("missing_physics", ["cubic_stiffness"], [], False, [], None, True)
    shaped = ShapeTermFit("periodic in z", "periodic_force",
                          {"period_m": 1e-4, "amplitude_N": 0.6, "phase_rad": 2.7}, 300.0,
                          "linear", "linear+cubic_stiffness", 300.0 - BEAT_NATS + 1.0)
    out.fitted_shape = shaped
    assert withheld_names(found, out) is None
    shaped.named_gain_nats = 100.0
    why = withheld_names(found, out)
    assert "fits the record better than linear+cubic_stiffness by 200 nats" in why
    judged = judge(found, SimpleNamespace(p_value=1e-4, significant=True, conflict=False),
                   FitJudgement(0.7, 0.55, "holdout", 2.0, None, 0.75), "linear",
                   DiagnosisSettings(), out)
    assert judged.missing == [] and judged.withheld == ["cubic_stiffness"]
    assert "the missing force: a force periodic in z, period 0.1 mm" in judged.headline
    assert out.to_dict()["fitted_shape"]["beats_names"] is True
    assert out.to_dict()["fitted_shape"]["speaks"] is True
