"""Evidence table of several model structures identified on one recording (``harvester
compare``): log evidence with its standard error, and log Bayes factors (eq. 12) against the
first structure.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd

#: Columns of evidence.csv.
EVIDENCE_COLUMNS = ["model", "log_evidence", "standard_error", "chains", "log_bayes_factor",
                    "bayes_factor_error", "reference"]


def evidence_table(summaries: Mapping[str, Mapping]) -> pd.DataFrame:
    """One row per structure, in the given order, from each run's evidence summary
    (``recording_fit.evidence_summary``): pooled log evidence (nats) and its standard error,
    and the log Bayes factor against the first structure, with the error
    sqrt(se^2 + se_reference^2) (NaN with one chain)."""
    models = list(summaries)
    if not models:
        raise ValueError("no models to compare")
    ref = summaries[models[0]]

    def se(s: Mapping) -> float:
        return np.nan if s["standard_error"] is None else float(s["standard_error"])

    rows = []
    for name in models:
        s = summaries[name]
        rows.append({"model": name, "log_evidence": float(s["log_evidence"]),
                     "standard_error": se(s), "chains": int(s["chains"]),
                     "log_bayes_factor": float(s["log_evidence"] - ref["log_evidence"]),
                     "bayes_factor_error": 0.0 if name == models[0] else
                     float(np.hypot(se(s), se(ref))), "reference": models[0]})
    return pd.DataFrame(rows, columns=EVIDENCE_COLUMNS)


def verdict(table: pd.DataFrame, decisive: float = np.log(100.0)) -> str:
    """In words: the structure with the largest evidence, and how far ahead of the next
    (log Bayes factor and its error; 'decisive' beyond ``decisive`` nats, Jeffreys' 100:1)."""
    ranked = table.sort_values("log_evidence", ascending=False).reset_index(drop=True)
    best = ranked.iloc[0]
    if len(ranked) == 1:
        return f"{best['model']}: log evidence {best['log_evidence']:.2f}"
    second = ranked.iloc[1]
    gap = best["log_evidence"] - second["log_evidence"]
    err = float(np.hypot(best["standard_error"], second["standard_error"]))
    strength = "decisive" if gap - (2 * err if np.isfinite(err) else 0.0) > decisive else \
        "not decisive"
    return (f"{best['model']} is most probable: log Bayes factor {gap:.2f}"
            + (f" +- {err:.2f}" if np.isfinite(err) else " (one chain, no error)")
            + f" over {second['model']} ({strength})")
