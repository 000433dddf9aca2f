"""Rule emps_predictive: posterior ensemble of one model in the closed loop of one record."""

import numpy as np

from harvester import emps
from harvester.data.fileio import atomic_path, read_json, write_json
from harvester.inference.posterior import posterior_theta, read_posterior
from harvester.inference.predictive import thin
from harvester.runlog import rule_log

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    idata = read_posterior(sm.input.posterior)
    rec = emps.load_emps(sm.input.record)
    known = read_json(sm.input.priors)["known"]
    problem = emps.closed_loop_problem(rec, emps.model_terms(sm.wildcards.model), known,
                                       stride=int(idata.posterior.attrs["stride"]))
    cfg = sm.params.predictive
    theta = thin(posterior_theta(idata), cfg["samples"], cfg["seed"])
    band = emps.tracking_band(problem, theta, rec)
    metrics = emps.error_metrics(band, stride=problem.stride)
    metrics.update(model=sm.wildcards.model, record=sm.wildcards.record, file=rec.name,
                   samples=int(len(band.sigma)))
    write_json(metrics, sm.output.metrics)
    with atomic_path(sm.output.band) as tmp:
        with open(tmp, "wb") as fh:
            np.savez_compressed(fh, time=band.time, measured=band.measured,
                                mean=band.tracking.mean(axis=0),
                                sd=np.sqrt(band.tracking.var(axis=0) + np.mean(band.sigma**2)),
                                force_mean=band.force.mean(axis=0), force=band.measured_force)
    log.info("%s on %s: %s", sm.wildcards.model, rec.name, metrics)
