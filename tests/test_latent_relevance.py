"""A named effect's size and relevance beside the latent force (diagnosis.size.relevance) and the
one-call entry point (diagnosis.size.missing_force)."""

from __future__ import annotations

import json
import logging

import numpy as np
import pytest

from latent_records import linear_state, recording, rk4_record
from harvester.diagnosis.size.missing_force import NamedEffect, missing_force
from harvester.diagnosis.size.relevance import RelevanceFloor
from harvester.model.structures import structure

pytestmark = pytest.mark.filterwarnings("ignore::UserWarning", "ignore::RuntimeWarning")


@pytest.fixture(autouse=True)
def _quiet():
    logging.getLogger("harvester").setLevel(logging.WARNING)
    yield


def test_a_relevant_friction_and_a_negligible_mass_error(tmp_path):
    """On a record with 6 N of Coulomb friction: the friction named (at its truth) has the
    latent force's size (4.2 N RMS against 4.5 N), 52 % of the drive, is relevant and
    explains 77 % of the missing force; an inertia error of 0.055 % of M (the literature
    grid's false alarm) is detectable but negligible, and relevant with the floor off."""
    truth = rk4_record(lambda z, v, t: 6.0 * np.tanh(v / 1e-3), 12.0)
    state = linear_state(recording(truth, "rel_acc"))
    friction = NamedEffect("coulomb_friction", structure("linear+coulomb_friction"),
                           np.array([60.0, 6.0]))
    mass = NamedEffect("inertia_error", structure("linear+inertia_error"),
                       np.array([60.0, 0.00055 * 12.8, 0.5]))
    unseen = rk4_record(lambda z, v, t: 0.0, 8.0, seed=5)["y"]
    out = missing_force(state, named=[friction, mass], unseen_input=unseen,
                        unseen_window=slice(256, -128), out_dir=tmp_path, draws=40)
    f_size, m_size = out.sizes
    assert f_size.label == "relevant"
    assert f_size.force_rms_N == pytest.approx(out.latent.rms_N, rel=0.25)  # 4.2 and 4.5 N
    assert f_size.share_of_latent > 0.6 and f_size.response_change_share > 0.1
    assert m_size.label == "detectable but negligible"
    assert m_size.share_of_drive < 1e-3 and m_size.response_change_share < 1e-3
    off = missing_force(state, named=[mass], floor=RelevanceFloor(enabled=False), draws=10)
    assert off.sizes[0].label == "relevant"
    entry = json.loads(json.dumps(out.to_dict()))
    assert entry["named_effects"][1]["relevance"] == "detectable but negligible"
    assert entry["shape"]["shapes"][0]["shape"] == "friction"
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "latent_force.png", "latent_force_coulomb_friction.png", "latent_force_inertia_error.png"]


def test_the_diagnosis_baseline_state_goes_through_in_one_call():
    """quick_detect's own BaselineState (linear baseline fitted by MAP, its c_m driven up to
    720 N s/m by the friction) on a record of the study's tanh device (Table 5): the missing
    force is friction-like beside negative viscous damping (8.1 N and -459 N s/m measured,
    against 11.9 N and 109.5 - 720 = -610 N s/m: the fit shares F and c)."""
    from harvester.diagnosis import DiagnosisSettings, quick_detect
    from harvester.synthetic.measured import TABLE1_KNOWN, TANH_TABLE5, measured_recording

    df, _ = measured_recording(("tanh_friction",), {**TABLE1_KNOWN, **TANH_TABLE5}, 20.0, seed=3)
    _, state = quick_detect(df, "linear", TABLE1_KNOWN,
                            settings=DiagnosisSettings(bootstrap=100, seed=0))
    out = missing_force(state, draws=40)
    best = out.description.best
    assert best.name == "friction" and 5.0 < best.parameters["F_N"] < 14.0
    assert best.parameters["c_N_s_per_m"] < 0.0
    assert json.loads(json.dumps(out.to_dict()))["latent_force"]["output_kind"] == "rel_acc"


def test_a_residual_the_smoother_cannot_carry_is_not_called_no_missing_force():
    """verdict.latent_unread: the smoother's noise at its bound (the baseline's sigma) and no
    force beyond its band, while the residual is far above the recording's own noise floor,
    is said as unread (the frame at 450 g), not as "no missing force"; below the floor's limit,
    or with the noise fitted below its bound, the description stands."""
    from types import SimpleNamespace

    from harvester.diagnosis.name.verdict import Conclusion, FitJudgement, headline, latent_unread
    lf = SimpleNamespace(noise_sd=2.8e-4, baseline_noise_sd=2.8e-4, force=np.full(50, 0.1),
                         sd=np.full(50, 0.2))
    missing = SimpleNamespace(latent=lf, sizes=[], description=SimpleNamespace(
        sentence="no missing force beyond its uncertainty (RMS 0.1 N against an sd of 0.2 N)"),
        fitted_shape=None, shape_speaks=False)
    missing.sentence = lambda: missing.description.sentence
    floor = SimpleNamespace(rms=1.0, bound="upper", method="repeated_periods")
    far = FitJudgement(0.95, 0.227, "holdout", 15.0, floor)
    assert latent_unread(missing, far, 3.0)
    found = Conclusion("missing_physics", [], [], True, [], None, False)
    said = headline("missing_physics", found, far, "linear", 3.0, missing)
    assert "not readable by the smoother" in said and "no missing force" not in said
    assert not latent_unread(missing, FitJudgement(0.95, 0.227, "holdout", 2.0, floor), 3.0)
    assert not latent_unread(missing, FitJudgement(0.95, 0.227, "holdout", 15.0, None), 3.0)
    lf.noise_sd = 1.8e-4
    assert not latent_unread(missing, far, 3.0)
    assert "no missing force" in headline("missing_physics", found, far, "linear", 3.0, missing)


def test_one_named_effect_is_sized_by_its_own_force_in_the_headline():
    """A named end stop whose force along the smoothed states (9.97 N, impacts where the
    states are uncertain by millimetres) is 53 x its own along its own response (0.189 N):
    the headline gives its own force with its interval and share of the drive; two effects
    together keep the force beyond the baseline's."""
    from types import SimpleNamespace

    from harvester.diagnosis.size.relevance import EffectSize, OwnForce, RelevanceFloor
    from harvester.diagnosis.name.verdict import _named
    own = OwnForce((0.189, 0.128, 0.202), (0.001, -0.01, 0.01), (0.189, 0.128, 0.202), False)
    size = EffectSize("end_stop", 9.97, 3.71, 0.0, None, None, False, RelevanceFloor(),
                      own=own, drive_rms_N=9.97 / 3.71)
    found = SimpleNamespace(named_fit=None, improved_fit=None, missing=["end_stop"], ties=[])
    said = _named(found, SimpleNamespace(sizes=[size], together=None))
    assert said == ("end_stop (its own force 0.189 N RMS, 95 % 0.128-0.202, 7.03% of the "
                    "drive, relevant)")
    two = _named(SimpleNamespace(named_fit=None, improved_fit=None,
                                 missing=["end_stop", "cubic_stiffness"], ties=[]),
                 SimpleNamespace(sizes=[size, size], together=None))
    assert "(together 9.97 N RMS, 371.00% of the drive, relevant)" in two
    # sized together from one fit: their own forces summed, with the interval
    both = OwnForce((0.00493, 0.0046, 0.0052), (0.0, -1e-4, 1e-4), (0.00493, 0.0046, 0.0052),
                    False)
    two = _named(SimpleNamespace(named_fit=None, improved_fit=None,
                                 missing=["end_stop", "cubic_stiffness"], ties=[]),
                 SimpleNamespace(sizes=[size, size], together=both))
    assert two.endswith("(together their own force 0.00493 N RMS, 95 % 0.0046-0.0052, "
                        "0.18% of the drive, relevant)")
    # an even force on an acceleration record: its varying part, its mean said apart
    size.own = OwnForce((0.24, 0.23, 0.26), (0.21, 0.2, 0.22), (0.115, 0.11, 0.12), False)
    assert _named(found, SimpleNamespace(sizes=[size], together=None)) == (
        "end_stop (its own force 0.115 N RMS about its mean, 95 % 0.11-0.12, its mean 0.21 N "
        "the form's, not the record's, 4.28% of the drive, relevant)")


def test_an_own_forces_share_of_the_drive_is_over_its_own_span():
    """relevance.drive_rms over another input, and effect_size's own_drive_N: the share of
    the drive the headline gives a term's own force is of the drive over the same span (the
    record after the lead-in), while the force along the states keeps the window's."""
    from types import SimpleNamespace

    from harvester.diagnosis.size.relevance import (EffectSize, OwnForce, RelevanceFloor, drive_rms,
                                               effect_size)
    window = np.full(100, 2.0)
    from harvester.data.units import SI
    lf = SimpleNamespace(values={"m": 0.5}, input_kind="base_acc", input=window, units=SI)
    assert drive_rms(lf) == pytest.approx(1.0)
    assert drive_rms(lf, np.full(50, 4.0)) == pytest.approx(2.0)
    ef = SimpleNamespace(term="inertia_error", rms_N=0.1, share=0.2)
    for own, drive in ((None, 1.0), (2.0, 2.0)):
        size = effect_size(lf, ef, RelevanceFloor(),
                           own=OwnForce((0.3, 0.25, 0.35), (0.0, -0.01, 0.01), (0.3, 0.25, 0.35)),
                           own_drive_N=own)
        assert isinstance(size, EffectSize) and size.share_of_drive == pytest.approx(0.1)
        assert size.own_share_of_drive == pytest.approx(0.3 / drive)


def test_a_term_named_beside_another_is_sized_by_its_own_force():
    """The Bouc-Wen benchmark's 40 s record named a mass error of 0.74 g beside the
    hysteretic spring from one fit: their force together is the spring's (23.4 N, 47 % of
    the drive), the mass error's own 0.036 N (0.07 %). It is detectable but negligible, not
    a name of missing physics; the spring alone is sized in the headline. Two terms each
    above the floor, or one without its own force, are left as they are."""
    from types import SimpleNamespace

    from harvester.diagnosis.size.relevance import (EffectSize, OwnForce, RelevanceFloor,
                                                    negligible_beside)
    from harvester.diagnosis.name.verdict import _named

    def size(term, own_rms, drive=50.1):
        own = None if own_rms is None else OwnForce((own_rms, own_rms, own_rms), (0, 0, 0),
                                                    (own_rms, own_rms, own_rms), False)
        return EffectSize(term, 23.4, 23.4 / drive, 0.98, None, None, False, RelevanceFloor(),
                          own=own, drive_rms_N=drive)

    spring, mass = size("hysteretic_spring", 22.6), size("inertia_error", 0.0356)
    assert negligible_beside([spring, mass]) == ["inertia_error"]
    assert mass.label == "detectable but negligible" and spring.label == "relevant"
    assert mass.sentence().startswith("inertia_error: named beside hysteretic_spring; its "
                                      "own force 0.0356 N RMS")
    found = SimpleNamespace(named_fit=None, improved_fit=None, ties=[],
                            missing=["hysteretic_spring"])
    said = _named(found, SimpleNamespace(sizes=[spring, mass], together=None))
    assert said == ("hysteretic_spring (its own force 22.6 N RMS, 95 % 22.6-22.6, 45.11% of "
                    "the drive, relevant)")
    assert negligible_beside([size("a", 22.6), size("b", 3.0)]) == []
    assert negligible_beside([size("a", 22.6), size("b", None)]) == []
    # the floor off: nothing is negligible
    off = size("c", 0.01)
    off.floor = RelevanceFloor(enabled=False)
    assert negligible_beside([size("a", 22.6), off]) == []


def test_a_name_negligible_beside_a_relevant_one_is_listed_as_negligible():
    """judge: a mass error negligible beside a relevant spring (the Bouc-Wen benchmark's 40 s
    record) leaves ``missing`` for ``negligible``; names that are all negligible stay named
    (the literature generator's Dahl, LuGre and ground friction at half the noise RMS, each
    0.16-0.29 % of the drive, are its right names), the verdict's label saying so."""
    from types import SimpleNamespace

    from harvester.diagnosis.name.verdict import Conclusion, FitJudgement, judge
    from harvester.diagnosis.prepare.settings import DiagnosisSettings
    from harvester.diagnosis.size.relevance import EffectSize, OwnForce, RelevanceFloor

    def size(term, own_rms, drive=50.1):
        own = OwnForce((own_rms,) * 3, (0.0,) * 3, (own_rms,) * 3, False)
        floor = RelevanceFloor()
        share = own_rms / drive
        return EffectSize(term, own_rms, share, 0.3, None, None, share < floor.force_share,
                          floor, own=own, drive_rms_N=drive)

    def judged(sizes):
        desc = SimpleNamespace(sentence="a hysteresis loop in (z, f)", readable=True,
                               determined=[], best=SimpleNamespace(name="loop", share=0.14))
        missing = SimpleNamespace(sizes=sizes, description=desc, fitted_shape=None,
                                  shape_speaks=False, together=None, residual_line=None,
                                  latent=SimpleNamespace(noise_sd=1.0, baseline_noise_sd=2.0))
        missing.sentence = lambda: desc.sentence
        found = Conclusion("missing_physics", [s.term for s in sizes], [], False, [], None,
                           True)
        fit = FitJudgement(0.99, 0.0035, "holdout", 0.97, None, None)
        detection = SimpleNamespace(p_value=1e-7, significant=True, conflict=False)
        return judge(found, detection, fit, "tanh", DiagnosisSettings(), missing)

    beside = judged([size("hysteretic_spring", 22.6), size("inertia_error", 0.0356)])
    assert beside.missing == ["hysteretic_spring"] and beside.negligible == ["inertia_error"]
    alone = judged([size("hysteresis", 0.08)])
    assert alone.missing == ["hysteresis"] and alone.negligible == []
    assert "detectable but negligible" in alone.headline
