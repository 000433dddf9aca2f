"""The units a recording's numbers are in: SI (N and m) unless its sidecar says otherwise.

A recording of a circuit (the Silverbox: a force and a displacement measured in volts) keeps
its numbers in its channels' own units; the sidecar's ``units`` key says which
(``units: {force: V, displacement: V}``; absent: N and m), and every size the diagnosis
writes takes its label from :meth:`Units.label` (and a small displacement's scale from
:meth:`Units.small`) instead of a hard "N" or "mm". Only the labels change: nothing is
converted (the numbers are the recording's).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from harvester.data.errors import DataError

#: Quantities of a sidecar's ``units`` and their SI unit (the default).
UNIT_QUANTITIES: dict[str, str] = {"force": "N", "displacement": "m"}
#: Quantities :meth:`Units.label` names, with their SI unit.
QUANTITIES: dict[str, str] = {
    "force": "N", "displacement": "m", "velocity": "m/s", "acceleration": "m/s^2",
    "stiffness": "N/m", "damping": "N s/m", "mass": "kg", "force rate": "N/s"}
_TOKEN = re.compile(r"\b(kg|N|m)\b")


@dataclass(frozen=True)
class Units:
    """The unit of the force and of the displacement (unit names; default N and m); every
    other quantity's follows from them (time stays in s)."""

    force: str = "N"
    displacement: str = "m"

    @property
    def si(self) -> bool:
        return (self.force, self.displacement) == ("N", "m")

    def label(self, what: str) -> str:
        """The label of a quantity (a :data:`QUANTITIES` name) or of an SI unit expression
        ("N s/m", "N/m^3", "kg") in these units: N -> the force's unit, m -> the
        displacement's, kg -> force s^2/displacement; unchanged when SI ("stiffness" ->
        "N/m", or "V/V" with volts)."""
        expr = QUANTITIES.get(what, what)
        if self.si:
            return expr
        mass = f"{self.force} s^2/{self.displacement}"
        mass = mass if expr == "kg" else f"({mass})"
        names = {"N": self.force, "m": self.displacement, "kg": mass}
        return _TOKEN.sub(lambda t: names[t.group(1)], expr)

    def small(self, what: str = "displacement") -> tuple[float, str]:
        """(scale, label) to show a small displacement-like quantity (``label``'s ``what``,
        e.g. "displacement" or "velocity"): with the displacement in m, 1e3 and "mm"
        ("mm/s"); in another unit, 1 and that unit's label (no factor)."""
        expr = QUANTITIES.get(what, what)
        if self.displacement == "m" and expr.startswith("m"):
            return 1e3, "m" + expr
        return 1.0, self.label(expr)

    def to_sidecar(self) -> dict[str, str]:
        """The sidecar's ``units`` mapping ({} for SI: the key is then left out)."""
        return {} if self.si else {"force": self.force, "displacement": self.displacement}


SI = Units()


def read_units(path: str | Path, value: Any, line: int | None = None) -> Units:
    """The sidecar ``path``'s ``units`` (``value``; None: SI). DataError naming the file,
    the key and its ``line`` for a non-mapping, an unknown quantity or a unit that is not a
    non-empty string."""
    if value is None:
        return SI
    allowed = ", ".join(f"{q} (default {u})" for q, u in UNIT_QUANTITIES.items())
    if not isinstance(value, dict):
        raise DataError(path, f"'units' must map quantities to unit names, e.g. "
                        f"{{force: V, displacement: V}}; got {value!r}", line=line)
    unknown = sorted(str(k) for k in value if k not in UNIT_QUANTITIES)
    if unknown:
        raise DataError(path, f"'units' has unknown quantity(ies) {unknown}; allowed: "
                        f"{allowed}", line=line)
    for q, unit in value.items():
        if not isinstance(unit, str) or not unit.strip():
            raise DataError(path, f"'units.{q}' must be a unit name (a non-empty string, "
                            f"e.g. V), got {unit!r}", line=line)
    return Units(**{q: str(u).strip() for q, u in value.items()})
