"""Figures 7, 9 and 10: model mean (black) against measured response (grey) with 3-sigma bounds."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from harvester.plots.posterior import SIMULATED_NOTE  # noqa: E402
from harvester.plots.style import (BOUNDS, HIGHLIGHT, LEGEND_SIZE, MEASURED, MODEL,  # noqa: E402
                                   TITLE_SIZE, save_figure)
from harvester.inference.predictive import PredictiveBand  # noqa: E402
from harvester.study.sticking import StickMisfit, stick_runs  # noqa: E402


def _spans(t: np.ndarray, mask: np.ndarray) -> list[tuple[float, float]]:
    """(start, stop) times (s) of the runs of True in ``mask``, half a step either side."""
    dt = float(t[1] - t[0]) if t.size > 1 else 0.0
    return [(t[a] - dt / 2, t[b - 1] + dt / 2) for a, b in zip(*stick_runs(mask))]


def _draw(ax, band: PredictiveBand, measured: np.ndarray, sel, k: float, lw: float,
          measured_label: str, stuck: np.ndarray | None, labels: bool) -> None:
    """One panel: the two kinds of bounds with the share of the shown measured samples
    outside each, the rig's stick intervals (truth) if given, measured and mean."""
    t, mean, y = band.time[sel], band.mean[sel], measured[sel]
    if stuck is not None:
        for i, (a, b) in enumerate(_spans(t, stuck[sel])):
            ax.axvspan(a, b, color=HIGHLIGHT, alpha=0.25, lw=0,
                       label="rig stuck (truth)" if labels and i == 0 else None)
    for bounds in ("predictive", "parameter"):
        color, alpha = BOUNDS[bounds]
        sd = band.sd(bounds)[sel]
        what = "parameters + likelihood sigma" if bounds == "predictive" else "parameters only"
        out = 100.0 * float(np.mean(np.abs(y - mean) > k * sd))
        ax.fill_between(t, mean - k * sd, mean + k * sd, color=color, alpha=alpha, lw=0,
                        label=f"mean $\\pm${k:g} sd ({what}): {out:.1f} % outside"
                        if labels else None)
    ax.plot(t, y, color=MEASURED, lw=lw, label=measured_label if labels else None)
    ax.plot(t, mean, color=MODEL, lw=lw, label="model mean" if labels else None)
    ax.margins(x=0)


def response_figure(band: PredictiveBand, measured: np.ndarray, path: str | Path, title: str,
                    window: tuple[float, float] | None = None, k: float = 3.0,
                    note: str = SIMULATED_NOTE,
                    ylabel: str = "relative acceleration $\\ddot z$ (m/s$^2$)",
                    measured_label: str = "measured (virtual rig)",
                    stuck: np.ndarray | None = None,
                    zoom: tuple[float, float] | None = None,
                    misfit: StickMisfit | None = None) -> None:
    """Measured output in grey, model mean in black, +-k sd bounds shaded (two kinds: the
    paper's, the ensemble of parameter samples, and the full predictive with the likelihood's
    sigma), each labelled with the share of the shown measured samples outside it; ``note``
    is the subtitle, ``ylabel`` the output with its unit. ``stuck`` (bool per sample of the
    band): where the rig stuck, shaded. ``zoom`` (s): a second panel on that section.
    ``misfit``: a last panel, the model's RMS misfit per band of screw speed and near the
    sticks against elsewhere (``study.sticking``)."""
    t = band.time
    sel = slice(None) if window is None else (t >= window[0]) & (t <= window[1])
    width = 11 if window is None or (window[1] - window[0]) > 20 else 9
    rows = 1 + (zoom is not None) + (misfit is not None)
    fig, axes = plt.subplots(rows, 1, figsize=(width, 4 + 3 * (rows - 1)), squeeze=False)
    axes = list(axes[:, 0])
    lw = 0.6 if window is None else 1.0
    _draw(axes[0], band, measured, sel, k, lw, measured_label, stuck, True)
    axes[0].set_title(f"{title}\n{note}", fontsize=TITLE_SIZE)
    axes[0].legend(loc="upper right", fontsize=LEGEND_SIZE, ncol=2, frameon=False)
    if zoom is not None:
        part = (t >= zoom[0]) & (t <= zoom[1])
        _draw(axes[1], band, measured, part, k, 1.2, measured_label, stuck, False)
        axes[1].set_title(f"section {zoom[0]:.2f}-{zoom[1]:.2f} s", fontsize=TITLE_SIZE)
        axes[0].axvspan(zoom[0], zoom[1], color="0.85", alpha=0.5, lw=0, zorder=0)
    for ax in axes[:rows - (misfit is not None)]:
        ax.set_xlabel("time (s)")
        ax.set_ylabel(ylabel)
    if misfit is not None:
        _misfit_panel(axes[-1], misfit, ylabel[ylabel.rfind("("):] if "(" in ylabel else "")
    save_figure(fig, path)


def _misfit_panel(ax, m: StickMisfit, unit: str) -> None:
    """Bars: the RMS of measured minus model mean per band of the rig's screw speed (truth),
    each labelled with its share of the samples; the title gives the misfit near the sticks
    over elsewhere, absolute and relative to the record there."""
    labels = [f"{lo:g}-{hi:g}" if np.isfinite(hi) else f"> {lo:g}" for lo, hi, _, _ in
              m.by_speed]
    rms = [r for *_, r in m.by_speed]
    bars = ax.bar(labels, rms, color=MODEL, alpha=0.6)
    for bar, (_, _, share, _) in zip(bars, m.by_speed):
        ax.annotate(f"{100 * share:.0f} %", (bar.get_x() + bar.get_width() / 2,
                                             bar.get_height()), ha="center", va="bottom",
                    fontsize=LEGEND_SIZE)
    ax.set_xlabel("rig's screw speed |z'| (mm/s, truth); labels: share of the samples")
    ax.set_ylabel(f"RMS of measured - mean {unit}".strip())
    ax.set_title("where the model misses (the rig's truth): RMS misfit per band of screw speed\n"
                 f"within 20 ms of its {m.sticks} sticks ({100 * m.near_share:.1f} % of the "
                 f"samples): {m.absolute_ratio:.2f} x the misfit elsewhere, "
                 f"{m.relative_ratio:.2f} x relative to the record there", fontsize=TITLE_SIZE)
