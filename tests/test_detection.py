"""Aggregation of the concealed-effect scenarios, and the workflow's SLURM profile (dry run)."""

from __future__ import annotations

import copy
import os
import subprocess
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from conftest import ROOT, SNAKEMAKE, fake_slurm

from harvester.grid import scoring as det


def _truth(effect, ratio, seed, baseline="tanh"):
    return {"effect": effect, "ratio": ratio, "seed": seed, "baseline": baseline,
            "contribution_ratio": ratio, "peak_to_noise": 2.0 * ratio, "invisible": True}


def _diag(*missing):
    return {"verdict": "missing_physics" if missing else "adequate", "missing": list(missing),
            "detection": {"p_value": 0.01 if missing else 0.5}}


def _flagged_unnamed():
    return {"verdict": "missing_physics", "missing": [], "detection": {"p_value": 0.01}}


@pytest.fixture
def results():
    pairs = [
        # end_stop at 0.5: named, named, second, passed
        (_truth("end_stop", 0.5, 0), _diag("end_stop", "cubic_stiffness")),
        (_truth("end_stop", 0.5, 1), _diag("end_stop")),
        (_truth("end_stop", 0.5, 2), _diag("cubic_stiffness", "end_stop")),
        (_truth("end_stop", 0.5, 3), _diag()),
        # end_stop at 1.0: all named
        (_truth("end_stop", 1.0, 0), _diag("end_stop")),
        (_truth("end_stop", 1.0, 1), _diag("end_stop")),
        # coulomb on the linear baseline: tanh_friction is accepted; stribeck is not
        (_truth("coulomb_friction", 0.5, 0, "linear"), _diag("tanh_friction", "coulomb_friction")),
        (_truth("coulomb_friction", 0.5, 1, "linear"), _diag("stribeck_friction")),
        (_truth("coulomb_friction", 0.5, 2, "linear"), _flagged_unnamed()),
        # effect-free: 1 alarm in 4 (tanh), 0 in 2 (linear)
        (_truth("none_tanh", 0.0, 0), _diag()),
        (_truth("none_tanh", 0.0, 1), _diag("backlash")),
        # the screen fired, the evidence did not confirm anything
        (_truth("none_tanh", 0.0, 2), {**_diag(), "detection": {"p_value": 0.02, "alpha": 0.05}}),
        (_truth("none_tanh", 0.0, 3), _diag()),
        (_truth("none_linear", 0.0, 0, "linear"), _diag()),
        (_truth("none_linear", 0.0, 1, "linear"), _diag()),
    ]
    return det.results_table(pairs)


def test_wilson_interval_matches_known_values():
    lo, hi = det.wilson_interval(9, 10)
    assert (lo, hi) == pytest.approx((0.59585, 0.98212), abs=1e-4)
    lo, hi = det.wilson_interval(0, 20)
    assert lo == pytest.approx(0.0, abs=1e-12) and hi == pytest.approx(0.16113, abs=1e-4)
    lo, hi = det.wilson_interval(np.array([20, 5]), np.array([20, 10]))
    assert hi[0] == pytest.approx(1.0) and lo[1] < 0.5 < hi[1]


def test_detection_table_rates(results):
    table = det.detection_table(results).set_index(["effect", "ratio"])
    row = table.loc[("end_stop", 0.5)]
    assert (row["seeds"], row["named"], row["named_rate"]) == (4, 2, 0.5)
    assert row["top2_rate"] == 0.75 and row["flagged_rate"] == 0.75
    assert row["meets_goal"] is False or row["meets_goal"] == False  # noqa: E712
    assert row["most_named_instead"] in ("cubic_stiffness", "adequate")
    row = table.loc[("end_stop", 1.0)]
    assert row["named_rate"] == 1.0 and row["meets_goal"] is None  # goal only at 0.5
    row = table.loc[("coulomb_friction", 0.5)]
    assert row["named"] == 1 and row["top2_rate"] == pytest.approx(1 / 3)
    assert row["baseline"] == "linear"
    assert row["named_lo"] < row["named_rate"] < row["named_hi"]
    assert ("none_tanh", 0.0) not in table.index


def test_accepted_names_can_be_configured(results):
    strict = det.results_table(
        [(_truth("coulomb_friction", 0.5, 0, "linear"), _diag("tanh_friction"))], accepted={})
    assert not strict["named"].iloc[0]
    loose = det.results_table(
        [(_truth("coulomb_friction", 0.5, 0, "linear"), _diag("tanh_friction"))])
    assert loose["named"].iloc[0]


def test_confusion_matrix(results):
    cm = det.confusion_matrix(results)
    assert list(cm.columns[:4]) == ["ratio", "true_effect", "adequate", "unnamed"]
    row = cm[(cm["ratio"] == "0.5") & (cm["true_effect"] == "end_stop")].iloc[0]
    assert (row["end_stop"], row["cubic_stiffness"], row["adequate"]) == (2, 1, 1)
    row = cm[(cm["ratio"] == "all") & (cm["true_effect"] == "end_stop")].iloc[0]
    assert row["end_stop"] == 4 and row.drop(["ratio", "true_effect"]).sum() == 6
    row = cm[(cm["ratio"] == "0.5") & (cm["true_effect"] == "coulomb_friction")].iloc[0]
    assert (row["tanh_friction"], row["stribeck_friction"], row["unnamed"]) == (1, 1, 1)
    row = cm[(cm["ratio"] == "0") & (cm["true_effect"] == "none_tanh")].iloc[0]
    assert (row["adequate"], row["backlash"]) == (3, 1)
    assert "none_tanh" not in set(cm.loc[cm["ratio"] == "all", "true_effect"])
    # every scenario counted once per its ratio
    per_ratio = cm[cm["ratio"] != "all"].drop(columns=["ratio", "true_effect"]).to_numpy().sum()
    assert per_ratio == len(results)


def test_wrong_name_rates_count_each_term_where_it_is_not_right():
    """Issue 63's catch-all count: a term named or tied under a flagging verdict where it is
    not a right name, over the records where it is not; an adequate verdict says none."""
    import pandas as pd
    table = pd.DataFrame({
        "said": [{"inertia_error"}, {"inertia_error", "unmodelled_mode"}, set(),
                 {"inertia_error"}, {"hysteresis"}],
        "right": [set(), {"hysteresis"}, set(), {"inertia_error"}, {"hysteresis"}]})
    rates = det.wrong_name_rates(table)
    assert rates == {"inertia_error": (2, 4), "unmodelled_mode": (1, 5), "hysteresis": (0, 3)}
    assert list(rates) == ["inertia_error", "unmodelled_mode", "hysteresis"]
    assert det.wrong_name_rates(table.iloc[:0]) == {}


def test_false_alarms(results):
    fa = det.false_alarms(results).set_index("baseline")
    assert (fa.loc["tanh", "scenarios"], fa.loc["tanh", "false_alarms"]) == (4, 1)
    assert (fa.loc["tanh", "screen_alarms"], fa.loc["all", "screen_alarms"]) == (2, 2)
    assert fa.loc["linear", "rate"] == 0.0 and fa.loc["linear", "meets_goal"]
    assert fa.loc["all", "rate"] == pytest.approx(1 / 6)
    assert not fa.loc["all", "meets_goal"] and not fa.loc["all", "goal_certain"]
    assert fa.loc["tanh", "named_on_false_alarm"] == "backlash"


def test_figure(results, tmp_path):
    path = tmp_path / "rates.png"
    det.detection_figure(det.detection_table(results), det.false_alarms(results), path)
    assert path.stat().st_size > 10_000


def test_scenario_grid_from_config():
    cfg = yaml.safe_load((ROOT / "config/config.yaml").read_text())["detection"]
    small = det.scenario_grid(cfg)
    g = cfg["grids"]["small"]
    assert len(small) == (len(g["effects"]) * len(g["ratios"]) * g["seeds"]
                          + len(g["effect_free"]) * g["false_alarm_seeds"])
    full = det.scenario_grid({**cfg, "grid": "full"})
    assert {e for e, r, s in full if r != "0"} == set(cfg["effects"])
    assert ("end_stop", "0.25", 19) in full and ("none_linear", "0", 99) in full


# --------------------------------------------------------------------------- workflow


def _small_detection_config() -> dict:
    cfg = copy.deepcopy(yaml.safe_load((ROOT / "config/config.yaml").read_text()))
    cfg["detection"]["grid"] = "small"
    cfg["detection"]["grids"]["small"].update(
        effects=["end_stop", "coulomb_friction"], ratios=[0.5], seeds=1,
        effect_free=["none_tanh"], false_alarm_seeds=1, duration_s=8.0, fast=True)
    return cfg


def _workdir(tmp_path: Path, cfg: dict) -> tuple[Path, Path]:
    """A working directory with the config, and a Snakefile that includes detection.smk
    (the repository's own Snakefile once it includes it)."""
    (tmp_path / "config.yaml").write_text(yaml.safe_dump(cfg))
    snakefile = ROOT / "Snakefile"
    if "rules/detection.smk" not in snakefile.read_text():
        wrapper = tmp_path / "Snakefile"
        wrapper.write_text(f'include: "{snakefile}"\n'
                           f'include: "{ROOT / "workflow/rules/detection.smk"}"\n')
        snakefile = wrapper
    return tmp_path, snakefile


def test_slurm_profile_dry_run_shows_rules_and_resources(tmp_path):
    workdir, snakefile = _workdir(tmp_path, _small_detection_config())
    marker = tmp_path / "called.txt"
    env = fake_slurm(tmp_path / "bin", marker)
    cmd = [str(SNAKEMAKE), "--profile", str(ROOT / "profiles/slurm"), "-n", "detection_all",
           "-s", str(snakefile), "-d", str(workdir), "--configfile", str(workdir / "config.yaml")]
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=300)
    out = proc.stdout + proc.stderr
    assert proc.returncode == 0, out[-4000:]
    assert not marker.exists(), marker.read_text()
    for rule, count in (("detection_scenario", 3), ("diagnose_scenario", 3),
                        ("detection_table", 1), ("detection_figure", 1), ("detection_all", 1)):
        assert any(line.split() == [rule, str(count)] for line in out.splitlines()), rule
    profile = yaml.safe_load((ROOT / "profiles/slurm/config.yaml").read_text())
    assert profile["executor"] == "slurm"
    for rule in ("diagnose_scenario", "detection_scenario", "detection_table"):
        shown = _job_resources(out, rule)
        assert len(shown) == {"diagnose_scenario": 3, "detection_scenario": 3}.get(rule, 1)
        for key, value in profile["set-resources"][rule].items():
            assert all(r[key] == str(value) for r in shown), (rule, key, shown[0])
        assert all(r["slurm_partition"] and r["slurm_account"] for r in shown)


def _job_resources(dry_run: str, rule: str) -> list[dict[str, str]]:
    """The resources line of each job of ``rule`` in a dry run's output, as a dict."""
    out = []
    for block in dry_run.split("\nrule ")[1:]:
        if not block.startswith(f"{rule}:"):
            continue
        line = next(ln for ln in block.splitlines() if ln.strip().startswith("resources:"))
        pairs = line.split(":", 1)[1].split(", ")
        out.append(dict(p.strip().split("=", 1) for p in pairs))
    return out


@pytest.mark.slow
def test_small_grid_runs_end_to_end(tmp_path):
    """The local run: scenarios, diagnoses, tables, figure (several minutes on two cores)."""
    workdir, snakefile = _workdir(tmp_path, _small_detection_config())
    cmd = [str(SNAKEMAKE), "detection_all", "-s", str(snakefile), "-d", str(workdir),
           "--configfile", str(workdir / "config.yaml"), "--cores", "2", "--quiet", "rules"]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=1800,
                          env=dict(os.environ, PYTHONWARNINGS="ignore"))
    assert proc.returncode == 0, (proc.stdout + proc.stderr)[-6000:]
    d = workdir / "results/detection/small"
    table = pd.read_csv(d / "detection_table.csv")
    assert set(table["effect"]) == {"end_stop", "coulomb_friction"}
    assert (table["seeds"] == 1).all()
    alarms = pd.read_csv(d / "false_alarms.csv")
    assert alarms.loc[alarms["baseline"] == "all", "scenarios"].iloc[0] == 1
    assert (d / "figures/detection_rates.png").stat().st_size > 10_000
    res = pd.read_csv(d / "scenario_results.csv")
    assert np.allclose(res.loc[~res["effect_free"], "contribution_ratio"], 0.5, rtol=0.01)
    assert res["p_value"].between(0.0, 1.0).all()


def _tie(*effects):
    return {"verdict": "missing_physics", "missing": [], "detection": {"p_value": 0.01},
            "ties": [{"effects": list(effects)}]}


def test_outcomes_named_tied_wrong_missed():
    rows = det.results_table([
        (_truth("coulomb_friction", 0.5, 0, "linear"), _tie("stribeck_friction",
                                                              "coulomb_friction")),
        (_truth("end_stop", 0.5, 0), _diag("cubic_stiffness")),
        (_truth("end_stop", 0.5, 1), _tie("cubic_stiffness", "unmodelled_mode")),
        (_truth("end_stop", 0.5, 2), _diag("end_stop")),
        (_truth("end_stop", 0.5, 3), _flagged_unnamed()),
        (_truth("end_stop", 0.5, 4), _diag()),
        # the literature generator's truth states its own correct names
        ({**_truth("lugre", 0.5, 0), "correct_names": ["hysteresis"]}, _diag("hysteresis")),
        ({**_truth("lugre", 0.5, 1), "correct_names": ["hysteresis"]}, _diag("lugre")),
    ]).set_index(["effect", "seed"])
    assert list(rows["outcome"]) == ["tied", "wrong", "wrong", "named", "missed", "missed",
                                     "named", "wrong"]
    assert rows.loc[("coulomb_friction", 0), "named_effect"] == \
        "stribeck_friction | coulomb_friction"
    table = det.detection_table(rows.reset_index()).set_index("effect")
    assert table.loc["coulomb_friction", "tied_rate"] == 1.0
    assert table.loc["end_stop", "wrong_rate"] == 0.4
    assert table.loc["end_stop", "missed_rate"] == 0.4


def test_a_named_terms_size_is_checked_against_the_generators_missing_force():
    """named_size: the first term named alone, its own force's 95 % interval against the
    truth's missing force RMS; NaN where nothing is named or the truth has none."""
    sized = {**_diag("cubic_stiffness"), "missing_force": {"named_effects": [
        {"term": "cubic_stiffness", "term_force_rms_N": 0.40,
         "term_force_rms_interval_N": [0.35, 0.45]}]}}
    truth = {**_truth("duffing", 0.5, 0), "literature": {"missing_force_rms_N": 0.41}}
    assert det.named_size(truth, sized)["size_covered"] == 1.0
    outside = {**truth, "literature": {"missing_force_rms_N": 0.5}}
    row = det.score(outside, sized)
    assert row["size_covered"] == 0.0 and row["size_lo_N"] == 0.35 and row["size_N"] == 0.4
    assert np.isnan(det.named_size(truth, _diag())["size_covered"])
    assert np.isnan(det.named_size(_truth("duffing", 0.5, 0), sized)["size_covered"])
    # where the diagnosis leaves the mean to the term's form, the varying parts are compared
    even = {**_diag("asymmetric_friction"), "missing_force": {"named_effects": [
        {"term": "asymmetric_friction", "term_force_rms_N": 0.24,
         "term_force_rms_interval_N": [0.23, 0.26], "term_force_mean_unfixed": True,
         "term_force_varying_rms_N": 0.115, "term_force_varying_rms_interval_N": [0.11, 0.12]}]}}
    asym = {"literature": {"missing_force_rms_N": 0.28, "missing_force_varying_rms_N": 0.118}}
    got = det.named_size(asym, even)
    assert got["size_covered"] == 1.0 and got["size_part"] == "varying"
    assert got["size_true_N"] == 0.118 and got["size_N"] == 0.115
    assert det.named_size(asym, {**even, "missing_force": {"named_effects": [
        {**even["missing_force"]["named_effects"][0], "term_force_mean_unfixed": False}]}}
    )["size_covered"] == 0.0
    # several named, sized together from one fit: their summed force against the truth
    two = {**_diag("cubic_stiffness", "inertia_error"), "missing_force": {
        "named_effects": sized["missing_force"]["named_effects"],
        "together": {"rms_N": 0.0049, "rms_interval_N": [0.0046, 0.0052],
                     "mean_unfixed": False}}}
    got = det.named_size({"literature": {"missing_force_rms_N": 0.00497}}, two)
    assert got["size_covered"] == 1.0 and got["size_part"] == "whole together"


def _informed(diagnosis, lam=0.1, window=(1.0, 16.0), rate=256.0, alpha=0.05):
    return {**diagnosis, "measurement_chain": {"tempering_lambda": lam, "analysis_rate_hz": rate},
            "tmcmc_window_s": list(window), "settings": {"evidence_alpha": alpha}}


def test_information_is_the_tempered_likelihood_gain_of_what_the_baseline_leaves():
    truth = {**_truth("inertia_error", 0.5, 0), "unabsorbed_to_noise": 0.12}
    diag = _informed(_diag())
    n = 15 * 256 + 1
    assert det.information_nats(truth, diag) == pytest.approx(0.5 * 0.1 * n * 0.12**2)
    assert det.acceptance_nats(diag) == pytest.approx(np.log(20.0))
    assert det.acceptance_nats(_informed(_diag(), alpha=0.01)) == pytest.approx(np.log(100.0))
    # unknown lambda or window: NaN, and the scenario counts as nameable (the plain rate)
    assert np.isnan(det.information_nats(truth, _diag()))
    rows = det.results_table([
        (truth, diag),                                                         # 2.8 nats
        ({**_truth("end_stop", 0.5, 0), "unabsorbed_to_noise": 0.5}, _informed(_diag("end_stop"))),
        (_truth("end_stop", 0.5, 1), _diag("cubic_stiffness")),                # not known
        (_truth("none_tanh", 0.0, 0), _informed(_diag())),
    ]).set_index(["effect", "seed"])
    assert not rows.loc[("inertia_error", 0), "nameable"]
    assert rows.loc[("end_stop", 0), "nameable"] and rows.loc[("end_stop", 1), "nameable"]
    assert rows.loc[("end_stop", 0), "information_nats"] == pytest.approx(0.5 * 0.1 * n * 0.25)
    assert not rows.loc[("none_tanh", 0), "nameable"]  # effect-free: nothing to name


def test_the_refit_measures_what_the_baseline_cannot_absorb():
    # extra viscous damping is c_m's to absorb; a cubic spring is not
    from harvester.grid.information import refit_unabsorbed
    from harvester.study.paper import TABLE1_KNOWN
    from harvester.synthetic.measured import measured_recording

    base = {**TABLE1_KNOWN, "c_m": 110.0, "F_c": 11.86, "beta": 88.35}
    kw = dict(noise_m_s2=0.0, lowpass_hz=None)
    plain, clean = measured_recording(("tanh_friction",), base, 8.0, 3, **kw)
    _, damped = measured_recording(("tanh_friction",), {**base, "c_m": 130.0}, 8.0, 3, **kw)
    _, cubic = measured_recording(("tanh_friction", "cubic_stiffness"),
                                  {**base, "k_cubic": 4e6}, 8.0, 3, **kw)
    known = {k: TABLE1_KNOWN[k] for k in ("M", "m", "k")}
    window = (256, 7 * 256)
    noise = 0.05
    assert refit_unabsorbed(plain.assign(rel_acc=damped), damped - clean, known, noise,
                            window=window) < 0.05
    assert refit_unabsorbed(plain.assign(rel_acc=cubic), cubic - clean, known, noise,
                            window=window) > 0.2
    truth = {**_truth("cubic_stiffness", 0.5, 0), "unabsorbed_to_noise": 0.4,
             "refit_unabsorbed_to_noise": 0.0}
    assert det.information_nats(truth, _informed(_diag())) == 0.0   # the refit's u is used


def test_goal_summary_pools_effects_and_separates_the_nameable():
    def pair(effect, seed, u, *missing, tie=None):
        d = _informed(_tie(*tie) if tie else _diag(*missing))
        return {**_truth(effect, 0.5, seed), "unabsorbed_to_noise": u}, d

    rows = det.results_table([
        pair("end_stop", 0, 0.5, "end_stop"),
        pair("end_stop", 1, 0.5, tie=["cubic_stiffness", "end_stop"]),
        pair("end_stop", 2, 0.5, "cubic_stiffness"),
        pair("quadratic_damping", 0, 0.03),                        # adequate, 0.17 nats
        pair("inertia_error", 0, 0.12),                            # adequate, 2.8 nats
        ({**_truth("none_tanh", 0.0, 0)}, _informed(_diag())),
    ])
    s = det.goal_summary(rows).set_index("ratio").loc[0.5]
    assert (s["scenarios"], s["named"], s["tied"], s["wrong"]) == (5, 1, 2, 1)
    assert (s["nameable"], s["named_nameable"], s["tied_nameable"]) == (3, 1, 2)
    assert s["wrong_nameable"] == 1 and s["missed_nameable"] == 0
    assert s["named_rate_nameable"] == pytest.approx(1 / 3) and s["named_rate"] == 0.2
    assert s["not_nameable"] == "inertia_error, quadratic_damping"
    assert s["named_nameable_lo"] < 1 / 3 < s["named_nameable_hi"]
    assert not s["meets_wrong_goal_nameable"]
    assert not s["meets_goal"] and not s["meets_goal_nameable"]
    table = det.detection_table(rows).set_index("effect")
    assert (table.loc["end_stop", "nameable"], table.loc["end_stop", "named_nameable"]) == (3, 1)
    assert table.loc["quadratic_damping", "nameable"] == 0


def test_figure_with_the_information_panel(results, tmp_path):
    rows = results.assign(information_nats=np.linspace(0.1, 80.0, len(results)))
    path = tmp_path / "rates.png"
    det.detection_figure(det.detection_table(rows), det.false_alarms(rows), path, results=rows)
    assert path.stat().st_size > 20_000


def test_literature_generator_writes_a_scenario_the_grid_scores(tmp_path):
    from harvester.data.daq import read_recording
    from harvester.grid.generators import make_scenario_files

    csv, js = tmp_path / "r.csv", tmp_path / "r.json"
    truth = make_scenario_files("literature", "duffing", 0.5, 0, {"duration_s": 6.0, "seed": 7},
                                {}, {}, csv, js)
    assert truth["correct_names"] == ["cubic_stiffness"] and truth["baseline"] == "tanh"
    assert set(truth["known"]) == {"M", "m", "k"}
    assert truth["contribution_ratio"] == pytest.approx(0.5, rel=0.02)
    rec = read_recording(csv)
    assert list(rec.columns)[:3] == ["time", "base_acc", "rel_acc"] and len(rec) == 6 * 256
    row = det.score(truth, _diag("cubic_stiffness"))
    assert row["outcome"] == "named"
    assert truth["refit_unabsorbed_to_noise"] > 0.0
    with pytest.raises(ValueError, match="generator"):
        make_scenario_files("mine", "duffing", 0.5, 0, {}, {}, {}, csv, js)


def test_a_name_of_the_same_physics_in_another_form_counts():
    """The literature grid's Bouc-Wen friction lists hysteresis: the hysteretic spring (Bouc-Wen
    in the spring, ``alike`` hysteresis) names it too; Coulomb friction's sticking form names
    Coulomb friction; configured names are taken as they are."""
    names = det.accepted_names("bouc_wen", truth={"correct_names": ["hysteresis"]})
    assert {"hysteresis", "hysteretic_spring"} <= names and "cubic_stiffness" not in names
    assert "sticking_friction" in det.accepted_names("coulomb_friction")
    assert det.accepted_names("coulomb_friction", accepted={}) == {"coulomb_friction"}
