"""Design under uncertainty: the power-vs-load curve with its band, the loads that maximise
the expected power and a low quantile of it, and the gain of a mechanical change.

Loads are scanned on a geometric grid; each optimum is refined by the vertex of a parabola
through the best grid point and its neighbours in ln R_L (the curves are smooth in ln R_L).
The gain of a change (friction halved) is paired: each posterior draw is simulated with and
without it, so the interval is that of the gain, not of two overlapping bands.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd


def load_grid(cfg: Mapping) -> np.ndarray:
    """Geometric grid of loads (ohm) from cfg min_ohm, max_ohm, count."""
    return np.geomspace(float(cfg["min_ohm"]), float(cfg["max_ohm"]), int(cfg["count"]))


def curve(loads: np.ndarray, power: np.ndarray, interval: float, low_quantile: float,
          per_record: np.ndarray | None = None) -> pd.DataFrame:
    """Per load (ohm): mean, median, low quantile and the equal-tailed interval of the mean
    power over the draws (the parameters' uncertainty), W; with ``per_record`` (rows: draws x
    records) also the interval and low quantile of the power of one record (``record_``)."""
    lo, hi = (1.0 - interval) / 2.0, (1.0 + interval) / 2.0
    q = np.nanquantile(power, [lo, 0.5, hi, low_quantile], axis=0)
    table = pd.DataFrame({"load_ohm": loads, "mean_W": np.nanmean(power, axis=0),
                          "median_W": q[1], f"q{lo:g}_W": q[0], f"q{hi:g}_W": q[2],
                          f"low_q{low_quantile:g}_W": q[3]})
    if per_record is not None:
        r = np.nanquantile(per_record, [lo, hi, low_quantile], axis=0)
        table[f"record_q{lo:g}_W"], table[f"record_q{hi:g}_W"] = r[0], r[1]
        table[f"record_low_q{low_quantile:g}_W"] = r[2]
    return table


def refined_argmax(loads: np.ndarray, values: np.ndarray) -> tuple[float, float]:
    """(load, value) at the maximum: the parabola's vertex in ln R_L through the best grid
    point and its neighbours; the grid point itself at an end of the grid."""
    i = int(np.nanargmax(values))
    if i == 0 or i == len(loads) - 1:
        return float(loads[i]), float(values[i])
    x = np.log(loads[i - 1:i + 2])
    a, b, c = np.polyfit(x, values[i - 1:i + 2], 2)
    if a >= 0:
        return float(loads[i]), float(values[i])
    x0 = -b / (2.0 * a)
    return float(np.exp(x0)), float(c - b * b / (4.0 * a))


def optimal_loads(table: pd.DataFrame, low_quantile: float) -> dict[str, dict[str, float]]:
    """The loads maximising the expected power, its low quantile over the parameters and, if
    the table has it, the low quantile of one record's power; with the maxima (W)."""
    loads = table["load_ohm"].to_numpy()
    columns = {"expected": "mean_W", "low_quantile": f"low_q{low_quantile:g}_W",
               "record_low_quantile": f"record_low_q{low_quantile:g}_W"}
    out = {}
    for key, column in columns.items():
        if column in table:
            r, p = refined_argmax(loads, table[column].to_numpy())
            out[key] = {"load_ohm": r, "power_W": p,
                        "grid_end": bool(r in (loads[0], loads[-1]))}
    return out


def at_load(loads: np.ndarray, values: np.ndarray, load_ohm: float) -> np.ndarray:
    """Each draw's value (rows of draws x loads) at one load (ohm), linear in ln R_L."""
    x = np.log(loads)
    return np.array([np.interp(np.log(load_ohm), x, row) for row in values])


def paired_gain(base: np.ndarray, changed: np.ndarray, loads: np.ndarray, load_ohm: float,
                interval: float) -> dict[str, float]:
    """Gain of a change at one load (ohm; interpolated in ln R_L): mean and interval of the
    paired difference (W) and ratio, and the probability that it helps."""
    pb, pc = at_load(loads, base, load_ohm), at_load(loads, changed, load_ohm)
    diff, ratio = pc - pb, pc / pb
    lo, hi = (1.0 - interval) / 2.0, (1.0 + interval) / 2.0
    return {"load_ohm": float(load_ohm), "base_W": float(np.nanmean(pb)),
            "changed_W": float(np.nanmean(pc)), "gain_W": float(np.nanmean(diff)),
            "gain_W_low": float(np.nanquantile(diff, lo)),
            "gain_W_high": float(np.nanquantile(diff, hi)),
            "ratio": float(np.nanmean(ratio)), "ratio_low": float(np.nanquantile(ratio, lo)),
            "ratio_high": float(np.nanquantile(ratio, hi)),
            "probability_of_gain": float(np.nanmean(diff > 0)), "interval": interval}


def energy_table(loads: np.ndarray, energy: np.ndarray,
                 quantiles=(0.05, 0.25, 0.5, 0.75, 0.95)) -> pd.DataFrame:
    """Distribution of the energy over a record (J) per load, rows of ``energy`` the draws
    (x records): mean and quantiles."""
    q = np.nanquantile(energy, quantiles, axis=0)
    table = pd.DataFrame({"load_ohm": loads, "mean_J": np.nanmean(energy, axis=0)})
    for level, row in zip(quantiles, q):
        table[f"q{level:g}_J"] = row
    return table
