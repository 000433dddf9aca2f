"""Rule validate_recording: posterior predictive of a group's model on one of its validation
recordings (predictive.csv, predictive.png, validation.json)."""

from pathlib import Path

from harvester.groups import validate_model
from harvester.runlog import rule_log

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    p = sm.params.predictive
    m = validate_model(sm.input.posterior, sm.input.data, int(p["samples"]), int(p["seed"]),
                       sm.params.lead_in_s, Path(sm.output.metrics).parent)
    log.info("%s on %s: NRMSE %.4g, outside +-3 sd %.2f %% (nominal %.2f %%)", m["model"],
             sm.wildcards.recording, m["nrmse"], 100 * m["outside_3sd"],
             100 * m["nominal_outside_3sd"])
