"""Rule evidence: log evidence per model and chain (eq. 11) and log Bayes factors (eq. 12)."""

from harvester.study import paper
from harvester.data.fileio import atomic_path
from harvester.inference.posterior import (bayes_factor_table, evidence_table, log_evidence,
                                           read_posterior)
from harvester.runlog import rule_log

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    ev = {m: log_evidence(read_posterior(p)) for m, p in zip(sm.params.models, sm.input)}
    reference = "linear" if "linear" in ev else sm.params.models[0]
    bf = bayes_factor_table(ev, reference, {("tanh", "linear"): paper.LOG_BAYES_FACTOR_TANH_LINEAR})
    for table, out in ((evidence_table(ev), sm.output.evidence), (bf, sm.output.bayes)):
        with atomic_path(out) as tmp:
            table.to_csv(tmp, index=False, float_format="%.6g")
        log.info("\n%s", table.to_string(index=False))
