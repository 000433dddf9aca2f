"""The study's headline numbers beside the paper's (the report's first page)."""

from __future__ import annotations

import html
from collections.abc import Mapping

import numpy as np
import pandas as pd

from harvester.study import paper

COLUMNS = ["quantity", "paper", "ours", "truth", "unit"]


def headline_table(table1: pd.DataFrame, posteriors: Mapping[str, pd.DataFrame],
                   bayes: pd.DataFrame, validation: pd.DataFrame) -> pd.DataFrame:
    """Rows: Table 1 values, posterior means (Tables 3, 5), eq. (12), share outside 3 sigma."""
    rows = [{"quantity": f"Table 1: {r.parameter}", "paper": r.paper, "ours": r.value,
             "truth": r.truth, "unit": r.unit} for r in table1.itertuples()]
    for model, df in posteriors.items():
        number = {"linear": "Table 3", "tanh": "Table 5"}.get(model, "posterior")
        rows += [{"quantity": f"{number} ({model}): posterior mean {r.parameter}",
                  "paper": r.paper, "ours": r.mean, "truth": r.truth, "unit": ""}
                 for r in df.itertuples()]
        rows += _interval_rows(number, model, df)
    for r in bayes.itertuples():
        rows.append({"quantity": f"eq. (12): log Bayes factor {r.model} / {r.reference} "
                                 f"(sd over chains {r.sd_over_chains:.2f})",
                     "paper": r.paper, "ours": r.log_bayes_factor, "truth": np.nan, "unit": "nats"})
    sel = validation[(validation["model"] == "tanh") & (validation["data"] == "unseen")]
    for r in sel.itertuples():
        rows.append({"quantity": f"tanh, unseen data: share outside 3 sd ({r.bounds} bounds)",
                     "paper": paper.OUTSIDE_3SIGMA_UNSEEN if r.bounds == "parameter" else np.nan,
                     "ours": r.outside_3sigma, "truth": np.nan, "unit": "fraction"})
    return pd.DataFrame(rows, columns=COLUMNS)


def _interval_rows(number: str, model: str, df: pd.DataFrame) -> list[dict]:
    """Where the rig's truth is known: the 95 % intervals of eq. (10) and adjusted for
    correlated residuals (``inference.correlated_residuals``), the truth beside them."""
    rows = []
    for r in df.to_dict("records"):
        if not np.isfinite(r["truth"]):
            continue
        adjusted = (f"[{r['q2.5_adj']:.4g}, {r['q97.5_adj']:.4g}]"
                    if np.isfinite(r.get("sd_adj", np.nan)) else "none stored")
        rows.append({"quantity": f"{number} ({model}): 95 % interval of {r['parameter']}, "
                                 "eq. (10) / adjusted for correlated residuals",
                     "paper": np.nan, "ours": f"[{r['q2.5']:.4g}, {r['q97.5']:.4g}] / {adjusted}",
                     "truth": r["truth"], "unit": ""})
    return rows


def _cell(x: object) -> str:
    if isinstance(x, float):
        return "" if np.isnan(x) else f"{x:.4g}"
    return html.escape(str(x))


def headline_html(df: pd.DataFrame) -> str:
    """A self-contained HTML page of the headline table."""
    head = "".join(f"<th>{c}</th>" for c in COLUMNS)
    body = "".join("<tr>" + "".join(f"<td>{_cell(v)}</td>" for v in row) + "</tr>"
                   for row in df[COLUMNS].itertuples(index=False))
    return ("<!DOCTYPE html><html><head><meta charset='utf-8'><title>Headline numbers</title>"
            "<style>td,th{padding:2px 8px;border-bottom:1px solid #ddd;text-align:left}</style>"
            "</head><body><h2>Green et al. (2015) reproduced on a SIMULATED virtual rig</h2>"
            "<p>The recordings come from the study's virtual rig, not the paper's device; "
            "'truth' is the rig's ground truth.</p>"
            f"<table><tr>{head}</tr>{body}</table></body></html>\n")
