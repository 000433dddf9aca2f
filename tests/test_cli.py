"""The command line: every command on the bundled recordings and on recordings written from
the virtual rig (bad input in detail: ``test_input_checks``)."""

from __future__ import annotations

import json
import logging

import numpy as np
import pandas as pd
import pytest

from harvester.cli import main
from harvester.data.daq import write_recording
from harvester.diagnosis.name.fits import candidate_priors
from harvester.model.priors import DeviceScale
from harvester.synthetic.measured import TABLE1_KNOWN, TANH_TABLE5, measured_recording
from harvester.initial.recording import recording_priors

pytestmark = pytest.mark.filterwarnings("ignore::UserWarning", "ignore::RuntimeWarning")


@pytest.fixture(autouse=True)
def _restore_logging():
    yield
    logging.getLogger("harvester").handlers.clear()


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    """8 s of the tanh model (Table 5) through the study's measurement chain."""
    df, _ = measured_recording(("tanh_friction",), {**TABLE1_KNOWN, **TANH_TABLE5}, 8.0, 21)
    path = tmp_path_factory.mktemp("rec") / "rec.csv"
    write_recording(df, path)
    return path, df


def _write_csv(path, text):
    path.write_text(text)
    return path


def _run(args, capsys):
    code = main(args)
    return code, capsys.readouterr().err


@pytest.mark.parametrize("mutate, message", [
    (lambda df: df.drop(columns="base_acc"), "missing column"),
    (lambda df: df.assign(rel_acc=np.where(np.arange(len(df)) == 40, np.nan, df.rel_acc)),
     "NaN"),
    (lambda df: df.assign(time=df.time + np.where(np.arange(len(df)) > 100, 0.001, 0.0)),
     "non-uniform time"),
    (lambda df: df.iloc[:700], "too short"),
])
def test_bad_input_gets_a_clear_error(recording, tmp_path, capsys, mutate, message):
    _, df = recording
    bad = mutate(df.copy())
    path = tmp_path / "bad.csv"
    bad.to_csv(path, index=False, na_rep="nan")
    (tmp_path / "bad.yaml").write_text("M: 12.8\nm: 8.0\nk: 250.0\n")
    code, err = _run(["diagnose", str(path), "--baseline", "tanh", "--out",
                      str(tmp_path / "out"), "--log", str(tmp_path / "log.txt")], capsys)
    assert code == 2
    assert message in err and "bad.csv" in err
    assert not (tmp_path / "out" / "diagnosis.json").exists()


def test_bad_metadata_and_options_get_clear_errors(recording, tmp_path, capsys):
    _, df = recording
    path = tmp_path / "r.csv"
    df.to_csv(path, index=False)
    (tmp_path / "r.yaml").write_text("M: 12.8\nm: -8\n")
    code, err = _run(["diagnose", str(path), "--baseline", "linear", "--out",
                      str(tmp_path / "o"), "--log", str(tmp_path / "l.txt")], capsys)
    assert code == 2 and "'m' must be a positive number" in err
    (tmp_path / "r.yaml").write_text("M: 12.8\nstiffness: 250\n")
    code, err = _run(["diagnose", str(path), "--baseline", "linear", "--out",
                      str(tmp_path / "o"), "--log", str(tmp_path / "l.txt")], capsys)
    assert code == 2 and "unknown key" in err
    (tmp_path / "r.yaml").write_text("M: 12.8\nm: 8.0\nk: 250.0\n"
                                     "priors:\n  damping: {mean: 9.0, sd: 1.0}\n")
    code, err = _run(["diagnose", str(path), "--baseline", "linear", "--out",
                      str(tmp_path / "o"), "--log", str(tmp_path / "l.txt")], capsys)
    assert code == 2 and "r.yaml" in err and "no prior for parameter 'damping'" in err
    (tmp_path / "r.yaml").unlink()
    code, err = _run(["diagnose", str(path), "--baseline", "linear", "--out",
                      str(tmp_path / "o"), "--lowpass", "500", "--paper-device", "--log",
                      str(tmp_path / "l.txt")], capsys)
    assert code == 2 and "--lowpass" in err
    with pytest.raises(SystemExit):
        main(["diagnose", str(path), "--baseline", "quadratic", "--out", str(tmp_path)])


def test_cli_end_to_end_writes_diagnosis_json(recording, tmp_path, capsys):
    path, _ = recording
    (path.parent / "rec.yaml").write_text("M: 12.8\nm: 8.0\nk: 250.0\n")
    out = tmp_path / "diag"
    code = main(["diagnose", str(path), "--baseline", "linear", "--out", str(out), "--fast",
                 "--particles", "60", "--top", "1", "--seed", "3",
                 "--candidates", "coulomb_friction",  # the tanh's stiff prior costs 30 s
                 "--log", str(tmp_path / "progress.log")])
    assert code == 0
    assert "->" in capsys.readouterr().out
    d = json.loads((out / "diagnosis.json").read_text())
    assert d["verdict"] in ("adequate", "missing_physics", "inadequate")
    assert d["headline"].startswith(d["verdict"]) and "explains" in d["headline"]
    assert d["explained_share"] <= 1.0 and d["unseen_nrmse"] > 0
    assert isinstance(d["missing"], list) and all(isinstance(m, str) for m in d["missing"])
    # a linear model of a friction device is not adequate, and friction is what it misses
    assert d["verdict"] == "missing_physics"
    # the missing force in newtons, the friction's size beside it, and one page with all of it
    mf = d["missing_force"]
    assert mf["latent_force"] and mf["shape"]["sentence"]
    sizes = {e["term"]: e for e in mf["named_effects"]}
    if d["missing"]:
        assert sizes[d["missing"][0]]["relevance"] == "relevant"
        assert sizes[d["missing"][0]]["force_rms_N"] > 1.0
    page = (out / "summary.html").read_text()
    assert d["headline"] in page.replace("&#x27;", "'") and "data:image/png;base64," in page
    assert (out / "latent_force.png").is_file() and "latent_force.png" in d["figures"]
    for c in d["candidates"]:
        assert isinstance(c["effect"], str)
        for key in ("log_evidence", "delta_log_evidence", "log_evidence_tmcmc"):
            assert isinstance(c[key], float)
        assert c["log_evidence_method"] in ("bridge", "tmcmc")
        # every candidate's TMCMC starts half its particles at the baseline's posterior (the
        # nested parameters); a secondary mode's also at the scan of its frequency
        start = c["tempered_from"]
        assert start["share"] == 0.5 and start["factors"][0]["kind"] == "gaussian"
        assert {"c_m", "sigma"} <= set(start["factors"][0]["variables"])
        if c["effect"] == "unmodelled_mode":
            assert start["factors"][1]["variable"] == "f_mode"
        assert c["restarted_from_prior"] in (False, True)
        for stats in c["parameters"].values():
            assert isinstance(stats["mean"], float) and isinstance(stats["sd"], float)
    loc = d["locations"]
    assert loc["time_windows_s"] and loc["state_regions"] and loc["frequency_bands_hz"]
    for w in loc["time_windows_s"]:
        assert w["stop"] > w["start"] and 0 <= w["energy_share"] <= 1
    for r in loc["state_regions"]:
        assert isinstance(r["region"], str) and 0 <= r["energy_share"] <= 1
    for b in loc["frequency_bands_hz"]:
        assert b["high"] > b["low"] >= 0
    for which in ("baseline", "improved"):
        entry = d["fit"][which]
        assert isinstance(entry["log_evidence"], float)
        assert isinstance(entry["nrmse"], float) and 0 <= entry["coverage_3sigma"] <= 1
    for name in d["figures"]:
        assert (out / name).stat().st_size > 1000
    assert "verdict" in (tmp_path / "progress.log").read_text()


def test_without_a_measured_friction_the_priors_span_the_damping_split():
    # a purely viscous device: c_m lies between 0 and the viscous fit, F_c between 0 and the
    # friction that alone gives that damping
    df, _ = measured_recording((), {**TABLE1_KNOWN, "c_m": 180.0}, 20.0, 3)
    specs = recording_priors(df, dict(TABLE1_KNOWN), {})
    assert specs["c_m"].mean == 0.0 and 150.0 < specs["c_m"].sd < 210.0
    assert specs["F_c"].mean == 0.0 and specs["F_c"].sd > 1.0
    # a device far from the paper's (Table 4: F_c 8.4 +- 5 N): its friction and damping lie
    # inside the priors, and nothing assumed puts them in a prior's tail
    far = {**TABLE1_KNOWN, "c_m": 40.0, "F_c": 30.0, "beta": 200.0}
    df, _ = measured_recording(("tanh_friction",), far, 20.0, 4, peak_m_s2=8.0)
    specs = recording_priors(df, dict(TABLE1_KNOWN), {})
    for name in ("c_m", "F_c", "beta"):
        assert specs[name].distribution().sf(far[name]) > 0.05, (name, specs[name])
    assert specs["c_m"].mean == 0.0 and specs["F_c"].mean == 0.0
    # beta: the tanh term's own prior, log-uniform over decades of the device's velocity scale
    assert specs["beta"].family == "loguniform"
    assert specs["beta"].distribution().cdf(far["beta"]) > 0.05
    # a friction law close to a sign law (Table 4's beta 100 +- 100 s/m would put it 50 sd out)
    sharp = {**far, "beta": 5000.0}
    df, _ = measured_recording(("tanh_friction",), sharp, 20.0, 4, peak_m_s2=8.0)
    assert recording_priors(df, dict(TABLE1_KNOWN), {})["beta"].distribution().sf(5000.0) > 0.05
    # a friction measured in static tests is taken as it is, as in the paper
    df, _ = measured_recording((), {**TABLE1_KNOWN, "c_m": 180.0}, 20.0, 3)
    specs = recording_priors(df, dict(TABLE1_KNOWN), {"F_c": {"mean": 0.0, "sd": 1.0}})
    assert specs["c_m"].mean == pytest.approx(180.0, rel=0.05) and specs["c_m"].sd == 50.0
    specs = recording_priors(df, dict(TABLE1_KNOWN), {"F_c": {"mean": 8.4, "sd": 1.0}})
    assert specs["c_m"].mean < 9.0 and specs["c_m"].sd == 50.0
    # a stated noise prior (a sidecar's, or the grid's) is taken with its unit
    sigma = recording_priors(df, dict(TABLE1_KNOWN), {"sigma": {"mean": 0.07, "sd": 0.03}})
    assert sigma["sigma"].unit == "m/s^2" and sigma["sigma"].mean == 0.07
    # the quadratic-damping candidate's prior keeps a positive scale
    scale = DeviceScale(force=5.0, v=0.05, z=0.01, f_high=20.0, M=12.8, m=8.0, k=250.0,
                        z_quantiles={0.75: 0.01})
    assert candidate_priors("quadratic_damping", scale)["c_quad"].sd > 0.0


# --------------------------------------------------------------------------- every command
#
# Each command on the bundled recordings (data/raw, converted and low-passed as the study
# does) and on recordings the tests write from the virtual rig's measurement chain
# (``measured_recording``) and from the physics of other recording kinds.

SIDECAR = "M: 12.8\nm: 8.0\nk: 250.0\n"
#: Small sampler settings: 2 s fitted, 20 particles, 2 chains (an evidence error needs 2).
TINY = ["--particles", "20", "--chains", "2", "--seed", "1", "--fit-seconds", "2"]


def _bundled(name: str, seconds: float, directory) -> object:
    """A bundled raw record converted to accelerations, its output low-passed at 20 Hz as in
    the study, cut to ``seconds``; with a sidecar giving M, m, k and the low-pass."""
    from pathlib import Path

    from harvester.data.daq import read_raw_record, to_accelerations
    from harvester.data.signals import filter_recording
    raw = Path(__file__).parents[1] / "data" / "raw"
    df = to_accelerations(*read_raw_record(raw / f"{name}.csv", raw / f"{name}.json"))
    df = filter_recording(df, 20.0, 8).iloc[: int(seconds * 256)]
    path = directory / f"{name}_acc.csv"
    write_recording(df, path)
    path.with_suffix(".yaml").write_text(SIDECAR + "filtered_at_hz: 20\n")
    return path


def _identify(rec, model: str, out, *extra: str) -> str:
    """Run ``harvester identify``; its stdout (asserting exit 0)."""
    import io
    from contextlib import redirect_stdout
    buf = io.StringIO()
    with redirect_stdout(buf):
        code = main(["identify", str(rec), "--model", model, "--out", str(out), *extra,
                     "--log", str(out.parent / f"{out.name}.log")])
    logging.getLogger("harvester").handlers.clear()
    assert code == 0
    return buf.getvalue()


@pytest.fixture(scope="module")
def bundled_fit(tmp_path_factory):
    """identify linear (the paper's M1) on the bundled training record, figures on:
    (directory, output directory, stdout). The linear model samples in seconds; the tanh
    model's steep friction takes minutes (``test_identify_tanh_on_the_bundled_record``)."""
    d = tmp_path_factory.mktemp("bundled")
    rec = _bundled("training", 8.0, d)
    return d, d / "fit", _identify(rec, "linear", d / "fit", *TINY)


def test_identify_writes_posterior_summary_evidence_and_assumptions(bundled_fit):
    d, out, said = bundled_fit
    assert "linear: log evidence" in said and "+-" in said
    assert {p.name for p in out.iterdir()} == {"posterior.nc", "summary.csv", "evidence.json",
                                               "posterior_pairs.png", "run.json"}
    summary = pd.read_csv(out / "summary.csv")
    assert list(summary.parameter) == ["c_m", "sigma"]
    assert list(summary.unit) == ["N s/m", "m/s^2"]
    assert (summary["q2.5"] <= summary["mean"]).all() and (summary["mean"] <= summary["q97.5"]).all()
    # the low-passed record's residuals are correlated: c_m's adjusted interval is wider, and
    # the command prints both
    c_m = summary.set_index("parameter").loc["c_m"]
    assert c_m["sd_adj"] > c_m["sd"]
    assert "c_m = " in said and "for correlated residuals" in said
    ev = json.loads((out / "evidence.json").read_text())
    assert len(ev["log_evidence_per_chain"]) == 2 and ev["standard_error"] > 0
    assert np.isfinite(ev["log_evidence"])
    run = json.loads((out / "run.json").read_text())
    assert run["known"] == TABLE1_KNOWN and run["assumed"]["values"] == {}
    assert run["output_filter"] == [20.0, 8] and run["identified"] == ["c_m", "sigma"]
    assert any("filtered_at_hz" in n for n in run["prior_notes"])
    assert run["window_s"] == [1.0, 3.0]
    assert "left" in (d / "fit.log").read_text()  # progress: time left of the run
    assert not list(d.glob(".fit.*"))  # nothing staged is left behind


def test_predict_on_the_unseen_bundled_record(bundled_fit, tmp_path, capsys):
    _, fit, _ = bundled_fit
    rec = _bundled("validation", 20.0, tmp_path)
    out = tmp_path / "pred"
    code = main(["predict", str(rec), "--posterior", str(fit / "posterior.nc"), "--out",
                 str(out), "--samples", "30", "--log", str(tmp_path / "p.log")])
    assert code == 0
    assert "NRMSE" in capsys.readouterr().out
    m = json.loads((out / "validation.json").read_text())
    assert 0.0 < m["nrmse"] < 1.0 and 0.0 <= m["outside_3sd"] <= 1.0 and m["unit"] == "m/s^2"
    table = pd.read_csv(out / "predictive.csv")
    assert list(table.columns) == ["time", "measured", "mean", "lower_3sd", "upper_3sd",
                                   "sd_parameter"]
    assert len(table) == 20 * 256 and (table.lower_3sd < table.upper_3sd).all()
    assert (out / "predictive.png").stat().st_size > 1000
    # a recording of other kinds than the posterior's is refused, with both named
    other = recording_of("force", "rel_acc", tmp_path)
    code = main(["predict", str(other), "--posterior", str(fit / "posterior.nc"), "--out",
                 str(tmp_path / "p2"), "--log", str(tmp_path / "p.log")])
    err = capsys.readouterr().err
    assert code == 2 and "identified from base_acc -> rel_acc" in err and "force" in err


@pytest.mark.slow
def test_identify_tanh_on_the_bundled_record_and_predict_the_unseen_one(tmp_path):
    """The paper's M2 on the rig's training record: the rig's friction (tanh law, F_c =
    11.86 N) is found, and the unseen record is predicted within its bounds (minutes)."""
    rec = _bundled("training", 8.0, tmp_path)
    _identify(rec, "tanh", tmp_path / "fit", "--particles", "60", "--chains", "2")
    summary = pd.read_csv(tmp_path / "fit" / "summary.csv").set_index("parameter")
    assert list(summary.unit) == ["N s/m", "N", "s/m", "m/s^2"]
    assert 8.0 < summary.loc["F_c", "mean"] < 16.0
    unseen = _bundled("validation", 20.0, tmp_path)
    assert main(["predict", str(unseen), "--posterior", str(tmp_path / "fit" / "posterior.nc"),
                 "--out", str(tmp_path / "pred"), "--samples", "50"]) == 0
    m = json.loads((tmp_path / "pred" / "validation.json").read_text())
    assert m["nrmse"] < 0.3 and m["outside_3sd"] < 0.1


def recording_of(input_kind: str, output_kind: str, directory, sidecar: str | None = None):
    """A 10 s recording of a sprung mass with Coulomb friction (tests/test_recording_kinds)."""
    from test_recording_kinds import synthetic
    path = directory / f"{input_kind}_{output_kind}.csv"
    write_recording(synthetic(input_kind, output_kind, n=2000), path)
    if sidecar:
        path.with_suffix(".yaml").write_text(sidecar)
    return path


@pytest.mark.parametrize("inp, out, sidecar, model", [
    ("force", "rel_disp", None, "linear"),
    pytest.param("force", "rel_disp", None, "linear+coulomb_friction", marks=pytest.mark.slow),
    pytest.param("base_acc", "rel_disp", "m: 8.0\n", "linear+coulomb_friction",
                 marks=pytest.mark.slow)])
def test_identify_takes_every_recording_kind(tmp_path, capsys, inp, out, sidecar, model):
    """Force or base input, displacement output; M, k (and m) not given are identified with
    priors from the FRF, and run.json says so. The sprung mass has Coulomb friction: the
    linear model finds its mass and stiffness, the right structure every parameter."""
    from test_recording_kinds import TRUTH
    rec = recording_of(inp, out, tmp_path, sidecar)
    _identify(rec, model, tmp_path / "fit", "--particles", "24", "--chains", "1",
              "--fit-seconds", "4", "--no-figures")
    summary = pd.read_csv(tmp_path / "fit" / "summary.csv").set_index("parameter")
    assert summary.loc["M", "unit"] == "kg" and summary.loc["sigma", "unit"] == "m"
    for name in ("M", "k", "c_m", "F_coulomb") if "coulomb" in model else ("M", "k"):
        assert summary.loc[name, "mean"] == pytest.approx(TRUTH[name], rel=0.2), name
    run = json.loads((tmp_path / "fit" / "run.json").read_text())
    assert run["input"] == inp and run["output"] == out
    assert "M" in run["identified"] and "k" in run["identified"]
    assert any("linear FRF fit" in n for n in run["prior_notes"])
    ev = json.loads((tmp_path / "fit" / "evidence.json").read_text())
    assert "one chain" in ev["note"] and (ev["standard_error"] is None or ev["standard_error"] > 0)


def test_identify_a_base_input_without_any_known_scale_says_where_to_give_one(tmp_path, capsys):
    rec = recording_of("base_acc", "rel_acc", tmp_path)
    code = main(["identify", str(rec), "--model", "tanh", "--out", str(tmp_path / "o"),
                 "--log", str(tmp_path / "l.log")])
    err = capsys.readouterr().err
    assert code == 2 and "fixes only m/M" in err and "base_acc_rel_acc.yaml" in err
    assert "--paper-device" in err and not (tmp_path / "o").exists()


@pytest.mark.parametrize("models, best", [
    (["linear", "linear+cubic_stiffness"], None),
    pytest.param(["linear", "tanh"], "tanh", marks=pytest.mark.slow)])
def test_compare_gives_evidence_and_bayes_factors(recording, tmp_path, capsys, models, best):
    """An evidence table with errors and Bayes factors against the first model; on the tanh
    device the tanh model is decisively more probable than the linear one (slow)."""
    _, df = recording
    rec = tmp_path / "rec.csv"
    write_recording(df, rec)
    rec.with_suffix(".yaml").write_text(SIDECAR)
    out = tmp_path / "cmp"
    code = main(["compare", str(rec), "--models", *models, "--out", str(out), *TINY,
                 "--no-figures", "--log", str(tmp_path / "c.log")])
    said = capsys.readouterr().out
    assert code == 0 and "is most probable: log Bayes factor" in said
    table = pd.read_csv(out / "evidence.csv")
    assert list(table.model) == models and table.reference.eq(models[0]).all()
    assert table.log_bayes_factor[0] == 0.0 and np.isfinite(table.log_bayes_factor[1])
    assert (table.standard_error >= 0).all() and table.bayes_factor_error[1] > 0
    for m in models:
        assert (out / "models" / m / "posterior.nc").exists()
    run = json.loads((out / "run.json").read_text())
    assert set(run["models"]) == set(models) and "verdict" in run
    if best is not None:
        assert f"{best} is most probable" in said and table.log_bayes_factor[1] > 10.0


def test_a_killed_run_leaves_nothing_and_resumes(recording, tmp_path, monkeypatch):
    from harvester.data import fileio
    from harvester.inference import recording_fit
    _, df = recording
    rec = tmp_path / "rec.csv"
    write_recording(df, rec)
    rec.with_suffix(".yaml").write_text(SIDECAR)
    args = ["identify", str(rec), "--model", "linear", "--out", str(tmp_path / "fit"),
            "--particles", "20", "--chains", "1", "--fit-seconds", "2", "--no-figures",
            "--log", str(tmp_path / "l.log")]

    def killed(*a, **k):
        raise KeyboardInterrupt

    monkeypatch.setattr(fileio, "write_json", killed)  # killed before run.json
    with pytest.raises(KeyboardInterrupt):
        main(args)
    assert not (tmp_path / "fit").exists()
    assert (tmp_path / ".fit.partial" / "evidence.json").exists()
    monkeypatch.undo()

    def sampled_again(*a, **k):
        raise AssertionError("the finished TMCMC run was not resumed")

    monkeypatch.setattr(recording_fit, "identify", sampled_again)
    assert main(args) == 0
    assert {p.name for p in (tmp_path / "fit").iterdir()} == {
        "posterior.nc", "summary.csv", "evidence.json", "run.json"}
    assert not (tmp_path / ".fit.partial").exists()
    assert "resuming" in (tmp_path / "l.log").read_text()


def test_terms_lists_the_library_with_units_and_priors(capsys):
    from harvester.model.terms import TERMS
    assert main(["terms"]) == 0
    text = capsys.readouterr().out
    assert "M z'' + c_m z' + k z + f = -m y''" in text
    for t in TERMS.values():
        assert f"{t.name} ({t.kind}" in text and t.equation in text
        for p in t.parameters:
            assert f"{p.name}  " in text and p.unit in text


def test_help_gives_units_and_an_example(capsys):
    for cmd in ("identify", "compare", "predict", "diagnose", "check"):
        with pytest.raises(SystemExit):
            main([cmd, "--help"])
        text = capsys.readouterr().out
        assert f"example:\n  harvester {cmd}" in text
        assert "base_acc  m/s^2" in text and "rel_disp  m" in text


@pytest.mark.slow
def test_diagnose_a_model_expression_with_warnings_in_its_notes(tmp_path, capsys):
    """Any model expression as the baseline; the check's warnings and the assumed device
    reach diagnosis.json's notes (~60 s)."""
    df, _ = measured_recording(("tanh_friction",), {**TABLE1_KNOWN, **TANH_TABLE5}, 8.0, 21)
    lo, hi = np.quantile(df.rel_acc, [0.002, 0.998])
    rec = tmp_path / "rec.csv"
    write_recording(df.assign(rel_acc=np.clip(df.rel_acc, lo, hi)), rec)
    out = tmp_path / "diag"
    code = main(["diagnose", str(rec), "--baseline", "tanh+cubic_stiffness", "--out", str(out),
                 "--paper-device", "--fast", "--particles", "40", "--chains", "1", "--top", "1",
                 "--no-figures", "--log", str(tmp_path / "d.log")])
    err = capsys.readouterr().err
    assert code == 0
    assert err.count("sit at the extreme value(s)") == 1  # the warning, once on the console
    d = json.loads((out / "diagnosis.json").read_text())
    assert d["verdict"] in ("adequate", "missing_physics", "inadequate")
    assert any("sit at the extreme value(s)" in n for n in d["notes"])
    assert any(n.startswith("ASSUMED (not measured): M = 12.8 kg") for n in d["notes"])
