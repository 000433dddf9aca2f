"""Rule identify: posterior and evidence of one model of a group by TMCMC (posterior.nc,
summary.csv, posterior_pairs.png, evidence.json)."""

from pathlib import Path

from harvester.groups import identify_model
from harvester.runlog import rule_log

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    fit = identify_model(sm.input.data, sm.input.priors, sm.wildcards.model, sm.params.settings,
                         Path(sm.output.posterior).parent)
    log.info("log evidence per chain: %s", fit.evidence["log_evidence_per_chain"])
