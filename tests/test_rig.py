"""The virtual rig (harvester.synthetic.rig): excitation, stick-slip mechanics, rocking mode, static test."""

from __future__ import annotations

import copy
import dataclasses
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml
from scipy import integrate, signal

from harvester.data import daq

from harvester.synthetic import rig

CONFIG = yaml.safe_load((Path(__file__).parents[1] / "config" / "config.yaml").read_text())
RIG = CONFIG["rig"]
FS_OUT = float(RIG["daq"]["sampling_rate_hz"])
FS = FS_OUT * int(RIG["daq"]["oversample"])
DEV = rig.Device.from_config(RIG)


def band_mean(x: np.ndarray, lo: float, hi: float) -> float:
    """Mean Welch PSD of x ((m/s^2)^2/Hz) over [lo, hi) Hz at the DAQ rate."""
    f, p = signal.welch(x, fs=FS_OUT, nperseg=512)
    return float(p[(f >= lo) & (f < hi)].mean())


def measured_rel_acc(sim: rig.RecordSimulation) -> np.ndarray:
    frame = pd.DataFrame({"time": sim.time, "ai0": sim.ai0, "ai1": sim.ai1})
    meta = daq.record_metadata(RIG, sim.name, len(frame), sim.seed)
    return daq.to_accelerations(frame, meta)["rel_acc"].to_numpy()


def without_session(cfg: dict) -> dict:
    """The rig config with no record's session: every record runs the rig's own sections."""
    cfg = copy.deepcopy(cfg)
    for spec in cfg["records"].values():
        spec.pop("session", None)
    return cfg


#: The paper's training record as the rig's own sections run it (no session).
BASE = without_session(RIG)
SESSION = rig.session_rig(RIG, "training")


@pytest.fixture(scope="module")
def training() -> rig.RecordSimulation:
    return rig.simulate_record(RIG, "training")


@pytest.fixture(scope="module")
def training_base() -> rig.RecordSimulation:
    return rig.simulate_record(BASE, "training")


@pytest.fixture(scope="module")
def training_no_rocking() -> rig.RecordSimulation:
    cfg = copy.deepcopy(BASE)
    cfg["rocking"]["gain"] = 0.0
    return rig.simulate_record(cfg, "training")


def test_session_merges_over_the_rigs_sections_for_its_records_only() -> None:
    assert SESSION["excitation"]["peak_m_s2"] == RIG["paper_session"]["excitation"]["peak_m_s2"]
    assert SESSION["excitation"]["cutoff_hz"] == RIG["excitation"]["cutoff_hz"]
    assert SESSION["friction"]["F_c"] == RIG["friction"]["F_c"]
    assert rig.session_rig(BASE, "training")["excitation"] == RIG["excitation"]
    assert RIG["excitation"]["peak_m_s2"] == 4.0  # the loaded records and scenarios keep theirs
    assert rig.ground_truth(RIG, "training")["F_s0"] == SESSION["friction"]["F_s0"]


def test_session_without_it_the_records_are_the_rigs_own(training_base) -> None:
    assert np.abs(training_base.truth["base_acc"]).max() == pytest.approx(4.0, rel=0.05)


def test_ground_truth_is_the_config() -> None:
    truth = rig.ground_truth(RIG)
    for key in ("M", "m", "k", "c_m"):
        assert truth[key] == RIG[key]
    for key in ("F_c", "beta", "F_s", "v_stick"):
        assert truth[key] == RIG["friction"][key]
    assert truth["F_s0"] == RIG["friction"]["F_s0"] and truth["dwell_s"] == RIG["friction"]["dwell_s"]
    assert truth["v_floor"] == 0.0  # no sliding floor: the shaker records follow the tanh law


def test_excitation_peak_and_band() -> None:
    exc = RIG["excitation"]
    y = rig.base_excitation(int(10 * FS), FS, exc["cutoff_hz"], exc["order"], exc["peak_m_s2"],
                            np.random.default_rng(0))
    assert np.abs(y).max() == pytest.approx(exc["peak_m_s2"], rel=1e-12)
    f, p = signal.welch(y, fs=FS, nperseg=8192)
    assert p[f <= 15.0].sum() / p.sum() > 0.85
    assert p[f <= 30.0].sum() / p.sum() > 0.999


def test_record_peak_base_acceleration_is_the_sessions(training) -> None:
    peak = SESSION["excitation"]["peak_m_s2"]
    assert np.abs(training.truth["base_acc"]).max() == pytest.approx(peak, rel=0.05)


def test_record_starts_from_rest(training) -> None:
    assert training.truth["stuck"][0]
    assert training.truth["z"][0] == 0.0 and training.truth["v"][0] == 0.0


def test_millisecond_reversals_build_no_stiction(training_base) -> None:
    """Static friction needs dwell time: with no static friction at zero dwell the shaker
    record hardly sticks after it starts."""
    stuck = training_base.truth["stuck"]
    assert stuck[int(0.5 * FS / RIG["daq"]["oversample"]):].mean() < 0.01


def test_paper_session_sticks_at_a_few_reversals(training) -> None:
    """The paper's session: F_s0 > 0 holds the mass at some reversals, briefly (Figure 7)."""
    stuck = training.truth["stuck"][int(1.0 * FS_OUT):]
    assert 0.01 < stuck.mean() < 0.06
    edge = np.diff(np.r_[0, stuck.astype(int), 0])
    runs = np.flatnonzero(edge == -1) - np.flatnonzero(edge == 1)
    assert runs.size >= 10 and runs.max() / FS_OUT < 0.1


def test_stiction_at_zero_dwell_makes_the_mass_stick() -> None:
    dev = dataclasses.replace(DEV, F_s0=6.0)
    y = rig.base_excitation(int(4 * FS), FS, 15.0, 4, 4.0, np.random.default_rng(3))
    stuck = rig.simulate_motion(y, FS, dev).stuck
    assert 0.05 < stuck.mean() < 0.95


def test_stuck_mass_has_zero_relative_acceleration() -> None:
    dev = dataclasses.replace(DEV, F_s0=6.0)
    y = rig.base_excitation(int(2 * FS), FS, 15.0, 4, 4.0, np.random.default_rng(3))
    motion = rig.simulate_motion(y, FS, dev)
    assert motion.stuck.any()
    assert np.all(np.abs(motion.acc[motion.stuck]) <= dev.v_stick * FS)  # at most the capture
    held = motion.friction[motion.stuck]
    assert np.all(np.abs(held) <= DEV.F_s + 1e-9)


def test_rocking_bump_30_80_hz(training_base, training_no_rocking) -> None:
    rel = measured_rel_acc(training_base)
    assert band_mean(rel, 30, 80) > 5.0 * band_mean(rel, 90, 120)
    # the bump is the rocking mode: it raises 40-60 Hz well above the same rig without it
    assert band_mean(rel, 40, 60) > 2.0 * band_mean(measured_rel_acc(training_no_rocking), 40, 60)


def test_rocking_rms_is_a_modest_share(training) -> None:
    share = training.truth["rocking"].std() / training.truth["rel_acc"].std()
    assert 0.10 <= share <= 0.30


def test_measured_rel_acc_is_truth_plus_rocking_plus_noise(training) -> None:
    err = measured_rel_acc(training) - training.truth["rel_acc"] - training.truth["rocking"]
    noise = SESSION["sensors"]["noise_m_s2"]
    extra = SESSION["sensors"]["mass_extra_noise_m_s2"]
    assert err.std() == pytest.approx(np.sqrt(2.0 * noise ** 2 + extra ** 2), rel=0.1)


def test_without_stiction_matches_solve_ivp_of_eq1() -> None:
    dev = dataclasses.replace(DEV, F_s=0.0, F_s0=0.0)
    n = int(1.0 * FS)
    y = rig.base_excitation(n, FS, 15.0, 4, 4.0, np.random.default_rng(1))
    t = np.arange(n) / FS

    def rhs(tt: float, s: np.ndarray) -> list[float]:
        z, v = s
        f = dev.F_c * np.tanh(dev.beta * v)
        return [v, (-dev.m * np.interp(tt, t, y) - dev.c_m * v - dev.k * z - f) / dev.M]

    sol = integrate.solve_ivp(rhs, (0.0, t[-1]), [0.0, 0.0], t_eval=t, method="DOP853",
                              rtol=1e-10, atol=1e-12, max_step=1.0 / FS)
    z, v = sol.y
    acc = (-dev.m * y - dev.c_m * v - dev.k * z - dev.F_c * np.tanh(dev.beta * v)) / dev.M
    motion = rig.simulate_motion(y, FS, dev)
    assert not motion.stuck.any()
    assert np.abs(motion.z - z).max() < 1e-8
    assert np.abs(motion.acc - acc).max() < 1e-5 * np.abs(acc).max()


def test_held_mass_stays_inside_the_stiction_band_only_after_a_hold() -> None:
    edge = DEV.F_s / DEV.k
    hold = RIG["static_test"]["hold_s"]
    for sign in (1.0, -1.0):
        assert rig.held_after_release(DEV, sign * (edge - 5e-4), hold, FS)
        assert not rig.held_after_release(DEV, sign * (edge + 5e-4), hold, FS)
        # static friction grows with the dwell: let go at once, the mass slides
        assert not rig.held_after_release(DEV, sign * 0.5 * edge, 0.0, FS)


def test_static_test_recovers_F_s() -> None:
    table = rig.static_friction_test(RIG)
    assert len(table) == 2 * RIG["static_test"]["repeats"]
    x1 = table.loc[table.direction == "down", "position_m"].to_numpy()
    x2 = table.loc[table.direction == "up", "position_m"].to_numpy()
    force = DEV.k * (x1 - x2) / 2.0  # our sign convention: x1 - x2 > 0, positions down-positive
    # the search keeps the last position that held: k step / 2 low on average
    bias = DEV.k * RIG["static_test"]["step_m"] / 2.0
    se = force.std(ddof=1) / np.sqrt(force.size)
    assert abs(force.mean() + bias - DEV.F_s) < 2.5 * se
    # the paper's spread x2 - x1 = 0.067 m at k = 250 N/m is 2 F_s / k here
    assert np.mean(x1 - x2) == pytest.approx(2.0 * DEV.F_s / DEV.k, abs=0.003)


def test_quantised_voltages_on_adc_codes(training) -> None:
    lo, hi = RIG["daq"]["range_V"]
    codes = (training.ai0 - lo) / ((hi - lo) / 2 ** RIG["daq"]["bits"])
    assert np.allclose(codes, np.round(codes), atol=1e-9)


def test_record_regenerates_bit_for_bit() -> None:
    a = rig.simulate_record(RIG, "training", duration_s=1.0)
    b = rig.simulate_record(RIG, "training", duration_s=1.0)
    c = rig.simulate_record(RIG, "validation", duration_s=1.0)
    assert a.ai0.tobytes() == b.ai0.tobytes() and a.ai1.tobytes() == b.ai1.tobytes()
    assert a.ai0.tobytes() != c.ai0.tobytes()
    assert a.seed == RIG["seed"] + RIG["records"]["training"]["seed_offset"]
