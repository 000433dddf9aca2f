"""File formats (harvester.data.daq): conversion, validation of bad input, checksums, committed data."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from harvester.data import daq

from harvester.synthetic import rig
from harvester.study.dataset import make_raw_data
from harvester.data.errors import DataError

ROOT = Path(__file__).parents[1]
CONFIG = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
RIG = CONFIG["rig"]
RAW = ROOT / CONFIG["data"]["raw_dir"]
G = 9.80665
N = 300


@pytest.fixture()
def raw(tmp_path: Path) -> tuple[Path, Path]:
    """A valid 300-sample raw record: mass channel 1 g above rest plus a small tone."""
    t = np.arange(N) / 256.0
    base = 2.5 + 0.8 + 0.01 * np.sin(2 * np.pi * 3 * t)
    frame = pd.DataFrame({"time": t, "ai0": base, "ai1": base + 0.8})
    csv, meta = tmp_path / "rec.csv", tmp_path / "rec.json"
    daq.write_raw_record(frame, csv, meta, daq.record_metadata(RIG, "rec", N, 1))
    return csv, meta


def edit_line(path: Path, line: int, text: str) -> None:
    """Replace 1-based ``line`` of ``path`` by ``text``."""
    lines = path.read_text().splitlines()
    lines[line - 1] = text
    path.write_text("\n".join(lines) + "\n")


def edit_meta(path: Path, **changes: object) -> None:
    meta = json.loads(path.read_text())
    meta.update(changes)
    path.write_text(json.dumps(meta))


def raises_at(match: str, line: int | None = None, column: str | None = None):
    where = ""
    if line is not None:
        where += f", line {line}"
    if column is not None:
        where += f", column '{column}'"
    return pytest.raises(DataError, match=f"{where}: .*{match}")


# --------------------------------------------------------------------------- conversion

def test_conversion_exact_on_known_voltage() -> None:
    meta = daq.record_metadata(RIG, "x", 3, 0)
    volts = pd.DataFrame({"time": [0.0, 1.0, 2.0], "ai0": [3.3, 2.5, 3.7],
                          "ai1": [3.3, 4.1, 2.9]})
    acc = daq.to_accelerations(volts, meta)
    # a = g (V - 2.5) / 0.8 - g: 3.3 V is rest (1 g), 2.5 V is -1 g, 3.7 V is +0.5 g
    assert acc["base_acc"].tolist() == pytest.approx([0.0, -G, 0.5 * G], abs=1e-12)
    assert acc["mass_acc"].tolist() == pytest.approx([0.0, G, -0.5 * G], abs=1e-12)
    assert acc["rel_acc"].tolist() == pytest.approx([0.0, 2 * G, -G], abs=1e-12)
    assert list(acc.columns) == ["time", "base_acc", "mass_acc", "rel_acc"]


def test_raw_record_round_trip(raw) -> None:
    df, meta = daq.read_raw_record(*raw)
    assert list(df.columns) == ["time", "ai0", "ai1"] and len(df) == N
    assert meta["simulated"] is True
    acc = daq.to_accelerations(df, meta)
    assert np.abs(acc["rel_acc"] - G).max() < 2e-5  # 0.8 V = 1 g, printed to 1 uV


def test_recording_round_trip(tmp_path) -> None:
    t = np.arange(100) / 256.0
    frame = pd.DataFrame({"time": t, "base_acc": np.sin(t), "rel_acc": np.cos(t),
                          "mass_acc": np.sin(t) + np.cos(t)})
    daq.write_recording(frame, tmp_path / "r.csv")
    back = daq.read_recording(tmp_path / "r.csv")
    assert list(back.columns) == ["time", "base_acc", "rel_acc", "mass_acc"]
    assert np.allclose(back.to_numpy(), frame.to_numpy(), rtol=1e-8, atol=1e-12)


# --------------------------------------------------------------------------- raw record errors

def test_missing_channel_in_csv(raw) -> None:
    csv, meta = raw
    frame = pd.read_csv(csv)[["time", "ai0"]]
    csv.write_text(frame.to_csv(index=False))
    with raises_at("missing from the header", line=1, column="ai1"):
        daq.read_raw_record(csv, meta)


def test_channel_not_in_metadata(raw) -> None:
    csv, meta = raw
    channels = json.loads(meta.read_text())["channels"][:1]
    edit_meta(meta, channels=channels)
    with raises_at("not a channel of rec.json", line=1, column="ai1"):
        daq.read_raw_record(csv, meta)


@pytest.mark.parametrize("line, row, message, column", [
    (7, "0.02343750,nan,3.300000", "NaN", "ai0"),
    (9, "0.03125000,3.300000,", "empty value", "ai1"),
    (5, "", "empty row", None),
    (12, "0.04300000,3.300000,4.100000", "non-uniform time", "time"),
])
def test_bad_row_is_named_with_its_line_and_column(raw, line, row, message, column) -> None:
    csv, meta = raw
    edit_line(csv, line, row)
    with raises_at(message, line=line, column=column):
        daq.read_raw_record(csv, meta)


def test_sampling_rate_disagrees(raw) -> None:
    csv, meta = raw
    edit_meta(meta, sampling_rate_hz=250.0)
    with raises_at("disagrees with sampling_rate_hz", line=3, column="time"):
        daq.read_raw_record(csv, meta)


def test_wrong_n_samples(raw) -> None:
    csv, meta = raw
    edit_meta(meta, n_samples=N + 1)
    with pytest.raises(DataError, match=r"rec\.json: n_samples is 301 but rec\.csv holds 300"):
        daq.read_raw_record(csv, meta)


@pytest.mark.parametrize("volts", ["0.000000", "4.999924", "5.000000"])
def test_sample_at_clipping_limit(raw, volts) -> None:
    csv, meta = raw
    edit_line(csv, 20, f"{18 / 256:.8f},3.300000,{volts}")
    with raises_at("clipping limit", line=20, column="ai1"):
        daq.read_raw_record(csv, meta)


def test_sensor_swing_limit_inside_adc_span(raw) -> None:
    csv, meta = raw
    channels = json.loads(meta.read_text())["channels"]
    channels[0]["range_g"] = 2.0  # sensor saturates at 2.5 +- 1.6 V
    edit_meta(meta, channels=channels)
    edit_line(csv, 4, f"{2 / 256:.8f},4.100000,3.300000")
    with raises_at("clipping limit", line=4, column="ai0"):
        daq.read_raw_record(csv, meta)


def test_ragged_row_and_text_value(raw) -> None:
    csv, meta = raw
    edit_line(csv, 6, "0.01953125,3.3,3.3,1.0")
    with raises_at("4 fields", line=6):
        daq.read_raw_record(csv, meta)
    edit_line(csv, 6, "0.01953125,3.3,volts")
    with raises_at("not a number", line=6, column="ai1"):
        daq.read_raw_record(csv, meta)


def test_bad_metadata(raw) -> None:
    csv, meta = raw
    meta.write_text('{"simulated": true,\n "n_samples": }')
    with raises_at("invalid JSON", line=2):
        daq.read_raw_record(csv, meta)
    meta.write_text(json.dumps({"simulated": True, "sampling_rate_hz": 256.0}))
    with pytest.raises(DataError, match="rec.json: missing key 'n_samples'"):
        daq.read_raw_record(csv, meta)


def test_missing_file(tmp_path) -> None:
    with pytest.raises(DataError, match="nothing.csv: file not found"):
        daq.read_recording(tmp_path / "nothing.csv")


# --------------------------------------------------------------------------- converted recording errors

@pytest.fixture()
def recording(tmp_path: Path) -> Path:
    t = np.arange(100) / 256.0
    path = tmp_path / "recording.csv"
    daq.write_recording(pd.DataFrame({"time": t, "base_acc": np.sin(t), "rel_acc": t}), path)
    return path


def test_recording_missing_column(recording) -> None:
    frame = pd.read_csv(recording).drop(columns="rel_acc")
    recording.write_text(frame.to_csv(index=False))
    with raises_at("missing column", line=1, column="rel_acc"):
        daq.read_recording(recording)


def test_recording_non_numeric_nan_and_empty(recording) -> None:
    good = recording.read_text()
    edit_line(recording, 10, "0.035156250,abc,0.1")
    with raises_at("not a number", line=10, column="base_acc"):
        daq.read_recording(recording)
    recording.write_text(good)
    edit_line(recording, 11, "0.039062500,0.1,NaN")
    with raises_at("NaN", line=11, column="rel_acc"):
        daq.read_recording(recording)
    recording.write_text(good)
    edit_line(recording, 12, ",,")
    with raises_at("empty row", line=12):
        daq.read_recording(recording)


def test_recording_non_uniform_time(recording) -> None:
    lines = recording.read_text().splitlines()
    del lines[30]  # a dropped sample: the step into file line 31 doubles
    recording.write_text("\n".join(lines) + "\n")
    with raises_at("non-uniform time", line=31, column="time"):
        daq.read_recording(recording)


def test_recording_too_short(tmp_path) -> None:
    path = tmp_path / "short.csv"
    t = np.arange(63) / 256.0
    daq.write_recording(pd.DataFrame({"time": t, "base_acc": t, "rel_acc": t}), path)
    with pytest.raises(DataError, match="63 samples; at least 64"):
        daq.read_recording(path)


def test_recording_times_rounded_to_6_decimals_accepted(tmp_path) -> None:
    t = np.arange(200) / 256.0
    lines = ["time,base_acc,rel_acc"] + [f"{x:.6f},{np.sin(9 * x):.6f},{np.cos(5 * x):.6f}"
                                          for x in t]
    (tmp_path / "r.csv").write_text("\n".join(lines) + "\n")
    assert len(daq.read_recording(tmp_path / "r.csv")) == 200


def test_failed_write_leaves_nothing(tmp_path) -> None:
    with pytest.raises(DataError, match="missing column"):
        daq.write_recording(pd.DataFrame({"time": [0.0]}), tmp_path / "x.csv")
    with pytest.raises(KeyError):
        daq.write_raw_record(pd.DataFrame({"time": [0.0]}), tmp_path / "r.csv",
                             tmp_path / "r.json", daq.record_metadata(RIG, "r", 1, 0))
    assert list(tmp_path.iterdir()) == []


# --------------------------------------------------------------------------- static test

@pytest.fixture()
def static(tmp_path: Path) -> tuple[Path, Path]:
    table = pd.DataFrame({"repeat": [1, 1, 2, 2], "direction": ["down", "up"] * 2,
                          "position_m": [0.034, -0.033, 0.0335, -0.0338]})
    meta = daq.static_test_metadata(RIG) | {"repeats": 2}
    csv, js = tmp_path / "static.csv", tmp_path / "static.json"
    daq.write_static_test(table, csv, js, meta)
    return csv, js


def test_static_test_round_trip(static) -> None:
    table, meta = daq.read_static_test(*static)
    assert table["position_m"].tolist() == [0.034, -0.033, 0.0335, -0.0338]
    assert "k" not in meta and meta["position"]["positive"] == "down"


def test_static_test_bad_rows(static) -> None:
    csv, js = static
    good = csv.read_text()
    edit_line(csv, 3, "1,sideways,0.01")
    with raises_at("direction must be", line=3, column="direction"):
        daq.read_static_test(csv, js)
    csv.write_text(good)
    edit_line(csv, 4, "2,down,")
    with raises_at("empty value", line=4, column="position_m"):
        daq.read_static_test(csv, js)
    csv.write_text(good)
    edit_line(csv, 5, "1,up,-0.03")
    with raises_at("appears twice", line=5):
        daq.read_static_test(csv, js)


# --------------------------------------------------------------------------- checksums and committed data

def test_checksums_detect_a_changed_file(raw) -> None:
    csv, meta = raw
    sums = daq.write_checksums(csv.parent, [csv.name, meta.name])
    assert daq.verify_checksums(sums) == [csv, meta]
    assert sums.read_text().splitlines()[0].endswith(f"  {csv.name}")
    edit_line(csv, 2, "0.00000000,3.300001,4.100000")
    with pytest.raises(DataError, match=r"rec\.csv: SHA256 .* does not match"):
        daq.verify_checksums(sums)
    csv.unlink()
    with pytest.raises(DataError, match=r"rec\.csv: listed in .* but missing"):
        daq.verify_checksums(sums)


def test_write_is_byte_reproducible(tmp_path) -> None:
    sim = rig.simulate_record(RIG, "training", duration_s=1.0)
    frame = pd.DataFrame({"time": sim.time, "ai0": sim.ai0, "ai1": sim.ai1})
    meta = daq.record_metadata(RIG, "training", len(frame), sim.seed)
    for d in ("a", "b"):
        (tmp_path / d).mkdir()
        daq.write_raw_record(frame, tmp_path / d / "r.csv", tmp_path / d / "r.json", meta)
    for name in ("r.csv", "r.json"):
        assert (tmp_path / "a" / name).read_bytes() == (tmp_path / "b" / name).read_bytes()


@pytest.mark.skipif(not (RAW / "SHA256SUMS").exists(), reason="data/raw not generated")
def test_committed_raw_data_is_valid() -> None:
    daq.verify_checksums(RAW / "SHA256SUMS")
    for record, spec in RIG["records"].items():
        df, meta = daq.read_raw_record(RAW / f"{record}.csv", RAW / f"{record}.json")
        assert meta["simulated"] is True
        assert len(df) == round(spec["duration_s"] * RIG["daq"]["sampling_rate_hz"])
    table, _ = daq.read_static_test(RAW / "static_friction.csv", RAW / "static_friction.json")
    assert len(table) == 2 * RIG["static_test"]["repeats"]


def test_byte_order_mark_is_ignored(tmp_path) -> None:
    t = np.arange(64) / 256.0
    lines = ["time,base_acc,rel_acc"] + [f"{x:.9f},{np.sin(9 * x):.6f},{np.cos(5 * x):.6f}"
                                          for x in t]
    (tmp_path / "r.csv").write_text("\ufeff" + "\n".join(lines) + "\n", encoding="utf-8")
    assert list(daq.read_recording(tmp_path / "r.csv").columns) == list(daq.RECORDING_COLUMNS)


def test_committed_data_regenerates_bit_for_bit(tmp_path) -> None:
    written = make_raw_data(CONFIG, tmp_path)
    listed = {line.split()[1] for line in (RAW / "SHA256SUMS").read_text().splitlines()}
    assert {p.name for p in written} == listed | {"SHA256SUMS"}
    assert (tmp_path / "SHA256SUMS").read_bytes() == (RAW / "SHA256SUMS").read_bytes()
    daq.verify_checksums(tmp_path / "SHA256SUMS")


def test_compare_checksums_names_the_file_that_differs(tmp_path) -> None:
    for d, text in (("a", "x"), ("b", "y")):
        (tmp_path / d).mkdir()
        (tmp_path / d / "f.csv").write_text(text)
        (tmp_path / d / "g.csv").write_text("same")
    a = daq.write_checksums(tmp_path / "a", ["g.csv"])
    b = daq.write_checksums(tmp_path / "b", ["g.csv"])
    assert "g.csv" in daq.compare_checksums(a, b)
    a = daq.write_checksums(tmp_path / "a", ["g.csv", "f.csv"])
    b = daq.write_checksums(tmp_path / "b", ["g.csv", "f.csv"])
    with pytest.raises(DataError, match=r"b/f\.csv: regenerated SHA256 .* differs"):
        daq.compare_checksums(a, b)
    b = daq.write_checksums(tmp_path / "b", ["g.csv"])
    with pytest.raises(DataError, match=r"b/f\.csv: listed in .* but not regenerated"):
        daq.compare_checksums(a, b)
