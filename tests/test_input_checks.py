"""Bad input, checked as an instrument would check it (issue 23, item 1).

One table: each row makes a file from a valid 8 s recording (the tanh device through the
study's measurement chain, M, m, k in its sidecar) and says what the command line must do:
exit 2 with the file and the words that name the line or column, what was found and what was
expected, nothing written and the error printed once; or exit 0 with a warning carrying its
evidence. Rows that must fail run ``harvester diagnose`` (they fail before any work); rows
that pass run ``harvester check`` (the same reader and checks, without the minutes of
sampling; ``test_cli`` runs the commands end to end).
"""

from __future__ import annotations

import functools
import logging
import re
import time

import numpy as np
import pandas as pd
import pytest

from harvester.cli import main
from harvester.data import checks
from harvester.data.daq import read_checked_recording, write_recording
from harvester.data.errors import DataError
from harvester.data.recording import G, RecordingKinds
from harvester.synthetic.measured import TABLE1_KNOWN, TANH_TABLE5, measured_recording

SIDECAR = "M: 12.8\nm: 8.0\nk: 250.0\n"


@pytest.fixture(autouse=True)
def _restore_logging():
    yield
    logging.getLogger("harvester").handlers.clear()


@pytest.fixture(scope="module")
def valid() -> pd.DataFrame:
    df, _ = measured_recording(("tanh_friction",), {**TABLE1_KNOWN, **TANH_TABLE5}, 8.0, 5)
    return df


def _text(df: pd.DataFrame, tmp_path) -> str:
    """The CSV text of a recording (pandas, for tables the library would not write)."""
    return df.to_csv(index=False, float_format="%.10g", lineterminator="\n")


def _edit_cell(text: str, line: int, column: int, value: str) -> str:
    """Replace one cell (1-based file line, 0-based column)."""
    lines = text.splitlines()
    cells = lines[line - 1].split(",")
    cells[column] = value
    lines[line - 1] = ",".join(cells)
    return "\n".join(lines) + "\n"


def _clip(x: np.ndarray, share: float) -> np.ndarray:
    lo, hi = np.quantile(x, [share / 2, 1 - share / 2])
    return np.clip(x, lo, hi)


def _flat(x: np.ndarray, start: int, n: int) -> np.ndarray:
    y = x.copy()
    y[start:start + n] = y[start]
    return y


# Each maker gets (valid DataFrame, tmp_path) and returns (file text or None, sidecar text or
# None); None text means the maker wrote (or deliberately did not write) the file itself.
def _df(f):
    return lambda df, tmp: (_text(f(df.copy()), tmp), SIDECAR)


def _txt(f, sidecar=SIDECAR):
    return lambda df, tmp: (f(_text(df, tmp)), sidecar)


def _force(f):
    """The valid recording driven by the force that moves its mass as its base did,
    F = -m y'' (eq. 1), in N; M, k in the sidecar."""
    def make(df, tmp):
        d = df.assign(force=-8.0 * df.base_acc)[["time", "force", "rel_acc"]]
        return _text(f(d), tmp), "M: 12.8\nk: 250.0\n"
    return make


@functools.lru_cache(maxsize=1)
def displacement_recording() -> pd.DataFrame:
    """8 s at 256 Hz of the tanh device under a base displacement of three sines (1 cm each at
    0.7, 1.3, 2.1 Hz) as a laser would record it: base_disp, and rel_disp with 10 um noise."""
    from harvester.model.simulate import simulate
    from harvester.model.structures import Layout
    fs, n = 256.0, 2048
    t = np.arange(n) / fs
    freqs, phases = np.array([0.7, 1.3, 2.1]), np.array([0.3, 1.1, 2.0])
    w = 2 * np.pi * freqs[:, None]
    y = 0.01 * np.sum(np.sin(w * t + phases[:, None]), axis=0)
    acc = -0.01 * np.sum(w**2 * np.sin(w * t + phases[:, None]), axis=0)
    lay = Layout.of(("tanh_friction",))
    values = {**TABLE1_KNOWN, **TANH_TABLE5}
    sim = simulate(lay, np.array([values[p] for p in lay.parameter_names]), acc, 1 / fs)
    z = sim.rel_disp[0] + 1e-5 * np.random.default_rng(3).standard_normal(n)
    return pd.DataFrame({"time": t, "base_disp": y, "rel_disp": z})


def _disp(f, sidecar=SIDECAR):
    return lambda df, tmp: (_text(f(displacement_recording().copy()), tmp), sidecar)


@functools.lru_cache(maxsize=1)
def acceleration_displacement_recording() -> pd.DataFrame:
    """:func:`displacement_recording` as base_acc -> rel_disp: its base displacement
    differentiated twice (``harvester.data.kinds.model_recording``), the output in m."""
    from harvester.data.kinds import model_recording
    return model_recording(displacement_recording(), None)[0]


def _acc_disp(f, sidecar=SIDECAR):
    return lambda df, tmp: (_text(f(acceleration_displacement_recording().copy()), tmp),
                            sidecar)


def _random_walk(d: pd.DataFrame) -> pd.DataFrame:
    """A sensor wandering as a random walk of 0.2 mm steps (4.6 mm RMS over 8 s)."""
    walk = 2e-4 * np.cumsum(np.random.default_rng(7).standard_normal(len(d)))
    return d.assign(base_disp=d.base_disp + walk)


def _warming_up(d: pd.DataFrame) -> pd.DataFrame:
    """A sensor warming up: 1 cm approached with a 2 s time constant (a curved drift)."""
    return d.assign(base_disp=d.base_disp + 0.01 * (1.0 - np.exp(-d.time / 2.0)))


def _semicolons(text: str, decimal_comma: bool) -> str:
    rows = [line.split(",") for line in text.splitlines()]
    if decimal_comma:
        rows = [[c.replace(".", ",") for c in r] for r in rows]
    return "\n".join(";".join(r) for r in rows) + "\n"


def _decimal_commas(text: str) -> str:
    head, *rows = text.splitlines()
    return "\n".join([head] + [r.replace(",", ";").replace(".", ",").replace(";", ",")
                               for r in rows]) + "\n"


def _gap(df: pd.DataFrame) -> pd.DataFrame:
    return df.drop(index=range(1000, 1026)).reset_index(drop=True)  # 0.1 s missing


def _duplicate(df: pd.DataFrame) -> pd.DataFrame:
    df.loc[500, "time"] = df.loc[499, "time"]
    return df


ERROR = 2
OK = 0
CASES = [
    # id, maker, command, exit code, words in the message
    ("nan", _txt(lambda t: _edit_cell(t, 42, 2, "NaN")), "diagnose", ERROR,
     ["line 42", "column 'rel_acc'", "NaN"]),
    ("empty_cell", _txt(lambda t: _edit_cell(t, 17, 1, "")), "diagnose", ERROR,
     ["line 17", "column 'base_acc'", "empty value"]),
    ("missing_column", _df(lambda d: d.drop(columns="rel_acc")), "diagnose", ERROR,
     ["line 1", "column 'rel_acc'", "missing column: harvester diagnose needs an output column",
      "rel_acc (m/s^2) or rel_disp (m)", "the header reads 'time,base_acc'"]),
    ("header_only", _txt(lambda t: t.splitlines()[0] + "\n"), "diagnose", ERROR,
     ["0 samples (no data rows after the header); at least 64"]),
    ("too_short", _df(lambda d: d.iloc[:1280]), "diagnose", ERROR,
     ["too short: 5.00 s", "needs at least 6.83 s"]),
    ("duplicate_times", _df(_duplicate), "diagnose", ERROR,
     ["line 502", "column 'time'", "time does not increase: 1.94921875 s after 1.94921875 s"]),
    ("negative_M", _txt(lambda t: t, "M: -12.8\nm: 8.0\nk: 250.0\n"), "diagnose", ERROR,
     ["rec.yaml, line 1", "'M' must be a positive number", "-12.8"]),
    ("unknown_sidecar_key", _txt(lambda t: t, "M: 12.8\nstiffness: 250\n"), "diagnose", ERROR,
     ["rec.yaml, line 2", "unknown key(s) ['stiffness']", "k (stiffness (N/m))"]),
    ("m_above_M", _txt(lambda t: t, "M: 8.0\nm: 12.8\nk: 250.0\n"), "diagnose", ERROR,
     ["rec.yaml, line 2", "m = 12.8 kg > M = 8 kg: impossible"]),
    ("missing_file", lambda df, tmp: (None, None), "diagnose", ERROR,
     ["rec.csv: file not found"]),
    ("directory", lambda df, tmp: ((tmp / "rec.csv").mkdir(), None)[::-1], "diagnose", ERROR,
     ["rec.csv: cannot read", "directory"]),
    ("gravity_left_in", _df(lambda d: d.assign(base_acc=d.base_acc + G)), "diagnose", ERROR,
     ["column 'base_acc'", "gravity left in, in m/s^2", "gravity removed"]),
    ("gap_0.1s", _df(_gap), "diagnose", ERROR,
     ["line 1002", "column 'time'", "step 0.10546875 s", "expected 0.00390625 s",
      "about 26 samples missing"]),
    ("semicolons", _txt(lambda t: _semicolons(t, False)), "diagnose", ERROR,
     ["line 1", "'time;base_acc;rel_acc'", "separated by semicolons", "needs commas"]),
    ("semicolons_decimal_commas", _txt(lambda t: _semicolons(t, True)), "diagnose", ERROR,
     ["line 1", "separated by semicolons", "'.' as the decimal point"]),
    ("decimal_commas", _txt(_decimal_commas), "diagnose", ERROR,
     ["line 2", "5 fields, the header has 3", "the row reads '0,0,0", "decimal commas?"]),
    ("dead_output", _df(lambda d: d.assign(rel_acc=0.0)), "diagnose", ERROR,
     ["column 'rel_acc'", "0 in all 2048 samples", "dead"]),
    ("saturated_30pct", _df(lambda d: d.assign(rel_acc=_clip(d.rel_acc.to_numpy(), 0.3))),
     "diagnose", ERROR, ["column 'rel_acc'", "saturated: ", "sit at the extreme value(s)",
                        "runs of up to", "at most 1% can be tolerated"]),
    ("base_acc_in_g", _df(lambda d: d.assign(base_acc=d.base_acc / G)), "diagnose", ERROR,
     ["median |rel_acc / base_acc|", "m/M = 0.625, from the sidecar", "factor g",
      "unit slipped"]),
    ("cell_1e300", _txt(lambda t: _edit_cell(t, 300, 1, "1e300")), "diagnose", ERROR,
     ["line 300", "column 'base_acc'", "1e+300 m/s^2", "beyond any sensor's range"]),
    ("time_in_ms", _df(lambda d: d.assign(time=d.time * 1000.0)), "diagnose", ERROR,
     ["line 3", "column 'time'", "0.256 Hz", "time column in ms", "256 Hz"]),
    # the other kinds (issue 41): a force, displacements, a base displacement
    ("force_in_kN", _force(lambda d: d.assign(force=d.force / 1000.0)), "diagnose", ERROR,
     ["median |rel_acc / force|", "1/M = 0.07812, from the sidecar", "factor 1000",
      "force in kN", "unit slipped"]),
    ("acceleration_as_force", _df(lambda d: d.rename(columns={"base_acc": "force"})),
     "diagnose", ERROR, ["|rel_acc / force|", "times the most a passive device allows",
                         "unit slipped"]),
    ("rel_disp_in_mm", _disp(lambda d: d.assign(rel_disp=d.rel_disp * 1000.0)), "diagnose",
     ERROR, ["column 'rel_disp'", "m/s RMS", "faster than the 5 m/s", "masses in kg",
             "probably mm"]),
    ("base_disp_in_mm", _disp(lambda d: d.assign(base_disp=d.base_disp * 1000.0)),
     "diagnose", ERROR, ["column 'base_disp'", "more than 5 m", "probably mm"]),
    ("rel_disp_in_mm_base_acc_in_m_s2", _acc_disp(lambda d: d.assign(rel_disp=d.rel_disp * 1e3)),
     "diagnose", ERROR, ["column 'rel_disp'", "moves at 17.2 m/s RMS", "probably mm",
                         "in m it would move at 0.0172 m/s", "rel_disp must be in m"]),
    ("base_disp_in_mm_below_5", _disp(lambda d: d.assign(base_disp=d.base_disp * 50.0,
                                                         rel_disp=d.rel_disp * 0.05)),
     "diagnose", ERROR, ["column 'base_disp'", "moves at 5.58 m/s RMS", "probably mm",
                         "base_disp must be in m"]),
    ("rel_disp_unit_in_header", _disp(lambda d: d.rename(columns={"rel_disp": "rel_disp_mm"})),
     "diagnose", ERROR, ["line 1", "column 'rel_disp_mm'", "in mm", "'rel_disp' in m"]),
    ("no_sidecar", _txt(lambda t: t, None), "diagnose", ERROR,
     ["rec.yaml", "needs M, m, k", "no sidecar", "--paper-device"]),
    ("unit_in_header", _txt(lambda t: t.replace("base_acc", "base_acc [g]", 1)), "diagnose",
     ERROR, ["line 1", "column 'base_acc [g]'", "in g (standard gravity)", "convert it"]),
    # data that may be right: exit 0, a warning with its evidence
    ("utf8_bom", _txt(lambda t: "\ufeff" + t), "check", OK, ["0 warning(s)"]),
    ("crlf", _txt(lambda t: t.replace("\n", "\r\n")), "check", OK, ["0 warning(s)"]),
    ("saturated_few", _df(lambda d: d.assign(rel_acc=_clip(d.rel_acc.to_numpy(), 0.004))),
     "check", OK, ["column 'rel_acc'", "sit at the extreme value(s)", "runs of up to"]),
    ("dropout", _df(lambda d: d.assign(base_acc=_flat(d.base_acc.to_numpy(), 700, 256))),
     "check", OK, ["column 'base_acc'", "256 equal values", "1 s) from line 702", "dropout"]),
    ("spike", _txt(lambda t: _edit_cell(t, 900, 2, "300")), "check", OK,
     ["line 900", "column 'rel_acc'", "robust sd", "the largest is 300"]),
    ("output_in_g", _df(lambda d: d.assign(rel_acc=d.rel_acc / G)), "check", OK,
     ["|rel_acc / base_acc|", "times the most a passive device allows", "rel_acc in g"]),
    ("clock_against_device", _txt(lambda t: t, "M: 12.8\nm: 8.0\nk: 2.5e7\n"), "check", OK,
     ["natural frequency", "222 Hz", "clock does not match the device"]),
    ("constant_extra_column", _df(lambda d: d.assign(temperature=21.0)), "check", OK,
     ["column 'temperature'", "constant (21)", "not used"]),
    ("paper_device_assumed", _txt(lambda t: t, None), "check --paper-device", OK,
     ["ASSUMED (not measured)", "M = 12.8 kg", "the paper's Table 1 (--paper-device)"]),
    ("force_valid", _force(lambda d: d), "check", OK, ["0 warning(s)"]),
    ("force_in_mN", _force(lambda d: d.assign(force=d.force * 1000.0)), "check", OK,
     ["median |rel_acc / force| is 4.274e-05", "0.000547 times the most a passive device",
      "1/M = 0.07812, from the sidecar", "factor 1000", "a unit slip (force in mN"]),
    ("displacements_valid", _disp(lambda d: d), "check", OK, ["0 warning(s)"]),
    ("acceleration_displacement_valid", _acc_disp(lambda d: d), "check", OK, ["0 warning(s)"]),
    ("fast_displacements_no_masses", _disp(lambda d: d.assign(base_disp=d.base_disp * 100.0,
                                                               rel_disp=d.rel_disp * 100.0),
                                            None),
     "check", OK, ["column 'base_disp'", "m/s RMS", "faster than the 5 m/s", "in mm?",
                   "a circuit in volts"]),
    ("drifting_base", _disp(lambda d: d.assign(base_disp=d.base_disp + 0.004 * d.time)),
     "check", OK, ["column 'base_disp'", "drifts by 0.03", "m over 8 s", "RMS oscillation",
                   "drifting sensor"]),
    ("drifting_base_random_walk", _disp(_random_walk), "check", OK,
     ["column 'base_disp'", "drifts by -0.01249 m over 8 s", "0.98 times its RMS oscillation",
      "more than 0.5 is reported", "drifting sensor"]),
    ("drifting_base_warming_up", _disp(_warming_up), "check", OK,
     ["column 'base_disp'", "drifts by 0.007361 m over 8 s", "0.62 times its RMS oscillation",
      "a laser or LVDT warming up", "a curved one adds a slow acceleration"]),
]


@pytest.mark.parametrize("maker, command, code, words",
                         [pytest.param(*c[1:], id=c[0]) for c in CASES])
def test_bad_input_matrix(valid, tmp_path, capsys, maker, command, code, words):
    text, sidecar = maker(valid, tmp_path)
    rec = tmp_path / "rec.csv"
    if text is not None:
        rec.write_text(text, newline="")
    if sidecar is not None:
        (tmp_path / "rec.yaml").write_text(sidecar)
    out = tmp_path / "out"
    cmd, *flags = command.split()
    args = [cmd, str(rec), *flags, "--log", str(tmp_path / "log.txt")]
    if cmd == "diagnose":
        args += ["--baseline", "tanh", "--out", str(out), "--fast", "--particles", "40",
                 "--chains", "1", "--no-figures"]
    start = time.perf_counter()
    assert main(args) == code
    std = capsys.readouterr()
    said = std.err if code == ERROR else std.out
    for w in words:
        assert w in said, (w, said)
    if code == ERROR:
        assert std.err.count("harvester: error:") == 1, std.err  # printed once
        assert "rec." in std.err
        assert not out.exists() and not list(tmp_path.glob(".out.*")), "something was written"
        assert time.perf_counter() - start < 15.0  # failed before the work
    elif words != ["0 warning(s)"]:
        assert "WARNING" in (tmp_path / "log.txt").read_text()  # and in the log


def test_the_matrix_covers_the_issue():
    """Every kind of bad input of issue 23 has a row (at least the 24 reported)."""
    ids = {c[0] for c in CASES}
    assert len(CASES) >= 24
    for case in ("nan", "empty_cell", "missing_column", "header_only", "too_short",
                 "duplicate_times", "negative_M", "unknown_sidecar_key", "missing_file",
                 "directory", "gravity_left_in", "gap_0.1s", "utf8_bom", "crlf", "dead_output",
                 "saturated_30pct", "base_acc_in_g", "cell_1e300", "time_in_ms", "semicolons",
                 "decimal_commas", "no_sidecar",
                 # issue 41: the new kinds
                 "force_in_kN", "force_in_mN", "rel_disp_in_mm", "base_disp_in_mm",
                 "base_disp_in_mm_below_5", "rel_disp_in_mm_base_acc_in_m_s2",
                 "drifting_base", "drifting_base_random_walk", "drifting_base_warming_up"):
        assert case in ids, case


def test_out_naming_a_file_fails_before_any_work(valid, tmp_path, capsys):
    write_recording(valid, tmp_path / "rec.csv")
    (tmp_path / "rec.yaml").write_text(SIDECAR)
    (tmp_path / "taken").write_text("someone's file\n")
    for cmd in (["diagnose", "--baseline", "tanh"], ["identify", "--model", "tanh"],
                ["compare", "--models", "linear", "tanh"],
                ["predict", "--posterior", str(tmp_path / "p.nc")]):
        start = time.perf_counter()
        code = main([cmd[0], str(tmp_path / "rec.csv"), *cmd[1:], "--out",
                     str(tmp_path / "taken"), "--log", str(tmp_path / "log.txt")])
        err = capsys.readouterr().err
        assert code == 2 and "taken: --out names an existing file" in err, (cmd, err)
        assert time.perf_counter() - start < 5.0
    assert (tmp_path / "taken").read_text() == "someone's file\n"
    # a directory holding the inputs, or other files, is not replaced by results
    (tmp_path / "notes").mkdir()
    (tmp_path / "notes" / "todo.txt").write_text("keep me\n")
    for out, words in ((tmp_path, "holds the input"), (tmp_path / "notes", "holding other files")):
        code = main(["identify", str(tmp_path / "rec.csv"), "--model", "linear", "--out",
                     str(out)])
        err = capsys.readouterr().err
        assert code == 2 and words in err, err
    assert (tmp_path / "notes" / "todo.txt").exists() and (tmp_path / "rec.csv").exists()
    code = main(["identify", str(tmp_path / "rec.csv"), "--model", "linear", "--out",
                 str(tmp_path / "new"), "--log", str(tmp_path / "new" / "log.txt")])
    assert code == 2 and "--log lies inside --out" in capsys.readouterr().err
    assert not (tmp_path / "new").exists()


def test_errors_without_a_log_file_are_printed_once(tmp_path, capsys):
    code = main(["check", str(tmp_path / "nothing.csv")])
    err = capsys.readouterr().err
    assert code == 2 and err.count("file not found") == 1, err


# --------------------------------------------------------------------------- the checks alone


def test_checks_pass_the_bundled_recordings_without_a_warning():
    """The study's converted records (unfiltered, with the rocking mode) and its 20 Hz
    low-passed training record raise nothing, with the paper's M, m, k."""
    from pathlib import Path

    from harvester.data.daq import read_raw_record, to_accelerations
    from harvester.data.signals import filter_recording
    raw = Path(__file__).parents[1] / "data" / "raw"
    for name in ("training", "validation"):
        df = to_accelerations(*read_raw_record(raw / f"{name}.csv", raw / f"{name}.json"))
        for frame in (df, filter_recording(df, 20.0, 8)):
            kinds = RecordingKinds("base_acc", "rel_acc")
            found = checks.check_recording(frame, kinds, 1 / 256.0, name, dict(TABLE1_KNOWN))
            assert found == [], found


@pytest.mark.parametrize("factor, expected", [(1.0, None), (1 / G, "factor g"),
                                              (1e-3, "factor 1000")])
def test_unit_slip_judged_from_the_mass_ratio(valid, factor, expected):
    kinds = RecordingKinds("base_acc", "rel_acc")
    df = valid.assign(base_acc=valid.base_acc * factor)
    if expected is None:
        g = checks.gain_above_resonance(df, kinds, 1 / 256.0, TABLE1_KNOWN)
        assert 0.3 < g["ratio"] < 1.5
        assert checks.check_units_by_physics(df, kinds, 1 / 256.0, TABLE1_KNOWN, "r") == []
    else:
        with pytest.raises(DataError, match=expected):
            checks.check_units_by_physics(df, kinds, 1 / 256.0, TABLE1_KNOWN, "r")


def test_heavy_friction_is_not_taken_for_a_unit_slip():
    """50 N of friction under a 4 m/s^2 shaker holds the mass most of the time: the median
    gain is an eighth of the bound, but the gain at the top of the band is not."""
    heavy = {**TABLE1_KNOWN, "c_m": 40.0, "F_c": 50.0, "beta": 200.0}
    df, _ = measured_recording(("tanh_friction",), heavy, 10.0, 4)
    kinds = RecordingKinds("base_acc", "rel_acc")
    g = checks.gain_above_resonance(df, kinds, 1 / 256.0, TABLE1_KNOWN)
    assert g["ratio"] < 0.2 < g["ratio_p90"]
    assert checks.check_units_by_physics(df, kinds, 1 / 256.0, TABLE1_KNOWN, "r") == []


def test_unit_slip_of_a_force_input_needs_the_mass(tmp_path):
    """Force in kN for a 10 kg mass: the gain |z''/F| is 1000 x the 1/M a device allows."""
    from test_recording_kinds import TRUTH, synthetic
    df = synthetic("force", "rel_acc", n=1600, noise=0.01)
    kinds = RecordingKinds("force", "rel_acc")
    known = {"M": TRUTH["M"], "k": TRUTH["k"]}
    assert checks.check_units_by_physics(df, kinds, 1 / 200.0, known, "r") == []
    assert checks.check_units_by_physics(df, kinds, 1 / 200.0, {}, "r") == []  # M unknown
    with pytest.raises(DataError, match="1/M = 0.1, from the sidecar.*factor 1000.*force in kN"):
        checks.check_units_by_physics(df.assign(force=df.force / 1000), kinds, 1 / 200.0,
                                      known, "r")


#: Said of a slip in one column, x1000: its verdict, gain over the bound, and the slips named.
_ALLOWS = "times the most a passive device allows"
SLIP_SAID = [
    ("base_acc", "rel_disp", "rel_disp",
     f"error: .* 994 {_ALLOWS}.*e.g. base_acc in g or rel_disp in mm\\)"),
    ("force", "rel_disp", "force", f"warning: .* 0.000994 {_ALLOWS}.*unit slip \\(force in mN\\)"),
    ("base_acc", "rel_acc", "base_acc",
     f"warning: .* 0.000994 {_ALLOWS}.*unit slip \\(base_acc in mm/s\\^2 or rel_acc in g\\)")]


@pytest.mark.parametrize("inp, out, column, expected", SLIP_SAID)
def test_a_unit_slip_names_the_slips_that_move_the_gain_its_way(inp, out, column, expected):
    """x1000 on one column of a broadband recording of a 10 kg device: the gain 1000 times
    too high is refused naming the slips that raise it (an output in mm, an input in g or
    kN), too low is a warning naming those that lower it (a force in mN, a base_acc in
    mm/s^2, a rel_acc in g)."""
    from test_recording_kinds import TRUTH, synthetic
    df = synthetic(inp, out, n=1600, noise=0.01)
    kinds = RecordingKinds(inp, out)
    assert checks.check_units_by_physics(df, kinds, 1 / 200.0, TRUTH, "r") == []
    df[column] *= 1000.0
    try:
        said = "warning: " + " ".join(str(w) for w in checks.check_units_by_physics(
            df, kinds, 1 / 200.0, TRUTH, "r"))
    except DataError as err:
        said = f"error: {err}"
    assert re.search(expected, said), said


def test_reader_returns_the_warnings_and_the_sidecar(valid, tmp_path):
    df = valid.assign(rel_acc=_clip(valid.rel_acc.to_numpy(), 0.004))
    write_recording(df, tmp_path / "r.csv")
    (tmp_path / "r.yaml").write_text("M: 12.8\nm: 8.0\nk: 250.0\nfiltered_at_hz: 20\n")
    checked = read_checked_recording(tmp_path / "r.csv")
    assert checked.sidecar.known == TABLE1_KNOWN and checked.sidecar.filtered_at_hz == 20.0
    assert [w.check for w in checked.warnings] == ["saturation"]
    assert "r.csv, line" in str(checked.warnings[0])


def _two_accelerometers(seconds: float = 60.0, fs: float = 256.0, seed: int = 3,
                        rms: float = 2.0):
    """A linear device (M 10 kg, m 3 kg, f_n 1.5 Hz, 5 % damping) shaken over 0.3-5 Hz
    (``rms`` m/s^2), rel_acc formed as the mass's accelerometer minus the base's, each with
    0.05 m/s^2 of white noise: beyond 5 Hz the base channel holds its noise alone, and
    rel_acc holds the same noise with gain -1. Synthesised in the frequency domain (periodic,
    no start-up)."""
    rng = np.random.default_rng(seed)
    n = int(seconds * fs)
    f = np.fft.rfftfreq(n, 1.0 / fs)
    spec = np.where((f > 0.3) & (f < 5.0), np.exp(2j * np.pi * rng.uniform(size=f.size)), 0)
    y = np.fft.irfft(spec, n)
    y *= rms / np.std(y)
    M, m, k = 10.0, 3.0, 10.0 * (2 * np.pi * 1.5) ** 2
    w = 2 * np.pi * f
    z = np.fft.irfft(np.fft.rfft(y) * m * w**2 / (k - M * w**2 + 2j * 0.05 * np.sqrt(k * M) * w),
                     n)
    base_noise, mass_noise = 0.05 * rng.standard_normal((2, n))
    df = pd.DataFrame({"time": np.arange(n) / fs, "base_acc": y + base_noise,
                       "rel_acc": z + mass_noise - base_noise})
    return df, {"M": M, "m": m, "k": k}


@pytest.mark.parametrize("rms", [2.0, 0.25])
def test_a_base_sensors_noise_shared_by_rel_acc_is_not_a_unit_slip(rms):
    """Beyond the excitation's band the coherent FRF lines hold the base sensor's noise at
    gain 1, above the device's m/M = 0.3: the record is read with a warning that says so (it
    was refused as a unit slip); a slip by g on the same record is still refused. At 0.25
    m/s^2 the noise's lines reach 1.5e-3 of the excitation's strongest (the literature
    grid's effect-free seed 36: 1.4e-3), which a rule of 1e-3 of that line missed."""
    df, known = _two_accelerometers(rms=rms)
    kinds = RecordingKinds("base_acc", "rel_acc")
    g = checks.gain_above_resonance(df, kinds, 1 / 256.0, known)
    assert g["ratio"] > checks.UNIT_RATIO and g["ratio_ceiling"] < checks.UNIT_RATIO
    found = checks.check_units_by_physics(df, kinds, 1 / 256.0, known, "r")
    assert len(found) == 1 and "the base sensor's own noise" in str(found[0])
    with pytest.raises(DataError, match="factor g"):
        checks.check_units_by_physics(df.assign(base_acc=df.base_acc / G), kinds, 1 / 256.0,
                                      known, "r")
