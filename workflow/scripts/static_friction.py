"""Rule static_friction: F_c from the static friction tests, eqs. (4)-(5)."""

from harvester.data.daq import read_static_test
from harvester.data.fileio import write_json
from harvester.initial.static_friction import static_friction
from harvester.runlog import rule_log

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    df, _ = read_static_test(sm.input.csv, sm.input.meta)
    est = static_friction(df, sm.params.k, source=sm.input.csv)
    write_json(est, sm.output[0])
    log.info("static friction %s", est)
