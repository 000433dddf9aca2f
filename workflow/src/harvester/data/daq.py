"""File formats of the recordings, in one place: raw DAQ records, static tests, converted data.

Raw record (a DAQ export; ours are SIMULATED by ``harvester.synthetic.rig``):

* ``<record>.csv``: header ``time,ai0,ai1``; time in s, channel voltages in V, uniform rate.
* ``<record>.json``: ``simulated``, ``source``, ``sampling_rate_hz``, ``n_samples``,
  ``adc`` {``bits``, ``range_V``}, ``channels`` (per channel ``name``, ``quantity``
  (``base_acceleration`` or ``mass_acceleration``), ``unit`` ``V``,
  ``sensitivity_mV_per_g``, ``zero_g_V``, ``range_g``, ``gravity_g``), ``seed``,
  ``generated_by``.
* Loaded records (``harvester.synthetic.electrical``, :func:`loaded_record_metadata`) add
  channels ``ai2`` and ``ai3``, quantity ``load_voltage``: the line voltages between generator
  terminals a and b, and b and c, each through a voltage sensor (``gain_V_per_V``, ``zero_V``,
  ``range_V`` in load volts, ``terminals``, ``between``), and a ``load`` block (``resistance_ohm`` per resistor of the star, null in open
  circuit) and a ``generator`` block (nameplate data; the constants to identify are withheld).

Static friction test (eqs. 4-5): ``static_friction.csv`` with ``repeat,direction,position_m``
(direction ``down`` or ``up``; positions downward-positive, m) and ``static_friction.json``.

Converted recording (also the input of ``harvester diagnose``): CSV with ``time`` (s),
one input column, ``base_acc`` (y'', m/s^2) or ``force`` (N), and one output column,
``rel_acc`` (z'' = x'' - y'', eq. 1, m/s^2) or ``rel_disp`` (z, m), plus optional extra numeric
columns. The column names declare the kinds (``harvester.data.recording``); the virtual rig's
recordings are ``time, base_acc, rel_acc``, with ``voltage`` and ``voltage_bc`` (V) from a
loaded record.

Every reader raises :class:`~harvester.data.errors.DataError` naming the file, the 1-based line
(the header is line 1) and the column. Every writer is atomic (temporary file + rename).
"""

from __future__ import annotations

import csv
import hashlib
import io
import json
import logging
import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from harvester.data.checks import CheckWarning, check_recording
from harvester.data.errors import DataError
from harvester.data.fileio import atomic_path
from harvester.data.recording import (INPUT_KINDS, OUTPUT_KINDS, UNITS, Accepted, RecordingKinds,
                                      check_annotations, recording_kinds)
from harvester.data.sidecar import Sidecar, read_sidecar
from harvester.data.signals import time_base

log = logging.getLogger("harvester.data")

#: Standard gravity (m/s^2) used to convert g to m/s^2.
G = 9.80665
#: Raw channels and what they measure.
CHANNEL_QUANTITIES: dict[str, str] = {"ai0": "base_acceleration", "ai1": "mass_acceleration"}
#: Columns of the virtual rig's converted recordings (other kinds: ``harvester.data.recording``).
RECORDING_COLUMNS: tuple[str, ...] = ("time", "base_acc", "rel_acc")
#: Fewest samples a converted recording may hold.
MIN_SAMPLES = 64
#: Largest relative deviation of a time step from the median step.
TIME_REL_TOL = 1.0e-6
STATIC_COLUMNS: tuple[str, ...] = ("repeat", "direction", "position_m")
DIRECTIONS: tuple[str, str] = ("down", "up")
SOURCE = ("virtual rig (harvester.synthetic.rig): SIMULATED recording, not data from Green et al. (2015) "
          "- the paper's recordings are not public")
GENERATED_BY = "workflow/scripts/make_raw_data.py (harvester.synthetic.rig, harvester.data.daq)"
_CHANNEL_KEYS = ("name", "quantity", "unit", "sensitivity_mV_per_g", "zero_g_V", "range_g",
                 "gravity_g")
#: The voltage channels of a loaded record (line-to-line, terminals), their quantity and keys.
VOLTAGE_CHANNEL = "ai2"
VOLTAGE_CHANNELS = {"ai2": ("a", "b"), "ai3": ("b", "c")}
VOLTAGE_QUANTITY = "load_voltage"
_VOLTAGE_KEYS = ("name", "quantity", "unit", "gain_V_per_V", "zero_V", "range_V")
GENERATED_BY_LOADED = ("workflow/scripts/make_raw_data.py (harvester.synthetic.electrical, "
                       "harvester.synthetic.rig, harvester.data.daq)")


# --------------------------------------------------------------------------- writing

def _write_text(path: Path, text: str) -> None:
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8", newline="\n")
        tmp.chmod(0o644)


def _write_json(path: Path, obj: Mapping[str, Any]) -> None:
    _write_text(path, json.dumps(obj, indent=2) + "\n")


def _csv_text(df: pd.DataFrame, fmts: Sequence[str]) -> str:
    buf = io.StringIO()
    np.savetxt(buf, df.to_numpy(dtype=float), fmt=list(fmts), delimiter=",",
               header=",".join(df.columns), comments="")
    return buf.getvalue()


def record_metadata(rig: Mapping[str, Any], record: str, n_samples: int,
                    seed: int) -> dict[str, Any]:
    """DAQ-export metadata of a simulated raw record, from the config's ``rig`` section."""
    sens, daq = rig["sensors"], rig["daq"]
    channels = [{"name": name, "quantity": quantity, "unit": "V",
                 "sensitivity_mV_per_g": float(sens["sensitivity_mV_per_g"]),
                 "zero_g_V": float(sens["zero_g_V"]), "range_g": float(sens["range_g"]),
                 "gravity_g": 1.0}
                for name, quantity in CHANNEL_QUANTITIES.items()]
    return {"simulated": True, "source": SOURCE, "record": record,
            "sampling_rate_hz": float(daq["sampling_rate_hz"]), "n_samples": int(n_samples),
            "adc": {"bits": int(daq["bits"]), "range_V": [float(v) for v in daq["range_V"]]},
            "channels": channels, "seed": int(seed), "generated_by": GENERATED_BY}


def loaded_record_metadata(rig: Mapping[str, Any], record: str, n_samples: int, seed: int,
                           load_ohm: float | None) -> dict[str, Any]:
    """Metadata of a simulated loaded record: :func:`record_metadata` plus the voltage channels
    ``ai2`` (v_ab) and ``ai3`` (v_bc), the load (``None``: open circuit) and the generator's nameplate data.

    The generator's constants (K_e, R_s, L_s) are not recorded: they are what a loaded record
    identifies, and they are ASSUMED values of the virtual rig (``rig.generator`` in the
    config), the cited device descriptions giving none that could be retrieved.
    """
    gen = rig["generator"]
    sensor = gen["voltage_sensor"]
    meta = record_metadata(rig, record, n_samples, seed)
    meta["source"] = SOURCE.replace("harvester.synthetic.rig",
                                    "harvester.synthetic.rig + harvester.synthetic.electrical")
    for name, (one, two) in VOLTAGE_CHANNELS.items():
        meta["channels"].append({
            "name": name, "quantity": VOLTAGE_QUANTITY, "unit": "V",
            "gain_V_per_V": float(sensor["gain_V_per_V"]), "zero_V": float(sensor["zero_V"]),
            "range_V": float(sensor["range_V"]), "terminals": one + two,
            "between": f"generator terminals {one} and {two} (line-to-line): across the two "
                       f"star-connected load resistors of phases {one} and {two} in series; "
                       "load voltage = (V - zero_V) / gain_V_per_V"})
    meta["load"] = {
        "connection": "three equal resistors in star on the generator terminals "
                      "(Green et al. 2015, Figure 2)",
        "resistance_ohm": None if load_ohm is None else float(load_ohm),
        "open_circuit": load_ohm is None}
    meta["generator"] = {
        "type": "three-phase brushless permanent-magnet generator driven by the ball screw",
        "lead_m": float(gen["lead_m"]), "pole_pairs": int(gen["pole_pairs"]),
        "constants": "ASSUMED values of the virtual rig (the paper and the device "
                     "descriptions it cites gave none that could be retrieved); K_e, R_s, L_s "
                     "are withheld here as the quantities to identify"}
    meta["generated_by"] = GENERATED_BY_LOADED
    return meta


def write_raw_record(df: pd.DataFrame, csv_path: str | Path, json_path: str | Path,
                     meta: Mapping[str, Any]) -> None:
    """Write columns time (s, %.8f), the channels (ai0, ai1[, ai2]; V, %.6f) and the metadata;
    byte-reproducible."""
    cols = ["time", *(c["name"] for c in meta["channels"])]
    _write_text(Path(csv_path), _csv_text(df[cols], ["%.8f"] + ["%.6f"] * (len(cols) - 1)))
    _write_json(Path(json_path), meta)


def static_test_metadata(rig: Mapping[str, Any]) -> dict[str, Any]:
    """Metadata of the simulated static friction test (the stiffness k is NOT recorded)."""
    st = rig["static_test"]
    return {
        "simulated": True, "source": SOURCE,
        "test": "static friction, Green et al. (2015) eqs. (4)-(5); device vertical",
        "columns": {"repeat": "repeat number, from 1",
                    "direction": "'down': largest downward displacement at which the mass, "
                                 "held and let go, stays put (x1); 'up': likewise upwards (x2)",
                    "position_m": "that position, read off the scale"},
        "procedure": {"hold_s": float(st["hold_s"]), "step_m": float(st["step_m"])},
        "position": {"unit": "m", "positive": "down",
                     "datum": "frictionless equilibrium (spring extended by m g / k)"},
        "friction_from_positions": "F_s = k (x1 - x2) / 2 (the paper writes 2 F_c = "
                                   "k (x2 - x1), measuring positions the other way)",
        "repeats": int(st["repeats"]),
        "seed": int(rig["seed"]) + int(st["seed_offset"]), "generated_by": GENERATED_BY,
    }


def write_static_test(df: pd.DataFrame, csv_path: str | Path, json_path: str | Path,
                      meta: Mapping[str, Any]) -> None:
    """Write the static test table (position %.6f m) and its metadata."""
    lines = [",".join(STATIC_COLUMNS)]
    lines += [f"{int(r)},{d},{x:.6f}" for r, d, x in df[list(STATIC_COLUMNS)].itertuples(
        index=False)]
    _write_text(Path(csv_path), "\n".join(lines) + "\n")
    _write_json(Path(json_path), meta)


def write_recording(df: pd.DataFrame, path: str | Path) -> None:
    """Write a converted recording: time (%.9f s), input, output, extras (%.9g, SI units).

    The input column is ``base_acc`` or ``force``, the output ``rel_acc`` or ``rel_disp``.
    """
    if "time" not in df.columns:
        raise DataError(path, "cannot write: missing column(s) ['time']")
    kinds = recording_kinds(df.columns, path)
    first = ["time", kinds.input_kind, kinds.output_kind]
    cols = [*first, *(c for c in df.columns if c not in first)]
    _write_text(Path(path), _csv_text(df[cols], ["%.9f"] + ["%.9g"] * (len(cols) - 1)))


# --------------------------------------------------------------------------- reading

def _read_text(path: Path) -> str:
    """File contents as text (UTF-8, a leading byte-order mark ignored)."""
    try:
        return path.read_text(encoding="utf-8-sig")
    except FileNotFoundError:
        raise DataError(path, "file not found") from None
    except UnicodeDecodeError as err:
        raise DataError(path, f"not UTF-8 text ({err.reason})") from None
    except OSError as err:
        raise DataError(path, f"cannot read: {err.strerror}") from None


#: Separators other than the format's comma that exports use, by name.
_OTHER_SEPARATORS = {";": "semicolons", "\t": "tabs", "|": "bars"}


def _shown(line: str, width: int = 60) -> str:
    """A line as read, quoted and cut to ``width`` characters."""
    return repr(line if len(line) <= width else line[:width] + "...")


def _separator_hint(first_line: str) -> str:
    """What a header that did not split on commas seems to be separated by ('' if nothing)."""
    for sep, name in _OTHER_SEPARATORS.items():
        if first_line.count(sep) >= 1 and "," not in first_line:
            return (f"the header {_shown(first_line)} was read as one column; it seems "
                    f"separated by {name} ({sep!r}): the format needs commas, with '.' as the "
                    "decimal point")
    return ""


def _ragged_row(path: Path, cells: list[str], header: list[str], line: int,
                text: str) -> DataError:
    """The error for a row whose field count differs from the header's, showing the row."""
    raw = text.splitlines()[line - 1] if line - 1 < len(text.splitlines()) else ",".join(cells)
    what = f"{len(cells)} fields, the header has {len(header)}: the row reads {_shown(raw)}"
    if len(cells) > len(header) and all(c.strip().lstrip("-").isdigit() for c in cells[1:]):
        what += ("; decimal commas? The format needs '.' as the decimal point and ',' "
                 "between fields")
    return DataError(path, what, line=line)


def _read_rows(path: Path) -> tuple[list[str], list[list[str]], list[int]]:
    """Header, data rows and their 1-based line numbers; rejects empty and ragged rows.

    A header that is one field holding ';' or tabs is reported as another separator, and a
    row with more fields than the header, all integers, as decimal commas; both errors show
    the line as read.
    """
    text = _read_text(path)
    reader = csv.reader(io.StringIO(text))
    header = [h.strip() for h in next(reader, [])]
    if not any(header):
        raise DataError(path, "no header row (an empty file?)", line=1)
    hint = _separator_hint(text.splitlines()[0]) if len(header) == 1 else ""
    if hint:
        raise DataError(path, hint, line=1)
    for j, name in enumerate(header):
        if not name or name in header[:j]:
            raise DataError(path, "empty or repeated column name in the header", line=1,
                            column=name)
    rows: list[list[str]] = []
    lines: list[int] = []
    blank: int | None = None  # blank lines are only allowed at the end of the file
    for cells in reader:
        if not cells or len(cells) == 1 and not cells[0].strip():
            blank = blank or reader.line_num
            continue
        if blank is not None:
            raise DataError(path, "empty row", line=blank)
        if not any(c.strip() for c in cells):
            raise DataError(path, "empty row", line=reader.line_num)
        if len(cells) != len(header):
            raise _ragged_row(path, cells, header, reader.line_num, text)
        rows.append(cells)
        lines.append(reader.line_num)
    return header, rows, lines


def _to_float(path: Path, cell: str, line: int, column: str) -> float:
    text = cell.strip()
    if not text:
        raise DataError(path, "empty value", line=line, column=column)
    try:
        value = float(text)
    except ValueError:
        raise DataError(path, f"not a number: {cell!r}", line=line, column=column) from None
    if not math.isfinite(value):
        raise DataError(path, f"{text} value (NaN or infinite); expected a finite number",
                        line=line, column=column)
    return value


def _numeric_table(path: Path, header: list[str], rows: list[list[str]],
                   lines: list[int]) -> pd.DataFrame:
    """All-numeric table: every cell a finite number, else DataError at its line and column."""
    out = np.empty((len(rows), len(header)))
    for i, (cells, line) in enumerate(zip(rows, lines)):
        for j, cell in enumerate(cells):
            out[i, j] = _to_float(path, cell, line, header[j])
    return pd.DataFrame(out, columns=header)


def _decimals(cells: Iterable[str]) -> int | None:
    """Most digits after the decimal point (None if any cell uses an exponent)."""
    most = 0
    for cell in cells:
        text = cell.strip().lower()
        if "e" in text:
            return None
        if "." in text:
            most = max(most, len(text) - text.index(".") - 1)
    return most


def _time_step(path: Path, t: np.ndarray, lines: list[int],
               decimals: int | None) -> tuple[float, float]:
    """Mean time step and its tolerance (s); DataError at the first sample off a uniform time
    base (``signals.time_base``). The tolerance is TIME_REL_TOL of the step plus one unit of
    the last decimal written (for the check against the metadata's sampling rate)."""
    dt, bad, why = time_base(t)
    if bad is not None:
        raise DataError(path, why, line=lines[bad], column="time")
    return dt, TIME_REL_TOL * dt + (10.0 ** -decimals if decimals is not None else 0.0)


def _uniform_time(path: Path, df: pd.DataFrame, header: list[str], rows: list[list[str]],
                  lines: list[int]) -> tuple[float, float]:
    col = header.index("time")
    return _time_step(path, df["time"].to_numpy(), lines, _decimals(r[col] for r in rows))


def _read_json(path: Path) -> dict[str, Any]:
    try:
        meta = json.loads(_read_text(path))
    except json.JSONDecodeError as err:
        raise DataError(path, f"invalid JSON: {err.msg}", line=err.lineno) from None
    if not isinstance(meta, dict):
        raise DataError(path, "expected a JSON object")
    return meta


def _require(path: Path, meta: Mapping[str, Any], key: str, kind: type | tuple[type, ...],
             where: str = "") -> Any:
    if key not in meta:
        raise DataError(path, f"missing key '{where}{key}'")
    value = meta[key]
    if not isinstance(value, kind) or isinstance(value, bool) and kind is not bool:
        raise DataError(path, f"key '{where}{key}' has the wrong type: {value!r}")
    return value


def _check_raw_meta(path: Path, meta: Mapping[str, Any]) -> None:
    _require(path, meta, "simulated", bool)
    fs = _require(path, meta, "sampling_rate_hz", (int, float))
    if fs <= 0:
        raise DataError(path, f"sampling_rate_hz must be positive, got {fs}")
    if _require(path, meta, "n_samples", int) < 0:
        raise DataError(path, "n_samples must be >= 0")
    adc = _require(path, meta, "adc", dict)
    _require(path, adc, "bits", int, "adc.")
    rng = _require(path, adc, "range_V", list, "adc.")
    if len(rng) != 2 or not all(isinstance(v, (int, float)) for v in rng) or rng[0] >= rng[1]:
        raise DataError(path, f"adc.range_V must be [low, high] volts, got {rng!r}")
    channels = _require(path, meta, "channels", list)
    for i, ch in enumerate(channels):
        if not isinstance(ch, dict):
            raise DataError(path, f"channels[{i}] is not an object")
        voltage = ch.get("quantity") == VOLTAGE_QUANTITY
        for key in _VOLTAGE_KEYS if voltage else _CHANNEL_KEYS:
            _require(path, ch, key, str if key in ("name", "quantity", "unit") else (int, float),
                     f"channels[{i}].")
        if ch["unit"] != "V":
            raise DataError(path, f"channels[{i}].unit must be 'V', got {ch['unit']!r}")
        if voltage and (ch["gain_V_per_V"] <= 0 or ch["range_V"] <= 0):
            raise DataError(path, f"channels[{i}]: gain and range must be positive")
        if not voltage and (ch["sensitivity_mV_per_g"] <= 0 or ch["range_g"] <= 0):
            raise DataError(path, f"channels[{i}]: sensitivity and range must be positive")


def clip_limits(meta: Mapping[str, Any], channel: Mapping[str, Any]) -> tuple[float, float]:
    """Lowest and highest voltage (V) a channel can report before it clips.

    The tighter of the sensor's output swing (zero_g_V +- sensitivity x range_g; for a voltage
    channel zero_V +- gain_V_per_V x range_V) and the ADC span (its first and last code).
    """
    lo, hi = meta["adc"]["range_V"]
    lsb = (hi - lo) / 2 ** meta["adc"]["bits"]
    if channel["quantity"] == VOLTAGE_QUANTITY:
        zero, swing = channel["zero_V"], channel["gain_V_per_V"] * channel["range_V"]
    else:
        zero = channel["zero_g_V"]
        swing = channel["sensitivity_mV_per_g"] / 1000.0 * channel["range_g"]
    return max(zero - swing, lo), min(zero + swing, hi - lsb)


def _check_clipping(path: Path, df: pd.DataFrame, meta: Mapping[str, Any],
                    lines: list[int]) -> None:
    lo_adc, hi_adc = meta["adc"]["range_V"]
    half_lsb = 0.5 * (hi_adc - lo_adc) / 2 ** meta["adc"]["bits"]
    for ch in meta["channels"]:
        lo, hi = clip_limits(meta, ch)
        v = df[ch["name"]].to_numpy()
        bad = np.flatnonzero((v <= lo + half_lsb) | (v >= hi - half_lsb))
        if bad.size:
            i = int(bad[0])
            raise DataError(path, f"sample at the clipping limit: {v[i]} V (channel clips "
                            f"outside [{lo:.6g}, {hi:.6g}] V)", line=lines[i], column=ch["name"])


def read_raw_record(csv_path: str | Path,
                    json_path: str | Path) -> tuple[pd.DataFrame, dict[str, Any]]:
    """Read and validate a raw record: DataFrame (time, channel volts) and its metadata.

    Rejects: a channel named in the metadata but not in the CSV or the reverse, empty rows,
    non-numeric or NaN values, a non-uniform time base, a time step that disagrees with
    ``sampling_rate_hz``, a row count other than ``n_samples``, samples at a clipping limit.
    """
    csv_path, json_path = Path(csv_path), Path(json_path)
    meta = _read_json(json_path)
    _check_raw_meta(json_path, meta)
    header, rows, lines = _read_rows(csv_path)
    names = [ch["name"] for ch in meta["channels"]]
    if "time" not in header:
        raise DataError(csv_path, "no 'time' column in the header", line=1, column="time")
    for name in names:
        if name not in header:
            raise DataError(csv_path, f"channel listed in {json_path.name} is missing from the "
                            "header", line=1, column=name)
    for name in header:
        if name != "time" and name not in names:
            raise DataError(csv_path, f"column is not a channel of {json_path.name}", line=1,
                            column=name)
    df = _numeric_table(csv_path, header, rows, lines)
    if len(df) != meta["n_samples"]:
        raise DataError(json_path, f"n_samples is {meta['n_samples']} but {csv_path.name} "
                        f"holds {len(df)} samples")
    dt, tol = _uniform_time(csv_path, df, header, rows, lines)
    fs = meta["sampling_rate_hz"]
    if abs(dt - 1.0 / fs) > tol:
        raise DataError(csv_path, f"time step {dt:.9g} s ({1.0 / dt:.9g} Hz) disagrees with "
                        f"sampling_rate_hz = {fs} in {json_path.name}", line=lines[1],
                        column="time")
    _check_clipping(csv_path, df, meta, lines)
    return df[["time", *names]], meta


def to_accelerations(df: pd.DataFrame, meta: Mapping[str, Any]) -> pd.DataFrame:
    """Volts to m/s^2: a = g (V - zero_g_V) / (sensitivity / 1000) - gravity_g g.

    Returns time, base_acc (y''), mass_acc (x'') and rel_acc = mass_acc - base_acc (z''),
    and from a loaded record's voltage channels ``voltage`` (terminals a-b) and ``voltage_bc``
    (b-c) = (V - zero_V) / gain_V_per_V, the line voltages in volts (extra columns).
    """
    out = {"time": df["time"].to_numpy(dtype=float)}
    for ch in meta["channels"]:
        v = df[ch["name"]].to_numpy(dtype=float)
        if ch["quantity"] == VOLTAGE_QUANTITY:
            terminals = ch.get("terminals", "ab")
            column = "voltage" if terminals == "ab" else f"voltage_{terminals}"
            out[column] = (v - ch["zero_V"]) / ch["gain_V_per_V"]
            continue
        acc = G * (v - ch["zero_g_V"]) / (ch["sensitivity_mV_per_g"] / 1000.0) \
            - ch["gravity_g"] * G
        out[{"base_acceleration": "base_acc", "mass_acceleration": "mass_acc"}[ch["quantity"]]] \
            = acc
    if "base_acc" not in out or "mass_acc" not in out:
        raise DataError(str(meta.get("record", "metadata")),
                        "needs one base_acceleration and one mass_acceleration channel")
    frame = pd.DataFrame(out, columns=["time", "base_acc", "mass_acc"])
    frame["rel_acc"] = frame["mass_acc"] - frame["base_acc"]
    for column in sorted(c for c in out if c.startswith("voltage")):
        frame[column] = out[column]
    return frame


@dataclass(frozen=True)
class CheckedRecording:
    """A converted recording as read and checked: its table, kinds, time step (s), the
    sidecar beside it, and the checks' warnings (``harvester.data.checks``)."""

    data: pd.DataFrame
    kinds: RecordingKinds
    dt: float
    sidecar: Sidecar
    warnings: list[CheckWarning]


#: Every kind the format takes.
FORMAT_KINDS = Accepted(tuple(INPUT_KINDS), tuple(OUTPUT_KINDS), "the format",
                        "time, one input and one output column")


def _check_accepted(path: Path, header: list[str], accept: Accepted) -> None:
    """DataError at the header when the input or output column is missing, showing the header
    read, or is of a kind the command does not take (``accept``), saying why."""
    for role, allowed, every in (("input", accept.inputs, INPUT_KINDS),
                                 ("output", accept.outputs, OUTPUT_KINDS)):
        present = [k for k in every if k in header]
        if present and present[0] in allowed or len(present) > 1:
            continue  # recording_kinds names a doubled kind
        need = " or ".join(f"{k} ({UNITS[k]})" for k in allowed)
        if present:
            raise DataError(path, f"{accept.purpose} needs the {role} {need}: {accept.why}; "
                            f"this file has {present[0]}", line=1, column=present[0])
        raise DataError(path, f"missing column: {accept.purpose} needs an {role} column, "
                        f"{need} ({accept.why}); the header reads {_shown(','.join(header))}",
                        line=1, column=allowed[0])


def read_checked_recording(path: str | Path, known: Mapping[str, float] | None = None,
                           known_from: str = "the sidecar", *,
                           accept: Accepted | None = None) -> CheckedRecording:
    """Read a converted recording and check it as an instrument would (``data.checks``).

    The format: time (s), one input and one output column, extras allowed. Input
    ``base_acc`` (m/s^2) or ``force`` (N); output ``rel_acc`` (m/s^2) or ``rel_disp`` (m)
    (``harvester.data.recording.recording_kinds`` tells which from the columns); ``accept``
    narrows them for a command that takes fewer, saying why. Every column must be numeric with
    no NaN or empty rows, the time base uniform (``signals.time_base``), at least 64 samples.
    Then ``checks.check_recording``: absurd magnitudes, a clock in ms, gravity left in or mm,
    dead channels, saturation, a unit slip judged from the physics with ``known`` M, m, k
    (default: the sidecar's); its warnings are returned, not logged.
    """
    path = Path(path)
    sidecar = read_sidecar(path)
    header, rows, lines = _read_rows(path)
    check_annotations(header, path)
    if "time" not in header:
        raise DataError(path, f"missing column: the header reads {_shown(','.join(header))}; "
                        "expected time (s), an input (base_acc in m/s^2 or force in N) and an "
                        "output (rel_acc in m/s^2 or rel_disp in m), comma-separated",
                        line=1, column="time")
    _check_accepted(path, header, accept or FORMAT_KINDS)
    kinds = recording_kinds(header, path)
    df = _numeric_table(path, header, rows, lines)
    if len(df) < MIN_SAMPLES:
        raise DataError(path, f"{len(df)} samples" + (" (no data rows after the header)"
                        if not rows else "") + f"; at least {MIN_SAMPLES} are needed")
    dt, _ = _uniform_time(path, df, header, rows, lines)
    known = sidecar.known if known is None else known
    found = check_recording(df, kinds, dt, path, known, lines, known_from,
                            sidecar.filtered_at_hz, sidecar.units)
    return CheckedRecording(df, kinds, dt, sidecar, found)


def read_recording(path: str | Path) -> pd.DataFrame:
    """Read a converted recording (:func:`read_checked_recording`), logging the checks'
    warnings; for the workflow's scripts."""
    checked = read_checked_recording(path)
    for warning in checked.warnings:
        log.warning("%s", warning)
    return checked.data


def read_static_test(csv_path: str | Path,
                     json_path: str | Path) -> tuple[pd.DataFrame, dict[str, Any]]:
    """Read and validate the static friction test: repeat, direction, position_m (m, down +)."""
    csv_path, json_path = Path(csv_path), Path(json_path)
    meta = _read_json(json_path)
    _require(json_path, meta, "simulated", bool)
    position = _require(json_path, meta, "position", dict)
    if position.get("unit") != "m" or position.get("positive") != "down":
        raise DataError(json_path, "position must be in 'm', positive 'down'")
    repeats = _require(json_path, meta, "repeats", int)
    header, rows, lines = _read_rows(csv_path)
    if header != list(STATIC_COLUMNS):
        raise DataError(csv_path, f"header must be {','.join(STATIC_COLUMNS)}", line=1)
    seen: set[tuple[int, str]] = set()
    records = []
    for (rep, direction, pos), line in zip(rows, lines):
        if not rep.strip().isdigit() or int(rep) < 1:
            raise DataError(csv_path, f"repeat must be a positive integer, got {rep!r}",
                            line=line, column="repeat")
        if direction.strip() not in DIRECTIONS:
            raise DataError(csv_path, f"direction must be 'down' or 'up', got {direction!r}",
                            line=line, column="direction")
        key = (int(rep), direction.strip())
        if key in seen:
            raise DataError(csv_path, f"repeat {key[0]} '{key[1]}' appears twice", line=line)
        seen.add(key)
        records.append((*key, _to_float(csv_path, pos, line, "position_m")))
    for d in DIRECTIONS:
        n = sum(1 for _, di in seen if di == d)
        if n != repeats:
            raise DataError(csv_path, f"{n} '{d}' rows but {json_path.name} says repeats = "
                            f"{repeats}")
    return pd.DataFrame(records, columns=list(STATIC_COLUMNS)), meta


# --------------------------------------------------------------------------- checksums

def sha256(path: str | Path) -> str:
    """Hex SHA256 of a file."""
    digest = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def write_checksums(directory: str | Path, names: Iterable[str],
                    sums_name: str = "SHA256SUMS") -> Path:
    """Write ``sha256sum``-format checksums of ``names`` (files in ``directory``)."""
    directory = Path(directory)
    text = "".join(f"{sha256(directory / n)}  {n}\n" for n in names)
    out = directory / sums_name
    _write_text(out, text)
    return out


def read_checksums(sums_file: str | Path) -> dict[str, str]:
    """File name -> hex SHA256 from a ``sha256sum``-format file."""
    sums_file = Path(sums_file)
    sums: dict[str, str] = {}
    for line_no, line in enumerate(_read_text(sums_file).splitlines(), start=1):
        if not line.strip():
            continue
        digest, sep, name = line.partition(" ")
        name = name[1:] if name[:1] in (" ", "*") else name
        if not sep or len(digest) != 64 or not name:
            raise DataError(sums_file, "expected '<sha256>  <file name>'", line=line_no)
        sums[name] = digest.lower()
    return sums


def verify_checksums(sums_file: str | Path) -> list[Path]:
    """Check every file listed in a ``sha256sum``-format file; returns the files checked.

    Raises DataError naming the file that is missing or whose checksum does not match.
    """
    sums_file = Path(sums_file)
    checked = []
    for name, expected in read_checksums(sums_file).items():
        path = sums_file.parent / name
        if not path.is_file():
            raise DataError(path, f"listed in {sums_file} but missing")
        actual = sha256(path)
        if actual != expected:
            raise DataError(path, f"SHA256 {actual} does not match {expected} in {sums_file}")
        checked.append(path)
    return checked


def compare_checksums(committed: str | Path, regenerated: str | Path) -> str:
    """Report that two checksum files list the same files and digests (bit-for-bit rerun).

    Raises DataError naming the regenerated file that is missing, extra or different.
    """
    old, new = read_checksums(committed), read_checksums(regenerated)
    where = Path(regenerated).parent
    for name in sorted(old.keys() | new.keys()):
        if name not in new:
            raise DataError(where / name, f"listed in {committed} but not regenerated")
        if name not in old:
            raise DataError(where / name, f"regenerated but not listed in {committed}")
        if new[name] != old[name]:
            raise DataError(where / name, f"regenerated SHA256 {new[name]} differs from "
                            f"{old[name]} in {committed}: the rig no longer reproduces it")
    return "".join(f"identical  {digest}  {name}\n" for name, digest in old.items())
