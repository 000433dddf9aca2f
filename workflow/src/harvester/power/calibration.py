"""Calibration checks: does the predicted power fall in its intervals at the stated rate on
records the identification never saw, and do the identified constants recover the rig's?

Held-out power. Each held-out loaded record (its own excitation, its load R_L) is cut into
windows after a lead-in. The measured power of a window is the mean of V^2 / (2 R_L), V the
space-vector magnitude of its two line voltages. Its prediction, for every draw of the BMA
posterior, is the same mean of the simulated V^2 plus sigma_V^2, the noise the likelihood
assigns to V (V_measured = V + e, e ~ N(0, sigma_V^2), so E[V_measured^2] = V^2 + sigma_V^2):
the posterior predictive of the measured quantity. Coverage at a level is the share of windows
whose measured power lies in the equal-tailed interval of that level. Windows of one record
share the parameters' error, so they are not independent trials: the coverage of a few
windows is a coarse check, reported with the number of windows.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd

from harvester.electrical import generator as gen
from harvester.electrical.problem import LAYOUT_TERMS, simulate_loaded
from harvester.electrical.records import LoadedRecord
from harvester.model.structures import Layout
from harvester.power.predict import PARAMETERS


def window_edges(record: LoadedRecord, window_s: float) -> list[tuple[int, int]]:
    """[start, stop) of consecutive windows of window_s seconds in the record's window."""
    step = int(round(window_s / record.dt))
    start, stop = record.window
    return [(a, a + step) for a in range(start, stop - step + 1, step)]


def held_out_windows(record: LoadedRecord, draws: pd.DataFrame, known: Mapping[str, float],
                     window_s: float, levels: Sequence[float]) -> pd.DataFrame:
    """One row per window: measured and predicted (mean, intervals) power in W, and whether
    the measured lies in each interval."""
    p = {k: draws[k].to_numpy(dtype=float) for k in PARAMETERS}
    v, a, ok = simulate_loaded(Layout.of(LAYOUT_TERMS), p, known, record.g, record.G,
                               record.base_acc, record.dt)
    volts = gen.line_voltage_magnitude(v, a, p["K_e"], p["R_s"], p["L_s"], record.g, record.G)
    rows = []
    for i, (s0, s1) in enumerate(window_edges(record, window_s)):
        measured = np.mean(record.voltage[s0:s1] ** 2) / (2.0 * record.load_ohm)
        pred = (np.mean(volts[ok, s0:s1] ** 2, axis=1) + p["sigma_V"][ok] ** 2) \
            / (2.0 * record.load_ohm)
        row = {"record": record.name, "load_ohm": record.load_ohm, "window": i,
               "start_s": s0 * record.dt, "measured_W": measured,
               "predicted_mean_W": float(np.mean(pred))}
        for level in levels:
            lo, hi = np.quantile(pred, [(1 - level) / 2, (1 + level) / 2])
            row.update({f"low_{level:g}_W": lo, f"high_{level:g}_W": hi,
                        f"inside_{level:g}": bool(lo <= measured <= hi)})
        rows.append(row)
    return pd.DataFrame(rows)


def coverage_table(windows: pd.DataFrame, levels: Sequence[float]) -> pd.DataFrame:
    """Per record and over all: windows, nominal level and the observed coverage."""
    rows = []
    for name, grp in [*windows.groupby("record"), ("all", windows)]:
        for level in levels:
            rows.append({"record": name, "windows": len(grp), "nominal": level,
                         "coverage": float(grp[f"inside_{level:g}"].mean()),
                         "median_ratio_measured_to_predicted": float(
                             np.median(grp["measured_W"] / grp["predicted_mean_W"]))})
    return pd.DataFrame(rows)


def truth_table(posteriors: Mapping[str, pd.DataFrame], truth: Mapping[str, float],
                interval: float) -> pd.DataFrame:
    """Per structure and parameter: posterior mean, sd, equal-tailed interval, the rig's
    truth, whether it lies inside, and its distance in posterior sds."""
    lo, hi = (1 - interval) / 2, (1 + interval) / 2
    rows = []
    for structure, post in posteriors.items():
        for name, value in truth.items():
            x = post[name].to_numpy()
            if structure == "resistive" and name == "L_s":
                continue
            q = np.quantile(x, [lo, hi])
            rows.append({"structure": structure, "parameter": name, "mean": x.mean(),
                         "sd": x.std(ddof=1), f"q{lo:g}": q[0], f"q{hi:g}": q[1],
                         "truth": value, "inside": bool(q[0] <= value <= q[1]),
                         "z": (x.mean() - value) / x.std(ddof=1)})
    return pd.DataFrame(rows)
