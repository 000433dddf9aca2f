"""Recording kinds (harvester.data.recording): input base_acc | force, output rel_acc | rel_disp.

Columns declare the kinds, units are checked, and fitting works for every combination on
synthetic recordings with known truth (the model of ``harvester.model.simulate`` plus noise).
"""

from __future__ import annotations

import re

import numpy as np
import pandas as pd
import pytest
from scipy import signal

from harvester.data import daq
from harvester.data.errors import DataError
from harvester.initial.frf import fit_linear_frf, initial_priors
from harvester.inference.identify import TMCMCSettings, identify
from harvester.inference.problems import make_problem
from harvester.model.structures import Layout
from harvester.inference.priors import PriorSpec
from harvester.data.recording import G, RecordingKinds, check_plausible, recording_kinds
from harvester.model.simulate import simulate

FS = 200.0
COMBINATIONS = [("base_acc", "rel_acc"), ("base_acc", "rel_disp"), ("force", "rel_acc"),
                ("force", "rel_disp")]
#: Truth: a sprung mass with Coulomb friction (layout M, m, k, c_m, F_coulomb).
TRUTH = {"M": 10.0, "m": 8.0, "k": 2000.0, "c_m": 30.0, "F_coulomb": 4.0}


def excitation(n: int, seed: int) -> np.ndarray:
    """Band-limited (15 Hz) Gaussian noise, unit RMS."""
    rng = np.random.default_rng(seed)
    sos = signal.butter(4, 15.0, fs=FS, output="sos")
    x = signal.sosfilt(sos, rng.standard_normal(n + 200))[200:]
    return x / np.std(x)


def synthetic(input_kind: str, output_kind: str, n: int = 1600, seed: int = 1,
              noise: float = 0.02) -> pd.DataFrame:
    """A recording of the TRUTH model: input 3 m/s^2 or 60 N RMS; output noise = noise x RMS."""
    u = excitation(n, seed) * (60.0 if input_kind == "force" else 3.0)
    lay = Layout.of(["coulomb_friction"])
    p = np.array([TRUTH[name] for name in lay.parameter_names])
    sim = simulate(lay, p, u, 1.0 / FS, force_input=input_kind == "force")
    y = sim.rel_acc[0] if output_kind == "rel_acc" else sim.rel_disp[0]
    y = y + noise * np.std(y) * np.random.default_rng(seed + 1).standard_normal(n)
    return pd.DataFrame({"time": np.arange(n) / FS, input_kind: u, output_kind: y})


# --------------------------------------------------------------------------- columns and units


@pytest.mark.parametrize("inp, out", COMBINATIONS)
def test_kinds_from_columns_and_round_trip(tmp_path, inp, out) -> None:
    df = synthetic(inp, out, n=300)
    df["extra"] = 1.0
    assert recording_kinds(df) == RecordingKinds(inp, out)
    daq.write_recording(df, tmp_path / "r.csv")
    back = daq.read_recording(tmp_path / "r.csv")
    assert list(back.columns) == ["time", inp, out, "extra"]
    assert np.allclose(back[out], df[out], rtol=1e-8, atol=1e-15)


def test_missing_or_doubled_kind_is_reported_at_the_header() -> None:
    with pytest.raises(DataError, match="line 1, column 'base_acc': missing column.*input"):
        recording_kinds(["time", "rel_acc"], "r.csv")
    with pytest.raises(DataError, match="column 'rel_acc': missing column.*output"):
        recording_kinds(["time", "force"], "r.csv")
    with pytest.raises(DataError, match="2 input columns"):
        recording_kinds(["time", "base_acc", "force", "rel_acc"], "r.csv")
    with pytest.raises(DataError, match="2 output columns"):
        recording_kinds(["time", "force", "rel_acc", "rel_disp"], "r.csv")


@pytest.mark.parametrize("header, what", [("rel_disp_mm", "in mm"), ("base_acc [g]", "in g"),
                                          ("force_kN", "in kN"), ("rel_acc(mm/s^2)", "mm/s^2"),
                                          ("force_N", "call it 'force'")])
def test_unit_in_a_header_is_reported(tmp_path, header, what) -> None:
    t = np.arange(100) / FS
    other = "rel_acc" if header.startswith(("force", "base")) else "force"
    lines = [f"time,{header},{other}"] + [f"{x:.6f},0.1,0.2" for x in t]
    (tmp_path / "r.csv").write_text("\n".join(lines) + "\n")
    with pytest.raises(DataError, match=f"line 1, column '{re.escape(header)}'.*{re.escape(what)}"):
        daq.read_recording(tmp_path / "r.csv")


def test_displacement_in_mm_is_reported(tmp_path) -> None:
    df = synthetic("force", "rel_disp", n=400)
    df["rel_disp"] *= 1000.0 * 0.5 / df["rel_disp"].abs().max()  # peak 0.5 m, written in mm
    daq.write_recording(df, tmp_path / "r.csv")
    with pytest.raises(DataError, match="column 'rel_disp'.*probably mm"):
        daq.read_recording(tmp_path / "r.csv")
    df["rel_disp"] /= 1000.0
    daq.write_recording(df, tmp_path / "r.csv")
    assert len(daq.read_recording(tmp_path / "r.csv")) == 400


@pytest.mark.parametrize("level, unit", [(G, "in m/s\\^2"), (1.0, "in g")])
def test_gravity_left_in_is_reported(level, unit) -> None:
    df = synthetic("base_acc", "rel_acc", n=2000)  # 10 s
    df["base_acc"] = df["base_acc"] / (G if unit == "in g" else 1.0) + level
    with pytest.raises(DataError, match=f"column 'base_acc'.*gravity left in, {unit}"):
        check_plausible(df, recording_kinds(df))
    df["base_acc"] -= level  # removed: accepted, and so is a small bias
    check_plausible(df.assign(base_acc=df["base_acc"] + 0.05), recording_kinds(df))


def test_acceleration_in_g_against_a_known_mass_is_reported() -> None:
    """Force -> acceleration with z'' written in g: the FRF's mass is 9.81 x the known one."""
    df = synthetic("force", "rel_acc", n=1600, noise=0.0)
    band = (2.0, 40.0)
    fit = fit_linear_frf(df, {"M": TRUTH["M"]}, band)
    assert fit.values["M"] == pytest.approx(TRUTH["M"], rel=0.1)
    with pytest.raises(DataError, match="M = 9[0-9.]+, [0-9.]+ times the known 10: .* in g "
                                        "instead of m/s"):
        fit_linear_frf(df.assign(rel_acc=df["rel_acc"] / G), {"M": TRUTH["M"]}, band)


def test_base_input_in_g_gives_an_impossible_mass_ratio() -> None:
    df = synthetic("base_acc", "rel_acc", n=1600, noise=0.0)
    with pytest.raises(DataError, match="m/M = .* > 1, impossible"):
        fit_linear_frf(df.assign(base_acc=df["base_acc"] / G), {"m": TRUTH["m"]}, (2.0, 40.0))


# --------------------------------------------------------------------------- problems


@pytest.mark.parametrize("inp, out", COMBINATIONS)
def test_make_problem_picks_up_the_kinds(inp, out) -> None:
    df = synthetic(inp, out, n=400)
    known = {"m": TRUTH["m"]} if inp == "base_acc" else {}
    p = make_problem(df, "linear+coulomb_friction", known, oversample=1)  # as `synthetic` samples
    assert (p.input_kind, p.output_kind) == (inp, out)
    expected = ("M", "k", "c_m") if inp == "base_acc" else ("M", "k", "c_m")
    assert p.structure.free_base == expected
    theta = np.array([[TRUTH[n] for n in p.structure.free_parameters] + [0.01]])
    pred = p.predict(theta)[0]
    clean = synthetic(inp, out, n=400, noise=0.0)[out].to_numpy()
    assert np.max(np.abs(pred - clean)) < 1e-9 * np.max(np.abs(clean)) + 1e-12


@pytest.mark.parametrize("inp, out", COMBINATIONS)
def test_residuals_are_the_likelihoods(inp, out) -> None:
    """``Problem.residuals`` (what a MAP fit reads) square-sum to ``residual_sums`` (what
    eq. (10) reads), through the DAQ's oversampling and the recording's output filter."""
    df = synthetic(inp, out, n=400)
    known = {"m": TRUTH["m"]} if inp == "base_acc" else {}
    p = make_problem(df, "linear+coulomb_friction", known, output_filter=(40.0, 8))
    theta = np.array([[1.1 * TRUTH[n] for n in p.structure.free_parameters] + [0.01]])
    sse, ok = p.residual_sums(theta)
    assert ok[0] and np.isclose(np.sum(p.residuals(theta) ** 2), sse[0], rtol=1e-6)


def test_force_input_needs_no_m_and_base_input_needs_a_scale() -> None:
    p = make_problem(synthetic("force", "rel_disp", n=200), "linear", {"k": 0.0})
    assert p.structure.free_base == ("M", "c_m") and p.known["m"] == 0.0
    with pytest.raises(ValueError, match="only m/M"):
        make_problem(synthetic("base_acc", "rel_acc", n=200), "linear", {})


def test_paper_case_is_unchanged() -> None:
    known = {"M": 12.8, "m": 8.0, "k": 250.0}
    p = make_problem(synthetic("base_acc", "rel_acc", n=200), "tanh", known)
    assert p.structure.free_base == ("c_m",)
    assert p.parameter_names == ("c_m", "F_c", "beta", "sigma")
    assert p.base_acc is p.input and p.rel_acc is p.output


@pytest.mark.parametrize("inp, out", COMBINATIONS)
def test_frf_priors_cover_the_truth(inp, out) -> None:
    df = synthetic(inp, out)
    known = {"m": TRUTH["m"]} if inp == "base_acc" else {}
    p = make_problem(df, "linear+coulomb_friction", known)
    _, specs = initial_priors(df, known, p.structure.free_base, (1.0, 40.0))
    for name in p.structure.free_base:
        assert abs(specs[name].mean - TRUTH[name]) < 2.0 * specs[name].sd, (name, specs[name])
    assert specs["sigma"].unit == ("m" if out == "rel_disp" else "m/s^2")


@pytest.mark.parametrize("inp, out", [
    ("force", "rel_disp"),
    pytest.param("base_acc", "rel_disp", marks=pytest.mark.slow),
    pytest.param("force", "rel_acc", marks=pytest.mark.slow),
    pytest.param("base_acc", "rel_acc", marks=pytest.mark.slow)])
def test_identification_recovers_the_truth(inp, out) -> None:
    """TMCMC on 8 s at 200 Hz, every 2nd sample: M, k, c_m, F_coulomb within 10 % of the truth
    (about 20 s each; the paper's own combination and two more are marked slow)."""
    df = synthetic(inp, out)
    known = {"m": TRUTH["m"]} if inp == "base_acc" else {}
    p = make_problem(df, "linear+coulomb_friction", known, stride=2)
    _, specs = initial_priors(df, known, p.structure.free_base, (1.0, 40.0))
    specs["F_coulomb"] = PriorSpec("F_coulomb", 5.0, 5.0, "N")
    # at most 8 moves a stage: the means move by at most 0.3 % of the truth against 30 moves
    # (all four combinations), in two thirds of the time
    idata = identify(p, specs, TMCMCSettings(particles=200, chains=1, seed=3, mcmc_steps=2,
                                             max_mcmc_steps=8, target_accept=0.25))
    for name in p.structure.free_parameters:
        mean = float(idata.posterior[name].mean())
        assert mean == pytest.approx(TRUTH[name], rel=0.1), name
