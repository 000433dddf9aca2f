"""Rule electrical_identify: TMCMC of one electrical structure on the loaded records, the
mechanical posterior of the open-circuit training record as prior (harvester.electrical)."""

from harvester.electrical.run import identify_structure
from harvester.runlog import rule_log

with rule_log(snakemake):  # noqa: F821
    sm = snakemake  # noqa: F821
    identify_structure(sm.input.records, sm.input.metas, sm.input.mechanical,
                       sm.wildcards.structure, sm.params.electrical, sm.params.preprocess,
                       sm.params.sigma_prior, sm.output.posterior, sm.output.samples,
                       sm.output.evidence)
