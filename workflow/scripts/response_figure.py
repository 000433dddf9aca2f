"""Rules fig07/fig09/fig10: model mean against measured response with 3-sigma bounds (the
ensemble of parameter samples and the full predictive, each with its share outside), where
the virtual rig stuck shaded from its truth (the record regenerated from the config), and
for Figure 7 a section around the rig's longest stick and where the model misses: near the
sticks or at speed (``study.sticking``)."""

import numpy as np

from harvester.inference.predictive import load_band
from harvester.plots.predictive import response_figure
from harvester.runlog import rule_log
from harvester.study.sticking import longest_stick_window, stick_misfit
from harvester.synthetic import rig

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    band, measured, _, _ = load_band(sm.input[0])
    window = tuple(sm.params.window) if sm.params.window else None
    sim = rig.simulate_record(sm.params.rig, sm.params.record)
    start = int(sm.params.lead_in)
    stuck = sim.truth["stuck"][start:start + band.time.size]
    if stuck.size != band.time.size or not np.allclose(sim.time[start], band.time[0]):
        raise ValueError(f"{sm.params.record}: the rig's record does not line up with the band")
    zoom = longest_stick_window(stuck, band.time, sm.params.zoom_s) if sm.params.zoom_s \
        else None
    log.info("rig stuck at %.2f %% of the shown samples; zoom %s", 100 * stuck.mean(), zoom)
    misfit = None
    if sm.params.zoom_s:  # Figure 7: where the model misses, near the sticks or at speed
        speed = sim.truth["v"][start:start + band.time.size]
        fs = 1.0 / float(band.time[1] - band.time[0])
        misfit = stick_misfit(measured - band.mean, measured, stuck, speed, fs)
        log.info("misfit near the rig's sticks over elsewhere: %s; RMS per speed band "
                 "(mm/s: share, RMS) %s", misfit.to_dict(),
                 [(lo, hi, round(sh, 3), round(r, 4)) for lo, hi, sh, r in misfit.by_speed])
    response_figure(band, measured, sm.output[0], sm.params.title, window=window, stuck=stuck,
                    zoom=zoom, misfit=misfit)
