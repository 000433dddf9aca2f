"""The electrical half's model and identification (harvester.electrical): the generator's
formulae against the virtual rig's truth generator, the records, priors and the likelihood."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
import yaml
from conftest import ROOT
from harvester.electrical import generator as gen
from harvester.electrical.identify import evidence_table, model_weights
from harvester.electrical.priors import MECHANICAL, generator_priors, mechanical_prior
from harvester.electrical.problem import ElectricalProblem, structure_parameters
from harvester.electrical.records import LoadedRecord, load_record, window_of
from harvester.synthetic import electrical as el

RIG = yaml.safe_load((ROOT / "config/config.yaml").read_text())["rig"]
GEN = el.Generator.from_config(RIG)
KNOWN = {"M": RIG["M"], "m": RIG["m"], "k": RIG["k"]}


@pytest.fixture(scope="module")
def loaded_1ohm():
    return el.simulate_loaded_record(RIG, "loaded_1ohm", duration_s=3.0)


def test_space_vector_magnitude_does_not_depend_on_the_rotor_angle():
    phase = np.linspace(0.0, 7.0, 50)
    v_ab, v_bc = 0.3 * np.sin(phase), 0.3 * np.sin(phase - 2 * np.pi / 3)
    np.testing.assert_allclose(gen.space_vector_magnitude(v_ab, v_bc), 0.3, rtol=1e-12)


def test_open_circuit_voltage_is_the_back_emf_and_no_force():
    v, a = np.array([[0.01, -0.02]]), np.zeros((1, 2))
    G = GEN.screw_ratio
    volts = gen.line_voltage_magnitude(v, a, 0.03, 1.0, 1e-3, 0.0, G)
    np.testing.assert_allclose(volts, math.sqrt(3) * 0.03 * G * np.abs(v))
    assert gen.electrical_damping(0.03, 1.0, 0.0, G) == 0.0
    assert np.all(gen.load_power(v, a, 0.03, 1.0, 1e-3, 0.0, G) == 0.0)


def test_damping_matches_the_rigs_and_power_is_the_load_share():
    for load in (1.0, 2.0, 10.0):
        g = gen.conductance(load)
        c_e = gen.electrical_damping(GEN.K_e, GEN.R_s, g, GEN.screw_ratio)
        assert c_e == pytest.approx(GEN.electrical_damping(load), rel=1e-12)
        v = np.array([[0.02]])
        p = gen.load_power(v, 0 * v, GEN.K_e, GEN.R_s, 0.0, g, GEN.screw_ratio)
        assert p[0, 0] == pytest.approx(c_e * 0.02 ** 2 * load / (load + GEN.R_s))
        volts = gen.line_voltage_magnitude(v, 0 * v, GEN.K_e, GEN.R_s, 0.0, g, GEN.screw_ratio)
        assert p[0, 0] == pytest.approx(volts[0, 0] ** 2 / (2 * load))


def test_first_order_model_reproduces_the_rigs_line_voltages(loaded_1ohm):
    """The rig integrates the full abc machine; the model's V from the rig's own z', z''
    matches its noise-free line voltages to well under the sensor noise, and the inductive
    lag is what closes most of the gap."""
    t = loaded_1ohm.truth
    true_mag = gen.space_vector_magnitude(t["voltage"], t["voltage_bc"])[256:]
    g, G = gen.conductance(1.0), GEN.screw_ratio
    err = {}
    for L in (0.0, GEN.L_s):
        model = gen.line_voltage_magnitude(t["v"], t["rel_acc"], GEN.K_e, GEN.R_s, L, g, G)
        err[L] = np.sqrt(np.mean((model[256:] - true_mag) ** 2))
    noise = RIG["generator"]["voltage_sensor"]["noise_V"]
    assert err[GEN.L_s] < 0.1 * noise
    assert err[0.0] > 5 * err[GEN.L_s]


def test_mechanical_equivalent_is_eq1_with_the_electrical_damping_and_mass():
    M, c = gen.mechanical_equivalent(12.8, 100.0, GEN.K_e, GEN.R_s, GEN.L_s, 0.5,
                                     GEN.screw_ratio)
    c_e = GEN.electrical_damping(2.0)
    assert c == pytest.approx(100.0 + c_e)
    assert M == pytest.approx(12.8 - c_e * GEN.L_s / 3.0)


def test_record_window_and_missing_second_voltage(tmp_path):
    assert window_of(2560, 256.0, 0.5, 1.5) == (128, 512)
    with pytest.raises(ValueError, match="lead-in"):
        window_of(100, 256.0, 1.0, None)
    csv = tmp_path / "r.csv"
    pd.DataFrame({"time": [0.0, 1.0], "base_acc": 0.0, "rel_acc": 0.0,
                  "voltage": 0.0}).to_csv(csv, index=False)
    meta = {"sampling_rate_hz": 1.0, "load": {"resistance_ohm": 2.0},
            "generator": {"lead_m": 0.02}}
    with pytest.raises(ValueError, match="voltage_bc"):
        load_record(csv, meta, 0.2, 2, 0.0, None)


def test_mechanical_prior_is_the_log_gaussian_of_the_samples():
    rng = np.random.default_rng(1)
    x = np.exp(np.log([110.0, 12.0, 90.0]) + 0.01 * rng.standard_normal((4000, 3)))
    prior = mechanical_prior(x, {"M": 12.8, "m": 8.0, "k": 250.0, "c_m": 1.0})
    assert prior.summary()["c_m"]["median"] == pytest.approx(110.0, rel=1e-3)
    assert prior.summary()["F_c"]["log_sd"] == pytest.approx(0.01, rel=0.05)
    assert set(prior.known) == {"M", "m", "k"}
    with pytest.raises(ValueError):
        mechanical_prior(-x, prior.known)
    assert set(generator_priors(True)) == {"K_e", "R_s", "L_s"}
    assert structure_parameters("resistive") == ("K_e", "R_s", "sigma_acc", "sigma_V")


def _record_from(sim) -> LoadedRecord:
    """A loaded record as the likelihood reads it, from a simulation's channels."""
    frame = pd.DataFrame({"time": sim.time, "ai0": sim.ai0, "ai1": sim.ai1, "ai2": sim.ai2,
                          "ai3": sim.ai3})
    from harvester.data import daq
    acc = daq.to_accelerations(frame, daq.loaded_record_metadata(
        RIG, sim.name, sim.time.size, sim.seed, sim.load_ohm))
    from harvester.data.signals import lowpass
    return LoadedRecord(sim.name, acc["base_acc"].to_numpy(),
                        lowpass(acc["rel_acc"].to_numpy(), 256.0, 20.0, 8),
                        gen.space_vector_magnitude(acc["voltage"], acc["voltage_bc"]),
                        sim.load_ohm, GEN.screw_ratio, 1 / 256.0, (128, 640))


def test_likelihood_peaks_near_the_truth(loaded_1ohm):
    truth = np.log([RIG["c_m"], RIG["friction"]["F_c"], RIG["friction"]["beta"]])
    prior = mechanical_prior(np.exp(truth + 0.01 * np.random.default_rng(0).standard_normal(
        (100, 3))), KNOWN)
    problem = ElectricalProblem([_record_from(loaded_1ohm)], "inductive", prior, (20.0, 8))
    base = [*truth, GEN.K_e, GEN.R_s, GEN.L_s, 0.03, 0.003]
    theta = np.tile(base, (4, 1))
    theta[1, 3] *= 1.02   # K_e
    theta[2, 4] *= 1.2    # R_s
    theta[3, 5] *= 3.0    # L_s
    ll = problem.loglike(theta)
    assert np.all(ll[1:] < ll[0] - 10.0), ll - ll[0]
    assert problem.parameter_names[:3] == tuple(f"ln_{n}" for n in MECHANICAL)


def test_the_record_past_the_filters_settling_is_not_simulated(loaded_1ohm, monkeypatch):
    """The likelihood stops the simulation settling_samples after its window (the rest of the
    record cannot change the filtered z'' there); it equals the whole record's."""
    import dataclasses

    import harvester.electrical.problem as ep

    truth = np.log([RIG["c_m"], RIG["friction"]["F_c"], RIG["friction"]["beta"]])
    prior = mechanical_prior(np.exp(truth + 0.01 * np.random.default_rng(1).standard_normal(
        (100, 3))), KNOWN)
    record = dataclasses.replace(_record_from(loaded_1ohm), window=(128, 300))
    problem = ElectricalProblem([record], "inductive", prior, (20.0, 8))
    theta = np.tile([*truth, GEN.K_e, GEN.R_s, GEN.L_s, 0.03, 0.003], (3, 1))
    theta[:, :3] += 0.02 * np.random.default_rng(2).standard_normal((3, 3))
    seen = []
    real = ep.simulate_loaded
    monkeypatch.setattr(ep, "simulate_loaded", lambda *a, **k: seen.append(a[5].size)
                        or real(*a, **k))
    settling = ep.settling_samples(ep.butterworth_sos(256.0, 20.0, 8))
    cut = problem.loglike(theta)
    monkeypatch.setattr(ep, "settling_samples", lambda sos: 10**9)
    whole = problem.loglike(theta)
    assert seen == [300 + settling, record.base_acc.size] and 300 + settling < seen[1]
    np.testing.assert_allclose(cut, whole, rtol=0, atol=1e-8)


def test_weights_and_evidence_table():
    w = model_weights({"resistive": 0.0, "inductive": np.log(3.0)})
    assert w["inductive"] == pytest.approx(0.75) and sum(w.values()) == pytest.approx(1.0)
    table = evidence_table([
        {"structure": "resistive", "log_evidence": 0.0, "log_evidence_se": 0.3,
         "log_evidence_chains": [0.0, 0.1], "wall_time_s": 1.0},
        {"structure": "inductive", "log_evidence": 5.0, "log_evidence_se": 0.2,
         "log_evidence_chains": [5.0, 5.1], "wall_time_s": 1.0}])
    assert list(table["structure"]) == ["inductive", "resistive"]
    assert table["log_bayes_factor_to_best"].tolist() == [0.0, -5.0]


def test_rig_records_two_line_voltages_whose_magnitude_is_the_current_s(loaded_1ohm):
    """ai3 holds v_bc; the magnitude of (v_ab, v_bc) is sqrt(3) R_L |i|, |i| the currents'
    space vector sqrt((2/3) sum_k i_k^2) (the truths: filtered voltages, sampled currents)."""
    assert loaded_1ohm.ai3 is not None and loaded_1ohm.ai3.shape == loaded_1ohm.ai2.shape
    t = loaded_1ohm.truth
    i_c = -t["i_a"] - t["i_b"]
    current = np.sqrt(2.0 / 3.0 * (t["i_a"] ** 2 + t["i_b"] ** 2 + i_c ** 2))
    volts = gen.space_vector_magnitude(t["voltage"], t["voltage_bc"])
    err = volts[256:] - math.sqrt(3.0) * 1.0 * current[256:]
    assert np.sqrt(np.mean(err ** 2)) < 0.02 * np.sqrt(np.mean(volts ** 2))


@pytest.mark.slow
def test_tmcmc_recovers_the_generator_and_prefers_the_inductance():
    """Both structures by TMCMC on short loaded records simulated by the rig: the inductive
    structure has the larger evidence and its intervals hold the rig's K_e, R_s, L_s."""
    from harvester.electrical.identify import (
        evidence_summary,
        identify,
        posterior_samples,
    )
    from harvester.inference.identify import TMCMCSettings

    records = [_record_from(el.simulate_loaded_record(RIG, name, duration_s=2.5))
               for name in ("open_circuit", "loaded_1ohm", "loaded_5ohm")]
    truth = np.log([RIG["c_m"], RIG["friction"]["F_c"], RIG["friction"]["beta"]])
    prior = mechanical_prior(np.exp(truth + 0.01 * np.random.default_rng(2).standard_normal(
        (400, 3))), KNOWN)
    settings = TMCMCSettings(particles=100, chains=1, seed=4, mcmc_steps=2, max_mcmc_steps=3,
                             target_accept=0.25)
    sigma = {"mean": 0.07, "sd": 0.03}
    fits = {s: identify(ElectricalProblem(records, s, prior, (20.0, 8)), sigma, settings)
            for s in ("resistive", "inductive")}
    z = {s: evidence_summary(f)["log_evidence"] for s, f in fits.items()}
    assert z["inductive"] > z["resistive"] + 5.0
    post = posterior_samples(fits["inductive"])
    for name, value in (("K_e", GEN.K_e), ("R_s", GEN.R_s), ("L_s", GEN.L_s)):
        lo, hi = np.quantile(post[name], [0.005, 0.995])
        assert lo <= value <= hi, (name, lo, hi)
