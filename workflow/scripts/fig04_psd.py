"""Rule fig04_psd: Figure 4, PSD of z'' unfiltered and filtered."""

from harvester.data.daq import read_recording
from harvester.plots.data import fig04_psd
from harvester.runlog import rule_log
from harvester.data.signals import sampling_rate

with rule_log(snakemake):  # noqa: F821
    sm = snakemake  # noqa: F821
    raw, filtered = read_recording(sm.input.raw), read_recording(sm.input.filtered)
    fig04_psd(raw, filtered, sampling_rate(raw), sm.params.cutoff, sm.output[0])
