"""Every kind of recording through the diagnosis (issue 41): the kind objects of
``harvester.data.kinds``, a base displacement differentiated for the model, the checks that
rest on linear theory on a visibly nonlinear recording, and the public recordings' readers.

Fast: the diagnosis runs as ``quick_detect`` (MAP and Laplace, seconds); the real frame
recordings are the bundled copies in data/public (skipped where absent).
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from harvester.data import checks
from harvester.data.errors import DataError
from harvester.data.kinds import (INPUTS, OUTPUTS, derivative, drift, input_kind,
                                  model_recording, output_kind, paper_case)
from harvester.data.recording import RecordingKinds
from harvester.diagnosis import DiagnosisSettings
from harvester.diagnosis.run import quick_detect
from harvester.synthetic.measured import TABLE1_KNOWN

from test_input_checks import displacement_recording

FS = 250.0
SHARED = Path(__file__).resolve().parents[1] / "data" / "public"  # bundled copies
FRAME = SHARED / "marino-frame"
SILVERBOX = SHARED / "silverbox" / "Schroeder80mV.mat"


def _sines(n: int = 2500):
    t = np.arange(n) / FS
    w = 2 * np.pi * np.array([1.1, 4.7])[:, None]
    amp = np.array([2e-3, 5e-4])[:, None]
    y = np.sum(amp * np.sin(w * t + 0.3), axis=0)
    return t, y, np.sum(amp * w * np.cos(w * t + 0.3), axis=0), \
        -np.sum(amp * w**2 * np.sin(w * t + 0.3), axis=0)


def test_derivatives_of_a_displacement_are_exact_in_the_band() -> None:
    t, y, v, a = _sines()
    y = y + 1e-4 * t  # a straight drift has no acceleration
    inner = slice(250, -250)
    acc = derivative(y, 1 / FS, 2, 20.0)
    vel = derivative(y, 1 / FS, 1, 20.0)
    assert np.max(np.abs(acc - a)[inner]) < 1e-8 * np.std(a)
    assert np.max(np.abs(vel - v - 1e-4)[inner]) < 1e-8 * np.std(v)
    # the edges (inside the lead-in and the last 0.5 s the diagnosis leaves out): within
    # 1e-3 from 0.25 s of them (the end points themselves: half the RMS)
    assert np.max(np.abs(acc - a)[62:-62]) < 1e-3 * np.std(a)


def test_one_object_per_kind() -> None:
    assert set(INPUTS) == {"base_acc", "force", "base_disp"}
    assert set(OUTPUTS) == {"rel_acc", "rel_disp"}
    assert input_kind("base_disp").model == "base_acc"
    assert input_kind("force").force_input and not input_kind("base_acc").force_input
    assert input_kind("base_acc").drive_gain({"m": 8.0}) == 8.0
    assert input_kind("force").drive_gain({}) == -1.0

    class Sim:
        rel_acc, rel_disp = np.ones(3), np.zeros(3)
    assert output_kind("rel_acc").simulated(Sim) is Sim.rel_acc
    assert output_kind("rel_disp").simulated(Sim) is Sim.rel_disp
    with pytest.raises(KeyError, match="known: base_acc, force, base_disp"):
        input_kind("base_vel")


def test_the_power_balance_does_not_depend_on_the_input_kind() -> None:
    """A force F = -m y'' drives eq. (1) as the base acceleration y'' does: the same
    dissipated force from either."""
    rng = np.random.default_rng(0)
    u, v = rng.standard_normal(500), rng.standard_normal(500)
    v = v - 0.3 * u
    base = input_kind("base_acc").dissipative_force(u, v, {"m": 8.0})
    force = input_kind("force").dissipative_force(-8.0 * u, v, {})
    assert base == pytest.approx(force) and base > 0


def test_a_base_displacement_becomes_the_model_input_and_the_raw_stays() -> None:
    t, y, _, a = _sines()
    raw = pd.DataFrame({"time": t, "base_disp": y, "rel_disp": 0.1 * y})
    kept = raw.copy()
    out, notes = model_recording(raw, 20.0, "rec.csv")
    assert list(out.columns) == ["time", "base_acc", "rel_disp"]
    assert np.max(np.abs(out.base_acc - a)[250:-250]) < 1e-8 * np.std(a)
    assert "second derivative of base_disp" in notes[0] and "20 Hz" in notes[0]
    pd.testing.assert_frame_equal(raw, kept)  # raw data never modified
    same, none = model_recording(out, 20.0)
    assert same is out and none == []
    pc, known = paper_case(raw.rename(columns={"base_disp": "force"}), {"M": 3.0}, 20.0)
    assert known["m"] == 1.0 and np.allclose(pc.base_acc, -y)


def test_a_drifting_base_sensor_is_a_warning_with_its_evidence() -> None:
    t, y, _, _ = _sines()
    d = drift(y + 5e-3 * t / t[-1], 1 / FS)
    assert d.drifting and d.drift == pytest.approx(5e-3, rel=0.2)
    df = pd.DataFrame({"time": t, "base_disp": y + 5e-3 * t / t[-1], "rel_disp": 0.1 * y})
    found = checks.drifting_base(df, RecordingKinds("base_disp", "rel_disp"), 1 / FS, "r.csv")
    assert len(found) == 1 and "drifts by" in found[0].message
    assert not checks.drifting_base(df.assign(base_disp=y), RecordingKinds("base_disp",
                                                                           "rel_disp"),
                                    1 / FS, "r.csv")


def test_the_diagnosis_names_friction_from_displacements() -> None:
    """base_disp -> rel_disp of the tanh device: a linear baseline misses friction, the tanh
    baseline misses nothing (quick_detect)."""
    rec = displacement_recording()
    settings = DiagnosisSettings.fast(lowpass_hz=None)
    det, state = quick_detect(rec, "linear", dict(TABLE1_KNOWN), settings=settings)
    assert (state.problem.input_kind, state.problem.output_kind) == ("base_acc", "rel_disp")
    best = max(det.candidates, key=lambda c: c.statistic)
    assert det.p_value < 1e-3 and best.effect == "tanh_friction"
    det, _ = quick_detect(rec, "tanh", dict(TABLE1_KNOWN), settings=settings)
    assert det.p_value > 0.05


@pytest.mark.skipif(not FRAME.is_dir(), reason="no data/public/marino-frame")
def test_the_frame_recordings_read_and_their_linear_frf_is_a_warning() -> None:
    from harvester.data.public import FRAME_LOWPASS_HZ, marino_frame
    from harvester.initial.frf import fit_linear_frf
    for load in (250, 450):
        rec = marino_frame(FRAME, load)
        assert list(rec.data.columns) == ["time", "base_disp", "rel_disp"]
        assert rec.sidecar == {"M": 3.0799, "m": 3.0799, "k": 1191.0,
                               "filtered_at_hz": FRAME_LOWPASS_HZ}
        assert 5e-4 < rec.data.rel_disp.std() < 1e-3  # m, not mm
        df, _ = model_recording(rec.data, FRAME_LOWPASS_HZ)
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # no numpy division warnings
            fit = fit_linear_frf(df, {"m": 3.0799}, (0.3, 0.8 * FRAME_LOWPASS_HZ),
                                 source=f"{load} g")
        assert "visibly nonlinear" in fit.notes[0] and "nepers RMS" in fit.notes[0]
        assert "which no linear device gives" in fit.notes[0]


def test_a_linear_recording_with_an_impossible_mass_ratio_is_still_an_error() -> None:
    from test_recording_kinds import TRUTH, synthetic
    from harvester.initial.frf import fit_linear_frf
    df = synthetic("base_acc", "rel_disp", n=1600, noise=0.0)
    with pytest.raises(DataError, match="m/M = .* > 1, impossible .* looks linear"):
        fit_linear_frf(df.assign(base_acc=df["base_acc"] / 9.80665), {"m": TRUTH["m"]},
                       (2.0, 40.0))


@pytest.mark.skipif(not FRAME.is_dir(), reason="no data/public/marino-frame")
def test_the_frame_with_its_friction_on_the_ground_is_a_force_input() -> None:
    """M x'' + C x' + K x + F_f(x') = K y + C y' as kinds.on_ground writes it: force K y
    (the C y' part left to c_m) -> rel_disp x = z + y, every friction term then acting on x',
    exactly the base form rewritten; it passes the checks (the lasers' common noise above
    10 Hz is filtered out)."""
    from harvester.data.public import FRAME_LOWPASS_HZ, marino_frame
    rec = marino_frame(FRAME, 450, friction_on="ground")
    base = marino_frame(FRAME, 450).data
    assert list(rec.data.columns) == ["time", "force", "rel_disp"]
    assert rec.sidecar == {"M": 3.0799, "k": 1191.0, "filtered_at_hz": FRAME_LOWPASS_HZ}
    assert 1.0 < rec.data.force.std() < 2.0  # N: K y with y about 1.3 mm RMS
    np.testing.assert_allclose(rec.data.force, 1191.0 * base.base_disp, rtol=0, atol=1e-12)
    x = base.rel_disp + base.base_disp
    np.testing.assert_allclose(rec.data.rel_disp, x - x.mean(), rtol=0, atol=1e-15)
    assert any("on_ground" in n for n in rec.notes) and not any("C y' part RMS" in n
                                                                for n in rec.notes)
    kinds = RecordingKinds("force", "rel_disp")
    assert checks.check_recording(rec.data, kinds, 0.004, "frame", rec.sidecar,
                                  lowpass_hz=rec.sidecar["filtered_at_hz"]) == []
    with pytest.raises(ValueError, match="'base' or 'ground'"):
        marino_frame(FRAME, 450, friction_on="storey")


def _check(rec, tmp_path, capsys, name: str) -> tuple[int, str]:
    """(exit status, what was said) of ``harvester check`` on ``rec`` written as name.csv
    with its sidecar: the reader and checks every command runs first."""
    from harvester.cli import main
    path = rec.write(tmp_path / f"{name}.csv")
    code = main(["check", str(path)])
    std = capsys.readouterr()
    return code, std.out + std.err


@pytest.mark.skipif(not FRAME.is_dir(), reason="no data/public/marino-frame")
@pytest.mark.parametrize("friction_on", ["base", "ground"])
def test_the_frame_in_other_units_is_named(tmp_path, capsys, friction_on) -> None:
    """The frame's recordings (both loads) as converted pass without a warning; a displacement
    in mm is refused with its column and speed (6.3-10.3 m/s RMS read as m), the ground
    form's force K y in kN (1.5 mN RMS) refused from its gain below resonance (about 1000
    times 1 / |k - M w^2|; as recorded 0.80-0.98 times it), in mN a warning."""
    from dataclasses import replace

    from harvester.data.public import marino_frame
    for load in (250, 450):
        rec = marino_frame(FRAME, load, friction_on=friction_on)
        code, said = _check(rec, tmp_path, capsys, f"{load}")
        assert code == 0 and "0 warning(s)" in said, said
        inp = rec.data.columns[1]
        for col in (inp, "rel_disp") if inp == "base_disp" else ("rel_disp",):
            bad = replace(rec, data=rec.data.assign(**{col: rec.data[col] * 1000.0}))
            code, said = _check(bad, tmp_path, capsys, f"{load}_{col}_mm")
            assert code == 2 and f"_mm.csv, column '{col}': {col} moves at" in said, said
            speed = float(said.split(" moves at ")[1].split(" m/s RMS")[0])
            assert 6.0 < speed < 11.0 and "probably mm" in said and f"{col} must be in m" in said
        if inp != "force":
            continue
        kn = replace(rec, data=rec.data.assign(force=rec.data.force / 1000.0))
        code, said = _check(kn, tmp_path, capsys, f"{load}_kN")
        assert code == 2 and "_kN.csv: below resonance (0.5-1 Hz" in said, said
        ratio = float(said.split("|rel_disp / force| is ")[1].split(", ")[1].split(" times")[0])
        assert 500 < ratio < 1500 and "factor 1000" in said and "force in kN" in said
        mn = replace(rec, data=rec.data.assign(force=rec.data.force * 1000.0))
        code, said = _check(mn, tmp_path, capsys, f"{load}_mN")
        assert code == 0 and "1 warning(s)" in said and "unit slip (force in mN)" in said


@pytest.mark.skipif(not FRAME.is_dir(), reason="no data/public/marino-frame")
def test_the_frame_with_a_drifting_base_laser_is_a_warning(tmp_path, capsys) -> None:
    """The frame's base laser drifts 0.27 times its oscillation as recorded (nothing said);
    with 2 mm added over the record, 1.8 times: a warning with the numbers."""
    from dataclasses import replace

    from harvester.data.public import marino_frame
    rec = marino_frame(FRAME, 450)
    d = drift(rec.data.base_disp, 0.004)
    assert 0.2 < d.share < 0.35 and not d.drifting
    t = rec.data.time
    ramp = replace(rec, data=rec.data.assign(base_disp=rec.data.base_disp + 0.002 * t / t.max()))
    code, said = _check(ramp, tmp_path, capsys, "drift")
    assert code == 0 and "1 warning(s)" in said, said
    assert "drift.csv, column 'base_disp': the base displacement drifts by 0.002345 m over 10 s"\
        in said and "1.8 times its RMS oscillation" in said and "drifting sensor" in said


@pytest.mark.skipif(not SILVERBOX.is_file(), reason="no data/public/silverbox")
def test_the_silverbox_reads_in_volts() -> None:
    """Read, and checked: its sidecar says volts and no low-pass (its roll-off is the
    excitation's band edge); its only warning is the displacement's speed read as m (it is
    in volts; M, m not known, so not refused)."""
    from harvester.data.public import silverbox
    rec = silverbox(SILVERBOX, samples=4096)
    assert list(rec.data.columns) == ["time", "force", "rel_disp"] and len(rec.data) == 4096
    assert rec.sidecar == {"units": {"force": "V", "displacement": "V"}, "filtered_at_hz": 0}
    assert "VOLTS" in rec.notes[0]
    assert 1.0 / np.mean(np.diff(rec.data.time)) == pytest.approx(610.35, abs=0.01)
    found = checks.check_recording(rec.data, RecordingKinds("force", "rel_disp"),
                                   1.0 / 610.3515625, "sb", rec.sidecar)
    assert [(w.check, w.column) for w in found] == [("unit", "rel_disp")]
    assert "24.6 m/s RMS" in found[0].message and "a circuit in volts" in found[0].message


def test_harvester_diagnose_takes_displacements_end_to_end(tmp_path, capsys) -> None:
    """The command on base_disp -> rel_disp (cheapest settings): diagnosis.json in the
    output's unit, the differentiation in its notes."""
    import json

    from harvester.cli import main
    from harvester.data.daq import write_recording
    rec = tmp_path / "rec.csv"
    write_recording(displacement_recording(), rec)
    (tmp_path / "rec.yaml").write_text("M: 12.8\nm: 8.0\nk: 250.0\n")
    out = tmp_path / "out"
    assert main(["diagnose", str(rec), "--baseline", "linear", "--out", str(out), "--fast",
                 "--particles", "40", "--chains", "1", "--no-figures", "--rounds", "1",
                 "--top", "1"]) == 0
    doc = json.loads((out / "diagnosis.json").read_text())
    assert any("second derivative of base_disp" in n for n in doc["notes"])
    assert "rel_disp, m" in doc["fit"]["likelihood"]
    assert doc["priors"]["sigma"]["unit"] == "m"


def test_unknown_masses_get_priors_from_the_recording() -> None:
    """A device known only through its recordings (issue 41 item 2): M, k not given are
    identified with the baseline, their priors from the recording's linear FRF fit; a base
    input with no scale at all is refused."""
    from test_recording_kinds import TRUTH, synthetic
    from harvester.initial.recording import diagnosis_priors
    df = synthetic("force", "rel_disp", n=1600, noise=0.01)
    specs, notes = diagnosis_priors(df, "linear", {})
    assert {"M", "k", "c_m"} <= set(specs) and "sigma" not in specs
    assert "M, k not given" in notes[0]
    for p in ("M", "k"):
        assert abs(specs[p].mean - TRUTH[p]) < 2 * specs[p].sd
    base = synthetic("base_acc", "rel_acc", n=1600)
    with pytest.raises(ValueError, match="only m/M"):
        diagnosis_priors(base, "linear", {})


def test_a_noisy_base_displacement_without_its_low_pass_is_a_warning() -> None:
    """Differentiating a laser's noise twice: most of base_acc's power near the DAQ's edge is
    reported with its share; with the recording's low-pass given, nothing is."""
    t, y, _, _ = _sines()
    noisy = y + 1e-5 * np.random.default_rng(1).standard_normal(y.size)  # 10 um
    df = pd.DataFrame({"time": t, "base_disp": noisy, "rel_disp": 0.1 * y})
    _, notes = model_recording(df, None, "laser.csv")
    assert len(notes) == 2 and "laser.csv: " in notes[1] and "lies above 25 Hz" in notes[1]
    assert "sensor's noise" in notes[1] and "filtered_at_hz" in notes[1]
    assert len(model_recording(df, 20.0)[1]) == 1
    assert len(model_recording(df.assign(base_disp=y), None)[1]) == 1


def test_friction_on_the_ground_from_the_sidecar(tmp_path) -> None:
    """The sidecar's friction_on: ground rewrites base_disp -> rel_disp in absolute
    coordinates (force k y, output x = z + y); a bad value is refused."""
    from harvester.data.kinds import on_ground
    from harvester.data.sidecar import read_sidecar
    t, y, _, _ = _sines()
    df = pd.DataFrame({"time": t, "base_disp": y, "rel_disp": -0.5 * y})
    out, known, notes = on_ground(df, {"M": 3.0, "m": 3.0, "k": 1000.0}, "rec.csv")
    assert list(out.columns) == ["time", "force", "rel_disp"] and "m" not in known
    assert np.allclose(out.force, 1000.0 * (y - y.mean()))
    assert np.allclose(out.rel_disp, 0.5 * y - np.mean(0.5 * y))
    assert "friction on the ground" in notes[0]
    with pytest.raises(DataError, match="needs k known"):
        on_ground(df, {"M": 3.0})
    (tmp_path / "r.yaml").write_text("k: 1000\nfriction_on: ground\n")
    assert read_sidecar(tmp_path / "r.csv").friction_on == "ground"
    (tmp_path / "r.yaml").write_text("k: 1000\nfriction_on: storey\n")
    with pytest.raises(DataError, match="line 2.*'friction_on' must be base or ground"):
        read_sidecar(tmp_path / "r.csv")


def test_friction_on_the_ground_with_a_force_input_is_the_recording_itself() -> None:
    """With a force input the base is fixed: the ground is the base, and the recording (any
    output) comes back unchanged, known and all (it was refused before: issue 63)."""
    from harvester.data.kinds import on_ground
    t, y, _, a = _sines()
    for out_kind, x in (("rel_acc", a), ("rel_disp", y)):
        df = pd.DataFrame({"time": t, "force": 40.0 * y, out_kind: x})
        out, known, notes = on_ground(df, {"M": 3.0, "m": 2.0, "k": 1000.0}, "rec.csv")
        pd.testing.assert_frame_equal(out, df)
        assert known == {"M": 3.0, "m": 2.0, "k": 1000.0} and "base is fixed" in notes[0]


def test_friction_on_the_ground_with_an_acceleration_output() -> None:
    """base_disp -> rel_acc: the same force k y as base_disp -> rel_disp, and the output
    x'' = z'' + y'' with y'' differentiated from the base's displacement (exact inside the
    record); a base acceleration is refused with what its double integral misses."""
    from harvester.data.kinds import on_ground
    t, y, _, a = _sines()
    known = {"M": 3.0, "m": 3.0, "k": 1000.0}
    ref, _, _ = on_ground(pd.DataFrame({"time": t, "base_disp": y, "rel_disp": -0.5 * y}),
                          known)
    out, k, notes = on_ground(pd.DataFrame({"time": t, "base_disp": y, "rel_acc": -0.5 * a}),
                              known, "rec.csv", lowpass_hz=20.0)
    assert list(out.columns) == ["time", "force", "rel_acc"] and "m" not in k
    assert np.allclose(out.force, ref.force) and "x'' = rel_acc + y''" in notes[0]
    inner = slice(250, -250)
    assert np.max(np.abs(out.rel_acc - 0.5 * a)[inner]) < 1e-6 * np.std(a)
    with pytest.raises(DataError, match="base_acc input needs the base's displacement"):
        on_ground(pd.DataFrame({"time": t, "base_acc": a, "rel_acc": -0.5 * a}), known)


def test_every_fitting_command_reads_a_ground_device_alike(tmp_path) -> None:
    """The command line's reader rewrites a friction_on: ground recording for identify,
    compare, predict and diagnose (not for check, which shows the file as it is)."""
    from harvester.cli import _read
    from harvester.data.daq import write_recording
    rec = tmp_path / "rec.csv"
    write_recording(displacement_recording(), rec)
    (tmp_path / "rec.yaml").write_text("M: 12.8\nm: 12.8\nk: 250.0\nfriction_on: ground\n")
    checked, kp = _read(rec, False, for_model=True)
    assert (checked.kinds.input_kind, checked.kinds.output_kind) == ("force", "rel_disp")
    assert "m" not in kp.values and kp.values["k"] == 250.0
    checked, kp = _read(rec, False)
    assert checked.kinds.input_kind == "base_disp" and kp.values["m"] == 12.8
