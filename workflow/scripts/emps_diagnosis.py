"""Rule emps_diagnosis: evidence of the viscous baseline and of each candidate term added to it."""

from harvester import emps
from harvester.emps.figures import evidence_figure
from harvester.data.fileio import atomic_path, write_json
from harvester.runlog import rule_log
from harvester.inference.posterior import read_posterior

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    runs = {m: read_posterior(p) for m, p in zip(sm.params.models, sm.input)}
    table, named = emps.evidence_table(runs)
    with atomic_path(sm.output.table) as tmp:
        table.to_csv(tmp, index=False, float_format="%.6g")
    write_json({"named_term": named, "expected": sm.params.extended,
                "agrees": named == sm.params.extended}, sm.output.named)
    evidence_figure(table, sm.output.figure)
    log.info("\n%s\nnamed missing physics: %s (config extended: %s)", table.to_string(index=False),
             named, sm.params.extended)
