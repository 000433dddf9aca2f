"""The study's headline numbers beside the paper's (the report's first page)."""

from __future__ import annotations

import html
from collections.abc import Mapping
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd
from scipy.stats import norm

from harvester.study import paper

if TYPE_CHECKING:  # the headline's tables are read without the simulator's import
    from harvester.inference.predictive import PredictiveBand

COLUMNS = ["quantity", "paper", "ours", "truth", "unit", "note"]


def headline_table(table1: pd.DataFrame, posteriors: Mapping[str, pd.DataFrame],
                   bayes: pd.DataFrame, validation: pd.DataFrame,
                   sticking: pd.DataFrame | None = None) -> pd.DataFrame:
    """Rows: Table 1 values, posterior means (Tables 3, 5), eq. (12), share outside 3 sigma,
    and Figure 7's misfit while the rig is stuck and while it moves (``sticking``: one row
    per model of ``study.sticking.StickMisfit.to_dict``)."""
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
    for r in ([] if sticking is None else sticking.itertuples()):
        rows.append({"quantity": f"Figure 7: {r.model} model's RMS misfit over the record's "
                                 f"RMS, while the rig is stuck ({r.stuck_pct:g} % of the "
                                 "samples) / while it moves",
                     "paper": np.nan, "ours": f"{r.nrmse_stuck:.3g} / {r.nrmse_moving:.3g}",
                     "truth": np.nan, "unit": ""})
    return pd.DataFrame(rows, columns=COLUMNS)


def _sigma(df: pd.DataFrame) -> float:
    return float(df.set_index("parameter").loc["sigma", "mean"])


def what_cannot_hold(posteriors: Mapping[str, pd.DataFrame], log_bf: float,
                     ensemble_ratio: float) -> dict[str, str]:
    """Notes, by the start of the headline's quantity, on the paper's numbers that cannot
    hold beside the others, computed from the paper's own numbers and ours (docs/design.md,
    the virtual rig). ``log_bf``: our eq. (12); ``ensemble_ratio``: the tanh model's
    parameter-ensemble sd over its RMS residual on the unseen record."""
    n, p3, p5 = paper.TRAINING_SAMPLES, paper.TABLE3["sigma"], paper.TABLE5["sigma"]
    lin, tanh = _sigma(posteriors["linear"]), _sigma(posteriors["tanh"])
    c_m = float(posteriors["linear"].set_index("parameter").loc["c_m", "mean"])
    need = norm.isf(paper.OUTSIDE_3SIGMA_UNSEEN / 2.0) / 3.0

    def ours_l(a: float, b: float) -> float:  # eq. (10)'s likelihood ratio at two sigmas
        return n * float(np.log(a / b))
    return {
        "Table 3 (linear): posterior mean sigma": (
            f"cannot hold beside Table 3's c_m and Table 5's sigma: the paper's sigmas leave "
            f"the linear model sqrt({p3}^2 - {p5}^2) = {np.sqrt(p3**2 - p5**2):.3f} m/s^2 of "
            f"misfit beyond the tanh model's; at a linear c_m of {c_m:.0f} N s/m (paper "
            f"{paper.TABLE3['c_m']}) the rig, with Table 5's friction, leaves "
            f"{np.sqrt(max(lin**2 - tanh**2, 0.0)):.3f}"),
        "eq. (12)": (
            f"with the paper's sigmas and N = {n}, eq. (10) alone gives the tanh model "
            f"N ln({p3} / {p5}) = {ours_l(p3, p5):.1f} nats over the linear one; "
            f"{paper.LOG_BAYES_FACTOR_TANH_LINEAR} needs the priors and Occam factors to take "
            f"{ours_l(p3, p5) - paper.LOG_BAYES_FACTOR_TANH_LINEAR:.1f} of them back, where "
            f"ours add {log_bf - ours_l(lin, tanh):+.1f} (N ln({lin:.4g} / {tanh:.4g}) = "
            f"{ours_l(lin, tanh):.1f} of our {log_bf:.1f})"),
        "tanh, unseen data: share outside 3 sd (parameter": (
            f"cannot hold with {n} independent residuals: the parameter ensemble's sd is "
            f"{ensemble_ratio:.3f} x the residual's, so Gaussian residuals fall outside 3 of "
            f"it in {2.0 * norm.sf(3.0 * ensemble_ratio):.1%} of the samples; "
            f"{paper.OUTSIDE_3SIGMA_UNSEEN:.1%} needs {need:.2f} x"),
    }


def figure7_notes(sticking: pd.DataFrame) -> dict[str, str]:
    """Notes on Figure 7's rows (``sticking``: one row per model of
    ``study.sticking.StickMisfit.to_dict``, the linear model's and the tanh model's): what
    each model misses while the rig is stuck against while it moves."""
    by = sticking.set_index("model")
    if not {"linear", "tanh"} <= set(by.index):
        return {}
    lin, tanh = by.loc["linear"], by.loc["tanh"]
    return {
        "Figure 7: linear": (
            f"the paper's reading, measured: the linear model, which cannot stick, misses "
            f"{lin.nrmse_stuck:.0%} of the record while the rig is stuck against "
            f"{lin.nrmse_moving:.0%} while it moves; in m/s^2 its misfit is largest at speed "
            f"({lin.rms_fastest_band:.3g} in the fastest band, {lin.rms_stuck:.3g} stuck)"),
        "Figure 7: tanh": (
            f"its misfit is its noise level stuck and moving ({tanh.rms_stuck:.3g} and "
            f"{tanh.rms_moving:.3g} m/s^2): the share while stuck is the noise's share of the "
            "small record there"),
    }


def headline_notes(posteriors: Mapping[str, pd.DataFrame], bayes: pd.DataFrame,
                   unseen: PredictiveBand, measured: np.ndarray,
                   sticking: pd.DataFrame) -> dict[str, str]:
    """Every note of the headline: :func:`what_cannot_hold` with our eq. (12) from ``bayes``
    and the tanh model's parameter-ensemble sd over its RMS residual on the ``unseen`` record
    (its band and the ``measured`` output), and :func:`figure7_notes`."""
    ratio = float(np.sqrt(np.mean(unseen.sd_parameter ** 2))
                  / np.sqrt(np.mean((measured - unseen.mean) ** 2)))
    log_bf = float(bayes.set_index("model").loc["tanh", "log_bayes_factor"])
    return {**what_cannot_hold(posteriors, log_bf, ratio), **figure7_notes(sticking)}


def with_notes(table: pd.DataFrame, notes: Mapping[str, str]) -> pd.DataFrame:
    """``table`` with each note on the rows whose quantity starts with its key."""
    out = table.copy()
    out["note"] = out["note"].astype(object)
    for key, note in notes.items():
        out.loc[out["quantity"].str.startswith(key), "note"] = note
    return out


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
            "<p>The recordings come from the study's virtual rig, not the paper's device, "
            "calibrated to the paper's statistics (docs/design.md); 'truth' is the rig's "
            "ground truth. Where one of the paper's numbers cannot hold beside its others, "
            "the note says why, computed from the paper's numbers and ours.</p>"
            f"<table><tr>{head}</tr>{body}</table></body></html>\n")
