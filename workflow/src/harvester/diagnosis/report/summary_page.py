"""The diagnosis as one self-contained page a user reads (``summary.html``).

From diagnosis.json and the figures beside it: the verdict in one sentence (the headline:
verdict, share of the unseen output explained, noise floor), what is missing with its size,
the missing force's views where they were made, where the mismatch lies, the candidates, and
the fit before and after on unseen data; each figure embedded (base64 PNG) with a line saying
how to read it, so the page opens alone, in a browser or in the Snakemake report.
"""

from __future__ import annotations

import base64
import html
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from harvester.report_style import STYLE

#: Sections of the page: (title, [(figure file, how to read it)]), in order. Figures a
#: diagnosis did not write are left out; figures not listed here go to the last section.
SECTIONS: tuple[tuple[str, tuple[tuple[str, str], ...]], ...] = (
    ("The missing force", (
        ("latent_force.png", "The force the baseline would need to reproduce the recording "
         "(N, grey, +-2 sd shaded; the best-fitting shape in black), then the same force "
         "against the states: a shape against velocity is friction or damping, against "
         "displacement a spring or a contact, a loop in (z, f) hysteresis; a band that holds "
         "zero throughout means nothing is missing."),
    )),
    ("Where the mismatch lies", (
        ("residual_windows.png", "Share of the residual's energy per time window against "
         "noise replicates: windows far above the band hold the mismatch."),
        ("state_regions.png", "Share per region of the motion (reversals, large |z|, high "
         "speed, standstill): the physics that is missing acts where the bars stand out."),
        ("frequency_bands.png", "Residual energy per band and the part the library's "
         "signatures explain together."),
    )),
    ("The candidates", (
        ("candidates.png", "Evidence gained by each candidate over the baseline (nats) with "
         "its Monte Carlo error, against the acceptance threshold."),
    )),
    ("The fit before and after, on unseen data", (
        ("before_after.png", "Measured output (grey), the baseline's and the improved model's "
         "predictive means (black) on data neither was fitted to."),
        ("added_parameters.png", "Posteriors of the added effect's parameters against their "
         "priors: a posterior piled at a prior's bound is a finding, not a result."),
    )),
)


#: How to read a named effect's force beside the missing force (``latent_force_TERM.png``).
EFFECT_FORCE = ("The named term's fitted force (black) beside the missing force (grey, band "
                "shaded), in time and against z' and z: where they agree, the term took the "
                "shape of what was missing; where they part, the name is doubtful.")


def _esc(x: Any) -> str:
    return html.escape(str(x))


def _figure(path: Path, how: str) -> str:
    data = base64.b64encode(path.read_bytes()).decode("ascii")
    return (f'<figure><img alt="{_esc(path.stem)}" src="data:image/png;base64,{data}">'
            f"<figcaption>{_esc(how)}</figcaption></figure>")


def _missing_lines(doc: Mapping[str, Any]) -> list[str]:
    """What is missing: each named effect with what it implies and its size, each tie with
    its members, and the missing force's shape."""
    cands = {c.get("effect"): c for c in doc.get("candidates") or []}
    mf = doc.get("missing_force") or {}
    sizes = {e.get("term"): e for e in mf.get("named_effects") or []}
    lines = [f"<b>{_esc(e)}</b>: {_esc((cands.get(e) or {}).get('implies', ''))}"
             + (f"<br>size: {_esc(sizes[e]['sentence'])}" if e in sizes else "")
             for e in doc.get("missing") or []]
    if mf.get("together"):
        lines.append(_together_line(mf["together"], sizes))
    if doc.get("negligible"):
        lines.append("detectable but negligible, not the mismatch's: "
                     + ", ".join(_esc(e) for e in doc["negligible"]))
    if doc.get("withheld"):
        lines.append("not named, their force lacks the missing force's shape: "
                     + ", ".join(_esc(e) for e in doc["withheld"]))
    if (mf.get("shape") or {}).get("sentence"):
        lines.append(f"the missing force, seen without the library: "
                     f"{_esc(mf['shape']['sentence'])}")
    shaped = mf.get("fitted_shape") or {}
    if shaped.get("speaks"):  # ``MissingForce.shape_speaks``
        lines.append(f"fitted as a term of the model: {_esc(shaped['sentence'])}"
                     + (f"; {_esc(shaped['named'])} gains {shaped['named_gain_nats']:+.0f} "
                        "nats by the same measure" if shaped.get("named") else ""))
    for tie in doc.get("ties") or []:
        lines.append("cannot tell apart " + " / ".join(_esc(e) for e in tie.get("effects", []))
                     + (f"; the experiment that would: {_esc(tie['recommended'])}"
                        if tie.get("recommended") else ""))
    return lines or ["no library effect named"]


def _together_line(both: Mapping[str, Any], sizes: Mapping[str, Any]) -> str:
    """Several named terms' own forces summed, with the interval (about their mean where the
    record leaves it to the form), in the recording's force unit."""
    key = "varying_rms" if both.get("mean_unfixed") else "rms"
    lo, hi = both[f"{key}_interval_N"]
    unit = next((e.get("force_unit") for e in sizes.values() if e.get("force_unit")), "N")
    about = " about their mean" if key == "varying_rms" else ""
    return (f"together, {_esc(' + '.join(both.get('terms') or []))}: their own force "
            f"{both[f'{key}_N']:.3g} {_esc(unit)} RMS{about} (95 % {lo:.3g}-{hi:.3g})")


def _fit_rows(doc: Mapping[str, Any]) -> str:
    fit = doc.get("fit") or {}
    rows = []
    for which in ("baseline", "improved"):
        f = fit.get(which) or {}
        nrmse = f.get("nrmse")
        rows.append(f"<tr><td>{which}</td><td>{_esc(f.get('structure'))}</td>"
                    f"<td>{'-' if nrmse is None else f'{nrmse:.3g}'}</td>"
                    f"<td>{'-' if nrmse is None else _share(1 - nrmse ** 2)}</td>"
                    f"<td>{_esc(f.get('unseen_data') or '-')}</td></tr>")
    return ("<table><tr><th></th><th>model</th><th>NRMSE</th><th>share explained</th>"
            "<th>unseen data</th></tr>" + "".join(rows) + "</table>")


def _share(x: float) -> str:
    """A share in %, with the digits that tell 99.9 % from 99.99 %."""
    return f"{x:.{1 if x < 0.999 else 3}%}"


def _candidate_rows(doc: Mapping[str, Any]) -> str:
    rows = [f"<tr><td>{c.get('round')}</td><td>{_esc(c.get('effect'))}</td>"
            f"<td>{_num(c.get('delta_log_evidence'))} &plusmn; "
            f"{_num(c.get('delta_log_evidence_se'))}</td><td>{_num(c.get('threshold'))}</td>"
            f"<td>{'yes' if c.get('accepted') else 'no'}</td></tr>"
            for c in doc.get("candidates") or []]
    return ("<table><tr><th>round</th><th>effect</th><th>evidence gain (nats)</th>"
            "<th>threshold</th><th>accepted</th></tr>" + "".join(rows) + "</table>")


def _num(x: Any) -> str:
    return "-" if x is None else f"{x:.3g}"


def summary_page(doc: Mapping[str, Any], figure_dir: str | Path, title: str,
                 links: Sequence[tuple[str, str]] = ()) -> str:
    """The page (module docstring) of diagnosis.json ``doc`` with the figures in
    ``figure_dir``; figures of ``doc["figures"]`` outside :data:`SECTIONS` go last, with
    their line from ``doc["figure_captions"]`` where it gives one; ``links`` (text, href
    relative to the page) last, under "See also" (a group's benchmark page)."""
    figure_dir = Path(figure_dir)
    body = [f"<h1>{_esc(title)}</h1>",
            f'<p class="headline">{_esc(doc.get("headline") or doc.get("verdict"))}</p>',
            "<h2>What is missing</h2><ul>"
            + "".join(f"<li>{line}</li>" for line in _missing_lines(doc)) + "</ul>"]
    listed = {name for _, figs in SECTIONS for name, _ in figs} | {
        p.name for p in figure_dir.glob("latent_force_*.png")}
    for section, figs in SECTIONS:
        parts = [_figure(figure_dir / name, how) for name, how in figs
                 if (figure_dir / name).is_file()]
        if section == "The missing force":
            parts += [_figure(path, EFFECT_FORCE) for path in
                      sorted(figure_dir.glob("latent_force_*.png"))]
        if section == "The candidates":
            parts.insert(0, _candidate_rows(doc))
        if section.startswith("The fit"):
            parts.insert(0, _fit_rows(doc))
        if parts:
            body.append(f"<h2>{_esc(section)}</h2>" + "".join(parts))
    captions = doc.get("figure_captions") or {}
    others = [_figure(figure_dir / Path(f).name, captions.get(Path(f).name, ""))
              for f in doc.get("figures") or []
              if Path(f).name not in listed and (figure_dir / Path(f).name).is_file()]
    if others:
        body.append("<h2>Other figures</h2>" + "".join(others))
    body.append(_time_section(doc.get("budget") or {}, doc.get("runtime_s")))
    body.append(_notes(doc.get("notes") or []))
    if links:
        body.append("<h2>See also</h2><ul>" + "".join(
            f'<li><a href="{_esc(href)}">{_esc(text)}</a></li>' for text, href in links)
            + "</ul>")
    return (f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{_esc(title)}</title>"
            f"<style>{STYLE}</style></head><body>{''.join(body)}</body></html>\n")


def _time_section(budget: Mapping[str, Any], runtime: float | None) -> str:
    """The time budget, what it left undecided, and where the time went (``budget``)."""
    total = budget.get("seconds")
    head = (f"<p>{_num(runtime)} s; no time budget</p>" if total is None else
            f"<p>{_num(runtime)} s of a budget of {total:.0f} s (the search's share "
            f"{budget.get('search_budget_seconds') or 0:.0f} s)</p>")
    cut = [f"<li>{_esc(u['where'])}: {_esc(u['what'])}: {_esc(u['how'])}</li>"
           for u in budget.get("unfinished") or []]
    undecided = ("<p>Not decided within the budget (run again with a larger "
                 "<code>--budget</code> to decide them):</p><ul>" + "".join(cut) + "</ul>"
                 if cut else "")
    rows = "".join(f"<tr><td>{_esc(t['step'])}</td><td>{t['seconds']:.1f}</td></tr>"
                   for t in budget.get("timeline") or [])
    table = f"<table><tr><th>step</th><th>s</th></tr>{rows}</table>" if rows else ""
    return "<h2>Time</h2>" + head + undecided + table


def _notes(notes: Sequence[str]) -> str:
    if not notes:
        return ""
    return "<h2>Notes</h2><ul>" + "".join(f"<li>{_esc(n)}</li>" for n in notes) + "</ul>"
