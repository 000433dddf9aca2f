"""Rule emps_headline: the EMPS study's numbers on one page (CSV and HTML), and its diagnosis
on the page every diagnosis has (summary.html)."""

from pathlib import Path

import pandas as pd

from harvester import emps
from harvester.data.fileio import atomic_path, read_json
from harvester.diagnosis.report.summary_page import summary_page
from harvester.runlog import rule_log
from harvester.inference.posterior import read_posterior

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    runtimes = {m: float(read_posterior(p).sample_stats.attrs["wall_time_s"])
                for m, p in zip(sm.params.models, sm.input.posteriors)}
    table = emps.headline_table(pd.read_csv(sm.input.comparison), pd.read_csv(sm.input.evidence),
                                read_json(sm.input.named), pd.read_csv(sm.input.validation),
                                runtimes, sm.params.baseline, sm.params.extended)
    with atomic_path(sm.output.csv) as tmp:
        table.to_csv(tmp, index=False, float_format="%.6g")
    with atomic_path(sm.output.html) as tmp:
        tmp.write_text(table.to_html(index=False, float_format=lambda x: f"{x:.5g}"))
    doc = emps.summary_doc(pd.read_csv(sm.input.comparison), pd.read_csv(sm.input.evidence),
                           read_json(sm.input.named), pd.read_csv(sm.input.validation),
                           sm.params.baseline, sm.params.extended)
    with atomic_path(sm.output.summary) as tmp:
        tmp.write_text(summary_page(doc, Path(sm.input.figures[0]).parent,
                                    "EMPS: the physics the viscous model misses"))
    log.info("\n%s", table.to_string(index=False))
