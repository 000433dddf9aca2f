"""The search's time budget (``diagnosis.name.budget``): TMCMC stops at its deadline, a round
the budget cuts is reported as not decided (never as named or as rejected), diagnosis.json
says what was left unfinished and follows its schema, and the command line takes --budget."""

from __future__ import annotations

import json
import time

import numpy as np
import pymc as pm
import pytest

from harvester.cli import main
from harvester.data.daq import write_recording
from harvester.diagnosis import DiagnosisSettings, diagnose_recording
from harvester.diagnosis.name.budget import (BUDGET_MAX_S, BUDGET_MIN_S, Unfinished,
                                             budget_dict, budget_seconds, search_seconds, spent,
                                             with_deadline)
from harvester.diagnosis.report.document import validate_document
from harvester.inference.tmcmc import TMCMC, OutOfTime, run_tmcmc

from test_topology import CUT, DEVICE, frame_record

pytestmark = pytest.mark.filterwarnings("ignore::UserWarning", "ignore::RuntimeWarning")

#: Cheap settings: one round, one candidate that the frame-like record needs.
OPTIONS = {"particles": 40, "chains": 1, "top": 1, "rounds": 1, "seed": 5,
           "candidates": ("coulomb_friction",), "figures": False}


def _gaussian_model() -> pm.Model:
    with pm.Model() as model:
        x = pm.Normal("x", 0.0, 10.0)
        pm.Normal("y", x, 1.0, observed=np.array([0.3, -0.2, 0.5]))
    return model


def test_tmcmc_stops_at_its_deadline_and_says_where():
    with pytest.raises(OutOfTime) as stop:
        run_tmcmc(_gaussian_model(), draws=50, chains=1, seed=1, deadline=time.time() - 1.0)
    assert stop.value.stage == 0 and stop.value.beta == 0.0
    assert "deadline" in str(stop.value)
    # without one it runs to beta = 1 and gives the evidence
    idata = run_tmcmc(_gaussian_model(), draws=50, chains=1, seed=1)
    assert np.isfinite(idata.sample_stats["log_evidence"].values).all()


def test_the_deadline_is_set_from_the_budget_and_none_without_one():
    s = with_deadline(DiagnosisSettings(budget_s=100.0), record_s=10.0, start=100.0)
    assert s.deadline == 100.0 + search_seconds(100.0, 10.0) and spent(s)
    assert with_deadline(DiagnosisSettings(budget=False), 10.0).deadline is None
    assert not spent(DiagnosisSettings(budget=False))
    # the default grows with the record: under 3 min for 10 s, under 5 min for 40 s
    auto = DiagnosisSettings()
    assert budget_seconds(auto, 10.0) < 180.0 and budget_seconds(auto, 40.0) < 300.0
    assert budget_seconds(auto, 1.0) == BUDGET_MIN_S
    assert budget_seconds(auto, 1e4) == BUDGET_MAX_S
    assert 0.2 * 20.0 <= search_seconds(20.0, 40.0) < 20.0  # never less than a fifth
    assert search_seconds(280.0, 40.0) < 280.0
    # budget_s is read from a config, the deadline never
    assert DiagnosisSettings.from_config({"budget": False}).budget is False
    assert "time budget of 20 s" in " ".join(DiagnosisSettings(budget_s=20.0).trades())


@pytest.fixture(scope="module")
def record(tmp_path_factory):
    root = tmp_path_factory.mktemp("budget")
    path = root / "frame.csv"
    write_recording(frame_record("ground"), path)
    (root / "frame.yaml").write_text(
        "M: {M}\nm: {m}\nk: {k}\nfiltered_at_hz: {c}\nfriction_on: ground\n".format(
            **DEVICE, c=CUT))
    return path


def _document(diag, out) -> dict:
    return json.loads((out / "diagnosis.json").read_text())


def test_a_spent_budget_leaves_the_round_undecided(record, tmp_path):
    settings = DiagnosisSettings.fast(**OPTIONS, budget_s=1e-3)  # the search gets 0.2 ms
    diag = diagnose_recording(record, "linear", settings=settings, out_dir=tmp_path)
    doc = _document(diag, tmp_path)
    validate_document(doc)
    assert diag.missing == [] and diag.ties == []
    assert doc["budget"]["cut"] and doc["budget"]["seconds"] == 1e-3
    assert doc["budget"]["search_budget_seconds"] == pytest.approx(2e-4)
    first = doc["budget"]["unfinished"][0]
    assert first["where"] == "round 1" and "coulomb_friction" in first["what"]
    assert "time budget ran out" in diag.headline, diag.headline
    assert "no library effect decided within the time budget" in diag.headline
    assert "deadline" not in doc["settings"]
    page = (tmp_path / "summary.html").read_text()
    assert "Not decided within the budget" in page and "coulomb_friction" in page
    steps = [t["step"] for t in doc["budget"]["timeline"]]
    assert steps[:4] == ["input", "prepare", "baseline", "rounds"] and "missing force" in steps


def test_a_candidate_stopped_mid_run_is_reported_not_judged(record, tmp_path, monkeypatch):
    """The candidate's TMCMC stops at its first check (the baseline's has no deadline):
    the round names nothing and says how far the candidate got."""
    def stop_if_budgeted(self):
        if self.deadline is not None:
            raise OutOfTime(self.chain, self.iteration, self.beta)
    monkeypatch.setattr(TMCMC, "check_time", stop_if_budgeted)
    settings = DiagnosisSettings.fast(**OPTIONS, budget_s=1e6)
    diag = diagnose_recording(record, "linear", settings=settings, out_dir=tmp_path)
    doc = _document(diag, tmp_path)
    validate_document(doc)
    stopped = [u for u in doc["budget"]["unfinished"] if "TMCMC stopped" in u["how"]]
    assert stopped and "coulomb_friction" in stopped[0]["what"], doc["budget"]
    assert diag.missing == [] and not any(r["accepted"] for r in doc["rounds"])


def test_a_candidate_whose_second_chain_is_stopped_is_judged_on_its_first(record, tmp_path,
                                                                          monkeypatch):
    """The candidate's second TMCMC chain stops at its first check: the first, finished,
    decides (the record's friction is named), its evidence's error at least 1 nat, and a
    note says it was judged on 1 of 2 chains."""
    from harvester.diagnosis.name.fits import CUT_MIN_SE

    def stop_second(self):
        if self.deadline is not None and self.chain >= 1:
            raise OutOfTime(self.chain, self.iteration, self.beta)
    monkeypatch.setattr(TMCMC, "check_time", stop_second)
    settings = DiagnosisSettings.fast(**{**OPTIONS, "chains": 2}, budget_s=1e6)
    diag = diagnose_recording(record, "linear", settings=settings, out_dir=tmp_path)
    doc = _document(diag, tmp_path)
    validate_document(doc)
    entry = next(c for c in doc["candidates"] if c["effect"] == "coulomb_friction")
    assert entry["chains_cut"] == 1 and len(entry["log_evidence_chains"]) == 1
    assert entry["log_evidence_se"] >= CUT_MIN_SE
    assert diag.missing == ["coulomb_friction"], diag.headline
    assert any("judged on 1 of 2 TMCMC chains" in n for n in doc["notes"]), doc["notes"]


@pytest.mark.parametrize("asked, how", [(1, "not screened"), (2, "MAP fit stopped")])
def test_a_screen_the_budget_cuts_leaves_its_candidates_unscreened(record, tmp_path,
                                                                  monkeypatch, asked, how):
    """The budget runs out between the round's start and its first MAP fit (asked once), or
    within that fit, before its first simulation (asked twice: the round, the screen)."""
    import harvester.diagnosis.name.rounds as rounds
    answers = iter([False] * asked)  # then every later question finds the budget spent
    monkeypatch.setattr(rounds, "spent", lambda settings: next(answers, True))
    monkeypatch.setattr("harvester.diagnosis.run.spent", lambda settings: True)  # no 2nd pass
    settings = DiagnosisSettings.fast(**OPTIONS, budget_s=1e6)
    diag = diagnose_recording(record, "linear", settings=settings, out_dir=tmp_path)
    doc = _document(diag, tmp_path)
    first = doc["budget"]["unfinished"][0]
    assert (first["where"], first["how"]) == ("round 1", how), doc["budget"]
    assert doc["rounds"][0]["screened"] == [] and diag.missing == []


def test_the_command_line_takes_a_budget_or_none(record, tmp_path, capsys):
    for bad in ("0", "-3", "soon"):
        with pytest.raises(SystemExit) as exit_:
            main(["diagnose", str(record), "--baseline", "linear", "--budget", bad,
                  "--out", str(tmp_path / bad)])
        assert exit_.value.code == 2
        assert "expected seconds > 0 or 'none'" in capsys.readouterr().err
    from harvester.cli import _diagnosis_settings, _parser

    def settings(*extra):
        args = _parser().parse_args(["diagnose", str(record), "--baseline", "linear",
                                     "--out", str(tmp_path / "x"), *extra])
        return _diagnosis_settings(args)
    assert (settings().budget, settings().budget_s) == (True, None)  # from the record's length
    assert (settings("--budget", "none").budget, settings("--budget", "90").budget_s) == (
        False, 90.0)


def test_the_budget_section_without_a_budget():
    doc = budget_dict(DiagnosisSettings(budget=False), 10.0, 3.0, [])
    assert doc == {"seconds": None, "search_budget_seconds": None, "search_seconds": 3.0,
                   "cut": False, "unfinished": [], "timeline": []}


def test_an_unfinished_step_in_words():
    u = Unfinished.stopped("round 2", "linear+cubic_stiffness", OutOfTime(0, 7, 0.031))
    assert u.sentence() == ("round 2: linear+cubic_stiffness: its TMCMC stopped at stage 7 of "
                            "chain 1 (tempering exponent 0.031)")
