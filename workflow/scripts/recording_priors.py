"""Rule recording_priors: the priors of a group's models from its training recording (the
sidecar's priors and the recording's FRF, as `harvester identify` sets them)."""

from harvester.data.fileio import write_json
from harvester.groups import group_priors
from harvester.runlog import rule_log

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    doc = group_priors(sm.input.data, sm.params.models, sm.params.settings)
    write_json(doc, sm.output[0])
    log.info("known %s; priors %s", doc["known"],
             {n: (p["mean"], p["sd"]) for n, p in doc["priors"].items()})
