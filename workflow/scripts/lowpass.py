"""Rule lowpass: zero-phase low-pass filter of both channels (paper: 20 Hz)."""

from harvester.data.daq import read_recording, write_recording
from harvester.runlog import rule_log
from harvester.data.signals import filter_recording

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    filtered = filter_recording(read_recording(sm.input[0]), sm.params.cutoff, sm.params.order)
    write_recording(filtered, sm.output[0])
    log.info("low-pass %g Hz, order %d (zero phase)", sm.params.cutoff, sm.params.order)
