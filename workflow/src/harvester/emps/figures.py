"""Figures of the EMPS study: measured in grey, model in black, bounds shaded, SI units labelled."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from harvester.emps.data import UNITS, EmpsRecord, disturbance_voltage  # noqa: E402
from harvester.plots.style import BOUNDS, MEASURED, MODEL, save_figure  # noqa: E402

REAL_NOTE = "real recordings: EMPS benchmark (Janot, Gautier and Brunot 2019)"


def _save(fig, path: str | Path) -> None:
    save_figure(fig, path)


def data_figure(records: Mapping[str, EmpsRecord], path: str | Path) -> None:
    """Per record: reference and position, tracking error, applied force."""
    fig, axes = plt.subplots(3, len(records), figsize=(6 * len(records), 7.5), sharex=True,
                             squeeze=False)
    for j, (label, rec) in enumerate(records.items()):
        ax = axes[:, j]
        ax[0].plot(rec.time, 1e3 * rec.qg, color="k", lw=0.8, label="reference $q_g$")
        ax[0].plot(rec.time, 1e3 * rec.qm, color="0.6", lw=0.8, ls="--",
                   label="measured $q_m$")
        ax[0].set_ylabel("position (mm)")
        ax[0].set_title(f"{label}: {rec.name}", fontsize=10)
        ax[0].legend(fontsize=8, frameon=False)
        ax[1].plot(rec.time, 1e6 * (rec.qm - rec.qg), color="0.5", lw=0.6)
        ax[1].set_ylabel("tracking error $q_m - q_g$ ($\\mu$m)")
        ax[2].plot(rec.time, rec.force, color="0.5", lw=0.6, label="$g_\\tau v_{ir}$")
        if np.any(rec.pulses):
            ax[2].plot(rec.time, rec.loop.gtau * disturbance_voltage(rec), color="k", lw=0.6,
                       label="added pulses $g_\\tau d$")
            ax[2].legend(fontsize=8, frameon=False, loc="lower right")
        ax[2].set_ylabel("force (N)")
        ax[2].set_xlabel("time (s)")
        for a in ax:
            a.margins(x=0)
    fig.suptitle(REAL_NOTE, fontsize=9)
    _save(fig, path)


def frf_figure(freqs: np.ndarray, measured: np.ndarray, model: np.ndarray, coherence: np.ndarray,
               band: tuple[float, float], path: str | Path, title: str) -> None:
    """Measured (grey) and fitted linear (black) FRF force -> position; coherence below."""
    sel = (freqs > 0) & (freqs <= 4 * band[1])
    f = freqs[sel]
    fig, ax = plt.subplots(3, 1, figsize=(7, 7.5), sharex=True,
                           gridspec_kw={"height_ratios": [3, 2, 1.2]})
    ax[0].loglog(f, np.abs(measured[sel]), color=MEASURED, lw=1.2,
                 label="measured (instrument $q_g$)")
    ax[0].loglog(f, np.abs(model[sel]), color=MODEL, lw=1.0, label="fitted linear eq. (1)")
    ax[0].set_ylabel("|position / force| (m/N)")
    ax[0].legend(fontsize=8, frameon=False)
    def phase(h: np.ndarray) -> np.ndarray:  # in [-360, 0): a mass line sits at -180
        return np.degrees(np.angle(h)) % 360.0 - 360.0

    ax[1].semilogx(f, phase(measured[sel]), color=MEASURED, lw=1.2)
    ax[1].semilogx(f, phase(model[sel]), color=MODEL, lw=1.0)
    ax[1].set_ylabel("phase (deg)")
    ax[1].set_ylim(-360, 0)
    ax[2].semilogx(f, coherence[sel], color="0.4", lw=1.0)
    ax[2].set_ylabel("coherence")
    ax[2].set_ylim(0, 1.05)
    ax[2].set_xlabel("frequency (Hz)")
    for a in ax:
        a.axvspan(*band, color="tab:blue", alpha=0.07, lw=0)
    ax[0].set_title(f"{title}\n{REAL_NOTE}", fontsize=10)
    _save(fig, path)


def posterior_figure(samples: Mapping[str, np.ndarray], published: Mapping[str, float],
                     idim: Mapping[str, float], path: str | Path, title: str) -> None:
    """Posterior histogram of each EMPS parameter; published value, +-5 % and IDIM-LS marked."""
    names = list(samples)
    fig, axes = plt.subplots(1, len(names), figsize=(3.2 * len(names), 3.2), squeeze=False)
    for ax, name in zip(axes[0], names):
        x = samples[name]
        pub = published[name]
        lo, hi = sorted((0.95 * pub, 1.05 * pub))
        ax.axvspan(lo, hi, color="tab:green", alpha=0.12, lw=0, label="published $\\pm$5 %")
        ax.hist(x, bins=30, color="0.6", density=True, label="posterior")
        ax.axvline(pub, color="k", ls="--", lw=1.2, label="published")
        if name in idim:
            ax.axvline(idim[name], color="k", ls=":", lw=1.2, label="IDIM-LS (ours)")
        span = max(hi - lo, 8 * np.std(x))
        centre = 0.5 * (pub + np.mean(x))
        ax.set_xlim(centre - 0.6 * span, centre + 0.6 * span)
        ax.set_xlabel(f"{name} ({UNITS[name]})")
        ax.set_yticks([])
    axes[0][0].set_ylabel("density")
    axes[0][-1].legend(fontsize=7, frameon=False, loc="upper right")
    fig.suptitle(f"{title} - {REAL_NOTE}", fontsize=10)
    _save(fig, path)


def tracking_figure(bands: Mapping[str, dict], path: str | Path, title: str,
                    window: tuple[float, float] | None = None, k: float = 3.0) -> None:
    """Top: measured tracking error (grey) and the last model's mean (black). Below, per model:
    the prediction error qm - q_mean with +-k sd (parameters and sigma) shaded, common scale."""
    fig, axes = plt.subplots(len(bands) + 1, 1, figsize=(11, 2.5 * (len(bands) + 1)),
                             sharex=True, squeeze=False)
    axes = axes[:, 0]
    last = list(bands)[-1]
    t = bands[last]["time"]
    sel = slice(None) if window is None else (t >= window[0]) & (t <= window[1])
    axes[0].plot(t[sel], 1e6 * bands[last]["measured"][sel], color=MEASURED, lw=2.0,
                 label="measured $q_m - q_g$")
    axes[0].plot(t[sel], 1e6 * bands[last]["mean"][sel], color=MODEL, lw=0.7,
                 label=f"{last}, mean (closed loop)")
    axes[0].set_ylabel("tracking error ($\\mu$m)")
    axes[0].legend(fontsize=8, frameon=False, loc="upper left")
    lim = 0.0
    for ax, (label, b) in zip(axes[1:], bands.items()):
        err = 1e6 * (b["measured"] - b["mean"])[sel]
        sd = 1e6 * b["sd"][sel]
        ax.fill_between(t[sel], -k * sd, k * sd, color=BOUNDS["predictive"][0],
                        alpha=BOUNDS["predictive"][1], lw=0,
                        label=f"$\\pm${k:g} sd (parameters + $\\sigma$)")
        ax.plot(t[sel], err, color="0.4", lw=0.6, label="measured - model mean")
        ax.axhline(0.0, color="k", lw=0.5)
        ax.set_ylabel("$q_m - q$ ($\\mu$m)")
        ax.set_title(f"{label}: RMS error {b['rms_position_um']:.2f} $\\mu$m over the record",
                     fontsize=9)
        lim = max(lim, float(np.max(np.abs(err))), float(k * np.max(sd)))
    for ax in axes[1:]:
        ax.set_ylim(-1.05 * lim, 1.05 * lim)
    axes[1].legend(fontsize=8, frameon=False, ncol=2, loc="upper right")
    for ax in axes:
        ax.margins(x=0)
    axes[-1].set_xlabel("time (s)")
    fig.suptitle(f"{title}\n{REAL_NOTE}", fontsize=10)
    _save(fig, path)


def evidence_figure(table: pd.DataFrame, path: str | Path) -> None:
    """Log evidence gain of each candidate term over the viscous baseline (bar chart)."""
    t = table[table["added_term"] != ""].sort_values("log_evidence_gain")
    fig, ax = plt.subplots(figsize=(6, 0.6 + 0.5 * len(t)))
    ax.barh(t["added_term"], t["log_evidence_gain"], color="0.5",
            xerr=t["sd_over_chains"].fillna(0.0), ecolor="k")
    ax.set_xlabel("log evidence gain over the viscous baseline (nats)")
    ax.set_title(f"Missing physics: candidates added to M q'' + Fv q' + OF = F\n{REAL_NOTE}",
                 fontsize=9)
    _save(fig, path)
