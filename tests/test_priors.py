"""Priors of Tables 2 and 4 (harvester.inference.priors) and the Table 1 they take their means from
(harvester.study.tables)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from harvester.study import paper
from harvester.initial.damping import DampingSummary
from harvester.initial.static_friction import StaticFrictionEstimate
from harvester.inference.priors import PriorSpec, prior_moments
from harvester.study.tables import prior_table
from harvester.study.tables import (
    COLUMNS,
    SIMULATED_NOTE,
    compare_table,
    render_table,
    table1,
    table1_notes,
    table1_values,
    write_table_png,
)

CONFIG = yaml.safe_load((Path(__file__).parents[1] / "config" / "config.yaml").read_text())


def damping_fit(c_m: float) -> DampingSummary:
    """A damping-fit summary as read back from its JSON file."""
    fit = DampingSummary(c_m=c_m, c_eq=600.0, sigma_v=0.01, F_c=8.1, residual=0.1,
                         band_hz=(0.3, 10.0))
    back = DampingSummary.from_dict(json.loads(json.dumps(fit.to_dict())))
    assert back == fit
    return back


@pytest.fixture()
def our_table1() -> pd.DataFrame:
    static = StaticFrictionEstimate(F_c=8.1, sd=0.4, se=0.13, n=10, span_m=0.0648)
    assert StaticFrictionEstimate.from_dict(json.loads(json.dumps(static.to_dict()))) == static
    return table1(static, damping_fit(95.0), CONFIG["rig"])


def test_table1_has_exactly_five_columns(our_table1: pd.DataFrame) -> None:
    assert list(our_table1.columns) == ["parameter", "value", "unit", "paper", "truth"]
    assert list(our_table1.columns) == COLUMNS


def test_table1_values_paper_and_truth(our_table1: pd.DataFrame) -> None:
    t = our_table1.set_index("parameter")
    assert list(t.index) == ["M", "m", "k", "F_c", "c_m"]
    assert t.loc["F_c", "value"] == 8.1 and t.loc["c_m", "value"] == 95.0
    assert t["paper"].to_dict() == paper.TABLE1
    assert t.loc["F_c", "truth"] == CONFIG["rig"]["friction"]["F_s"]
    assert t.loc["c_m", "truth"] == CONFIG["rig"]["c_m"]
    assert t.loc["M", "value"] == t.loc["M", "truth"] == CONFIG["rig"]["M"]
    assert t.loc["c_m", "unit"] == "N s/m"


def test_rendered_table_carries_notes_and_simulated_label(our_table1: pd.DataFrame,
                                                          tmp_path: Path) -> None:
    static = StaticFrictionEstimate(F_c=8.1, sd=0.4, se=0.13, n=10, span_m=0.0648)
    notes = table1_notes(static, damping_fit(95.0), CONFIG["rig"])
    text = render_table(our_table1, "Table 1. Initial parameter estimates", notes)
    assert "| parameter | value | unit | paper | truth |" in text
    assert SIMULATED_NOTE in text and "static friction F_s" in text
    write_table_png(our_table1, tmp_path / "t1.png", "Table 1", notes)
    assert (tmp_path / "t1.png").stat().st_size > 5_000


def test_compare_table_fills_missing_with_nan() -> None:
    df = compare_table({"c_m": 400.0, "sigma": 0.1}, paper.TABLE3, {"c_m": 109.5},
                       {"c_m": "N s/m"})
    assert list(df.columns) == COLUMNS
    assert np.isnan(df.loc[1, "truth"]) and df.loc[1, "unit"] == ""
    assert df.loc[0, "paper"] == 432.6


def test_prior_means_from_table1(our_table1: pd.DataFrame) -> None:
    specs = prior_moments(CONFIG["priors"], table1_values(our_table1))
    assert specs["c_m"] == PriorSpec("c_m", 95.0, 50.0, "N s/m", 0.0)
    assert specs["F_c"].mean == 8.1 and specs["F_c"].sd == 5.0
    assert specs["beta"].mean == 100.0 and specs["sigma"].sd == 0.03


def test_prior_is_gaussian_truncated_at_zero() -> None:
    spec = PriorSpec("F_c", mean=8.4, sd=5.0, unit="N")
    assert spec.lower == 0.0
    assert spec.logpdf(-1e-9) == -np.inf
    samples = spec.distribution().rvs(size=20_000, random_state=1)
    assert samples.min() >= 0.0
    # density ratio inside the support is the untruncated Gaussian's
    ratio = np.exp(spec.logpdf(8.4) - spec.logpdf(3.4))
    assert ratio == pytest.approx(np.exp(0.5))


def test_prior_config_errors_name_the_key() -> None:
    with pytest.raises(ValueError, match="priors.c_m"):
        prior_moments({"c_m": {"from": "table1", "sd": 50.0}}, {"F_c": 8.0})
    with pytest.raises(ValueError, match="priors.beta.*sd"):
        prior_moments({"beta": {"mean": 100.0, "sd": 0.0}}, {})
    with pytest.raises(ValueError, match="priors.beta"):
        prior_moments({"beta": {"sd": 1.0}}, {})


def test_prior_tables_2_and_4_side_by_side(our_table1: pd.DataFrame) -> None:
    specs = prior_moments(CONFIG["priors"], table1_values(our_table1))
    t2 = prior_table(["c_m", "sigma"], specs)
    assert list(t2.columns) == ["parameter", "mean", "sd", "unit", "paper_mean", "paper_sd"]
    assert t2["paper_mean"].tolist() == [170.0, 0.07]
    assert t2.loc[0, "paper_sd"] == 50.0 and np.isnan(t2.loc[1, "paper_sd"])
    t4 = prior_table(["c_m", "F_c", "beta", "sigma"], specs)
    assert t4["paper_sd"].tolist() == [50.0, 5.0, 100.0, 0.03]
    assert t4["mean"].tolist() == [95.0, 8.1, 100.0, 0.07]
