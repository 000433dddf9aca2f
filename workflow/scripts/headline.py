"""Rule headline: the paper's headline numbers beside ours (CSV and HTML for the report)."""

import pandas as pd

from harvester.data.fileio import atomic_path
from harvester.runlog import rule_log
from harvester.study.summary import headline_html, headline_table

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    models = sm.params.models
    table = headline_table(pd.read_csv(sm.input.table1),
                           {m: pd.read_csv(p) for m, p in zip(models, sm.input.posteriors)},
                           pd.read_csv(sm.input.bayes), pd.read_csv(sm.input.validation))
    with atomic_path(sm.output.csv) as tmp:
        table.to_csv(tmp, index=False, float_format="%.6g")
    with atomic_path(sm.output.html) as tmp:
        tmp.write_text(headline_html(table))
    log.info("\n%s", table.to_string(index=False))
