"""Rule convert_public: a public benchmark's .mat file -> the recording format and the sidecar
its source gives (``harvester.data.public.public_recording``)."""

from harvester.data.public import public_recording
from harvester.runlog import rule_log

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    rec = public_recording(sm.input[0])
    rec.write(sm.output.csv)
    for note in rec.notes:
        log.info("%s", note)
