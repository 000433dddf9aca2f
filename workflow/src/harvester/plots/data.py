"""Figures of the data and the initial modelling: Figures 4 and 5 and the damping fit.

Paper look: measured (unfiltered) data in grey, filtered data / model in black, axis labels
with units, and a footnote that the recordings come from the SIMULATED virtual rig.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from harvester.initial.damping import DampingFit  # noqa: E402
from harvester.data.signals import psd  # noqa: E402
from harvester.plots.style import MEASURED, MODEL, NOTE_SIZE, save_figure  # noqa: E402

SIMULATED = "Virtual rig (simulated recordings), not the paper's measurements."

#: The rocking mode of the mass shows between these frequencies (Hz), paper Figure 4.
ROCKING_BAND_HZ = (30.0, 80.0)


def _finish(fig: Figure, path: str | Path) -> None:
    """Add the simulated-recordings footnote, save (``style.save_figure``) and close."""
    fig.text(0.01, 0.005, SIMULATED, fontsize=NOTE_SIZE, style="italic", va="bottom")
    save_figure(fig, path, rect=(0.0, 0.03, 1.0, 1.0))


def fig04_psd(raw_df: pd.DataFrame, filtered_df: pd.DataFrame, fs: float, cutoff: float,
              path: str | Path) -> None:
    """Figure 4: PSD ((m/s^2)^2/Hz, log scale) of the relative acceleration z'', unfiltered
    (grey) and low-passed at ``cutoff`` Hz (black), over 0 to fs/2 Hz, rocking band shaded."""
    f_raw, p_raw = psd(raw_df["rel_acc"].to_numpy(dtype=float), fs)
    f_fil, p_fil = psd(filtered_df["rel_acc"].to_numpy(dtype=float), fs)
    fig, ax = plt.subplots(figsize=(6.4, 3.8))
    ax.axvspan(*ROCKING_BAND_HZ, color="0.92", zorder=0, label="rocking mode, 30-80 Hz")
    ax.semilogy(f_raw, p_raw, color=MEASURED, lw=1.0, label="unfiltered")
    ax.semilogy(f_fil, p_fil, color=MODEL, lw=1.0, label=f"filtered ({cutoff:g} Hz low-pass)")
    ax.axvline(cutoff, color=MODEL, lw=0.6, ls="--")
    ax.set_xlim(0.0, fs / 2.0)
    ax.set_ylim(bottom=max(p_fil[p_fil > 0].min(), p_raw.max() * 1e-9))
    ax.set_xlabel("Frequency (Hz)")
    ax.set_ylabel(r"PSD of $\ddot z$ ((m/s$^2$)$^2$/Hz)")
    ax.set_title("Figure 4: filtered and unfiltered relative acceleration PSD", fontsize=10)
    ax.legend(fontsize=8, frameon=False)
    _finish(fig, path)


def fig05_time_history(raw_df: pd.DataFrame, filtered_df: pd.DataFrame, path: str | Path,
                       window: tuple[float, float] | None = None) -> None:
    """Figure 5: relative acceleration z'' (m/s^2) against time (s), unfiltered (grey) and
    filtered (black); ``window`` = (start, end) in s, default the whole record."""
    t = raw_df["time"].to_numpy(dtype=float)
    keep = np.ones(t.size, dtype=bool) if window is None else (t >= window[0]) & (t <= window[1])
    fig, ax = plt.subplots(figsize=(6.4, 3.4))
    ax.plot(t[keep], raw_df["rel_acc"].to_numpy()[keep], color=MEASURED, lw=0.8,
            label="unfiltered")
    ax.plot(t[keep], filtered_df["rel_acc"].to_numpy()[keep], color=MODEL, lw=0.9,
            label="filtered")
    ax.set_xlim(t[keep][0], t[keep][-1])
    ax.set_xlabel("Time (s)")
    ax.set_ylabel(r"Relative acceleration $\ddot z$ (m/s$^2$)")
    ax.set_title("Figure 5: filtered and unfiltered relative acceleration (training data)",
                 fontsize=10)
    ax.legend(fontsize=8, frameon=False, ncol=2)
    _finish(fig, path)


def fig_damping_fit(fit: DampingFit, path: str | Path) -> None:
    """FRF z''/y'' (magnitude, phase in degrees, coherence) of the training data (grey) and of
    the fitted equivalent-linear model (black: same H1 estimator; dashed: exact FRF)."""
    f = fit.freqs_hz
    show = (f > 0.0) & (f <= 2.0 * fit.band_hz[1])
    fig, axes = plt.subplots(3, 1, figsize=(6.4, 6.4), sharex=True,
                             gridspec_kw={"height_ratios": [3, 2, 1]})
    for ax in axes:
        ax.axvspan(*fit.band_hz, color="0.95", zorder=0)
    series = [(fit.h_measured, MEASURED, "-", "training data (H1)"),
              (fit.h_model, MODEL, "-", "model, same estimator"),
              (fit.h_model_exact, MODEL, "--", "model, exact FRF")]
    for h, colour, style, label in series:
        axes[0].loglog(f[show], np.abs(h[show]), color=colour, ls=style, lw=1.0, label=label)
        axes[1].semilogx(f[show], np.degrees(np.unwrap(np.angle(h[show]))), color=colour,
                         ls=style, lw=1.0)
    axes[2].semilogx(f[show], fit.coherence[show], color=MEASURED, lw=1.0)
    axes[0].set_ylabel(r"$|\ddot z / \ddot y|$ (-)")
    axes[1].set_ylabel("Phase (deg)")
    axes[2].set_ylabel(r"Coherence $\gamma^2$")
    axes[2].set_ylim(0.0, 1.05)
    axes[2].set_xlabel("Frequency (Hz)")
    axes[0].legend(fontsize=8, frameon=False)
    axes[0].set_title("Initial modelling: equivalent-linear fit of the FRF (band shaded)\n"
                      f"c_m = {fit.c_m:.1f} N s/m, c_eq = {fit.c_eq:.1f} N s/m "
                      f"(F_c = {fit.F_c:.2f} N, sigma_v = {fit.sigma_v:.4f} m/s)", fontsize=9)
    _finish(fig, path)
