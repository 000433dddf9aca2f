"""Rule lowpass: zero-phase low-pass of the measured output (paper: 20 Hz on z'')."""

from harvester.data.daq import read_recording, write_recording
from harvester.data.recording import recording_kinds
from harvester.data.signals import filter_recording
from harvester.runlog import rule_log

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    rec = read_recording(sm.input[0])
    output = recording_kinds(rec, sm.input[0]).output_kind
    filtered = filter_recording(rec, sm.params.cutoff, sm.params.order, sm.input[0], (output,))
    write_recording(filtered, sm.output[0])
    log.info("%s low-passed at %g Hz, order %d (zero phase)", output, sm.params.cutoff,
             sm.params.order)
