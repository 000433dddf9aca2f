"""Figures 6 and 8: posterior samples of each model, pairwise, beside the paper's means."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from harvester.plots.style import HIGHLIGHT, MEASURED, MODEL, TITLE_SIZE, save_figure  # noqa: E402

SIMULATED_NOTE = "recordings: virtual rig (simulated)"
UNITS = {"c_m": "N s/m", "F_c": "N", "beta": "s/m", "sigma": "m/s$^2$"}


def label(name: str, units: dict[str, str] | None = None) -> str:
    unit = (units or {}).get(name) or UNITS.get(name)
    return f"{name} ({unit})" if unit else name


def pair_plot(samples: np.ndarray, names: list[str], path: str | Path, title: str,
              paper: dict[str, float] | None = None, truth: dict[str, float] | None = None,
              note: str = SIMULATED_NOTE, units: dict[str, str] | None = None) -> None:
    """Pairwise scatter of posterior samples (grey), paper's mean (black cross), rig truth (red).

    ``note``: the subtitle (default: the recordings are simulated); ``units``: axis units by
    parameter name beyond :data:`UNITS`."""
    n = len(names)
    size = 2.4 * max(n, 2)
    fig, axes = plt.subplots(n, n, figsize=(size, size), squeeze=False)
    for i in range(n):
        for j in range(n):
            ax = axes[i, j]
            if j > i:
                ax.axis("off")
                continue
            if i == j:
                ax.hist(samples[:, i], bins=30, color=MEASURED, edgecolor="0.3")
                _mark_1d(ax, names[i], paper, MODEL, "paper")
                _mark_1d(ax, names[i], truth, HIGHLIGHT, "rig truth")
            else:
                ax.plot(samples[:, j], samples[:, i], ".", color="0.45", ms=2, alpha=0.6)
                _mark_2d(ax, names[j], names[i], paper, MODEL, "x")
                _mark_2d(ax, names[j], names[i], truth, HIGHLIGHT, "+")
            if i == n - 1:
                ax.set_xlabel(label(names[j], units))
            if j == 0 and i > 0:
                ax.set_ylabel(label(names[i], units))
    handles = [plt.Line2D([], [], color=MODEL, marker="x", ls="--", label="paper (posterior mean)"),
               plt.Line2D([], [], color=HIGHLIGHT, marker="+", ls=":", label="virtual rig truth")]
    if paper or truth:
        fig.legend(handles=handles, loc="upper right", frameon=False)
    fig.suptitle(f"{title}\n{note}", fontsize=TITLE_SIZE)
    save_figure(fig, path)


def _mark_1d(ax, name, values, color, what) -> None:  # noqa: ANN001
    if values and name in values and np.isfinite(values[name]):
        ax.axvline(values[name], color=color, ls="--" if what == "paper" else ":", lw=1.2)


def _mark_2d(ax, x, y, values, color, marker) -> None:  # noqa: ANN001
    if values and x in values and y in values:
        ax.plot(values[x], values[y], marker, color=color, ms=10, mew=2)


def fit_pair_figure(note: str = "recording as given"):
    """A ``recording_fit.FitFigure``: the posterior's pair figure of a fit, with ``note``
    under it, as posterior_pairs.png in the fit's directory."""
    def draw(fit, directory: Path) -> str:
        from harvester.inference.posterior import parameter_names, posterior_theta
        pair_plot(posterior_theta(fit.idata), parameter_names(fit.idata),
                  directory / "posterior_pairs.png",
                  f"posterior of {fit.problem.structure.name}", note=note,
                  units={n: s.unit for n, s in fit.priors.items()})
        return "posterior_pairs.png"
    return draw
