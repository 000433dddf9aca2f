"""The sidecar of a recording, ``RECORDING.yaml``: what is known about the device.

Keys (all optional):

============== ====== ===================================================================
key            unit   meaning
============== ====== ===================================================================
M              kg     effective mass m + J (2 pi / l)^2 (eq. 2)
m              kg     oscillating mass (M >= m)
k              N/m    spring stiffness
M_sd, m_sd,    as M,  the standard uncertainty of M, m, k as measured (default: DEFAULT_RELATIVE_SD
k_sd           m, k   of the value); the diagnosis holds the device a named effect implies
                      against the value +- it (``harvester.diagnosis.name.plausibility``)
priors                ``{parameter: {mean, sd}}``, e.g. a static test's ``F_c``
filtered_at_hz Hz     cut-off of a zero-phase low-pass the recording already went through (0:
                      none, and none is looked for in its spectrum)
friction_on           ``base`` or ``ground``: what the device's friction acts on, the
                      velocity relative to the base, or the mass's own (a contact fixed
                      to the ground, as on the frame of Marino and Cicirello);
                      ``harvester.data.kinds.on_ground`` writes such a recording. Not
                      given: relative to the base, except where ``harvester diagnose``
                      can compare both (``harvester.diagnosis.prepare.topology``)
units                 ``{force: UNIT, displacement: UNIT}``: the units of a recording not
                      in N and m (a circuit's volts: ``{force: V, displacement: V}``);
                      only the diagnosis's labels follow them (``harvester.data.units``);
                      not given: N and m
============== ====== ===================================================================

Parameters the sidecar does not give are identified where the method can (``harvester
identify``), or must be given, or assumed explicitly (``--paper-device``: the paper's Table 1),
where it cannot (``harvester diagnose``): :func:`resolve_known` says which and why, and what
was assumed is logged and written to the output.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from harvester.data.errors import DataError
from harvester.data.units import SI, Units, read_units

log = logging.getLogger("harvester.data.sidecar")

#: Keys of a sidecar and what each holds.
SIDECAR_KEYS: dict[str, str] = {
    "M": "effective mass (kg)", "m": "oscillating mass (kg)", "k": "stiffness (N/m)",
    "M_sd": "uncertainty of M (kg)", "m_sd": "uncertainty of m (kg)",
    "k_sd": "uncertainty of k (N/m)",
    "priors": "{parameter: {mean, sd}}", "filtered_at_hz": "low-pass already applied (Hz; 0: none)",
    "friction_on": "base or ground (what the friction acts on)",
    "units": "{force: UNIT, displacement: UNIT} where not N and m",
}
#: Device parameters a sidecar may give, with their units.
DEVICE_PARAMETERS: dict[str, str] = {"M": "kg", "m": "kg", "k": "N/m"}
#: The standard uncertainty of a sidecar's M, m or k where it states none (its ``M_sd``...),
#: relative to the value. Lenient on purpose: the diagnosis refuses a mass error only beyond
#: 3 of these (``harvester.diagnosis.name.plausibility``), a mass several times the stated one, not
#: a scale's error. The literature generator's mass-error records (payload and rotor inertia,
#: seeds 0-4 at 0.5, 1 and 2 x the noise RMS, 30 records) put the true M and m up to 26 % and
#: 35 % from their sidecar's: 2.3 of these at 15 %, 3.5 at 10 % (docs/diagnosis.md).
DEFAULT_RELATIVE_SD = 0.15


@dataclass(frozen=True)
class Sidecar:
    """A recording's sidecar as read: ``found`` False when there is none (all empty)."""

    path: Path
    found: bool = False
    known: dict[str, float] = field(default_factory=dict)
    priors: dict[str, dict[str, float]] = field(default_factory=dict)
    filtered_at_hz: float | None = None
    friction_on: str | None = None  # None: not stated (relative to the base unless compared)
    units: Units = SI  # the force's and the displacement's units (default N, m)
    known_sd: dict[str, float] = field(default_factory=dict)  # M_sd, m_sd, k_sd as given

    def uncertainty(self, name: str, value: float | None = None) -> float | None:
        """The standard uncertainty of device parameter ``name`` (M, m, k): the sidecar's
        ``<name>_sd``, else DEFAULT_RELATIVE_SD of ``value`` (default: the sidecar's own);
        None without either."""
        if name in self.known_sd:
            return self.known_sd[name]
        value = self.known.get(name) if value is None else value
        return None if value is None else DEFAULT_RELATIVE_SD * abs(float(value))

    def summary(self) -> dict[str, Any]:
        """For run.json: where it is and what it gave."""
        return {"path": str(self.path), "found": self.found, "known": dict(self.known),
                "priors": dict(self.priors), "filtered_at_hz": self.filtered_at_hz,
                "friction_on": self.friction_on, "units": self.units.to_sidecar(),
                "known_sd": dict(self.known_sd)}


def sidecar_path(recording: str | Path) -> Path:
    """``RECORDING.yaml`` beside ``RECORDING.csv``."""
    return Path(recording).with_suffix(".yaml")


def _key_lines(text: str) -> dict[str, int]:
    """1-based line of each top-level key of a YAML mapping ({} if not a mapping)."""
    import yaml
    node = yaml.compose(text)
    if not isinstance(node, yaml.MappingNode):
        return {}
    return {str(k.value): k.start_mark.line + 1 for k, _ in node.value}


def _positive(path: Path, key: str, value: Any, line: int | None) -> float:
    if isinstance(value, str):  # YAML 1.1 reads 2.5e7 (no sign in the exponent) as text
        try:
            value = float(value)
        except ValueError:
            pass
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not value > 0 \
            or value == float("inf"):
        raise DataError(path, f"'{key}' must be a positive number ({SIDECAR_KEYS[key]}), got "
                        f"{value!r}", line=line)
    return float(value)


def _cutoff_hz(path: Path, value: Any, line: int | None) -> float:
    """``filtered_at_hz``: a positive cut-off (Hz), or 0 for no low-pass."""
    if value == 0 and not isinstance(value, bool):
        return 0.0
    return _positive(path, "filtered_at_hz", value, line)


def _priors(path: Path, priors: Any, line: int | None) -> dict[str, dict[str, float]]:
    if not isinstance(priors, dict):
        raise DataError(path, f"'priors' must map parameter names to {{mean, sd}}, got "
                        f"{priors!r}", line=line)
    out = {}
    for name, spec in priors.items():
        ok = isinstance(spec, dict) and {"mean", "sd"} <= set(spec) and all(
            isinstance(spec[k], (int, float)) and not isinstance(spec[k], bool)
            for k in ("mean", "sd")) and spec["sd"] > 0
        if not ok:
            raise DataError(path, f"priors.{name} must be {{mean: number, sd: positive "
                            f"number}}, got {spec!r}", line=line)
        out[str(name)] = {k: float(v) for k, v in spec.items()}
    return out


def read_sidecar(recording: str | Path) -> Sidecar:
    """Read and check the sidecar beside ``recording`` (none: an empty Sidecar).

    DataError (file and line) for invalid YAML, a non-mapping, an unknown key, a value that
    is not a positive number, malformed priors, malformed units (``units.read_units``), or
    m > M (M = m + J (2 pi / l)^2 >= m).
    """
    import yaml
    path = sidecar_path(recording)
    if not path.exists():
        return Sidecar(path)
    try:
        text = path.read_text(encoding="utf-8-sig")
        meta, lines = yaml.safe_load(text), _key_lines(text)
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        raise DataError(path, f"invalid YAML: {getattr(err, 'problem', None) or err}",
                        line=mark.line + 1 if mark else None) from None
    except (OSError, UnicodeDecodeError) as err:
        raise DataError(path, f"cannot read: {err}") from None
    if meta is None:
        return Sidecar(path, found=True)
    if not isinstance(meta, dict):
        raise DataError(path, f"expected a mapping with keys {', '.join(SIDECAR_KEYS)}, got "
                        f"{type(meta).__name__}", line=1)
    unknown = sorted(str(k) for k in meta if k not in SIDECAR_KEYS)
    if unknown:
        raise DataError(path, f"unknown key(s) {unknown}; allowed: "
                        + ", ".join(f"{k} ({v})" for k, v in SIDECAR_KEYS.items()),
                        line=lines.get(unknown[0]))
    known = {k: _positive(path, k, meta[k], lines.get(k)) for k in DEVICE_PARAMETERS if k in meta}
    if "M" in known and "m" in known and known["m"] > known["M"]:
        raise DataError(path, f"m = {known['m']:g} kg > M = {known['M']:g} kg: impossible, the "
                        "effective mass M = m + J (2 pi / l)^2 includes m", line=lines.get("m"))
    known_sd = {k: _positive(path, f"{k}_sd", meta[f"{k}_sd"], lines.get(f"{k}_sd"))
                for k in DEVICE_PARAMETERS if f"{k}_sd" in meta}
    alone = [k for k in known_sd if k not in known]
    if alone:
        raise DataError(path, f"'{alone[0]}_sd' is the uncertainty of {alone[0]}, which this "
                        f"sidecar does not give: give {alone[0]} too, or drop it",
                        line=lines.get(f"{alone[0]}_sd"))
    cutoff = meta.get("filtered_at_hz")
    friction_on = meta.get("friction_on")
    if friction_on not in (None, "base", "ground"):
        raise DataError(path, f"'friction_on' must be base or ground (what the device's "
                        f"friction acts on), got {friction_on!r}", line=lines.get("friction_on"))
    return Sidecar(path, True, known, _priors(path, meta.get("priors", {}), lines.get("priors")),
                   None if cutoff is None else _cutoff_hz(path, cutoff,
                                                          lines.get("filtered_at_hz")),
                   friction_on, read_units(path, meta.get("units"), lines.get("units")),
                   known_sd)


@dataclass(frozen=True)
class KnownParameters:
    """The device parameters a command uses: ``values`` (all), ``given`` (by the sidecar),
    ``assumed`` (defaults filled in, and where they come from); the others are left to the
    identification."""

    values: dict[str, float]
    given: dict[str, float]
    assumed: dict[str, float]
    assumed_from: str

    def notes(self, sidecar: Sidecar) -> list[str]:
        """What was known, assumed and identified, in words (for the log and the output)."""
        where = sidecar.path if sidecar.found else f"no sidecar ({sidecar.path} not found)"
        out = [f"device parameters from {where}: " + (", ".join(
            f"{k} = {v:g} {DEVICE_PARAMETERS[k]}" for k, v in self.given.items()) or "none")]
        if self.assumed:
            out.append("ASSUMED (not measured): " + ", ".join(
                f"{k} = {v:g} {DEVICE_PARAMETERS[k]}" for k, v in self.assumed.items())
                + f" from {self.assumed_from}")
        return out

    @property
    def source(self) -> str:
        """Where the values come from, for messages."""
        return "the sidecar" + (f" and {self.assumed_from} (assumed)" if self.assumed else "")

    def require(self, required: Sequence[str], purpose: str, sidecar: Sidecar) -> None:
        """DataError naming the sidecar when a parameter ``purpose`` needs is neither given
        nor assumed."""
        missing = [p for p in required if p not in self.values]
        if missing:
            raise DataError(sidecar.path, f"{purpose} needs {', '.join(missing)} "
                            f"({', '.join(DEVICE_PARAMETERS[p] for p in missing)}), "
                            + ("which this sidecar does not give" if sidecar.found else
                               "and there is no sidecar") + ": write them there (e.g. "
                            f"'{missing[0]}: ...'), or pass --paper-device to assume the "
                            "paper's Table 1 values")


def resolve_known(sidecar: Sidecar, defaults: Mapping[str, float] | None = None,
                  defaults_from: str = "") -> KnownParameters:
    """The device parameters a command uses: the sidecar's, and ``defaults`` (an explicit
    choice of the user, e.g. the paper's Table 1) for those it lacks; the others are left to
    the identification (or refused by :meth:`KnownParameters.require`)."""
    given = dict(sidecar.known)
    assumed = {k: float(v) for k, v in (defaults or {}).items() if k not in given}
    return KnownParameters({**given, **assumed}, given, assumed,
                           defaults_from if assumed else "")
