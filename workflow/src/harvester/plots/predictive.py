"""Figures 7, 9 and 10: model mean (black) against measured response (grey) with 3-sigma bounds."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from harvester.plots.posterior import SIMULATED_NOTE  # noqa: E402
from harvester.plots.style import (BOUNDS, LEGEND_SIZE, MEASURED, MODEL, TITLE_SIZE,  # noqa: E402
                                   save_figure)
from harvester.inference.predictive import PredictiveBand  # noqa: E402


def response_figure(band: PredictiveBand, measured: np.ndarray, path: str | Path, title: str,
                    window: tuple[float, float] | None = None, k: float = 3.0,
                    note: str = SIMULATED_NOTE,
                    ylabel: str = "relative acceleration $\\ddot z$ (m/s$^2$)",
                    measured_label: str = "measured (virtual rig)") -> None:
    """Measured output in grey, model mean in black, +-k sd bounds shaded (two kinds,
    labelled); ``note`` is the subtitle, ``ylabel`` the output with its unit."""
    t = band.time
    sel = slice(None) if window is None else (t >= window[0]) & (t <= window[1])
    width = 11 if window is None or (window[1] - window[0]) > 20 else 9
    fig, ax = plt.subplots(figsize=(width, 4))
    mean = band.mean[sel]
    for bounds in ("predictive", "parameter"):
        color, alpha = BOUNDS[bounds]
        sd = band.sd(bounds)[sel]
        what = "parameters + likelihood sigma" if bounds == "predictive" else "parameters only"
        ax.fill_between(t[sel], mean - k * sd, mean + k * sd, color=color, alpha=alpha, lw=0,
                        label=f"mean $\\pm${k:g} sd ({what})")
    lw = 0.6 if window is None else 1.0
    ax.plot(t[sel], measured[sel], color=MEASURED, lw=lw, label=measured_label)
    ax.plot(t[sel], mean, color=MODEL, lw=lw, label="model mean")
    ax.set_xlabel("time (s)")
    ax.set_ylabel(ylabel)
    ax.set_title(f"{title}\n{note}", fontsize=TITLE_SIZE)
    ax.legend(loc="upper right", fontsize=LEGEND_SIZE, ncol=2, frameon=False)
    ax.margins(x=0)
    save_figure(fig, path)
