"""Rule posterior_table: Tables 3 and 5 (posterior mean, sd, 95% interval, paper, truth)."""

from harvester.study import paper
from harvester.data.fileio import atomic_path
from harvester.inference.posterior import posterior_truth, read_posterior, summary_table
from harvester.runlog import rule_log

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    idata = read_posterior(sm.input.posterior)
    truth = posterior_truth(sm.params.rig, sm.wildcards.model)
    table = summary_table(idata, paper.POSTERIOR_MEANS.get(sm.wildcards.model, {}), truth)
    with atomic_path(sm.output[0]) as tmp:
        table.to_csv(tmp, index=False, float_format="%.6g")
    log.info("\n%s", table.to_string(index=False))
