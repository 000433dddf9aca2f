"""Rules fig07/fig09/fig10: model mean against measured response with 3-sigma bounds."""

from harvester.plots.predictive import response_figure
from harvester.inference.predictive import load_band
from harvester.runlog import rule_log

with rule_log(snakemake):  # noqa: F821
    sm = snakemake  # noqa: F821
    band, measured, _, _ = load_band(sm.input[0])
    window = tuple(sm.params.window) if sm.params.window else None
    response_figure(band, measured, sm.output[0], sm.params.title, window=window)
