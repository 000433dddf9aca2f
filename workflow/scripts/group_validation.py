"""Rule group_validation: NRMSE, mean log predictive density and the shares outside +-1, 2,
3 sd of every model of a group on each of its validation recordings."""

from harvester.data.fileio import atomic_path, read_json
from harvester.groups import validation_table
from harvester.runlog import rule_log

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    table = validation_table([read_json(p) for p in sm.input])
    with atomic_path(sm.output[0]) as tmp:
        table.to_csv(tmp, index=False, float_format="%.6g")
    log.info("\n%s", table.to_string(index=False))
