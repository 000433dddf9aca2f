"""Rule headline: the paper's headline numbers beside ours, with the notes on what cannot
hold and on Figure 7 (CSV and HTML for the report)."""

import pandas as pd

from harvester.data.fileio import atomic_path
from harvester.inference.predictive import load_band
from harvester.runlog import rule_log
from harvester.study.summary import headline_html, headline_notes, headline_table, with_notes

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    posteriors = {m: pd.read_csv(p) for m, p in zip(sm.params.models, sm.input.posteriors)}
    bayes, sticking = pd.read_csv(sm.input.bayes), pd.read_csv(sm.input.sticking)
    table = headline_table(pd.read_csv(sm.input.table1), posteriors, bayes,
                           pd.read_csv(sm.input.validation), sticking)
    band, measured, _, _ = load_band(sm.input.unseen)  # the tanh model on the unseen record
    table = with_notes(table, headline_notes(posteriors, bayes, band, measured, sticking))
    with atomic_path(sm.output.csv) as tmp:
        table.to_csv(tmp, index=False, float_format="%.6g")
    with atomic_path(sm.output.html) as tmp:
        tmp.write_text(headline_html(table))
    log.info("\n%s", table.to_string(index=False))
