"""The diagnosis's decision rules: the verdict, and which ranked candidates are sampled."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from harvester.diagnosis.detect.scores import DetectionSettings, data_estimate, prior_conflicts
from harvester.diagnosis.name.rank import RankedCandidate, limit_rivals, rivals, to_confirm
from harvester.inference.priors import PriorSpec
from harvester.diagnosis.detect.floor import Floor
from harvester.diagnosis.run import decide_verdict
from harvester.diagnosis.prepare.settings import DiagnosisSettings
from harvester.diagnosis.name.verdict import FitJudgement
from harvester.diagnosis.detect.signatures import candidate_terms


def test_verdict_needs_evidence_or_a_strong_unexplained_detection():
    # a screening detection at p < 0.05 alone is not enough: it fires in 5 % of clean records
    assert decide_verdict(0.01, accepted=False, unexplained_alpha=0.001) == "adequate"
    assert decide_verdict(0.0005, accepted=False, unexplained_alpha=0.001) == "missing_physics"
    # an effect confirmed by evidence is enough whatever the screening said (prior conflict)
    assert decide_verdict(0.4, accepted=True, unexplained_alpha=0.001) == "missing_physics"
    assert decide_verdict(0.4, accepted=False, unexplained_alpha=0.001) == "adequate"


def test_a_model_that_explains_little_is_inadequate_unless_the_noise_limits_it():
    # the frame's linear baseline: holdout NRMSE 0.87-1.03, "adequate" before (p at its floor)
    for share in (0.0, 0.24, 0.49):
        assert decide_verdict(0.2, False, 0.001, explained=share) == "inadequate"
        assert decide_verdict(0.2, True, 0.001, explained=share) == "inadequate"
        # a residual shown to lie at the recording's noise floor: the noise limits the share
        assert decide_verdict(0.2, False, 0.001, explained=share,
                              within_floor=True) == "adequate"
    assert decide_verdict(0.2, False, 0.001, explained=0.9) == "adequate"
    # a residual far above an independent floor is mismatch, whatever the replicates say
    assert decide_verdict(0.2, False, 0.001, explained=0.9, above_floor=True) == \
        "missing_physics"


def _judgement(ratio, bound, explained=0.6, improved=None):
    return FitJudgement(explained, np.sqrt(1 - explained), "holdout", ratio,
                        Floor(1.0, "repeated_periods", "", bound), improved)


def test_a_floor_bound_decides_only_the_side_it_bounds():
    assert _judgement(5.0, "upper").above(3.0) is True
    assert _judgement(5.0, "lower").above(3.0) is None  # the true floor may be higher
    assert _judgement(2.0, "lower").within(3.0) is True
    assert _judgement(2.0, "upper").within(3.0) is None  # the true floor may be lower
    assert _judgement(2.0, "estimate").above(3.0) is False
    assert _judgement(2.0, "upper", 0.2, 0.84).library_share() == pytest.approx(0.8)


def test_every_alpha_of_the_settings_is_reachable_at_the_default_settings():
    """The smallest p-value each verdict's test can give at the default settings lies below
    its alpha: the detection's p-value at a statistic far out in the replicates' tail (the
    replicates' count is the default ``bootstrap``), the evidence's by construction."""
    from harvester.inference.tail import tail_p

    s = DiagnosisSettings()
    reps = np.max(np.random.default_rng(0).standard_normal((s.bootstrap, 40)) ** 2, axis=1)
    smallest = tail_p(float(reps.max()) * 3.0, reps).p
    alphas = {k: v for k, v in s.__dict__.items() if k.endswith("alpha")}
    assert set(alphas) == {"alpha", "evidence_alpha", "unexplained_alpha"}
    for name in ("alpha", "unexplained_alpha"):
        assert smallest < alphas[name], (name, smallest, alphas[name])
    fast = DiagnosisSettings.fast()
    reps = reps[:fast.bootstrap]
    assert tail_p(float(reps.max()) * 3.0, reps).p < fast.unexplained_alpha


def _ranked(effect, p, dchi2, similar=()):
    score = SimpleNamespace(p_value=p)
    return RankedCandidate(effect, score, dchi2, 0.0, 1.0, list(similar))


def test_an_open_round_fits_every_rival_whose_score_points_towards_it():
    # the hardening spring of the literature generator: a mass error scored p 0.03 and a
    # cubic spring only z 1.4 (delta_chi2 2.0), yet the spring's fit gained 521 nats to 199
    detection = SimpleNamespace(alpha=0.05, conflict=False)
    ranked = [_ranked("unmodelled_mode", 0.008, 13.6), _ranked("inertia_error", 0.035, 6.2),
              _ranked("cubic_stiffness", 0.16, 2.0), _ranked("end_stop", 0.29, 1.7),
              _ranked("stribeck_friction", 0.41, 0.9)]
    chosen = to_confirm(ranked, detection, top=6)
    assert [r.effect for r in chosen] == ["unmodelled_mode", "inertia_error"]
    assert [r.effect for r in rivals(ranked, chosen)] == ["cubic_stiffness", "end_stop"]
    assert rivals(ranked, ranked) == []


def test_a_terms_limits_are_screened_beside_it():
    """Hysteresis with no pre-sliding displacement is friction that sticks, or a sign law:
    both are screened where hysteresis is, if the structure can take them and they are not
    screened already; a term without limits brings none."""
    allowed = set(candidate_terms(()))
    assert limit_rivals(["hysteresis", "cubic_stiffness"], allowed) == [
        "sticking_friction", "coulomb_friction"]
    assert limit_rivals(["hysteresis", "coulomb_friction"], allowed) == ["sticking_friction"]
    assert limit_rivals(["cubic_stiffness"], allowed) == []
    assert limit_rivals(["hysteresis"], allowed - {"sticking_friction"}) == ["coulomb_friction"]


def test_candidates_similar_to_a_chosen_one_are_sampled_too():
    detection = SimpleNamespace(alpha=0.05, conflict=False)
    ranked = [_ranked("stribeck_friction", 0.01, 30.0, ["tanh_friction", "coulomb_friction"]),
              _ranked("tanh_friction", 0.01, 28.0, ["stribeck_friction", "coulomb_friction"]),
              _ranked("coulomb_friction", 0.2, 20.0, ["stribeck_friction", "tanh_friction"]),
              _ranked("end_stop", 0.01, 3.0),  # too little gain to sample
              _ranked("backlash", 0.5, 10.0)]  # neither significant nor similar
    chosen = [r.effect for r in to_confirm(ranked, detection, top=2)]
    assert chosen == ["stribeck_friction", "tanh_friction", "coulomb_friction"]
    assert [r.effect for r in to_confirm(ranked, detection, top=2, similar_extra=0)] == \
        ["stribeck_friction", "tanh_friction"]


def test_prior_data_conflict_judges_what_the_data_alone_say():
    # conjugate Gaussian: prior N(0, 1), likelihood N(3, 0.5^2) -> posterior N(2.4, 0.2)
    m_l, s_l = data_estimate(0.0, 1.0, 2.4, np.sqrt(0.2))
    assert m_l == pytest.approx(3.0) and s_l == pytest.approx(0.5)
    rng = np.random.default_rng(0)
    prior = {"c_m": PriorSpec("c_m", 0.0, 1.0, "N s/m", -np.inf)}
    settings = DetectionSettings(conflict_alpha=0.01)

    def flagged(post_mean, post_sd):
        x = post_mean + post_sd * rng.standard_normal((200_000, 1))
        (c,) = prior_conflicts(("c_m",), x, prior, settings)
        return c.z, c.conflict

    # the data put the parameter at 4 +- 0.8 (z = 4 / sqrt(1 + 0.64)): a conflict, although
    # the posterior (2.44 +- 0.62) is neither narrow nor far out in the prior's tail
    z, hit = flagged(*_posterior(0.0, 1.0, 4.0, 0.8))
    assert hit and z == pytest.approx(4.0 / np.sqrt(1.64), abs=0.02)
    # data that barely inform it: the posterior moved, but the prior predicts such data
    z, hit = flagged(*_posterior(0.0, 1.0, 4.0, 3.0))
    assert not hit and abs(z) < 1.5
    # the data agree with the prior
    assert not flagged(*_posterior(0.0, 1.0, 0.5, 0.2))[1]


def _posterior(m0, s0, m_l, s_l):
    """Conjugate Gaussian posterior (mean, sd)."""
    prec = 1 / s0**2 + 1 / s_l**2
    return (m0 / s0**2 + m_l / s_l**2) / prec, float(np.sqrt(1 / prec))


def test_a_prior_conflict_gets_its_best_reliever_sampled():
    ranked = [_ranked("backlash", 0.003, 9.3),
              _ranked("unmodelled_mode", 0.6, 2.6),
              _ranked("quadratic_damping", 0.4, 1.1)]
    ranked[1].relief_alone, ranked[2].relief_alone = 0.1, 1.5
    quiet = SimpleNamespace(alpha=0.05, conflict=False)
    assert [r.effect for r in to_confirm(ranked, quiet, top=3)] == ["backlash"]
    # the conflict is the only trace of an effect the parameters absorb completely
    conflict = SimpleNamespace(alpha=0.05, conflict=True)
    assert [r.effect for r in to_confirm(ranked, conflict, top=3)] == \
        ["backlash", "quadratic_damping"]


def test_a_refinement_of_friction_is_a_candidate_only_on_top_of_a_sliding_friction_law():
    """A Stribeck excess or a direction-dependent part refines a sliding friction: on the
    linear structure dry friction itself is the candidate; once it is in, they are."""
    linear = candidate_terms(())
    assert "coulomb_friction" in linear and "tanh_friction" in linear
    assert "stribeck_friction" not in linear and "asymmetric_friction" not in linear
    for law in ("tanh_friction", "coulomb_friction", "hysteresis"):
        on_top = candidate_terms((law,))
        assert {"stribeck_friction", "asymmetric_friction"} <= set(on_top), law
        assert law not in on_top
    assert candidate_terms((), ("stribeck_friction", "cubic_stiffness")) == ["cubic_stiffness"]
