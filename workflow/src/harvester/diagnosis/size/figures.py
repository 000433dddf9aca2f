"""Figures of the missing force (``latent``), its shape (``shapes``) and a named effect's force
beside it (``views.effect_force``), in the project's style: the force estimated from
the recording in grey with its +-2 sd band shaded, the model (a fitted shape, a term's force)
in black, every axis labelled with its unit."""

from __future__ import annotations

from pathlib import Path

from harvester.data.units import Units
from harvester.diagnosis.size.latent import LatentForce
from harvester.diagnosis.size.views import Binned, EffectForce, views
from harvester.diagnosis.size.shapes import ShapeDescription
from harvester.plots.style import (BOUNDS, LEGEND_SIZE, MEASURED, MODEL, TITLE_SIZE,
                                   axis_label, plt, save_figure)

BAND_COLOUR, BAND_ALPHA = BOUNDS["predictive"]


def _force_label(units: Units, what: str = "missing force f") -> str:
    return axis_label(what, units.label("force"))


def _band(ax, x, lower, upper, label="+-2 sd") -> None:
    ax.fill_between(x, lower, upper, color=BAND_COLOUR, alpha=BAND_ALPHA, lw=0, label=label)


def _binned_panel(ax, b: Binned, units: Units) -> None:
    _band(ax, b.centre, b.lower, b.upper)
    ax.plot(b.centre, b.mean, "o-", color=MEASURED, ms=3, lw=1, label="latent force (binned)")
    ax.axhline(0.0, color=MODEL, lw=0.5)
    ax.set_xlabel(axis_label(b.label, b.unit))
    ax.set_ylabel(_force_label(units))


def _time_panel(ax, lf: LatentForce, desc: ShapeDescription | None) -> None:
    _band(ax, lf.time, lf.lower, lf.upper)
    ax.plot(lf.time, lf.force, color=MEASURED, lw=0.6, label="latent force")
    if desc is not None:
        ax.plot(lf.time, desc.best.fitted, color=MODEL, lw=0.6, label=f"{desc.best.name} fit")
    ax.set_xlabel(axis_label("time", "s"))
    ax.set_ylabel(_force_label(lf.units))
    ax.legend(fontsize=LEGEND_SIZE, loc="upper right")


def latent_force_figure(lf: LatentForce, desc: ShapeDescription | None,
                        path: str | Path) -> Path:
    """Six panels: f(t) with its band and the best shape's fit; the (z, f) loop; binned
    means of f against z, z', the time and the input. Title: the one-sentence description."""
    fig, axes = plt.subplots(3, 2, figsize=(10, 10))
    _time_panel(axes[0, 0], lf, desc)
    ax = axes[0, 1]
    scale, z_unit = lf.units.small("displacement")
    ax.plot(scale * lf.rel_disp, lf.force, color=MEASURED, lw=0.4, label="latent force")
    if desc is not None:
        ax.plot(scale * lf.rel_disp, desc.best.fitted, color=MODEL, lw=0.4, label="shape fit")
    ax.set_xlabel(axis_label("z", z_unit))
    ax.set_ylabel(_force_label(lf.units))
    ax.set_title("loop in (z, f)", fontsize=TITLE_SIZE)
    for ax, b in zip(axes[1:].ravel(), views(lf).values()):
        _binned_panel(ax, b, lf.units)
    axes[1, 0].legend(fontsize=LEGEND_SIZE)
    title = desc.sentence if desc is not None else f"missing force of {lf.baseline}"
    fig.suptitle(_wrap(f"{lf.baseline}: {title}"), fontsize=TITLE_SIZE)
    return save_figure(fig, path, rect=(0, 0, 1, 0.96))


def effect_force_figure(ef: EffectForce, path: str | Path, excerpt_s: float = 5.0,
                        share: float | None = None) -> Path:
    """The named effect's force beside the latent force: an excerpt of both in time, and
    both against z' and against z; titled with ``share`` (the share of the missing force it
    explains as the shapes read theirs, ``ShapeDescription.share_of``; default its plain
    share)."""
    fig, axes = plt.subplots(1, 3, figsize=(13, 4))
    t0 = ef.time[0]
    sel = ef.time <= t0 + excerpt_s
    ax = axes[0]
    _band(ax, ef.time[sel], (ef.latent - 2 * ef.latent_sd)[sel],
          (ef.latent + 2 * ef.latent_sd)[sel])
    ax.plot(ef.time[sel], ef.latent[sel], color=MEASURED, lw=0.8, label="latent force")
    ax.plot(ef.time[sel], ef.change[sel], color=MODEL, lw=0.8,
            label=f"improved - baseline ({ef.term})")
    ax.set_xlabel(axis_label("time", "s"))
    ax.set_ylabel(_force_label(ef.units, "force"))
    ax.legend(fontsize=LEGEND_SIZE)
    scale, z_unit = ef.units.small("displacement")
    for ax, x, label in ((axes[1], ef.rel_vel, axis_label("z'", ef.units.label("velocity"))),
                         (axes[2], scale * ef.rel_disp, axis_label("z", z_unit))):
        ax.plot(x, ef.latent, ".", color=MEASURED, ms=1, label="latent force")
        ax.plot(x, ef.change, ".", color=MODEL, ms=1, label="improved - baseline")
        ax.set_xlabel(label)
        ax.set_ylabel(_force_label(ef.units, "force"))
    share = ef.share if share is None else share
    fig.suptitle(f"{ef.term}: explains {100 * max(share, 0):.0f} % of the latent force, "
                 f"{100 * ef.coverage:.0f} % of samples within its band", fontsize=TITLE_SIZE)
    return save_figure(fig, path, rect=(0, 0, 1, 0.93))


def _wrap(text: str, width: int = 110) -> str:
    words, lines, line = text.split(), [], ""
    for w in words:
        if len(line) + len(w) + 1 > width:
            lines.append(line)
            line = w
        else:
            line = f"{line} {w}".strip()
    return "\n".join(lines + [line])


def all_latent_figures(lf: LatentForce, desc: ShapeDescription | None, out_dir: str | Path,
                       effects: list[EffectForce] = (), shares: list[float] | None = None
                       ) -> list[str]:
    """Write the figures to ``out_dir``; returns their file names. ``shares``: each effect's
    share of the missing force as the shapes read theirs (``EffectSize.explains``)."""
    out = Path(out_dir)
    files = [latent_force_figure(lf, desc, out / "latent_force.png").name]
    files += [effect_force_figure(ef, out / f"latent_force_{ef.term}.png",
                                  share=None if shares is None else shares[i]).name
              for i, ef in enumerate(effects)]
    return files
