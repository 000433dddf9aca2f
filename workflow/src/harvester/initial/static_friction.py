"""The static friction test, eqs. (4)-(5) of Green et al. (2015).

With rest positions measured downward positive (x1 after a downward displacement, x2 after
an upward one), k x1 = m g + F_c and k x2 = m g - F_c, so F_c = k (x1 - x2) / 2. (The paper
writes 2 F_c = k (x2 - x1) with its own sign convention; the span is the same 0.067 m.)
"""

from __future__ import annotations

import logging
from dataclasses import asdict, dataclass, fields
from typing import Any

import numpy as np
import pandas as pd

from harvester.data.errors import DataError

log = logging.getLogger("harvester.initial")

# --------------------------------------------------------------------------- static test


@dataclass(frozen=True)
class StaticFrictionEstimate:
    """Static (Coulomb) friction from the static test, eqs. (4)-(5).

    F_c: mean over repeats of k (x1 - x2) / 2 (N); sd: standard deviation over repeats (N);
    se: standard error of the mean (N); n: number of paired repeats;
    span_m: mean of x1 - x2 (m), the paper's |x2 - x1| = 0.067 m.
    """

    F_c: float
    sd: float
    se: float
    n: int
    span_m: float

    def to_dict(self) -> dict[str, Any]:
        """Plain dict (for JSON)."""
        return asdict(self)

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> StaticFrictionEstimate:
        """Inverse of :meth:`to_dict` (extra keys ignored)."""
        return cls(**{f.name: d[f.name] for f in fields(cls)})


def _paired_rest_positions(df: pd.DataFrame, source: str) -> pd.DataFrame:
    """Rest positions (m) per repeat: columns ``down`` (x1) and ``up`` (x2)."""
    for column in ("repeat", "direction", "position_m"):
        if column not in df.columns:
            raise DataError(source, "static test needs columns repeat, direction, position_m",
                            column=column)
    bad = sorted(set(df["direction"]) - {"down", "up"})
    if bad:
        raise DataError(source, f"direction must be 'down' or 'up', found {bad}",
                        column="direction")
    if df.duplicated(["repeat", "direction"]).any():
        raise DataError(source, "more than one rest position for a repeat and direction",
                        column="repeat")
    wide = df.pivot(index="repeat", columns="direction", values="position_m")
    unpaired = wide.index[wide.reindex(columns=["down", "up"]).isna().any(axis=1)].tolist()
    if unpaired:
        raise DataError(source, f"repeats without both a down and an up rest position: "
                        f"{unpaired}", column="repeat")
    return wide[["down", "up"]].astype(float)


def static_friction(df_static: pd.DataFrame, k: float,
                    source: str = "<static test>") -> StaticFrictionEstimate:
    """Static friction F_c (N) from the static test, eqs. (4)-(5), with stiffness k (N/m).

    ``df_static`` has columns ``repeat``, ``direction`` ('down'/'up') and ``position_m``
    (rest position, downward positive, m). Down and up positions are paired by repeat;
    each pair gives F_c = k (x1 - x2) / 2.
    """
    wide = _paired_rest_positions(df_static, source)
    span = (wide["down"] - wide["up"]).to_numpy()
    forces = 0.5 * k * span
    n = forces.size
    if n == 0:
        raise DataError(source, "no repeats in the static test")
    if forces.mean() <= 0.0:
        raise DataError(source, "mean x1 - x2 is not positive: positions must be downward "
                        "positive, x1 the rest after a downward displacement", column="position_m")
    sd = float(forces.std(ddof=1)) if n > 1 else float("nan")
    return StaticFrictionEstimate(F_c=float(forces.mean()), sd=sd, se=float(sd / np.sqrt(n)), n=n,
                                  span_m=float(span.mean()))


