"""Paper-versus-ours tables: Table 1 now, the same layout later for Tables 3 and 5.

Every table has exactly the columns ``parameter, value, unit, paper, truth``: ``value`` is
ours (from the SIMULATED recordings of the virtual rig), ``paper`` is Green et al. (2015) and
``truth`` is the virtual rig's parameter where one exists (NaN otherwise). Notes go in the
rendered table, never in the CSV.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from harvester.study import paper
from harvester.initial.damping import DampingFit, DampingSummary
from harvester.initial.static_friction import StaticFrictionEstimate
from harvester.inference.priors import PriorSpec

#: Columns of every comparison table, in order.
COLUMNS: list[str] = ["parameter", "value", "unit", "paper", "truth"]

#: Footnote carried by every rendered table.
SIMULATED_NOTE = ("Recordings from the virtual rig (SIMULATED), not the paper's measurements; "
                  "'truth' is the virtual rig's parameter.")


#: The paper's prior tables, by model structure.
PAPER_PRIORS: dict[str, Mapping[str, tuple[float, float | None]]] = {
    "linear": paper.TABLE2, "tanh": paper.TABLE4,
}


def _paper_priors_for(model_params: Sequence[str]) -> Mapping[str, tuple[float, float | None]]:
    """The paper table whose parameters are exactly ``model_params`` (Table 2 or Table 4)."""
    for table in PAPER_PRIORS.values():
        if set(table) == set(model_params):
            return table
    return paper.TABLE4


def prior_table(model_params: Sequence[str], specs: Mapping[str, PriorSpec],
                paper_priors: Mapping[str, tuple[float, float | None]] | None = None
                ) -> pd.DataFrame:
    """Our priors beside the paper's (Table 2 or 4) for the parameters of one model.

    Columns: parameter, mean, sd, unit, paper_mean, paper_sd (NaN where the paper gives
    none, e.g. sigma's sd in Table 2). ``paper_priors`` defaults to the paper table with the
    same parameter set (Table 2 for {c_m, sigma}, otherwise Table 4).
    """
    missing = [p for p in model_params if p not in specs]
    if missing:
        raise ValueError(f"no prior for {missing}; config priors has {sorted(specs)}")
    reference = _paper_priors_for(model_params) if paper_priors is None else paper_priors
    rows = []
    for name in model_params:
        spec = specs[name]
        paper_mean, paper_sd = reference.get(name, (np.nan, np.nan))
        rows.append({"parameter": name, "mean": spec.mean, "sd": spec.sd, "unit": spec.unit,
                     "paper_mean": float(paper_mean),
                     "paper_sd": np.nan if paper_sd is None else float(paper_sd)})
    return pd.DataFrame(rows, columns=["parameter", "mean", "sd", "unit", "paper_mean",
                                       "paper_sd"])


def compare_table(ours: Mapping[str, float], paper_values: Mapping[str, float],
                  truth: Mapping[str, float], units: Mapping[str, str]) -> pd.DataFrame:
    """Ours beside the paper's and the rig's values, one row per key of ``ours``, in order.

    Missing paper or truth values are NaN; missing units are ''.
    """
    rows = [{"parameter": name, "value": float(value), "unit": units.get(name, ""),
             "paper": float(paper_values.get(name, np.nan)),
             "truth": float(truth.get(name, np.nan))}
            for name, value in ours.items()]
    return pd.DataFrame(rows, columns=COLUMNS)


def rig_truth(config_rig: Mapping[str, Any]) -> dict[str, float]:
    """The virtual rig's Table 1 parameters: M, m, k, c_m and F_c = static friction F_s."""
    return {"M": float(config_rig["M"]), "m": float(config_rig["m"]),
            "k": float(config_rig["k"]), "F_c": float(config_rig["friction"]["F_s"]),
            "c_m": float(config_rig["c_m"])}


def table1(static: StaticFrictionEstimate, damping: DampingFit | DampingSummary,
           config_rig: Mapping[str, Any]) -> pd.DataFrame:
    """Table 1, initial parameter estimates: M, m, k (known, config ``rig``), F_c, c_m.

    F_c is ours from the static test (eqs. (4)-(5)); its truth is the rig's static friction
    F_s, which the static test measures. c_m is ours from the equivalent-linearisation FRF fit.
    """
    ours = {"M": float(config_rig["M"]), "m": float(config_rig["m"]),
            "k": float(config_rig["k"]), "F_c": static.F_c, "c_m": damping.c_m}
    return compare_table(ours, paper.TABLE1, rig_truth(config_rig), paper.TABLE1_UNITS)


def table1_notes(static: StaticFrictionEstimate, damping: DampingFit | DampingSummary,
                 config_rig: Mapping[str, Any]) -> list[str]:
    """Footnotes of the rendered Table 1 (the CSV holds only the five columns)."""
    friction = config_rig["friction"]
    return [
        "M, m and k are taken as known (config rig), as the paper measured them directly.",
        f"F_c: static test, mean of k(x1 - x2)/2 over {static.n} repeats "
        f"(sd {static.sd:.2f} N, standard error {static.se:.2f} N, mean span "
        f"{static.span_m:.4f} m; paper span {paper.STATIC_TEST_SPAN_M} m). Truth is the rig's "
        f"static friction F_s; its kinetic friction is {friction['law']} with "
        f"F_c = {friction['F_c']} N.",
        f"c_m: fitted to the FRF z''/y'' over {damping.band_hz[0]}-{damping.band_hz[1]} Hz with "
        f"Coulomb friction F_c = {damping.F_c:.2f} N linearised as c_eq = sqrt(2/pi) F_c/sigma_v "
        f"= {damping.c_eq:.1f} N s/m (sigma_v = {damping.sigma_v:.4f} m/s).",
    ]


def table1_values(df: pd.DataFrame) -> dict[str, float]:
    """parameter -> value of a comparison table (e.g. our Table 1, for the priors)."""
    return {str(p): float(v) for p, v in zip(df["parameter"], df["value"])}


def _fmt(x: Any) -> str:
    """Four significant figures; a dash for NaN; strings unchanged."""
    if isinstance(x, str):
        return x
    if x is None or (isinstance(x, float) and np.isnan(x)):
        return "—"
    return f"{x:.4g}"


def render_table(df: pd.DataFrame, title: str, notes: Sequence[str] = ()) -> str:
    """Markdown fragment: a title line, the table, and numbered notes ending with the
    simulated-recordings footnote."""
    header = "| " + " | ".join(map(str, df.columns)) + " |"
    rule = "|" + "|".join("---" for _ in df.columns) + "|"
    body = ["| " + " | ".join(_fmt(x) for x in row) + " |"
            for row in df.itertuples(index=False)]
    all_notes = [*notes, SIMULATED_NOTE]
    footer = [f"{i}. {note}" for i, note in enumerate(all_notes, start=1)]
    return "\n".join([f"**{title}**", "", header, rule, *body, "", *footer, ""])


def write_table_png(df: pd.DataFrame, path: str | Path, title: str,
                    notes: Sequence[str] = ()) -> None:
    """The table as a PNG image (matplotlib), with its notes and the simulated footnote."""
    import textwrap

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from harvester.plots.style import save_figure

    cells = [[_fmt(x) for x in row] for row in df.itertuples(index=False)]
    lines = [textwrap.fill(f"{i}. {n}", width=120, subsequent_indent="   ")
             for i, n in enumerate([*notes, SIMULATED_NOTE], start=1)]
    n_note_lines = sum(line.count("\n") + 1 for line in lines)
    table_h, notes_h = 0.28 * (len(cells) + 1) + 0.4, 0.16 * n_note_lines + 0.1
    fig, (ax_t, ax_n) = plt.subplots(2, 1, figsize=(8.5, table_h + notes_h),
                                     gridspec_kw={"height_ratios": [table_h, notes_h]})
    for ax in (ax_t, ax_n):
        ax.axis("off")
    ax_t.set_title(title, fontsize=10)
    table = ax_t.table(cellText=cells, colLabels=list(df.columns), loc="center",
                       cellLoc="center", bbox=(0.0, 0.0, 1.0, 1.0))
    table.auto_set_font_size(False)
    table.set_fontsize(9)
    ax_n.text(0.0, 1.0, "\n".join(lines), fontsize=7, va="top", ha="left",
              transform=ax_n.transAxes)
    save_figure(fig, path, tight=False, crop=True)
