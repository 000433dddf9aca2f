"""Rule group_evidence: log evidence of a group's models with its standard error, and log
Bayes factors against the first model (CSV, and HTML for the report)."""

from harvester.data.fileio import atomic_path
from harvester.groups import evidence_table, table_html
from harvester.runlog import rule_log

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    table, verdict = evidence_table(sm.params.models, sm.input)
    with atomic_path(sm.output.csv) as tmp:
        table.to_csv(tmp, index=False, float_format="%.6g")
    with atomic_path(sm.output.html) as tmp:
        tmp.write_text(table_html(table, f"Evidence of the models of group {sm.wildcards.group} "
                                  "(nats)", [verdict]))
    log.info("\n%s\n%s", table.to_string(index=False), verdict)
