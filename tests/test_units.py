"""The units of a recording not in N and m (``harvester.data.units``): the sidecar's ``units``
key, the labels the diagnosis writes with them, and the Silverbox's sidecar in volts."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from harvester.data.errors import DataError
from harvester.data.sidecar import read_sidecar
from harvester.data.units import SI, Units, read_units

VOLTS = Units(force="V", displacement="V")
SILVERBOX = Path(__file__).resolve().parents[1] / "data" / "public" / "silverbox" / \
    "Schroeder80mV.mat"


def test_labels_in_si_and_in_volts() -> None:
    """SI: the library's units, mm for small displacements; volts: every N and m replaced, a
    mass in V s^2/V, no 1e3 factor."""
    si = {q: SI.label(q) for q in ("force", "displacement", "velocity", "stiffness",
                                   "damping", "mass")}
    assert si == {"force": "N", "displacement": "m", "velocity": "m/s", "stiffness": "N/m",
                  "damping": "N s/m", "mass": "kg"}
    assert [SI.label(u) for u in ("N/m^3", "N s^2/m^2", "s/m", "Hz", "-")] == \
        ["N/m^3", "N s^2/m^2", "s/m", "Hz", "-"]
    assert SI.small("displacement") == (1e3, "mm") and SI.small("velocity") == (1e3, "mm/s")
    volts = {q: VOLTS.label(q) for q in si}
    assert volts == {"force": "V", "displacement": "V", "velocity": "V/s", "stiffness": "V/V",
                     "damping": "V s/V", "mass": "V s^2/V"}
    assert [VOLTS.label(u) for u in ("N/m^3", "N s^2/m^2", "s/m", "Hz", "N/s")] == \
        ["V/V^3", "V s^2/V^2", "s/V", "Hz", "V/s"]
    assert VOLTS.small("displacement") == (1.0, "V") and VOLTS.small("velocity") == (1.0, "V/s")
    # a force in V on a displacement in m still shows mm
    assert Units(force="V").small("velocity") == (1e3, "mm/s")
    assert Units(force="V").label("stiffness") == "V/m"
    assert SI.si and not VOLTS.si and SI.to_sidecar() == {}
    assert VOLTS.to_sidecar() == {"force": "V", "displacement": "V"}


def _sidecar(tmp_path: Path, text: str) -> Path:
    (tmp_path / "rec.yaml").write_text(text)
    return tmp_path / "rec.csv"


def test_the_sidecar_reads_units_and_refuses_malformed_ones(tmp_path) -> None:
    """Absent: SI; given: read; a non-mapping, an unknown quantity or an empty unit: a
    DataError naming the file, the key and its line."""
    assert read_sidecar(_sidecar(tmp_path, "k: 1191\n")).units == SI
    got = read_sidecar(_sidecar(tmp_path, "k: 2.0\nunits: {force: V, displacement: V}\n"))
    assert got.units == VOLTS and got.summary()["units"] == {"force": "V",
                                                             "displacement": "V"}
    assert read_sidecar(_sidecar(tmp_path, "units: {force: mV}\n")).units == \
        Units(force="mV", displacement="m")
    bad = {"units: V\n": "'units' must map quantities to unit names",
           "M: 1\nunits: {force: V, temperature: K}\n": "unknown quantity(ies) ['temperature']",
           "units: {force: ''}\n": "'units.force' must be a unit name",
           "units: {displacement: 3}\n": "'units.displacement' must be a unit name"}
    for text, what in bad.items():
        with pytest.raises(DataError) as err:
            read_sidecar(_sidecar(tmp_path, text))
        line = text.count("\n", 0, text.index("units")) + 1
        assert f"rec.yaml, line {line}: " in str(err.value) and what in str(err.value)
    with pytest.raises(DataError, match="diagnosis settings: 'units' has unknown"):
        read_units("diagnosis settings", {"mass": "kg"})


def _latent(units: Units, n: int = 400) -> tuple:
    """A small latent force: Coulomb friction of 0.5 on a 1 Hz motion of 1e-3 (in the
    recording's units), the baseline's values SI-like; (LatentForce, force)."""
    from harvester.diagnosis.size.latent import LatentForce
    t = np.arange(n) * 0.01
    z = 1e-3 * np.sin(2 * np.pi * t)
    v = 2e-3 * np.pi * np.cos(2 * np.pi * t)
    a = -(2 * np.pi) ** 2 * z
    f = 0.5 * np.tanh(v / 1e-4)
    zeros = np.zeros(n)
    lf = LatentForce(t, f, np.full(n, 0.01), z, np.full(n, 1e-6), v, a, zeros, zeros,
                     "linear", {"M": 1.0, "m": 1.0, "k": 10.0, "c_m": 0.1}, "force", "rel_disp",
                     "matern52", 0.1, 1.0, 1e-4, 1e-4, 0.0, np.inf, 1, 0.0, units=units)
    return lf, f


def test_shape_sentences_say_the_recordings_units() -> None:
    """The friction, periodic and loop shapes and the description: "V", not " N" or "mm",
    with volts; "N" and "mm" with SI, as before."""
    from harvester.diagnosis.size import shapes
    lf, f = _latent(VOLTS)
    for shape in (shapes.friction, shapes.periodic_in_z, shapes.odd_in_z, shapes.damping,
                  shapes.drift, shapes.loop, shapes.inertial):
        said = shape(lf, f).sentence
        assert " V" in said and " N" not in said and "mm" not in said and "kg" not in said, said
    fr = shapes.friction(lf, f)
    assert "of 0.5 V (smoothed over" in fr.sentence and " V/s;" in fr.sentence
    assert "V s/V of viscous damping" in fr.sentence
    assert "k_1 = " in shapes.odd_in_z(lf, f).sentence and \
        " V/V, k_3" in shapes.odd_in_z(lf, f).sentence
    desc = shapes.describe(lf, (shapes.friction, shapes.drift))
    assert desc.sentence.startswith("a friction-like force") and "(RMS 0.495 V)" in desc.sentence
    si, f = _latent(SI)
    said = shapes.friction(si, f).sentence
    assert "of 0.5 N (smoothed over" in said and " mm/s;" in said and "N s/m" in said
    assert " mm, amplitude" in shapes.periodic_in_z(si, f).sentence


def test_verdict_and_size_sentences_say_the_recordings_units() -> None:
    """A named effect's strength (its probe parameter's unit) and its size in the headline,
    and the relevance sentence, in volts; in N with SI."""
    from harvester.diagnosis.size.relevance import EffectSize, RelevanceFloor
    from harvester.diagnosis.name.verdict import _level, _named
    fit = SimpleNamespace(summary=lambda: {"F_hyst": {"mean": 0.636, "sd": 0.0052}})
    assert _level("hysteresis", fit, VOLTS) == "hysteresis (friction, F_hyst 0.636 +- 0.0052 V)"
    assert _level("hysteresis", fit) == "hysteresis (friction, F_hyst 0.636 +- 0.0052 N)"
    size = EffectSize("hysteresis", 0.2, 0.05, 0.7, None, None, False, RelevanceFloor(), VOLTS)
    assert size.sentence().startswith("hysteresis: 0.2 V RMS (5 % of the drive)")
    assert size.to_dict()["force_unit"] == "V"
    found = SimpleNamespace(missing=["hysteresis"], ties=[], improved_fit=fit, named_fit=None)
    named = _named(found, SimpleNamespace(sizes=[size], together=None), VOLTS)
    assert named == ("hysteresis (friction, F_hyst 0.636 +- 0.0052 V) (0.2 V RMS, 5.00% of "
                     "the drive, relevant)") and " N" not in named
    si = EffectSize("hysteresis", 0.2, 0.05, 0.7, None, None, False, RelevanceFloor())
    assert "(0.2 N RMS" in _named(found, SimpleNamespace(sizes=[si], together=None))


def test_units_reach_the_diagnosis_settings_and_the_prepared_sidecar() -> None:
    """A config's units mapping becomes the settings' Units; the workflow's prepared sidecar
    keeps a given sidecar's units and writes none for SI."""
    import yaml

    from harvester.diagnosis.prepare.settings import DiagnosisSettings
    from harvester.groups import _sidecar_text
    assert DiagnosisSettings().units == SI
    cfg = DiagnosisSettings.from_config({"units": {"force": "V", "displacement": "V"}})
    assert cfg.units == VOLTS
    assert yaml.safe_load(_sidecar_text({}, {}, 20.0, [], VOLTS.to_sidecar())) == \
        {"filtered_at_hz": 20.0, "units": {"force": "V", "displacement": "V"}}
    assert "units" not in yaml.safe_load(_sidecar_text({"k": 1.0}, {}, None, [],
                                                       SI.to_sidecar()))


@pytest.mark.skipif(not SILVERBOX.is_file(), reason="no data/public/silverbox")
def test_the_silverbox_sidecar_says_volts(tmp_path) -> None:
    """The reader's sidecar, written and read back: units V and V, no device values; the
    workflow's prepared copy (the study's Silverbox group) keeps them."""
    from harvester.data.public import public_recording, silverbox
    from harvester.groups import prepare_recording
    path = silverbox(SILVERBOX, samples=256).write(tmp_path / "sb.csv")
    text = (tmp_path / "sb.yaml").read_text()
    assert "# no device values" in text
    got = read_sidecar(path)
    assert got.found and got.units == VOLTS and got.known == {}
    study = public_recording(SILVERBOX).write(tmp_path / "study.csv")
    prepare_recording(study, study.with_suffix(".yaml"), tmp_path / "g" / "sb.csv")
    assert read_sidecar(tmp_path / "g" / "sb.csv").units == VOLTS


def test_the_missing_force_views_are_labelled_in_the_recordings_units() -> None:
    """latent_views.views: z in mm and F in N for SI; in V (no factor of 1e3) for volts."""
    from harvester.diagnosis.size.views import views
    x = np.linspace(-1.0, 1.0, 100)
    lf = SimpleNamespace(rel_disp=x, rel_vel=x, time=np.arange(100.0), input=x, force=x**3,
                         draws=np.tile(x**3, (3, 1)), input_kind="force", units=SI)
    si = views(lf)
    assert (si["z"].unit, si["z'"].unit, si["input"].unit) == ("mm", "m/s", "N")
    assert np.isclose(si["z"].centre.max(), 1e3 * x[-4:].mean(), rtol=0.05)
    lf.units = Units("V", "V")
    volts = views(lf)
    assert (volts["z"].unit, volts["z'"].unit, volts["input"].unit) == ("V", "V/s", "V")
    assert volts["z"].centre.max() < 1.0 + 1e-12


def test_a_displacement_in_volts_is_not_judged_as_metres(tmp_path) -> None:
    """A fast 'displacement' (24 V/s RMS, the Silverbox's scale) warns "in mm?" without a
    unit, and says nothing where the sidecar gives it in volts."""
    from harvester.data.daq import read_checked_recording
    t = np.arange(2000) / 610.0
    x = 0.2 * np.sin(2 * np.pi * 20.0 * t)  # derivative RMS about 18 (units/s)
    f = 0.1 * np.sin(2 * np.pi * 20.0 * t + 0.3)
    path = tmp_path / "circuit.csv"
    pd.DataFrame({"time": t, "force": f, "rel_disp": x}).to_csv(path, index=False)
    fast = [w for w in read_checked_recording(path).warnings if "in mm?" in str(w)]
    assert len(fast) == 1
    (tmp_path / "circuit.yaml").write_text("units: {force: V, displacement: V}\n")
    assert not [w for w in read_checked_recording(path).warnings if "in mm?" in str(w)]
