"""Readers of public recordings of real devices into the recording format.

Each reader takes the files as published (read only; nothing is downloaded) and returns a
recording (``harvester.data.recording``: time, one input, one output, SI units) and the
sidecar (``harvester.data.sidecar``) its source gives, with what was done said in ``notes``.

* :func:`marino_frame`: the base-excited single-storey frame with a brass-on-steel friction
  contact of Marino and Cicirello (2023): laser displacements of the storey x and of the base
  y in mm at 250 Hz -> ``base_disp`` = y and ``rel_disp`` = x - y in m, both low-passed
  (zero phase) at :data:`FRAME_LOWPASS_HZ` (above 10 Hz the channels hold sensor noise only,
  and the base displacement is differentiated twice for the model), each about its mean (the
  lasers' zero is arbitrary); sidecar M = m = 3.0799 kg, k = 1191 N/m (their initial
  estimates, from tests without the contact), filtered_at_hz.
* :func:`silverbox`: the Silverbox electronic Duffing oscillator (Wigren and Schoukens 2013):
  input V1 (a force, in volts) -> ``force``, output V2 (a displacement, in volts) ->
  ``rel_disp``, each about its mean (their offsets are measurement errors); M, m, k unknown,
  so no device values: the values are volts, not N and m, which the sidecar's
  ``units: {force: V, displacement: V}`` says (:data:`SILVERBOX_UNITS`; the diagnosis labels
  its sizes with them, ``harvester.data.units``). :func:`silverbox_heldout` cuts
  it into samples to fit and samples held out after them (a simulation-error test), and
  :func:`silverbox_benchmark` cuts SNLS80mV.mat as the benchmark does.

The shared data directory's SOURCE.md files give the provenance.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from harvester.data.errors import DataError
from harvester.data.signals import lowpass

#: The frame's device (Marino and Cicirello 2023, initial estimates): M z'' + C z' + K z
#: + F_f = -M y'' with z = x - y, so m = M.
FRAME_DEVICE = {"M": 3.0799, "m": 3.0799, "k": 1191.0}
#: Zero-phase low-pass (Hz, order 8) of both frame channels: above 10 Hz they hold sensor
#: noise only (SOURCE.md), and that noise is common to both lasers: with a 20 Hz low-pass the
#: storey's absolute x follows F = K y at 9.5-15.5 Hz with 17.9 times the gain a passive mass
#: allows (the unit check's error), which relative to the base (x - y) does not show, so a
#: recording rewritten with its friction on the ground (``kinds.on_ground``) would carry it.
FRAME_LOWPASS_HZ = 10.0
FRAME_FILTER_ORDER = 8
#: The benchmark's own cuts of SNLS80mV.mat (samples [start, stop)), as nonlinearbenchmark.org's
#: data loader makes them (github.com/GerbenBeintema/nonlinear_benchmarks,
#: ``nonlinear_benchmarks/benchmarks.py``, ``Silverbox``): the multisine's first 75 % to train
#: on, its last 25 % and the 'arrow' (whose end extrapolates in amplitude; without it, its
#: first 32000 samples) to test on. Errors are RMS errors (mV) on the tests after their first
#: :data:`SILVERBOX_INIT` samples, the model simulated for the test's input alone.
SILVERBOX_TRAIN = (40650, 105712)
SILVERBOX_TESTS = {"multisine": (105712, 127400), "arrow_full": (100, 40575),
                   "arrow_no_extrapolation": (100, 32100)}
#: Samples at a test's start not scored (the loader's state initialisation window).
SILVERBOX_INIT = 50
# Published free-run errors on these tests, each read in its source: harvester.data.published.

#: The Silverbox's units (its sidecar's ``units``): both channels in volts.
SILVERBOX_UNITS = {"force": "V", "displacement": "V"}
#: Its sidecar's ``filtered_at_hz``: no low-pass (:func:`_silverbox_sidecar`). Both channels
#: fall at 190 Hz, the excitation's band edge (the input flat within 2 dB to 190 Hz, -20 dB by
#: 200 Hz), which a search of the output's spectrum takes for a filter at 181 Hz; filtering
#: the model's output there cost the cubic fit of the benchmark's first 8 s 5335 nats and
#: doubled its noise sd (0.76 against 0.33 mV) and its test errors (0.80 against 0.43 mV on
#: the arrow).
SILVERBOX_LOWPASS_HZ = 0
SILVERBOX_NO_LOWPASS = ("no low-pass (filtered_at_hz: 0): the roll-off of both channels at "
                        "190 Hz is the excitation's band edge, not a filter")
#: Silverbox sampling rate (Hz): 1e7 / 2^14.
SILVERBOX_FS = 1e7 / 2**14
#: First sample of its periodic multisine (SOURCE.md).
SILVERBOX_START = 10585


def _silverbox_sidecar() -> dict:
    """The Silverbox's sidecar: volts, no low-pass (:data:`SILVERBOX_LOWPASS_HZ`)."""
    return {"units": dict(SILVERBOX_UNITS), "filtered_at_hz": SILVERBOX_LOWPASS_HZ}


@dataclass
class PublicRecording:
    """A recording read from public files: the table, the sidecar's content (as a
    ``RECORDING.yaml`` would hold it) and what was done."""

    data: pd.DataFrame
    sidecar: dict
    notes: list[str] = field(default_factory=list)

    def write(self, csv_path: str | Path) -> Path:
        """The recording as ``csv_path`` and its sidecar beside it (``.yaml``, the notes as
        comments; written also when the source gives no device values, so that it says so)."""
        import yaml

        from harvester.data.daq import write_recording
        from harvester.data.sidecar import sidecar_path
        csv_path = Path(csv_path)
        csv_path.parent.mkdir(parents=True, exist_ok=True)
        write_recording(self.data, csv_path)
        head = "".join(f"# {line}\n" for line in self.notes)
        if not {"M", "m", "k"} & set(self.sidecar):
            head += "# no device values: its source gives none in SI units\n"
        body = yaml.safe_dump(self.sidecar, sort_keys=False) if self.sidecar else ""
        sidecar_path(csv_path).write_text(head + body)
        return csv_path


def _mat(path: Path, names: tuple[str, ...]) -> dict[str, np.ndarray]:
    """Variables of a MATLAB file as flat float arrays (DataError naming the file and what
    is missing)."""
    from scipy.io import loadmat
    if not path.is_file():
        raise DataError(path, "file not found")
    try:
        data = loadmat(str(path))
    except (OSError, ValueError, NotImplementedError) as err:
        raise DataError(path, f"cannot read as a MATLAB file: {err}") from None
    missing = [n for n in names if n not in data]
    if missing:
        found = sorted(k for k in data if not k.startswith("__"))
        raise DataError(path, f"no variable {', '.join(missing)} (found {', '.join(found)})")
    return {n: np.asarray(data[n], dtype=float).ravel() for n in names}


def marino_frame(directory: str | Path, load_g: int, friction_on: str = "base"
                 ) -> PublicRecording:
    """The frame's recording at the normal load ``load_g`` (g: 250 or 450 shipped) from
    ``directory``/s_b_{load}g_x.mat and _y.mat (module docstring).

    ``friction_on``: "base" (as recorded: base_disp -> rel_disp, the library's friction
    terms then act on the velocity relative to the base) or "ground", the frame's own
    topology (its contact is fixed to the ground): that same base form rewritten by
    :func:`harvester.data.kinds.on_ground`, the one place of that rewrite. The storey's
    equation in absolute coordinates, M x'' + C x' + K x + F_f(x') = K y + C y', becomes eq.
    (1) driven by the force F = K y (N, K the authors' 1191 N/m) with the output x = z + y (m,
    about its mean), so that every friction term acts on x'; the C y' part (C 0.669 N s/m,
    the authors' estimate) is left out of F, as the model's c_m is identified. The model's k
    must then be the K that made F (the sidecar gives it; m is dropped, M = m).
    """
    directory = Path(directory)
    xf, yf = (directory / f"s_b_{load_g}g_{c}.mat" for c in ("x", "y"))
    x, y = _mat(xf, ("t", "x")), _mat(yf, ("t", "y"))
    if x["t"].shape != y["t"].shape or not np.allclose(x["t"], y["t"], atol=1e-9):
        raise DataError(yf, f"its time t differs from {xf.name}'s: the channels are not one "
                        "record")
    t = x["t"] - x["t"][0]
    fs = 1.0 / float(np.mean(np.diff(t)))
    base = y["y"] / 1000.0
    rel = (x["x"] - y["y"]) / 1000.0
    base, rel = (lowpass(c, fs, FRAME_LOWPASS_HZ, FRAME_FILTER_ORDER) for c in (base, rel))
    if friction_on not in ("base", "ground"):
        raise ValueError(f"friction_on must be 'base' or 'ground', got {friction_on!r}")
    data = pd.DataFrame({"time": t, "base_disp": base - base.mean(),
                         "rel_disp": rel - rel.mean()})
    notes = [f"{xf.name}, {yf.name}: x, y (mm) -> base_disp = y, rel_disp = x - y (m), each "
             f"low-passed at {FRAME_LOWPASS_HZ:g} Hz (order {FRAME_FILTER_ORDER}, zero phase) "
             f"and taken about its mean; time from 0 (the file's starts at {x['t'][0]:g} s)"]
    sidecar = {**FRAME_DEVICE, "filtered_at_hz": FRAME_LOWPASS_HZ}
    if friction_on == "ground":
        from harvester.data.kinds import on_ground
        data, known, done = on_ground(data, FRAME_DEVICE, f"{xf.name}, {yf.name}")
        notes += [f"friction_on='ground' (marino_frame's argument, not a sidecar): the "
                  "recording above rewritten by harvester.data.kinds.on_ground (the C y' part "
                  "of the storey's drive left out, the model's c_m identified)"] + done
        sidecar = {**known, "filtered_at_hz": FRAME_LOWPASS_HZ}
    return PublicRecording(data, sidecar, notes)


def silverbox(path: str | Path, start: int = SILVERBOX_START,
              samples: int | None = None) -> PublicRecording:
    """The Silverbox record ``path`` (Schroeder80mV.mat) from sample ``start`` (``samples``
    of it, None: to the end) as force -> rel_disp in volts (module docstring)."""
    path = Path(path)
    v = _mat(path, ("V1", "V2"))
    stop = v["V1"].size if samples is None else start + int(samples)
    if not 0 <= start < stop <= v["V1"].size:
        raise DataError(path, f"samples {start}-{stop} outside its {v['V1'].size} samples")
    u, y = (v[c] - np.mean(v[c]) for c in ("V1", "V2"))
    n = stop - start
    data = pd.DataFrame({"time": np.arange(n) / SILVERBOX_FS, "force": u[start:stop],
                         "rel_disp": y[start:stop]})
    notes = [f"{path.name}: V1 -> force, V2 -> rel_disp, in VOLTS (the circuit's M, m, k are "
             f"not known in SI; units: force V, displacement V), each about its mean over the "
             f"file; samples {start}-{stop} at {SILVERBOX_FS:.6g} Hz"]
    return PublicRecording(data, _silverbox_sidecar(), notes + [SILVERBOX_NO_LOWPASS])


@dataclass(frozen=True)
class HeldOut:
    """A record cut for a simulation-error test: ``fit`` (the first samples, what a model is
    identified from), ``whole`` (the same samples continued by held-out ones and a margin)
    and ``section``, the held-out samples [start, stop) of ``whole`` its error is taken on."""

    fit: PublicRecording
    whole: PublicRecording
    section: tuple[int, int]


#: Samples after a held-out section read with it: a zero-phase output filter's end effects
#: (0.5 s at the Silverbox's rate, as ``recording_fit.END_EFFECTS_S``) fall on them.
SILVERBOX_MARGIN = 306


def silverbox_heldout(path: str | Path, fit_samples: int, held_samples: int,
                      start: int = SILVERBOX_START) -> HeldOut:
    """The Silverbox record ``path`` from ``start``: ``fit_samples`` to identify from, then
    ``held_samples`` not used in fitting, read on as one record from the same start so that
    a model simulated from rest for the input alone reaches them with the fit's transient
    long gone (:func:`silverbox`; both in volts)."""
    whole = silverbox(path, start, fit_samples + held_samples + SILVERBOX_MARGIN)
    fit = silverbox(path, start, fit_samples)
    return HeldOut(fit, whole, (fit_samples, fit_samples + held_samples))


@dataclass(frozen=True)
class BenchmarkSplit:
    """The Silverbox benchmark's record cut as published (:data:`SILVERBOX_TESTS`): ``fit``,
    the first samples of its training multisine (a recording, V), and per test the input and
    the measured output (V), both about the training samples' means (``offsets``: V1's and
    V2's there; an error on the centred output is the error on the raw one with the offset
    added back to the model's output)."""

    fit: PublicRecording
    tests: dict[str, tuple[np.ndarray, np.ndarray]]
    offsets: tuple[float, float]


def silverbox_benchmark(path: str | Path, fit_samples: int) -> BenchmarkSplit:
    """SNLS80mV.mat at ``path`` as the benchmark cuts it: the first ``fit_samples`` of the
    training multisine to identify from, the three tests to simulate (:class:`BenchmarkSplit`).
    Offsets from the training samples only: nothing of a test is used but its input."""
    path = Path(path)
    v = _mat(path, ("V1", "V2"))
    a, b = SILVERBOX_TRAIN
    last = max(stop for _, stop in SILVERBOX_TESTS.values())
    if v["V1"].size < last or not 0 < fit_samples <= b - a:
        raise DataError(path, f"{v['V1'].size} samples: expected the benchmark's 131072 "
                        f"(SNLS80mV.mat) and 0 < fit samples <= {b - a} (got {fit_samples})")
    off = (float(np.mean(v["V1"][a:b])), float(np.mean(v["V2"][a:b])))
    u, y = v["V1"] - off[0], v["V2"] - off[1]
    n = int(fit_samples)
    data = pd.DataFrame({"time": np.arange(n) / SILVERBOX_FS, "force": u[a:a + n],
                         "rel_disp": y[a:a + n]})
    notes = [f"{path.name}: the benchmark's training multisine, samples {a}-{a + n}: V1 -> "
             f"force, V2 -> rel_disp, in VOLTS, about their means over samples {a}-{b} "
             f"({1e3 * off[0]:.3f} and {1e3 * off[1]:.3f} mV)"]
    fit = PublicRecording(data, _silverbox_sidecar(), notes + [SILVERBOX_NO_LOWPASS])
    tests = {k: (u[i:j].copy(), y[i:j].copy()) for k, (i, j) in SILVERBOX_TESTS.items()}
    return BenchmarkSplit(fit, tests, off)


#: Samples of the Silverbox the study reads (8 s: of Schroeder80mV.mat from SILVERBOX_START, of
#: SNLS80mV.mat from the training multisine's start).
SILVERBOX_STUDY_SAMPLES = 4883


def public_recording(path: str | Path) -> PublicRecording:
    """A public benchmark's file read by its name (the recording sheet's kind ``public``):
    ``s_b_{load}g_x.mat`` the frame at that load (:func:`marino_frame` as recorded, with its
    ``_y.mat`` beside it; the sidecar adds ``friction_on: ground``, what its source says of
    the contact), ``Schroeder80mV.mat`` the Silverbox's first
    :data:`SILVERBOX_STUDY_SAMPLES` samples of the multisine (:func:`silverbox`),
    ``SNLS80mV.mat`` as many of the benchmark's training multisine
    (:func:`silverbox_benchmark`). DataError for any other file."""
    import re
    path = Path(path)
    frame = re.fullmatch(r"s_b_(\d+)g_x\.mat", path.name)
    if frame:
        rec = marino_frame(path.parent, int(frame.group(1)))
        rec.sidecar["friction_on"] = "ground"
        rec.notes.append(f"{path.name}: friction_on: ground (the contact is fixed to the "
                         "ground: SOURCE.md)")
        return rec
    if path.name == "Schroeder80mV.mat":
        return silverbox(path, samples=SILVERBOX_STUDY_SAMPLES)
    if path.name == "SNLS80mV.mat":
        return silverbox_benchmark(path, SILVERBOX_STUDY_SAMPLES).fit
    raise DataError(path, "not a public recording this reader knows: expected the frame's "
                    "s_b_{load}g_x.mat (with its _y.mat beside it) or the Silverbox's "
                    "Schroeder80mV.mat or SNLS80mV.mat")
