"""Rule validation_table: NRMSE, coverage of 1/2/3-sigma bounds and MLPD per model and record."""

from harvester.data.fileio import atomic_path
from harvester.inference.predictive import load_band, validation_rows, validation_table
from harvester.runlog import rule_log

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    rows = []
    for path in sm.input:
        band, measured, model, data = load_band(path)
        rows += validation_rows(model, data, measured, band)
    table = validation_table(rows)
    with atomic_path(sm.output[0]) as tmp:
        table.to_csv(tmp, index=False, float_format="%.6g")
    log.info("\n%s", table.to_string(index=False))
