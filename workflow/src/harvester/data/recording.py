"""What a recording measures: the kind of its input and output columns, their units, plausibility.

A converted recording (the input of ``harvester diagnose`` and of
:func:`harvester.inference.problems.make_problem`) has a ``time`` column (s) and declares by
its column names what drives the device and what was measured:

========== ====== ===================================================================
column     unit   meaning
========== ====== ===================================================================
base_acc   m/s^2  input: base acceleration y'' (eq. 1 driven by -m y'')
base_disp  m      input: base displacement y (laser, LVDT), zero-phase differentiated twice
                  into y'' for the model (``harvester.data.kinds``)
force      N      input: force on the mass, base fixed (eq. 1 driven by F; m unused)
rel_acc    m/s^2  output: z'' = x'' - y'', the mass's acceleration relative to the base
rel_disp   m      output: z, the mass's displacement relative to the base (to ground
                  for a force input), zero at the rest position the record starts from
========== ====== ===================================================================

Exactly one input and one output column; other numeric columns are carried along unused.
What each kind means to the model and to the diagnosis is its object in
``harvester.data.kinds``.

Units are SI only. A column that says it is in another unit (``rel_disp_mm``, ``base_acc [g]``,
``force_kN``) is reported, never converted silently, and so are values that only make sense in
another unit: an acceleration whose mean is 1 g or 1 (gravity left in, m/s^2 or g), a
displacement of metres beyond :data:`MAX_DISPLACEMENT_M` (mm). A column in g *without* gravity
or a force in kN cannot be told from its values alone; :func:`check_scale` catches them when a
parameter is known (the FRF fit's mass, or m/M, then differs from it by a factor of g or 1000).
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from harvester.data.errors import DataError
from harvester.data.signals import uniform_step

#: Standard gravity (m/s^2).
G = 9.80665

#: Input kinds: column name -> (SI unit, meaning).
INPUT_KINDS: dict[str, tuple[str, str]] = {
    "base_acc": ("m/s^2", "base acceleration y''"),
    "force": ("N", "force on the mass, base fixed"),
    "base_disp": ("m", "base displacement y (laser, LVDT)"),
}
#: Output kinds: column name -> (SI unit, meaning).
OUTPUT_KINDS: dict[str, tuple[str, str]] = {
    "rel_acc": ("m/s^2", "acceleration of the mass relative to the base, z''"),
    "rel_disp": ("m", "displacement of the mass relative to the base (to ground for a force "
                      "input), z"),
}
#: Every kind column and its SI unit.
UNITS: dict[str, str] = {**{k: u for k, (u, _) in INPUT_KINDS.items()},
                         **{k: u for k, (u, _) in OUTPUT_KINDS.items()}}

#: Largest plausible |relative displacement| (m): beyond it the column is probably in mm.
MAX_DISPLACEMENT_M = 5.0
#: Largest plausible velocity change (m/s) implied by an acceleration column's mean over the
#: record (mean x duration): relative and shaker velocities stay bounded.
MAX_VELOCITY_CHANGE = 2.0
#: A mean within this fraction of 1 g (or of 1) is named as gravity in m/s^2 (or in g).
GRAVITY_REL_TOL = 0.05

#: Unit spellings that are not SI, and what they are.
_NON_SI = {
    "g": "g (standard gravity)", "gs": "g (standard gravity)", "mg": "milli-g",
    "mm": "mm", "cm": "cm", "um": "micrometres", "µm": "micrometres", "in": "inches",
    "kn": "kN", "mn": "mN", "lbf": "pounds-force", "mm/s^2": "mm/s^2", "mm/s2": "mm/s^2",
    "ft/s^2": "ft/s^2", "v": "volts (not converted)", "mv": "millivolts (not converted)",
}
_SI = {"m/s^2", "m/s2", "ms-2", "m/s/s", "m", "n"}
_ANNOTATED = re.compile(
    r"^\s*(?P<kind>base_acc|base_disp|force|rel_acc|rel_disp)[\s_\-]*[\[(]?\s*"
    r"(?P<unit>[^\])\s]+)\s*[\])]?\s*$", re.IGNORECASE)


@dataclass(frozen=True)
class RecordingKinds:
    """The input kind ('base_acc' | 'base_disp' | 'force') and output kind ('rel_acc' |
    'rel_disp')."""

    input_kind: str
    output_kind: str

    @property
    def input_unit(self) -> str:
        return UNITS[self.input_kind]

    @property
    def output_unit(self) -> str:
        return UNITS[self.output_kind]


@dataclass(frozen=True)
class Accepted:
    """The kinds a command takes when it takes fewer than the format allows, and why."""

    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    purpose: str  # e.g. "harvester diagnose"
    why: str  # e.g. "its detection works on accelerations only"


def _annotated(name: str) -> tuple[str, str] | None:
    """(kind, unit) of a header such as ``rel_disp_mm`` or ``base_acc [g]``, else None."""
    if name in UNITS:
        return None
    match = _ANNOTATED.match(name)
    if match is None:
        return None
    return match["kind"].lower(), match["unit"]


def check_annotations(columns: Iterable[str], source: str | Path) -> None:
    """DataError for a kind column whose header names a unit (``rel_disp_mm``)."""
    for name in columns:
        found = _annotated(name)
        if found is None:
            continue
        kind, unit = found
        if unit.lower() in _SI:
            raise DataError(source, f"column {name!r} names its unit: call it {kind!r} "
                            f"(the format fixes the unit, {UNITS[kind]})", line=1, column=name)
        what = _NON_SI.get(unit.lower(), repr(unit))
        raise DataError(source, f"column {name!r} is in {what}; the format needs {kind!r} in "
                        f"{UNITS[kind]}: convert it (nothing is converted silently)", line=1,
                        column=name)


def recording_kinds(columns: Iterable[str] | pd.DataFrame,
                    source: str | Path = "<recording>") -> RecordingKinds:
    """Input and output kind declared by a recording's columns.

    Raises DataError (at line 1, the header) if the input or output column is missing or
    appears twice, or if a kind column names a unit other than the format's.
    """
    cols = list(columns.columns if isinstance(columns, pd.DataFrame) else columns)
    check_annotations(cols, source)
    found = {}
    for role, kinds in (("input", INPUT_KINDS), ("output", OUTPUT_KINDS)):
        present = [k for k in kinds if k in cols]
        if not present:
            first = next(iter(kinds))
            raise DataError(source, f"missing column: need an {role} column, one of "
                            f"{', '.join(kinds)}", line=1, column=first)
        if len(present) > 1:
            raise DataError(source, f"{len(present)} {role} columns ({', '.join(present)}): "
                            f"a recording has exactly one", line=1, column=present[1])
        found[role] = present[0]
    return RecordingKinds(found["input"], found["output"])


def check_plausible(df: pd.DataFrame, kinds: RecordingKinds,
                    source: str | Path = "<recording>") -> None:
    """DataError if a column's values only make sense in another unit.

    * acceleration (base_acc, rel_acc) whose mean is 1 g or 1 (within
      :data:`GRAVITY_REL_TOL`) and would change the velocity over the record by more than
      :data:`MAX_VELOCITY_CHANGE`: gravity left in, in m/s^2 or in g. (A relative velocity and
      a shaker's velocity stay bounded, so their accelerations average to ~0 over a long
      record; a smaller mean is left alone, as an accelerometer's bias may give one.)
    * displacement (rel_disp, base_disp) beyond :data:`MAX_DISPLACEMENT_M`: mm (or another
      small unit); one that moves faster than a rig can is a warning
      (``checks.fast_displacements``: a circuit in volts may).
    """
    t = df["time"].to_numpy(dtype=float)
    duration = float(t[-1] - t[0]) if t.size > 1 else 0.0
    for name in (kinds.input_kind, kinds.output_kind):
        x = df[name].to_numpy(dtype=float)
        if name in ("base_acc", "rel_acc"):
            mean = float(np.mean(x))
            if abs(mean) * duration <= MAX_VELOCITY_CHANGE:
                continue
            for level, unit in ((G, "m/s^2"), (1.0, "g")):
                if abs(abs(mean) - level) < GRAVITY_REL_TOL * level:
                    raise DataError(source, f"mean {mean:.4g} over {duration:.3g} s would "
                                    f"change the velocity by {abs(mean) * duration:.3g} m/s: "
                                    f"looks like gravity left in, in {unit}; {name} must be "
                                    "in m/s^2 with gravity removed", column=name)
        elif name in ("rel_disp", "base_disp"):
            peak = float(np.max(np.abs(x)))
            if peak > MAX_DISPLACEMENT_M:
                raise DataError(source, f"displacement up to {peak:.4g}: more than "
                                f"{MAX_DISPLACEMENT_M:g} m, probably mm; {name} must be in m",
                                column=name)


def check_scale(estimated: Mapping[str, float], known: Mapping[str, float],
                kinds: RecordingKinds, source: str | Path = "<recording>",
                tolerance: float = 0.25) -> None:
    """DataError if a data-estimated parameter is a known one times g, 1/g, 1000 or 1/1000.

    ``estimated``: values from the recording (e.g. the FRF fit's M, or m/M as ``m_over_M``);
    ``known``: the sidecar's values. A ratio within ``tolerance`` (relative) of a unit factor
    is the signature of a column in g, mm or kN; the message names the columns that could be.
    """
    factors = {G: "g instead of m/s^2 (or m/s^2 where g was meant)",
               1000.0: "mm instead of m, or N where kN (or kN where N) was meant"}
    for name, value in estimated.items():
        ref = known.get(name)
        if ref is None or not (np.isfinite(value) and ref and value):
            continue
        ratio = abs(value / ref)
        for factor, what in factors.items():
            for r in (factor, 1.0 / factor):
                if abs(ratio / r - 1.0) < tolerance:
                    raise DataError(source, f"the data give {name} = {value:.4g}, {ratio:.4g} "
                                    f"times the known {ref:.4g}: a column is probably in "
                                    f"{what} (input {kinds.input_kind} in {kinds.input_unit}, "
                                    f"output {kinds.output_kind} in {kinds.output_unit})")


def input_output(df: pd.DataFrame) -> tuple[RecordingKinds, np.ndarray, np.ndarray, float]:
    """(kinds, input, output, dt in s) of a recording DataFrame (columns as in the table above)."""
    kinds = recording_kinds(df)
    t = df["time"].to_numpy(dtype=float)
    dt = uniform_step(t)
    return (kinds, df[kinds.input_kind].to_numpy(dtype=float),
            df[kinds.output_kind].to_numpy(dtype=float), dt)
