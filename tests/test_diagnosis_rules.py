"""The diagnosis's decision rules: the verdict, and which ranked candidates are sampled."""

from __future__ import annotations

from types import SimpleNamespace

from harvester.diagnosis.rank import RankedCandidate, to_confirm
from harvester.diagnosis.run import decide_verdict


def test_verdict_needs_evidence_or_a_strong_unexplained_detection():
    # a screening detection at p < 0.05 alone is not enough: it fires in 5 % of clean records
    assert decide_verdict(0.01, accepted=False, unexplained_alpha=0.001) == "adequate"
    assert decide_verdict(0.0005, accepted=False, unexplained_alpha=0.001) == "missing_physics"
    # an effect confirmed by evidence is enough whatever the screening said (prior conflict)
    assert decide_verdict(0.4, accepted=True, unexplained_alpha=0.001) == "missing_physics"
    assert decide_verdict(0.4, accepted=False, unexplained_alpha=0.001) == "adequate"


def _ranked(effect, p, dchi2, similar=()):
    score = SimpleNamespace(p_value=p)
    return RankedCandidate(effect, score, dchi2, 0.0, 1.0, list(similar))


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
