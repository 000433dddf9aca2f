"""``harvester diagnose``: bad input gets a clear error, a short recording runs end to end."""

from __future__ import annotations

import json
import logging

import numpy as np
import pytest

from harvester.cli import main
from harvester.data.daq import write_recording
from harvester.diagnosis.confirm import candidate_priors
from harvester.diagnosis.signatures import MotionScale
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
    (tmp_path / "r.yaml").write_text("priors:\n  damping: {mean: 9.0, sd: 1.0}\n")
    code, err = _run(["diagnose", str(path), "--baseline", "linear", "--out",
                      str(tmp_path / "o"), "--log", str(tmp_path / "l.txt")], capsys)
    assert code == 2 and "r.yaml" in err and "no prior for parameter 'damping'" in err
    (tmp_path / "r.yaml").unlink()
    code, err = _run(["diagnose", str(path), "--baseline", "linear", "--out",
                      str(tmp_path / "o"), "--lowpass", "500", "--log",
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
                 "--log", str(tmp_path / "progress.log")])
    assert code == 0
    assert "->" in capsys.readouterr().out
    d = json.loads((out / "diagnosis.json").read_text())
    assert d["verdict"] in ("adequate", "missing_physics")
    assert isinstance(d["missing"], list) and all(isinstance(m, str) for m in d["missing"])
    # a linear model of a friction device is not adequate, and friction is what it misses
    assert d["verdict"] == "missing_physics"
    for c in d["candidates"]:
        assert isinstance(c["effect"], str)
        for key in ("log_evidence", "delta_log_evidence", "log_evidence_tmcmc"):
            assert isinstance(c[key], float)
        assert c["log_evidence_method"] in ("bridge", "tmcmc")
        # a secondary mode's TMCMC starts half its particles at the linear model's posterior
        # and at the scan of its frequency; every other candidate's at its prior
        start = c["tempered_from"]
        if c["effect"] != "unmodelled_mode":
            assert start is None
        else:
            assert start["share"] == 0.5 and start["factors"][0]["kind"] == "gaussian"
            assert set(start["factors"][0]["variables"]) == {"c_m", "sigma"}
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
        assert specs[name].mean == 0.0
        assert specs[name].distribution().sf(far[name]) > 0.05, (name, specs[name])
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
    # the quadratic-damping candidate's prior keeps a positive scale
    scale = MotionScale(z=0.01, v=0.05, z_quantiles={0.75: 0.01}, f_high=20.0)
    assert candidate_priors("quadratic_damping", scale)["c_quad"].sd > 0.0
