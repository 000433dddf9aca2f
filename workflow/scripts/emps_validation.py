"""Rule emps_validation: error of each model on the identification and the unseen record."""

import pandas as pd

from harvester.emps.results import VALIDATION_COLUMNS
from harvester.data.fileio import atomic_path, read_json
from harvester.runlog import rule_log

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    table = pd.DataFrame([read_json(p) for p in sm.input], columns=VALIDATION_COLUMNS)
    with atomic_path(sm.output[0]) as tmp:
        table.to_csv(tmp, index=False, float_format="%.6g")
    log.info("\n%s", table.to_string(index=False))
