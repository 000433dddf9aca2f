"""The README's section "From Python" runs as written, and the package's face: its version, its
lazy public names, the command line's sampler defaults and the command line's identification."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def readme_python_block() -> str:
    """The one ```python block of the README's section "From Python"."""
    text = (ROOT / "README.md").read_text()
    section = text.split("\n## From Python\n", 1)[1].split("\n## ", 1)[0]
    blocks = re.findall(r"```python\n(.*?)```", section, flags=re.S)
    assert len(blocks) == 1, f"expected one python block in 'From Python', found {len(blocks)}"
    return blocks[0]


def run_python(code: str, cwd: Path, timeout: float = 120) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONWARNINGS="ignore")
    return subprocess.run([sys.executable, "-c", code], cwd=cwd, capture_output=True,
                          text=True, env=env, timeout=timeout)


def test_readme_example_runs(tmp_path: Path) -> None:
    """From a directory holding the clone's data/ (as from its root), writing only there: the
    frame's tanh friction, F_c about 0.65 N, is printed with its interval."""
    (tmp_path / "data").symlink_to(ROOT / "data")
    proc = run_python(readme_python_block(), tmp_path)
    assert proc.returncode == 0, proc.stderr[-4000:]
    assert "rel_disp" in proc.stdout and "log evidence" in proc.stdout
    row = next(line.split() for line in proc.stdout.splitlines() if line.split()[:1] == ["F_c"])
    f_c, low, high = (float(x) for x in row[2:5])
    assert low < f_c < high and 0.5 < f_c < 0.8, proc.stdout
    assert (tmp_path / "frame/frame_250g.yaml").is_file()


def test_import_is_light_and_names_resolve() -> None:
    """``import harvester`` loads neither numpy nor PyMC; each public name is the library's."""
    code = ("import sys, harvester; print(sorted(m for m in sys.modules if m.split('.')[0] "
            "in ('numpy', 'pandas', 'pymc', 'scipy')))")
    proc = run_python(code, ROOT)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == "[]"
    import harvester
    import harvester.api
    import harvester.diagnosis
    from harvester.data.daq import read_checked_recording
    assert harvester.load_recording is read_checked_recording
    assert harvester.identify is harvester.api.identify
    assert harvester.diagnose is harvester.diagnosis.diagnose_recording
    assert set(harvester.__all__) <= set(dir(harvester))
    with pytest.raises(AttributeError, match="no attribute 'nothing'"):
        harvester.nothing  # noqa: B018


def test_version_is_pyproject_s() -> None:
    """``harvester.__version__``, ``harvester --version`` and CITATION.cff give pyproject.toml's
    version."""
    import harvester
    stated = re.search(r'(?m)^version\s*=\s*"([^"]+)"',
                       (ROOT / "pyproject.toml").read_text()).group(1)
    assert harvester.__version__ == stated
    proc = subprocess.run([str(Path(sys.executable).with_name("harvester")), "--version"],
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0 and proc.stdout.strip() == f"harvester {stated}"
    cited = re.search(r"(?m)^version: (\S+)$", (ROOT / "CITATION.cff").read_text()).group(1)
    assert cited == stated, "CITATION.cff's version is not pyproject.toml's"


def test_python_defaults_are_the_command_line_s() -> None:
    """``harvester.identify`` samples as ``harvester identify`` does by default."""
    import inspect

    from harvester import api
    from harvester.cli import CLI_TMCMC
    params = inspect.signature(api.identify).parameters
    assert (params["particles"].default, params["chains"].default, api.MCMC_STEPS,
            api.TARGET_ACCEPT) == (CLI_TMCMC["particles"], CLI_TMCMC["chains"],
                                   CLI_TMCMC["mcmc_steps"], CLI_TMCMC["target_accept"])


def test_python_identify_is_the_command_s(tmp_path: Path) -> None:
    """The same recording (the frame, whose sidecar says friction_on: ground), model and
    settings give the same evidence and posterior from ``harvester.identify`` as from
    ``harvester identify``: the same steps, not a second version of them."""
    import json

    import numpy as np

    from harvester import identify
    from harvester.cli import main
    from harvester.data.public import public_recording
    rec = public_recording(ROOT / "data/public/marino-frame/s_b_250g_x.mat").write(
        tmp_path / "frame.csv")
    settings = {"particles": 30, "chains": 1, "fit_seconds": 2.0}
    fit = identify(rec, "linear", **settings)
    assert main(["identify", str(rec), "--model", "linear", "--out", str(tmp_path / "cli"),
                 "--particles", "30", "--chains", "1", "--fit-seconds", "2",
                 "--no-figures"]) == 0
    cli = json.loads((tmp_path / "cli" / "evidence.json").read_text())
    assert fit.evidence["log_evidence"] == cli["log_evidence"]
    table = fit.summary().set_index("parameter")
    from harvester.inference.posterior import read_posterior
    from harvester.inference.recording_fit import parameter_table
    cli_table = parameter_table(read_posterior(tmp_path / "cli" / "posterior.nc"),
                                fit.priors).set_index("parameter")
    np.testing.assert_array_equal(table["mean"], cli_table["mean"])
