"""Rule emps_tracking_figure: measured and simulated tracking error, baseline and extended model."""

import numpy as np

from harvester.emps.figures import tracking_figure
from harvester.data.fileio import read_json
from harvester.runlog import rule_log

with rule_log(snakemake):  # noqa: F821
    sm = snakemake  # noqa: F821
    bands = {}
    for model, band, metrics in zip(sm.params.models, sm.input.bands, sm.input.metrics):
        with np.load(band) as f:
            bands[model] = {k: f[k] for k in ("time", "measured", "mean", "sd")}
        bands[model]["rms_position_um"] = read_json(metrics)["rms_position_um"]
    tracking_figure(bands, sm.output.full, sm.params.title)
    tracking_figure(bands, sm.output.zoom, sm.params.title, window=tuple(sm.params.zoom))
