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
                    misfit: StickMisfit | None = None,
                    compare: tuple[str, StickMisfit] | None = None) -> None:
    """Measured output in grey, model mean in black, +-k sd bounds shaded (two kinds: the
    paper's, the ensemble of parameter samples, and the full predictive with the likelihood's
    sigma), each labelled with the share of the shown measured samples outside it; ``note``
    is the subtitle, ``ylabel`` the output with its unit. ``stuck`` (bool per sample of the
    band): where the rig stuck, shaded. ``zoom`` (s): a second panel on that section.
    ``misfit``: a last panel, the model's RMS misfit while the rig is stuck, per band of screw
    speed and near the sticks against elsewhere (``study.sticking``); ``compare``: another
    model's (label, misfit) beside it."""
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
        _misfit_panel(axes[-1], misfit, ylabel[ylabel.rfind("("):] if "(" in ylabel else "",
                      compare)
    save_figure(fig, path)


def _misfit_rows(m: StickMisfit) -> list[tuple[str, float, float, float]]:
    """(label, share of the samples, RMS residual, RMS of the record): stuck, then the speed
    bands while moving."""
    return [("stuck", m.stuck_share, *m.stuck)] + [
        (f"{lo:g}-{hi:g}" if np.isfinite(hi) else f"> {lo:g}", share, r, y)
        for lo, hi, share, r, y in m.by_speed]


def _misfit_panel(ax, m: StickMisfit, unit: str,
                  compare: tuple[str, StickMisfit] | None = None) -> None:
    """Bars: the RMS of measured minus model mean (dark) beside the record's own RMS (light)
    while the rig is stuck and per band of its screw speed while it moves (truth), each
    labelled with the misfit's share of the record there and the share of the samples;
    ``compare``'s misfit hatched beside them. The title gives the shares stuck and moving,
    and the misfit near the sticks over elsewhere."""
    rows = _misfit_rows(m)
    x = np.arange(len(rows))
    w = 0.27 if compare else 0.4
    res, rec = (np.nan_to_num([r[i] for r in rows]) for i in (2, 3))
    ax.bar(x - w / 2, res, w, color=MODEL, alpha=0.7, label="RMS of measured - mean")
    ax.bar(x + w / 2, rec, w, color=MEASURED, alpha=0.5, label="RMS of the record")
    top = max(rec.max(), res.max())
    if compare is not None:
        other = np.nan_to_num([r[2] for r in _misfit_rows(compare[1])])
        ax.bar(x + 1.5 * w, other, w, color="white", edgecolor=MODEL, hatch="///",
               label=f"RMS of measured - mean, {compare[0]} (for comparison)")
    for xi, (_, share, r, y) in zip(x, rows):
        if share > 0:
            ax.annotate(f"{100 * r / y:.0f} % of the record\n{100 * share:.1f} % of samples",
                        (xi - w / 2, r), ha="center", va="bottom", fontsize=LEGEND_SIZE)
    ax.set_xticks(x, [r[0] for r in rows])
    ax.set_xlabel("the rig stuck, or moving at screw speed |z'| (mm/s; its truth)")
    ax.set_ylabel(f"RMS {unit}".strip())
    ax.set_ylim(0, 1.3 * top)
    ax.legend(loc="upper left", fontsize=LEGEND_SIZE, frameon=False)
    also = ("" if compare is None else f"; the {compare[0]} model's "
            f"{100 * compare[1].stuck_nrmse:.0f} and {100 * compare[1].moving_nrmse:.0f} %")
    ax.set_title(f"where the model misses (the rig's truth), as a share of the record there: "
                 f"while the rig is stuck ({m.sticks} sticks, {100 * m.stuck_share:.1f} % of "
                 f"the samples)\n{100 * m.stuck_nrmse:.0f} %, while it moves "
                 f"{100 * m.moving_nrmse:.0f} %{also}; within 20 ms of the sticks "
                 f"({100 * m.near_share:.1f} %): {m.absolute_ratio:.2f} x the misfit "
                 f"elsewhere,\n{m.relative_ratio:.2f} x relative to the record there",
                 fontsize=TITLE_SIZE)


def prediction_figure(note: str = "recording as given"):
    """Draws a prediction's (``inference.unseen.Prediction``) response figure, with ``note``
    under it, as predictive.png in its directory; returns the file name."""
    def draw(pred, directory: Path) -> str:
        unit = pred.metrics["unit"]
        what = "relative acceleration (m/s$^2$)" if unit == "m/s^2" else \
            "relative displacement (m)"
        response_figure(pred.band, pred.measured, directory / "predictive.png",
                        f"{pred.metrics['model']}: posterior predictive, NRMSE "
                        f"{pred.metrics['nrmse']:.3f}", note=note, ylabel=what,
                        measured_label="measured")
        return "predictive.png"
    return draw
