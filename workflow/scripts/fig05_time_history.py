"""Rule fig05_time_history: Figure 5, z'' unfiltered and filtered over the training window."""

from harvester.data.daq import read_recording
from harvester.plots.data import fig05_time_history
from harvester.runlog import rule_log

with rule_log(snakemake):  # noqa: F821
    sm = snakemake  # noqa: F821
    raw, filtered = read_recording(sm.input.raw), read_recording(sm.input.filtered)
    start = sm.params.lead_in
    t = raw["time"].to_numpy()
    window = (t[start], t[min(start + sm.params.samples, len(t)) - 1])
    fig05_time_history(raw, filtered, sm.output[0], window)
