"""EMPS (harvester.emps.closed_loop) on slices of the real recordings: controller, closed loop, IDIM-LS."""

from __future__ import annotations

from pathlib import Path

import arviz as az
import numpy as np
import pandas as pd
import pytest
import xarray as xr
import yaml

from harvester import emps
from harvester.data.errors import DataError
from harvester.data.sheet import load_sheets
from harvester.initial.frf import fit_linear_frf
from harvester.inference.identify import TMCMCSettings, identify
from harvester.inference.priors import PriorSpec
from harvester.model.simulate import simulate

ROOT = Path(__file__).parents[1]
CFG = yaml.safe_load((ROOT / "config/config.yaml").read_text())["emps"]
#: The EMPS study's recordings, from its sheet.
_SHEET = load_sheets("config/emps/recordings.tsv", bases=(ROOT,))
_GROUP = _SHEET.groups["emps"]
TRAINING, VALIDATION = (ROOT / _SHEET.file(_GROUP.training),
                        ROOT / _SHEET.file(_GROUP.validation[0]))
#: Published parameters in our layout order for the model viscous + coulomb_friction.
MODEL = emps.BASELINE_TERMS + ("coulomb_friction",)


def published_theta(problem, sigma: float = 2e-6) -> np.ndarray:
    ours = {our: emps.PUBLISHED[name] for name, our in emps.PARAMETERS.items()}
    return np.array([[ours[n] for n in problem.structure.free_parameters] + [sigma]])


def broad_priors() -> dict[str, PriorSpec]:
    """Priors of viscous + coulomb_friction centred away from the published values."""
    broad = {"M": (90.0, 30.0, "kg", 0.0), "c_m": (150.0, 100.0, "N s/m", 0.0),
             "F_offset": (0.0, 10.0, "N", -np.inf), "F_coulomb": (10.0, 20.0, "N", 0.0),
             "sigma": (1e-5, 1e-5, "m", 0.0)}
    return {n: PriorSpec(n, *v) for n, v in broad.items()}


def sliced(record: emps.EmpsRecord, stop_s: float) -> emps.EmpsRecord:
    n = int(round(stop_s / record.dt))
    return emps.EmpsRecord(record.name, record.time[:n], record.qm[:n], record.qg[:n],
                           record.vir[:n], record.loop, record.pulses[:n])


@pytest.fixture(scope="module")
def training() -> emps.EmpsRecord:
    return emps.load_emps(TRAINING, CFG["sha256"]["training"])


@pytest.fixture(scope="module")
def validation() -> emps.EmpsRecord:
    return emps.load_emps(VALIDATION, CFG["sha256"]["validation"])


def test_files_and_checksums(training, validation, tmp_path) -> None:
    assert len(training) == len(validation) == 24841
    assert training.dt == pytest.approx(1e-3, rel=1e-4)
    assert training.loop == emps.ServoLoop(pytest.approx(35.1507, rel=1e-5), 160.18, 243.45)
    assert not training.pulses.any() and set(np.unique(validation.pulses)) == {0.0, 5.0}
    with pytest.raises(DataError, match="SHA256"):
        emps.load_emps(TRAINING, "0" * 64)
    with pytest.raises(DataError, match="file not found"):
        emps.load_emps(tmp_path / "none.mat")


def test_controller_law_matches_the_recorded_voltage(training, validation) -> None:
    """vir = kv (kp (qg - qm) - (qm_k - qm_k-2) / 2 dt) + pulses: 0.3 % residual, gains 1."""
    for rec in (training, validation):
        check = emps.check_controller(rec)
        assert check.rel_residual < 0.004
        assert check.gains_scale == pytest.approx((1.0, 1.0), abs=1e-3)
        assert check.rel_residual_one_step > 5 * check.rel_residual  # a one-step velocity is not it
    assert emps.check_controller(validation).pulse_gain == pytest.approx(1.014, abs=0.003)
    assert np.isnan(emps.check_controller(training).pulse_gain)


def test_closed_loop_reproduces_qm_where_open_loop_drifts(training) -> None:
    """Published parameters on 8 s: closed loop within 3 um RMS; open loop off by millimetres."""
    rec = sliced(training, 8.0)
    p = emps.closed_loop_problem(rec, MODEL)
    q = p.predict(published_theta(p))[0]
    rms_closed = np.sqrt(np.mean((q - rec.qm) ** 2))
    assert rms_closed < 3e-6
    lay = p.structure.layout
    open_loop = simulate(lay, p.layout_params(published_theta(p)), rec.force, rec.dt,
                         force_input=True).rel_disp[0] + rec.qm[0]
    assert np.sqrt(np.mean((open_loop - rec.qm) ** 2)) > 100 * rms_closed


def test_one_substep_is_converged(training) -> None:
    rec = sliced(training, 5.0)
    p = emps.closed_loop_problem(rec, MODEL)
    args = (p.structure.layout, p.layout_params(published_theta(p)), rec.qg,
            np.zeros(len(rec)), rec.loop, rec.dt, rec.qm[0])
    one = emps.simulate_closed_loop(*args, n_substeps=1).rel_disp[0]
    fine = emps.simulate_closed_loop(*args, n_substeps=16).rel_disp[0]
    assert np.max(np.abs(one - fine)) < 1e-8  # m (3 nm found), against a ~1.7e-6 m residual


def test_pulses_enter_the_validation_loop(validation) -> None:
    rec = sliced(validation, 6.0)
    with_pulses = emps.closed_loop_problem(rec, MODEL)
    without = emps.closed_loop_problem(rec, MODEL, disturbance=np.zeros(len(rec)))
    th = published_theta(with_pulses)
    err = [np.sqrt(np.mean((p.predict(th)[0] - rec.qm) ** 2)) for p in (with_pulses, without)]
    assert err[0] < 4e-6 < 10 * err[0] < err[1]


def test_map_fit_finds_the_published_friction(training) -> None:
    """The MAP that starts the study's TMCMC (``fit_map`` on the closed loop): its residuals
    are the likelihood's (same sums of squares), and on 8 s it lands within 10 % of the
    published Fc and Fv (20.4 N, 203.5 N s/m), from broad priors centred away from them."""
    from harvester.inference.map_fit import fit_map
    rec = sliced(training, 8.0)
    p = emps.closed_loop_problem(rec, MODEL)
    th = published_theta(p)
    sse, ok = p.residual_sums(th)
    assert ok[0] and np.isclose(np.sum(p.residuals(th) ** 2), sse[0], rtol=1e-9)
    priors = broad_priors()
    fit = dict(zip(p.parameter_names, fit_map(p, priors, seed=0).theta))
    assert abs(fit["F_coulomb"] / emps.PUBLISHED["Fc"] - 1.0) < 0.1
    assert abs(fit["c_m"] / emps.PUBLISHED["Fv"] - 1.0) < 0.1


def test_likelihood_prefers_coulomb_friction(training) -> None:
    rec = sliced(training, 8.0)
    p = emps.closed_loop_problem(rec, MODEL)
    th = published_theta(p)
    no_friction = th.copy()
    no_friction[0, p.parameter_names.index("F_coulomb")] = 0.0
    ll = p.loglike(np.vstack([th, no_friction]))
    assert ll[0] > ll[1] + 100
    assert p.n_data == len(range(0, len(rec), 10))


def test_idim_ls_reproduces_the_published_values(training) -> None:
    fit = emps.idim_ls(training)
    for name, value in emps.PUBLISHED.items():
        assert fit.values[name] == pytest.approx(value, rel=0.01), name


def test_instrumented_frf_gives_the_mass(training) -> None:
    fit = fit_linear_frf(emps.to_recording(training), emps.KNOWN, (0.5, 20.0), reference="qg")
    assert fit.values["k"] == 0.0 and fit.fitted == ("M", "c_m")
    assert fit.values["M"] == pytest.approx(emps.PUBLISHED["M"], rel=0.1)


def test_model_names() -> None:
    assert emps.emps_model_name(MODEL) == "viscous+coulomb_friction"
    assert emps.model_terms("viscous") == emps.BASELINE_TERMS
    assert emps.model_terms("viscous+coulomb_friction") == MODEL
    with pytest.raises(KeyError):
        emps.model_terms("viscous+nonsense")


def fake_idata(values: dict[str, np.ndarray], log_evidence: list[float]) -> az.InferenceData:
    post = xr.Dataset({k: (("chain", "draw"), v) for k, v in values.items()})
    stats = xr.Dataset({"log_evidence": (("chain",), np.array(log_evidence))})
    return az.InferenceData(posterior=post, sample_stats=stats)


def test_parameter_and_evidence_tables() -> None:
    rng = np.random.default_rng(0)
    draws = {our: emps.PUBLISHED[name] + 0.01 * rng.standard_normal((2, 50))
             for name, our in emps.PARAMETERS.items()}
    idata = fake_idata(draws, [10.0, 10.2])
    table = emps.parameters_table(idata)
    assert list(table.columns) == ["parameter", "mean", "sd", "q2.5", "q97.5", "sd_adj",
                                   "q2.5_adj", "q97.5_adj", "published"]
    assert list(table["parameter"]) == ["M", "Fv", "Fc", "offset"]
    assert table["sd_adj"].isna().all()  # no adjustment stored with these draws
    comparison = emps.comparison_table(table, emps.PUBLISHED)
    assert comparison["within_tolerance"].all() and (comparison["idim_ls_error_pct"] == 0).all()
    runs = {"viscous": fake_idata({"M": draws["M"]}, [5.0, 5.0]),
            "viscous+coulomb_friction": idata,
            "viscous+quadratic_damping": fake_idata({"M": draws["M"]}, [7.0, 7.0])}
    ev, named = emps.evidence_table(runs)
    assert named == "coulomb_friction"
    assert list(ev["model"]) == ["viscous+coulomb_friction", "viscous+quadratic_damping",
                                 "viscous"]
    assert ev.loc[ev["model"] == "viscous", "log_evidence_gain"].item() == 0.0


def test_the_diagnosis_summary_page_of_the_emps_study(tmp_path) -> None:
    """``summary_doc``: the named term with its level beside the published one, every
    candidate but the baseline (read back from CSV, its empty term as NaN), both models on
    the unseen record; the page every diagnosis has renders it, figures with their lines."""
    from harvester.diagnosis.report.summary_page import summary_page
    evidence = pd.DataFrame({
        "model": ["viscous+coulomb_friction", "viscous+tanh_friction", "viscous"],
        "added_term": ["coulomb_friction", "tanh_friction", np.nan], "n_parameters": [4, 5, 3],
        "log_evidence": [1840.0, 1839.5, 1630.0], "sd_over_chains": [0.1, 0.02, 0.02],
        "log_evidence_gain": [210.0, 209.5, 0.0], "tied_with_best": [True, True, False]})
    comparison = pd.DataFrame({"parameter": ["Fc"], "mean": [20.38], "q2.5": [19.48],
                               "q97.5": [21.27], "published": [20.39]})
    validation = pd.DataFrame({"model": ["viscous", "viscous+coulomb_friction"],
                               "record": ["validation"] * 2, "rms_position_um": [6.9, 1.98],
                               "nrmse_tracking": [0.0118, 0.0034]})
    doc = emps.summary_doc(comparison, evidence, {"named_term": "coulomb_friction"},
                           validation, "viscous", "viscous+coulomb_friction")
    assert doc["missing"] == ["coulomb_friction"]
    assert "F_c 20.38 N" in doc["headline"] and "published 20.39" in doc["headline"]
    assert "from 6.9 to 1.98 um RMS" in doc["headline"]
    assert [c["effect"] for c in doc["candidates"]] == ["coulomb_friction", "tanh_friction"]
    assert [c["accepted"] for c in doc["candidates"]] == [True, False]
    assert "tanh_friction" in doc["notes"][0]  # within a nat of the best
    assert doc["fit"]["improved"]["nrmse"] == 0.0034
    fig_dir = tmp_path / "figures"
    fig_dir.mkdir()
    import matplotlib.pyplot as plt
    plt.figure(figsize=(1, 1)).savefig(fig_dir / "evidence.png")
    plt.close("all")
    page = summary_page(doc, fig_dir, "EMPS")
    assert page.count("<figure>") == 1 and emps.results.SUMMARY_FIGURES["evidence.png"] in page
    assert "<td>nan</td>" not in page


@pytest.mark.slow
def test_tmcmc_on_a_slice_is_within_5_percent(training) -> None:
    """TMCMC, Coulomb model, first 12 s, 200 particles: every parameter within 5 % (~1 min)."""
    rec = sliced(training, 12.0)
    p = emps.closed_loop_problem(rec, MODEL)
    priors = {"M": PriorSpec("M", 90.0, 25.0, "kg"), "c_m": PriorSpec("c_m", 200.0, 100.0, ""),
              "F_coulomb": PriorSpec("F_coulomb", 10.0, 20.0, "N"),
              "F_offset": PriorSpec("F_offset", 0.0, 10.0, "N", -np.inf),
              "sigma": PriorSpec("sigma", 1e-5, 1e-5, "m")}
    idata = identify(p, priors, TMCMCSettings(particles=200, chains=1, seed=1,
                                              target_accept=0.25))
    table = emps.comparison_table(emps.parameters_table(idata), {})
    assert table["within_tolerance"].all(), table
    assert isinstance(table, pd.DataFrame)


def test_map_start_gives_the_evidence_of_the_prior_start(training) -> None:
    """TMCMC tempered from the MAP start (``TMCMCSettings.start = "map"``) estimates the same
    evidence and posterior as from the prior, on 4 s of the record, in fewer stages."""
    rec = sliced(training, 4.0)
    p = emps.closed_loop_problem(rec, MODEL)
    priors = broad_priors()
    runs = {start: identify(p, priors, TMCMCSettings(particles=150, chains=2, seed=3,
                                                     target_accept=0.25, start=start))
            for start in ("prior", "map")}
    ev = {k: v.sample_stats["log_evidence"].values for k, v in runs.items()}
    assert abs(ev["map"].mean() - ev["prior"].mean()) < 1.0 + np.ptp(ev["prior"])
    fc = {k: v.posterior["F_coulomb"].values.ravel() for k, v in runs.items()}
    assert abs(fc["map"].mean() - fc["prior"].mean()) < 2.0 * fc["prior"].std()
    stages = {k: int(v.sample_stats["n_stages"].values.sum()) for k, v in runs.items()}
    assert stages["map"] < stages["prior"]
    with pytest.raises(ValueError, match="start"):
        TMCMCSettings(start="posterior")
