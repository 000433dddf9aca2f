"""Rule diagnose: the diagnosis of one identified model of a group on its training recording
(diagnosis.json, its figures, and a summary for the report)."""

from pathlib import Path

from harvester.data.fileio import atomic_path, read_json
from harvester.diagnosis.report.summary_page import summary_page
from harvester.groups import diagnose_model
from harvester.runlog import rule_log

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    diag = diagnose_model(sm.input.data, sm.input.get("validation"), sm.input.posterior,
                          sm.input.priors, sm.wildcards.model, sm.params.settings,
                          Path(sm.output.json).parent)
    with atomic_path(sm.output.summary) as tmp:
        tmp.write_text(summary_page(read_json(sm.output.json), Path(sm.output.json).parent,
                                    f"Diagnosis of {sm.wildcards.model}, group "
                                    f"{sm.wildcards.group}", sm.params.links))
    log.info("verdict %s, missing %s", diag.verdict, diag.missing)
