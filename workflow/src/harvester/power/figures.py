"""Figures of the power study in the paper's style (``harvester.plots.style``): the model's
mean in black, bounds shaded, measured values in grey, axes labelled with units."""

from __future__ import annotations

import textwrap
from collections.abc import Mapping
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from harvester.plots.style import (
    BOUNDS,
    HIGHLIGHT,
    LEGEND_SIZE,
    MEASURED,
    MODEL,
    TITLE_SIZE,
    axis_label,
    save_figure,
)


def _columns(interval: float, prefix: str = "") -> tuple[str, str]:
    lo, hi = (1 - interval) / 2, (1 + interval) / 2
    return f"{prefix}q{lo:g}_W", f"{prefix}q{hi:g}_W"


def _curves(ax, table: pd.DataFrame, interval: float, style: str, label: str) -> None:
    """Mean (black), the parameters' band and, if present, one record's band."""
    x, (lo, hi) = table["load_ohm"], _columns(interval)
    record = _columns(interval, "record_")
    if record[0] in table:
        ax.fill_between(x, 1e3 * table[record[0]], 1e3 * table[record[1]],
                        color=BOUNDS["predictive"][0], alpha=BOUNDS["predictive"][1], lw=0,
                        label=f"{interval:.0%}, one record{label}")
    ax.fill_between(x, 1e3 * table[lo], 1e3 * table[hi], color=BOUNDS["parameter"][0],
                    alpha=BOUNDS["parameter"][1], lw=0, label=f"{interval:.0%}, parameters{label}")
    ax.plot(x, 1e3 * table["mean_W"], style, color=MODEL, lw=1.2, label=f"mean{label}")


def _relative(ax, tables: list[tuple[pd.DataFrame, str]], interval: float) -> None:
    """The bands relative to the mean (%)."""
    for table, style in tables:
        mean, x = table["mean_W"], table["load_ohm"]
        for prefix, (color, alpha) in (("record_", BOUNDS["predictive"]),
                                       ("", BOUNDS["parameter"])):
            lo, hi = _columns(interval, prefix)
            if lo in table:
                ax.plot(x, 100 * (table[lo] / mean - 1), style, color=color, lw=1.2)
                ax.plot(x, 100 * (table[hi] / mean - 1), style, color=color, lw=1.2)
    ax.axhline(0.0, color=MODEL, lw=0.8)
    ax.set_ylabel(axis_label("band - mean", "%"))


def power_vs_load(base: pd.DataFrame, changed: pd.DataFrame | None, optimum: Mapping,
                  interval: float, low_quantile: float, title: str, path: str | Path) -> Path:
    """Top: mean load power against R_L with the parameters' band, one record's band (if
    the table has it), the optima and, if given, the changed device's curves (dashed).
    Bottom: the bands relative to the mean (%)."""
    fig, (ax, rel) = plt.subplots(2, 1, figsize=(6.0, 5.4), sharex=True,
                                  gridspec_kw={"height_ratios": [3, 1.3]})
    _curves(ax, base, interval, "-", "")
    tables = [(base, "-")]
    if changed is not None:
        _curves(ax, changed, interval, "--", ", friction halved")
        tables.append((changed, "--"))
    for key, marker in (("expected", "o"), ("low_quantile", "v"), ("record_low_quantile", "s")):
        if key in optimum:
            opt = optimum[key]
            ax.plot(opt["load_ohm"], 1e3 * opt["power_W"], marker, color=HIGHLIGHT, ms=5,
                    label=f"best for {key.replace('_', ' ')}: {opt['load_ohm']:.2f} ohm")
    _relative(rel, tables, interval)
    rel.set_xscale("log")
    rel.set_xlabel(axis_label("load resistance per phase R_L", "ohm"))
    ax.set_ylabel(axis_label("mean power into the load", "mW"))
    ax.set_title(textwrap.fill(title, 48), fontsize=TITLE_SIZE)
    ax.legend(fontsize=LEGEND_SIZE, frameon=False, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    return save_figure(fig, path)


def energy_distribution(energy: np.ndarray, changed: np.ndarray | None, load_ohm: float,
                        seconds: float, title: str, path: str | Path) -> Path:
    """Histograms over posterior draws (and records) of the energy (mJ) delivered over one
    record of ``seconds`` at one load, as identified and (if given) with the change, each
    with its mean and 90 % interval."""
    sets = [("as identified", energy, MODEL)]
    if changed is not None:
        sets.append(("friction halved", changed, BOUNDS["predictive"][0]))
    fig, axes = plt.subplots(1, len(sets), figsize=(3.4 * len(sets), 3.2), squeeze=False)
    for ax, (label, values, color) in zip(axes[0], sets):
        mj = 1e3 * np.asarray(values)
        ax.hist(mj, bins=20, color=color, alpha=0.6)
        for q, style in ((np.mean(mj), "-"), *((v, ":") for v in np.quantile(mj, [0.05, 0.95]))):
            ax.axvline(q, color=MODEL, ls=style, lw=1.0)
        ax.set_title(label, fontsize=TITLE_SIZE)
        ax.set_xlabel(axis_label(f"energy over one record of {seconds:g} s", "mJ"))
        ax.set_ylabel("posterior draws")
    fig.suptitle(f"{title}\nR_L = {load_ohm:.2f} ohm: mean (solid), 90 % interval (dotted)",
                 fontsize=TITLE_SIZE)
    return save_figure(fig, path)


def held_out_coverage(windows: pd.DataFrame, level: float, path: str | Path) -> Path:
    """Measured window power (grey) against the predicted mean (black) and its interval
    (shaded bar), per held-out record."""
    records = list(dict.fromkeys(windows["record"]))
    fig, axes = plt.subplots(1, len(records), figsize=(3.2 * len(records), 3.2), squeeze=False)
    for ax, name in zip(axes[0], records):
        w = windows[windows["record"] == name]
        width = float(np.diff(w["start_s"]).min()) if len(w) > 1 else 1.0
        x = w["start_s"].to_numpy() + 0.5 * width
        lo, hi = 1e3 * w[f"low_{level:g}_W"], 1e3 * w[f"high_{level:g}_W"]
        ax.bar(x, hi - lo, bottom=lo, width=0.6 * width, color=BOUNDS["parameter"][0],
               alpha=BOUNDS["parameter"][1], label=f"{level:.0%} interval")
        ax.plot(x, 1e3 * w["predicted_mean_W"], "_", color=MODEL, ms=12, label="predicted")
        ax.plot(x, 1e3 * w["measured_W"], "o", color=MEASURED, ms=4, label="measured")
        ax.set_title(f"{name} ({w['load_ohm'].iloc[0]:g} ohm)", fontsize=TITLE_SIZE)
        ax.set_xlabel(axis_label("window centre", "s"))
        ax.set_ylabel(axis_label("mean load power", "mW"))
    axes[0][0].legend(fontsize=LEGEND_SIZE, frameon=False)
    return save_figure(fig, path)
