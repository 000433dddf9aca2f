"""Rule convert: raw DAQ voltages -> accelerations (m/s^2) and z'' = x'' - y''; a loaded
record's voltage channel -> the load voltage (V), column ``voltage``."""

from harvester.data.daq import read_raw_record, to_accelerations, write_recording
from harvester.runlog import rule_log

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    raw, meta = read_raw_record(sm.input.csv, sm.input.meta)
    acc = to_accelerations(raw, meta)
    write_recording(acc, sm.output[0])
    log.info("%s: %d samples at %g Hz converted", sm.input.csv, len(acc), meta["sampling_rate_hz"])
