"""Figures of a diagnosis: where the mismatch is, which effects explain it, the fit before
and after. Measured in grey, model mean in black, bounds shaded (the paper's look)."""

from __future__ import annotations

import logging
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from harvester.plots.style import save_figure  # noqa: E402

log = logging.getLogger("harvester.diagnosis")


def _output(diag) -> tuple[str, str]:
    """(symbol, unit) of the recording's output kind for axis labels."""
    kind = diag.rounds[0].state.problem.output_type if diag.rounds else None
    if kind is None or kind.order == 2:
        return "$\\ddot z$", "m/s$^2$"
    return "$z$", "m"


def residual_windows(diag, path: Path) -> Path:
    """Band-limited residual over time, windows with excess energy shaded."""
    det = diag.rounds[0].detection
    w, ws = det.windows, det.window_stats
    t = w.time
    fig, (ax, bx) = plt.subplots(2, 1, figsize=(10, 5.5), sharex=True,
                                 gridspec_kw={"height_ratios": [2, 1]})
    thr = ws.threshold()
    ratio = np.exp(ws.observed) / w.expected_share()
    for (a, b), z, rt in zip(w.bounds_s, ws.z, ratio):
        if z >= thr and rt > 1:
            ax.axvspan(a, b, color="tab:red", alpha=0.15, lw=0)
            bx.axvspan(a, b, color="tab:red", alpha=0.15, lw=0)
    ax.plot(t, det.residual_band, color="0.55", lw=0.6, label="residual (measured - model mean)")
    ax.plot(t, det.explained_band, color="k", lw=0.8, label="part explained by the candidates")
    symbol, unit = _output(diag)
    ax.set_ylabel(f"{symbol} residual ({unit})")
    ax.set_title(f"{diag.baseline.name}: residual in {det.frame.f_low:g}-{det.frame.f_high:.1f} Hz"
                 f" (shaded: windows holding significantly more energy)", fontsize=10)
    ax.legend(loc="upper right", fontsize=8, frameon=False)
    centres = [0.5 * (a + b) for a, b in w.bounds_s]
    widths = [0.9 * (b - a) for a, b in w.bounds_s]
    bx.bar(centres, ratio, width=widths, color="0.5")
    bx.axhline(1.0, color="k", lw=0.8)
    bx.set_ylabel("energy / expected")
    bx.set_xlabel("time (s)")
    return save_figure(fig, path)


def state_regions(diag, path: Path) -> Path:
    """Share of residual energy per state region against its share of time, and the residual's
    mean square against the relative velocity and displacement."""
    rnd = diag.rounds[0]
    det, st = rnd.detection, rnd.state
    rg, rs = det.regions, det.region_stats
    fig, axes = plt.subplots(1, 3, figsize=(13, 4.2))
    ratio = rg.energy_share(rs.observed) / rg.time_share()
    ok = (rs.z >= rs.threshold()) & (ratio > 1)
    y = np.arange(len(rg.names))
    axes[0].barh(y, ratio, color=np.where(ok, "tab:red", "0.55"))
    axes[0].axvline(1.0, color="k", lw=0.8)
    axes[0].set_yticks(y, [n.replace("_", " ") for n in rg.names], fontsize=8)
    axes[0].set_xlabel("residual energy share / time share")
    axes[0].set_title("state regions (red: significant excess)", fontsize=10)
    sl = slice(det.frame.start, det.frame.stop)
    e = det.residual_band**2 / np.maximum(det.frame.time_weight, 1e-3)
    for ax, x, label in ((axes[1], st.rel_vel[sl], "relative velocity $\\dot z$ (m/s)"),
                         (axes[2], st.rel_disp[sl] - np.median(st.rel_disp[sl]),
                          "relative displacement $z$ (m)")):
        edges = np.quantile(x, np.linspace(0, 1, 21))
        idx = np.clip(np.searchsorted(edges, x, side="right") - 1, 0, 19)
        ms = np.array([e[idx == k].mean() if np.any(idx == k) else np.nan for k in range(20)])
        ax.plot(0.5 * (edges[1:] + edges[:-1]), np.sqrt(ms), "o-", color="k", ms=3)
        ax.axhline(np.sqrt(np.mean(e)), color="0.5", lw=0.8, ls="--", label="overall")
        ax.set_xlabel(label + " (model)")
        ax.set_ylabel(f"RMS residual ({_output(diag)[1]})")
        ax.legend(fontsize=8, frameon=False)
    axes[1].set_title("where the residual lives in the motion", fontsize=10)
    return save_figure(fig, path)


def frequency_bands(diag, path: Path) -> Path:
    """Residual PSD against white noise through the passband, and the explained part."""
    det = diag.rounds[0].detection
    fr = det.frame
    scale = 2.0 / (fr.fs * fr.n * np.mean(fr.taper**2))  # periodogram -> one-sided PSD
    band = fr.mask > 0
    f = fr.freqs[band]
    p_res = fr.smoothed_mean(np.abs(det.residual_dft) ** 2)[band] * scale
    p_exp = fr.smoothed_mean(np.abs(np.fft.rfft(det.explained_band)) ** 2)[band] * scale
    floor = np.median(det.spectrum[band]) * scale
    fig, ax = plt.subplots(figsize=(9, 4.2))
    b, bs = det.bands, det.band_explained_stats
    thr = bs.threshold()
    for (lo, hi), z in zip(b.bounds_hz, bs.z):
        if z >= thr:
            ax.axvspan(lo, hi, color="tab:red", alpha=0.12, lw=0)
    ax.semilogy(f, p_res, color="0.55", label="residual")
    ax.semilogy(f, np.maximum(p_exp, 1e-30), color="k", label="explained by the candidates")
    ax.semilogy(f, np.full_like(f, floor) * fr.mask[band] ** 2, color="tab:blue", ls="--",
                label="white noise at the residual's median level")
    ax.set_ylim(0.3 * min(np.min(p_res), floor), 3 * max(np.max(p_res), floor))
    ax.set_xlabel("frequency (Hz)")
    ax.set_ylabel(f"PSD (({_output(diag)[1]})$^2$/Hz)")
    ax.set_title("residual spectrum (shaded: bands where the candidates explain significant "
                 "energy)", fontsize=10)
    ax.legend(fontsize=8, frameon=False)
    return save_figure(fig, path)


def candidates(diag, path: Path) -> Path:
    """Cheap ranking and, for the sampled candidates, the evidence gain and threshold."""
    rnd = diag.rounds[0]
    ranked = rnd.ranked[:10]
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.2))
    y = np.arange(len(ranked))
    axes[0].barh(y, [r.rank_score for r in ranked],
                 color=["tab:red" if r.score.p_value < rnd.detection.alpha else "0.6"
                        for r in ranked])
    axes[0].set_yticks(y, [r.effect.replace("_", " ") for r in ranked], fontsize=8)
    axes[0].invert_yaxis()
    axes[0].set_xlabel("score + prior-conflict relief, delta chi^2 / 2 (nats)")
    axes[0].set_title("ranking (red: significant score test)", fontsize=10)
    confirmed = [(i + 1, r) for i, rd in enumerate(diag.rounds) for r in rd.confirmed]
    if confirmed:
        y2 = np.arange(len(confirmed))
        axes[1].barh(y2, [r.delta_log_evidence for _, r in confirmed],
                     xerr=[2 * r.delta_se for _, r in confirmed],
                     color=["tab:green" if r.accepted else "0.6" for _, r in confirmed])
        for k, (_, r) in enumerate(confirmed):
            axes[1].plot([r.threshold, r.threshold], [k - 0.4, k + 0.4], color="k", lw=1.5)
        axes[1].set_yticks(y2, [f"round {i}: +{r.effect.replace('_', ' ')}"
                                for i, r in confirmed], fontsize=8)
        axes[1].invert_yaxis()
        axes[1].axvline(0, color="k", lw=0.6)
    axes[1].set_xlabel("delta log evidence (nats; bar: acceptance threshold)")
    axes[1].set_title("TMCMC evidence (green: accepted)", fontsize=10)
    return save_figure(fig, path)


def before_after(diag, path: Path, seconds: float = 6.0) -> Path:
    """Unseen data: measured (grey), model mean (black), 3-sigma predictive bounds."""
    panels = [("before: " + diag.baseline.name, diag.unseen_before),
              ("after: " + diag.improved.name, diag.unseen_after)]
    fig, axes = plt.subplots(2, 1, figsize=(10, 6), sharex=True)
    for ax, (title, u) in zip(axes, panels):
        if u is None:
            ax.set_title(title + " (no unseen data)", fontsize=10)
            continue
        sel = u.time <= u.time[0] + seconds
        t = u.time[sel]
        ax.fill_between(t, (u.mean - 3 * u.sd)[sel], (u.mean + 3 * u.sd)[sel], color="tab:blue",
                        alpha=0.2, lw=0, label="mean $\\pm$3 sd (predictive)")
        ax.plot(t, u.measured[sel], color="0.6", lw=1.0, label=f"measured ({u.data})")
        ax.plot(t, u.mean[sel], color="k", lw=0.9, label="model mean")
        ax.set_ylabel("{} ({})".format(*_output(diag)))
        ax.set_title(f"{title}: NRMSE {u.nrmse:.3f}, {100 * u.coverage_3sigma:.1f} % inside "
                     "3 sd", fontsize=10)
        ax.legend(loc="upper right", fontsize=8, ncol=3, frameon=False)
    axes[-1].set_xlabel("time (s)")
    return save_figure(fig, path)


def added_parameters(diag, path: Path) -> Path | None:
    """Posterior of the parameters the diagnosis added (histograms), with their priors."""
    fit = diag.improved_fit
    if fit is None:
        return None
    from harvester.model.terms import term
    names = [p for t in diag.improved.terms if t not in diag.baseline.terms
             for p in term(t).parameter_names]
    if not names:
        return None
    fig, axes = plt.subplots(1, len(names), figsize=(4 * len(names), 3.4), squeeze=False)
    for ax, name in zip(axes[0], names):
        j = fit.names.index(name)
        x = fit.samples[:, j]
        ax.hist(x, bins=30, density=True, color="0.6")
        spec = fit.priors.get(name)
        if spec is not None:
            lo, hi = spec.distribution().ppf([0.01, 0.99])
            grid = np.linspace(min(x.min(), lo), max(x.max(), hi), 200)
            ax.plot(grid, np.exp(spec.logpdf(grid)), color="k", lw=1, label="prior")
            unit = f" ({spec.unit})" if spec.unit else ""
        else:
            unit = ""
        ax.set_xlabel(name + unit)
        ax.set_ylabel("density")
        ax.legend(fontsize=8, frameon=False)
    added = ", ".join(t for t in diag.improved.terms if t not in diag.baseline.terms)
    fig.suptitle(f"added: {added} (posterior histogram, prior curve)", fontsize=10)
    return save_figure(fig, path)


FIGURES = {
    "residual_windows.png": residual_windows,
    "state_regions.png": state_regions,
    "frequency_bands.png": frequency_bands,
    "candidates.png": candidates,
    "before_after.png": before_after,
    "added_parameters.png": added_parameters,
}


def all_figures(diag, out_dir: Path) -> list[str]:
    """Write every figure; returns notes on the ones that failed. Sets diag.figure_files."""
    notes, files = [], []
    for name, fn in FIGURES.items():
        try:
            made = fn(diag, Path(out_dir) / name)
            if made is not None:
                files.append(name)
        except Exception as err:  # a figure must never lose the diagnosis
            log.exception("figure %s failed", name)
            notes.append(f"figure {name} failed: {err}")
    diag.figure_files[:] = files
    return notes
