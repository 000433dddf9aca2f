"""Rule headline: the paper's headline numbers beside ours (CSV and HTML for the report)."""

import numpy as np
import pandas as pd

from harvester.data.fileio import atomic_path
from harvester.inference.predictive import load_band
from harvester.runlog import rule_log
from harvester.study.summary import (figure7_notes, headline_html, headline_table,
                                     what_cannot_hold, with_notes)

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    models = sm.params.models
    posteriors = {m: pd.read_csv(p) for m, p in zip(models, sm.input.posteriors)}
    sticking = pd.read_csv(sm.input.sticking)
    table = headline_table(pd.read_csv(sm.input.table1), posteriors,
                           pd.read_csv(sm.input.bayes), pd.read_csv(sm.input.validation),
                           sticking)
    band, measured, _, _ = load_band(sm.input.unseen)  # the tanh model on the unseen record
    ratio = float(np.sqrt(np.mean(band.sd_parameter ** 2))
                  / np.sqrt(np.mean((measured - band.mean) ** 2)))
    bayes = pd.read_csv(sm.input.bayes).set_index("model")
    table = with_notes(table, {**what_cannot_hold(
        posteriors, float(bayes.loc["tanh", "log_bayes_factor"]), ratio),
        **figure7_notes(sticking)})
    with atomic_path(sm.output.csv) as tmp:
        table.to_csv(tmp, index=False, float_format="%.6g")
    with atomic_path(sm.output.html) as tmp:
        tmp.write_text(headline_html(table))
    log.info("\n%s", table.to_string(index=False))
