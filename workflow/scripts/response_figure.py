"""Rules fig07/fig09/fig10: model mean against measured response with 3-sigma bounds (the
ensemble of parameter samples and the full predictive, each with its share outside), where
the virtual rig stuck shaded from its truth (the record regenerated from the config), and
for Figure 7 a section around the rig's longest stick and where the model misses: while the
rig is stuck, near the sticks or at speed (``study.sticking``), beside the second input's
model (the tanh model) for comparison."""

import numpy as np
import pandas as pd

from harvester.data.fileio import atomic_path
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
    misfit, compare = None, None
    if sm.params.zoom_s:  # Figure 7: where the model misses, stuck, near the sticks, at speed
        speed = sim.truth["v"][start:start + band.time.size]
        fs = 1.0 / float(band.time[1] - band.time[0])
        misfit = stick_misfit(measured - band.mean, measured, stuck, speed, fs)
        if len(sm.input) > 1:  # the other model of the same record, for comparison
            other, _, _, _ = load_band(sm.input[1])
            compare = (sm.params.compare, stick_misfit(measured - other.mean, measured, stuck,
                                                       speed, fs))
            log.info("%s's misfit: %s", sm.params.compare, compare[1].to_dict())
        log.info("misfit near the rig's sticks over elsewhere: %s; while stuck (RMS residual, "
                 "record) %s; per speed band while moving (mm/s: share, RMS residual, record) "
                 "%s", misfit.to_dict(), [round(x, 4) for x in misfit.stuck],
                 [(lo, hi, round(sh, 3), round(r, 4), round(y, 4))
                  for lo, hi, sh, r, y in misfit.by_speed])
    response_figure(band, measured, sm.output[0], sm.params.title, window=window, stuck=stuck,
                    zoom=zoom, misfit=misfit, compare=compare)
    if len(sm.output) > 1:  # Figure 7's numbers for the headline
        rows = [{"model": sm.params.model, **misfit.to_dict()}]
        if compare is not None:
            rows.append({"model": compare[0], **compare[1].to_dict()})
        with atomic_path(sm.output[1]) as tmp:
            pd.DataFrame(rows).to_csv(tmp, index=False, float_format="%.6g")
