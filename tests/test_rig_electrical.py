"""The virtual rig's electrical half (harvester.synthetic.electrical): generator, star load,
voltmeter, and the loaded raw records."""

from __future__ import annotations

import dataclasses
import hashlib
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from harvester.data import daq
from harvester.study.dataset import write_loaded_records
from harvester.synthetic import electrical as el
from harvester.synthetic import rig

ROOT = Path(__file__).parents[1]
CONFIG = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
RIG = CONFIG["rig"]
RAW = ROOT / CONFIG["data"]["raw_dir"]
DEV = rig.Device.from_config(RIG)
GEN = el.Generator.from_config(RIG)


def excitation(seconds: float, seed: int = 5) -> tuple[np.ndarray, float]:
    """The rig's shaker acceleration y'' on its internal grid, and that grid's rate (Hz)."""
    grid = rig.record_grid(RIG, seconds)
    return rig.shaker_acceleration(RIG, grid, np.random.default_rng(seed)), grid.fs


@pytest.fixture(scope="module")
def y_dd() -> tuple[np.ndarray, float]:
    return excitation(4.0)


# --------------------------------------------------------------------------- physics

@pytest.mark.parametrize("F_s0", [0.0, 3.0])  # 3 N: the stick-slip events are exercised
def test_open_circuit_is_the_rigs_mechanics_and_the_voltage_the_back_emf(y_dd, F_s0) -> None:
    y, fs = y_dd
    dev = dataclasses.replace(DEV, F_s0=F_s0)
    plain = rig.simulate_motion(y, fs, dev)
    open_ = el.simulate_loaded_motion(y, fs, dev, GEN, None, theta0=0.7)
    for name in ("z", "v", "acc", "friction", "stuck"):
        np.testing.assert_array_equal(getattr(open_, name), getattr(plain, name), err_msg=name)
    assert not open_.i_a.any() and not open_.i_b.any() and not open_.force.any()
    # e_a - e_b = sqrt(3) K_e omega sin(p theta + pi/6), theta = theta0 + 2 pi z / l
    theta = 0.7 + 2 * math.pi / GEN.lead_m * plain.z
    omega = 2 * math.pi / GEN.lead_m * plain.v
    expected = math.sqrt(3) * GEN.K_e * omega * np.sin(GEN.pole_pairs * theta + math.pi / 6)
    np.testing.assert_allclose(open_.voltage, expected, rtol=0, atol=1e-12)
    assert np.abs(open_.voltage).max() > 0.1  # the record has something to show


@pytest.mark.parametrize("load, F_s0", [(1.0, 0.0), (10.0, 0.0), (2.0, 3.0)])
def test_energy_balance_mechanical_power_into_the_generator(y_dd, load, F_s0) -> None:
    """int F_e z' dt = int (R_s + R_L) sum i_k^2 dt + [L_s / 2 sum i_k^2], over the record."""
    y, fs = y_dd
    m = el.simulate_loaded_motion(y, fs, dataclasses.replace(DEV, F_s0=F_s0), GEN, load,
                                  theta0=0.7)
    dt = 1.0 / fs
    into = np.trapezoid(m.force * m.v, dx=dt)
    copper = np.trapezoid((GEN.R_s + load) * m.current_squares, dx=dt)
    magnetic = 0.5 * GEN.L_s * (m.current_squares[-1] - m.current_squares[0])
    assert into > 1e-3  # joules: a real transfer, not a trivial balance
    assert abs(into - copper - magnetic) < 1e-6 * into
    np.testing.assert_allclose(m.i_a + m.i_b + m.i_c, 0.0, atol=1e-15)  # star, no neutral
    # the recorded v_ab is across two load resistors: R_L (i_a - i_b)
    np.testing.assert_allclose(m.voltage, load * (m.i_a - m.i_b), rtol=0, atol=1e-15)


def test_resistive_limit_is_viscous_damping_c_e(y_dd) -> None:
    """L_s -> 0: F_e -> c_e z', c_e = (3/2)(2 pi / l)^2 K_e^2 / (R_s + R_L), and the motion
    tends to the rig's with c_m + c_e; the gap closes in proportion to L_s."""
    y, fs = excitation(2.0)
    load = 2.0
    c_e = GEN.electrical_damping(load)
    assert c_e == pytest.approx(1.5 * (2 * math.pi / GEN.lead_m * GEN.K_e) ** 2
                                / (GEN.R_s + load), rel=1e-14)
    viscous = rig.simulate_motion(y, fs, dataclasses.replace(DEV, c_m=DEV.c_m + c_e))
    gaps = {}
    for L_s in (1e-4, 1e-5):
        m = el.simulate_loaded_motion(y, fs, DEV, dataclasses.replace(GEN, L_s=L_s), load)
        gaps[L_s] = (np.abs(m.z - viscous.z).max() / np.abs(viscous.z).max(),
                     np.abs(m.force - c_e * m.v).max() / np.abs(c_e * m.v).max())
    assert gaps[1e-5][0] < 1e-5 and gaps[1e-5][1] < 5e-4
    for i in (0, 1):
        assert 7.0 < gaps[1e-4][i] / gaps[1e-5][i] < 13.0  # first order in L_s


def test_integrator_converges_under_step_refinement(y_dd) -> None:
    """Fourth order: the drive is linear between samples, so a finer grid (linearly
    interpolated drive) integrates the same equations; errors against 16x finer."""
    y, fs = y_dd
    t = np.arange(y.size) / fs

    def run(q: int) -> el.LoadedMotion:
        tf = np.arange((y.size - 1) * q + 1) / (fs * q)
        return el.simulate_loaded_motion(np.interp(tf, t, y), fs * q, DEV, GEN, 1.0,
                                         theta0=0.7, nsub=1)

    ref = run(16)
    err = {q: np.abs(run(q).i_a - ref.i_a[:: 16 // q]).max() for q in (1, 2, 4)}
    assert err[1] < 1e-5 * np.abs(ref.i_a).max()
    assert err[1] / err[2] > 10.0 and err[2] / err[4] > 10.0  # ~16 for RK4


def test_substeps_keep_the_electrical_rate_resolved() -> None:
    dt = 1.0 / (float(RIG["daq"]["sampling_rate_hz"]) * int(RIG["daq"]["oversample"]))
    assert GEN.substeps(None, dt) == 1
    for load in (0.0, 1.0, 10.0, 100.0):
        h = dt / GEN.substeps(load, dt)
        assert (GEN.R_s + load) / GEN.L_s * h <= el.RATE_STEP
        assert GEN.pole_pairs * GEN.screw_ratio * el.V_BOUND * h <= el.RATE_STEP
    with pytest.raises(ValueError, match="load resistance"):
        el.simulate_loaded_motion(np.zeros(8), 4096.0, DEV, GEN, -1.0)


# --------------------------------------------------------------------------- the study's loads

def test_generator_matches_the_rig_and_damping_stays_below_c_m() -> None:
    truth = el.electrical_truth(RIG)
    # eq. (2): J (2 pi / l)^2 = M - m
    assert truth["J"] * (2 * math.pi / GEN.lead_m) ** 2 == pytest.approx(RIG["M"] - RIG["m"])
    loads = [el.load_of(RIG, r) for r in RIG["loaded_records"]]
    assert None in loads  # an open-circuit record
    finite = [x for x in loads if x is not None]
    matched = truth["matched_load_ohm"]
    assert min(finite) < matched["broadband"] < matched["harmonic"] < max(finite)
    for name, c_e in truth["c_e"].items():
        assert c_e < RIG["c_m"], name  # comparable, never dominant
    assert max(truth["c_e"].values()) > 0.5 * RIG["c_m"]


def test_loaded_record_voltage_channel_has_its_own_noise() -> None:
    """Converted load voltage = the true v_ab through the DAQ filter, plus the voltmeter's
    noise (noise_V RMS; quantisation adds LSB^2/12)."""
    sim = el.simulate_loaded_record(RIG, "loaded_1ohm", duration_s=4.0)
    volts = pd.DataFrame({"time": sim.time, "ai0": sim.ai0, "ai1": sim.ai1, "ai2": sim.ai2,
                          "ai3": sim.ai3})
    frame = daq.to_accelerations(
        volts, daq.loaded_record_metadata(RIG, sim.name, sim.time.size, sim.seed, sim.load_ohm))
    noise = frame["voltage"].to_numpy() - sim.truth["voltage"]
    sd = RIG["generator"]["voltage_sensor"]["noise_V"]
    assert 0.85 * sd < noise.std() < 1.15 * sd
    assert sim.truth["voltage"].std() > 10 * sd
    np.testing.assert_allclose(frame["rel_acc"], sim.truth["rel_acc"] + sim.truth["rocking"],
                               atol=0.3)  # the accelerometers as in the rig's records


# --------------------------------------------------------------------------- raw data

@pytest.fixture(scope="module")
def regenerated(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("loaded")
    write_loaded_records(RIG, out)
    return out


def test_loaded_raw_data_regenerate_bit_for_bit_and_verify(regenerated) -> None:
    committed = daq.read_checksums(RAW / "SHA256SUMS")
    names = [f"{r}.{ext}" for r in RIG["loaded_records"] for ext in ("csv", "json")]
    for name in names:
        digest = hashlib.sha256((regenerated / name).read_bytes()).hexdigest()
        assert committed.get(name) == digest, name
    checked = {p.name for p in daq.verify_checksums(RAW / "SHA256SUMS")}
    assert set(names) <= checked


@pytest.mark.parametrize("record", ["open_circuit", "loaded_2ohm"])
def test_loaded_raw_record_reads_and_converts_with_a_voltage_column(record) -> None:
    raw, meta = daq.read_raw_record(RAW / f"{record}.csv", RAW / f"{record}.json")
    assert list(raw.columns) == ["time", "ai0", "ai1", "ai2", "ai3"]
    assert meta["simulated"] is True and "ASSUMED" in meta["generator"]["constants"]
    assert meta["load"]["resistance_ohm"] == el.load_of(RIG, record)
    assert len(raw) == round(RIG["loaded_records"][record]["duration_s"] * 256)
    acc = daq.to_accelerations(raw, meta)
    assert list(acc.columns) == ["time", "base_acc", "mass_acc", "rel_acc", "voltage",
                                 "voltage_bc"]
    assert 0.01 < acc["voltage"].std() < RIG["generator"]["voltage_sensor"]["range_V"]
