"""The workflow on recording sheets: the sheet's checks at start-up, the shipped sheets and the
SLURM profile in dry runs, the test configuration (.test) end to end with its report, and a new
sheet written here running with no edit of the workflow."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from pathlib import Path

import pandas as pd
import pytest
import yaml

from conftest import ROOT, SNAKEMAKE, fake_slurm

from harvester.data.errors import DataError
from harvester.data.sheet import COLUMNS, load_sheets
from harvester.groups import group_settings
from harvester.synthetic.measured import write_example_recording

SCHEMA = yaml.safe_load((ROOT / "workflow/schemas/recordings.schema.yaml").read_text())
CONFIG = yaml.safe_load((ROOT / "config/config.yaml").read_text())


def snakemake(workdir: Path, *args: str, env: dict | None = None,
              timeout: int = 900) -> subprocess.CompletedProcess:
    """The repository's Snakefile in ``workdir`` (its config/config.yaml, if any, read over
    the repository's)."""
    cmd = [str(SNAKEMAKE), *args, "-s", str(ROOT / "Snakefile"), "-d", str(workdir)]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=timeout,
                          env=env or dict(os.environ, PYTHONWARNINGS="ignore"))


def job_counts(dry_run: str) -> dict[str, int]:
    """The job table of a dry run: rule -> count."""
    table = dry_run.split("Job stats:", 1)[1].split("total", 1)[0]
    return {p[0]: int(p[1]) for p in (ln.split() for ln in table.splitlines())
            if len(p) == 2 and p[1].isdigit()}


def write_sheet(path: Path, rows: list[list[str]], header=COLUMNS) -> Path:
    path.write_text("\n".join("\t".join(r) for r in [list(header), *rows]) + "\n")
    return path


# --------------------------------------------------------------------------- the sheet


@pytest.fixture
def recordings(tmp_path) -> Path:
    for name, seed in (("a", 1), ("b", 2)):
        write_example_recording(tmp_path / f"{name}.csv", duration_s=4.0, seed=seed)
    return tmp_path


def test_the_shipped_sheets_give_the_paper_and_emps_groups():
    sheet = load_sheets(CONFIG["recordings"], SCHEMA, bases=(ROOT,))
    paper, emps = sheet.groups["paper"], sheet.groups["emps"]
    assert (paper.training, paper.validation, paper.chain) == ("training", ("validation",),
                                                                "generic")
    assert (emps.training, emps.validation, emps.chain) == ("DATA_EMPS", ("DATA_EMPS_PULSES",),
                                                            "emps")
    assert sheet.raw_meta("training") == "data/raw/training.json"
    # the paper's group takes the study's preprocessing, in seconds of the rig's 256 Hz
    s = group_settings(CONFIG, "paper")
    assert (s["lowpass_hz"], s["lead_in_s"], s["fit_seconds"], s["priors"]) == \
        (20.0, 1.0, 2000 / 256, "study")


def test_the_public_sheet_gives_the_real_recordings_groups(tmp_path):
    """The frame (both loads) and the Silverbox, kind public, each alone in its group; their
    reader's sidecar states the frame's friction on the ground, and the workflow's
    prepare_recording rewrites the frame so (force k y -> the storey's x)."""
    from harvester.data.public import public_recording
    from harvester.groups import prepare_recording
    sheet = load_sheets(["config/public/recordings.tsv"], SCHEMA, bases=(ROOT,))
    assert set(sheet.groups) == {"frame_250g", "frame_450g", "silverbox"}
    assert all(sheet.row(r)["kind"] == "public" for r in sheet.recordings())
    assert group_settings(CONFIG, "frame_450g")["models"] == group_settings(CONFIG, "frame_450g")["diagnose"] == ["linear"]
    frame = public_recording(ROOT / "data/public/marino-frame/s_b_250g_x.mat")
    assert frame.sidecar["friction_on"] == "ground"
    csv = frame.write(tmp_path / "frame.csv")
    out = prepare_recording(csv, csv.with_suffix(".yaml"), tmp_path / "g/frame.csv")
    assert (out["input"], out["output"], out["friction_on"]) == ("force", "rel_disp", "ground")
    assert "m" not in out["known"] and out["known"]["k"] == 1191.0
    with pytest.raises(DataError, match="not a public recording this reader knows"):
        public_recording(tmp_path / "frame.csv")


@pytest.mark.parametrize("rows, message", [
    ([["a", "a.csv", "csv", "", "training", "g"]], "line 2, column 'kind': unknown kind 'csv'"),
    ([["a", "missing.csv", "converted", "", "training", "g"]],
     "line 2, column 'file': recording 'missing.csv' not found"),
    ([["a", "a.csv", "converted", "", "validation", "g"]],
     "group 'g' has no training recording"),
    ([["a", "a.csv", "converted", "", "training", "g"],
      ["a", "b.csv", "converted", "", "validation", "g"]], "line 3, column 'recording': "
     "recording 'a' is named twice"),
    ([["a", "a.csv", "converted", "", "training", "g"],
      ["b", "b.csv", "converted", "", "training", "g"]], "has 2 training recordings"),
    ([["a", "a.csv", "converted", "a.json", "training", "g"]], "a sidecar is a .yaml file"),
    ([["a", "a.csv", "converted", "", "train", "g"]], "unknown role 'train'"),
    ([["a b", "a.csv", "converted", "", "training", "g"]], "column 'recording': 'a b' does not "
     "match"),
])
def test_a_bad_sheet_is_refused_naming_line_column_and_what_was_expected(recordings, rows,
                                                                         message):
    sheet = write_sheet(recordings / "sheet.tsv", rows)
    with pytest.raises(DataError) as err:
        load_sheets(str(sheet), SCHEMA, bases=(recordings,))
    assert str(sheet) in str(err.value) and message in str(err.value)


def test_a_sheet_that_is_not_tab_separated_is_refused(recordings):
    sheet = recordings / "sheet.csv"
    sheet.write_text("recording,file,kind,sidecar,role,group\na,a.csv,converted,,training,g\n")
    with pytest.raises(DataError, match="tab-separated"):
        load_sheets(str(sheet), SCHEMA, bases=(recordings,))


def test_snakemake_stops_at_start_up_on_a_bad_sheet(recordings):
    write_sheet(recordings / "sheet.tsv", [["a", "a.csv", "converted", "", "training", "g"],
                                           ["b", "b.csv", "emps", "", "validation", "g"]])
    (recordings / "config").mkdir()
    (recordings / "config/config.yaml").write_text("recordings: sheet.tsv\n")
    proc = snakemake(recordings, "-n", "all")
    assert proc.returncode != 0
    assert "sheet.tsv, line 3, column 'file': a emps recording is a .mat file" in \
        proc.stdout + proc.stderr


# --------------------------------------------------------------------------- dry runs


def test_dry_runs_of_the_shipped_sheets(tmp_path):
    """The default reads both studies' sheets; config/emps.yaml the EMPS one alone (in a
    fresh working directory: the repository's data, no results)."""
    (tmp_path / "data").symlink_to(ROOT / "data")
    proc = snakemake(tmp_path, "-n", "all")
    assert proc.returncode == 0, (proc.stdout + proc.stderr)[-4000:]
    both = job_counts(proc.stdout)
    # the paper's two models and the real recordings' groups (the frame's linear model, the
    # Silverbox's two; the linear ones diagnosed; no validation recordings: the diagnosis holds
    # out each record's end)
    assert both["identify"] == 2 + 2 * 1 + 2 and both["diagnose"] == 2 + 3
    assert both["validate_recording"] == 2 and both["convert_public"] == 3
    assert both["emps_tmcmc"] == 4 and both["fig10_tanh_unseen_full"] == 1
    emps = snakemake(tmp_path, "-n", "all", "--configfile", str(ROOT / "config/emps.yaml"))
    assert emps.returncode == 0, (emps.stdout + emps.stderr)[-4000:]
    counts = job_counts(emps.stdout)
    assert counts["emps_tmcmc"] == 4 and "identify" not in counts and "table1" not in counts


def _test_workdir(tmp_path: Path) -> Path:
    work = tmp_path / "test-config"
    shutil.copytree(ROOT / ".test", work, ignore=shutil.ignore_patterns(
        "results", "logs", ".snakemake"))
    return work


def test_the_slurm_profile_dry_runs_the_test_configuration(tmp_path):
    work = _test_workdir(tmp_path)
    marker = tmp_path / "called.txt"
    proc = snakemake(work, "--profile", str(ROOT / "profiles/slurm"), "-n", "all",
                     env=fake_slurm(tmp_path / "bin", marker))
    assert proc.returncode == 0, (proc.stdout + proc.stderr)[-4000:]
    assert not marker.exists()
    counts = job_counts(proc.stdout)
    assert counts["identify"] == 2 and counts["prepare_recording"] == 2


# --------------------------------------------------------------------------- runs


@pytest.mark.slow
def test_the_test_configuration_runs_end_to_end_with_its_report(tmp_path):
    """.test: two 8 s recordings, both models, evidence, validation, diagnosis, report."""
    work = _test_workdir(tmp_path)
    proc = snakemake(work, "--cores", "2", "all")
    assert proc.returncode == 0, (proc.stdout + proc.stderr)[-6000:]
    group = work / "results/groups/shaker"
    evidence = pd.read_csv(group / "evidence.csv").set_index("model")
    assert evidence.loc["tanh", "log_bayes_factor"] > 20  # the recordings have friction
    validation = pd.read_csv(group / "validation.csv").set_index("model")
    assert validation.loc["tanh", "nrmse"] < validation.loc["linear", "nrmse"]
    diagnosis = json.loads((group / "diagnosis/linear/diagnosis.json").read_text())
    assert diagnosis["verdict"] in ("missing_physics", "adequate", "inadequate")
    assert diagnosis["headline"].startswith(diagnosis["verdict"])
    report = work / "report.html"
    proc = snakemake(work, "--report", str(report))
    assert proc.returncode == 0, (proc.stdout + proc.stderr)[-4000:]
    assert report.stat().st_size > 100_000


def test_a_new_sheet_runs_with_no_edit_of_the_workflow(tmp_path):
    """Two recordings written here, a sheet and a config of a few lines: the whole chain."""
    write_example_recording(tmp_path / "bench/run_1.csv", duration_s=8.0, seed=31)
    write_example_recording(tmp_path / "bench/run_2.csv", duration_s=8.0, seed=32)
    write_sheet(tmp_path / "bench/recordings.tsv",
                [["run_1", "bench/run_1.csv", "converted", "", "training", "bench"],
                 ["run_2", "bench/run_2.csv", "converted", "", "validation", "bench"]])
    (tmp_path / "config").mkdir()
    (tmp_path / "config/config.yaml").write_text(yaml.safe_dump({
        "recordings": "bench/recordings.tsv", "models": ["linear"],
        "tmcmc": {"particles": 40, "chains": 2, "seed": 1, "mcmc_steps": 1,
                  "max_mcmc_steps": 2},
        "predictive": {"samples": 10, "seed": 1},
        "groups": {"bench": {"diagnose": False, "fit_seconds": 4.0}}}))
    proc = snakemake(tmp_path, "--cores", "2", "all")
    assert proc.returncode == 0, (proc.stdout + proc.stderr)[-6000:]
    group = tmp_path / "results/groups/bench"
    check = json.loads((group / "data/run_1.check.json").read_text())
    assert check["filtered_at_hz"] == 20.0 and check["known"] == {"M": 12.8, "m": 8.0,
                                                                  "k": 250.0}
    assert list(pd.read_csv(group / "evidence.csv")["model"]) == ["linear"]
    summary = pd.read_csv(group / "models/linear/summary.csv").set_index("parameter")
    assert summary.loc["c_m", "unit"] == "N s/m"
    row = pd.read_csv(group / "validation.csv").iloc[0]
    assert row["recording"] == "run_2" and 0 < row["nrmse"] < 1
    assert (group / "validation/linear/run_2/predictive.png").stat().st_size > 10_000
    assert not (group / "diagnosis").exists()


@pytest.mark.skipif(not (ROOT / "data/public/silverbox/SNLS80mV.mat").is_file(),
                    reason="no data/public/silverbox/SNLS80mV.mat")
def test_a_group_on_the_silverbox_benchmark_is_scored_on_its_tests(tmp_path):
    """A sheet of one group trained on SNLS80mV.mat (kind public): rule silverbox_benchmark
    simulates its models (a few TMCMC particles) on the benchmark's three tests. The cubic
    model's errors lie below the linear one's on every test (the circuit's cubic spring),
    each in mV against an output of about 50 mV RMS, and the published rows follow with
    their sources."""
    from harvester.data.public import SILVERBOX_TESTS
    from harvester.data.published import SILVERBOX_PUBLISHED
    write_sheet(tmp_path / "sb.tsv", [["sb", str(ROOT / "data/public/silverbox/SNLS80mV.mat"),
                                       "public", "", "training", "sb"]])
    (tmp_path / "config").mkdir()
    (tmp_path / "config/config.yaml").write_text(yaml.safe_dump({
        "recordings": "sb.tsv", "models": ["linear", "linear+cubic_stiffness"],
        "tmcmc": {"particles": 60, "chains": 1, "seed": 1, "mcmc_steps": 1,
                  "max_mcmc_steps": 2, "start": "map"},
        "predictive": {"samples": 10, "seed": 1},
        "groups": {"sb": {"diagnose": False, "fit_seconds": 3.0}}}))
    proc = snakemake(tmp_path, "--cores", "2", "results/groups/sb/benchmark.csv")
    assert proc.returncode == 0, (proc.stdout + proc.stderr)[-6000:]
    table = pd.read_csv(tmp_path / "results/groups/sb/benchmark.csv")
    assert list(table["model"][:2]) == ["linear", "linear+cubic_stiffness"]
    ours = table.iloc[:2].set_index("model")[list(SILVERBOX_TESTS)]  # input band-limited
    assert (ours.loc["linear+cubic_stiffness"] < ours.loc["linear"]).all()
    assert ((ours > 0.1) & (ours < 30)).all().all()
    # the same models with the input held and linear between samples, then the published
    assert list(table["model"][2:6]) == ["linear", "linear+cubic_stiffness"] * 2
    held = table.iloc[3][list(SILVERBOX_TESTS)].astype(float)  # the cubic model, input held
    assert (held > 3 * ours.loc["linear+cubic_stiffness"]).all()
    assert list(table["model"][6:]) == [p.method for p in SILVERBOX_PUBLISHED]
    html = (tmp_path / "results/groups/sb/benchmark.html").read_text()
    assert "Beintema" in html and "arrow full (mV)" in html and "non-causal" in html
