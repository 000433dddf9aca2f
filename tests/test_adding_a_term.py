"""docs/adding-a-term.md works: the term file it shows, saved as one file and registered, is
simulated by the compiled simulator with its force in eq. (1), and listed by ``harvester terms``.
"""

import re
from pathlib import Path

import numpy as np
import pytest

from harvester import cli
from harvester.model.simulate import simulate
from harvester.model.structures import structure
from harvester.model.terms import TERMS, load_term_file

DOC = Path(__file__).resolve().parents[1] / "docs" / "adding-a-term.md"
NAME = "quintic_stiffness"


@pytest.fixture
def new_term(tmp_path, monkeypatch):
    """The walk-through's term file, written alone into a fresh directory and registered; the
    registry is restored afterwards so that no other test sees the term."""
    code = re.search(r"```python\n(.*?)```", DOC.read_text(), re.S).group(1)
    path = tmp_path / f"{NAME}.py"
    path.write_text(code)
    monkeypatch.setenv("HARVESTER_CACHE", str(tmp_path / "cache"))
    saved = dict(TERMS)
    try:
        yield load_term_file(path)
    finally:
        TERMS.clear()
        TERMS.update(saved)


def test_the_walk_through_term_enters_the_compiled_simulation(new_term):
    assert new_term.name == NAME and new_term.source.endswith(f"{NAME}.py")
    model = structure(f"tanh+{NAME}")
    assert model.layout.parameter_names == ("M", "m", "k", "c_m", "F_c", "beta", "k_quintic")
    M, m, k, c_m, F_c, beta, k5 = 12.8, 8.0, 250.0, 109.5, 11.86, 88.35, 3.0e12
    fs = 256.0
    t = np.arange(int(2 * fs)) / fs
    y_dd = 4.0 * np.sin(2 * np.pi * 1.5 * t)  # base acceleration, m/s^2
    sim = simulate(model.layout, np.array([M, m, k, c_m, F_c, beta, k5]), y_dd, 1 / fs)
    assert sim.ok.all()
    z, v, a = sim.rel_disp[0], sim.rel_vel[0], sim.rel_acc[0]
    quintic = k5 * z**5  # the new term's force (N), by hand
    by_hand = (-m * y_dd - c_m * v - k * z - F_c * np.tanh(beta * v) - quintic) / M
    np.testing.assert_allclose(a, by_hand, rtol=1e-9, atol=1e-9)
    # the force matters: a sizeable share of the spring force at the largest displacement
    assert np.max(np.abs(quintic)) > 0.2 * np.max(np.abs(k * z))


def test_the_walk_through_term_is_listed_by_harvester_terms(new_term, capsys):
    assert cli.main(["terms"]) == 0
    out = capsys.readouterr().out
    assert f"{NAME} (mass): fifth-order spring" in out
    assert "f = k_quintic z^5" in out and "k_quintic  N/m^5" in out


def test_the_registry_refuses_the_file_without_its_prior_reasoning(tmp_path):
    code = re.search(r"```python\n(.*?)```", DOC.read_text(), re.S).group(1)
    bad = re.sub(r"\nPriors:\n.*?\n(?=\"\"\")", "\n", code, flags=re.S)  # no reasoning
    assert bad != code and "Priors:" not in bad
    path = tmp_path / f"{NAME}.py"
    path.write_text(bad)
    with pytest.raises(ValueError, match="why"):
        load_term_file(path)
    assert NAME not in TERMS


def test_the_registry_refuses_a_prior_reason_for_no_parameter(tmp_path):
    code = re.search(r"```python\n(.*?)```", DOC.read_text(), re.S).group(1)
    bad = code.replace("- k_quintic:", "- k_quintc:")
    assert bad != code
    path = tmp_path / f"{NAME}.py"
    path.write_text(bad)
    with pytest.raises(ValueError, match=r"k_quintc.*not its parameters"):
        load_term_file(path)
    assert NAME not in TERMS
