"""Rule prepare_recording: a recording of the sheet copied for its group with its sidecar
beside it (filtered_at_hz set), checked; what the checks found as JSON."""

from harvester.data.fileio import write_json
from harvester.groups import prepare_recording
from harvester.runlog import rule_log

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    lowpass, order = sm.params.lowpass
    found = prepare_recording(sm.input.data, sm.input.get("sidecar"), sm.output.csv,
                              lowpass, order, sm.wildcards.recording)
    write_json(found, sm.output.check)
    log.info("%s: %s -> %s, %d samples at %g Hz; filtered at %s Hz (%s); %d warning(s)",
             sm.wildcards.recording, found["input"], found["output"], found["samples"],
             found["sampling_rate_hz"], found["filtered_at_hz"], found["filtered_at_from"],
             len(found["warnings"]))
