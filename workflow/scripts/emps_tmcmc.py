"""Rule emps_tmcmc: posterior and evidence of one EMPS model, simulated in closed loop (netCDF)."""

import numpy as np

from harvester import emps
from harvester.data.fileio import atomic_path, read_json
from harvester.inference.identify import TMCMCSettings, identify
from harvester.inference.priors import PriorSpec
from harvester.runlog import rule_log

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    rec = emps.load_emps(sm.input.training)
    prior_file = read_json(sm.input.priors)
    priors = {n: PriorSpec(**p) for n, p in prior_file["priors"].items()}
    problem = emps.closed_loop_problem(rec, emps.model_terms(sm.wildcards.model),
                                       prior_file["known"], stride=sm.params.stride,
                                       temper=prior_file["temper"])
    idata = identify(problem, priors, TMCMCSettings.from_config(sm.params.tmcmc))
    idata.posterior.attrs["stride"] = problem.stride
    idata.posterior.attrs["temper"] = problem.temper
    idata.posterior.attrs["record"] = rec.name
    with atomic_path(sm.output[0]) as tmp:
        idata.to_netcdf(str(tmp))
    log.info("log evidence per chain: %s; wall time %.1f s; %d likelihood evaluations",
             idata.sample_stats["log_evidence"].values, idata.sample_stats.attrs["wall_time_s"],
             problem.n_evaluations)
    for name in problem.parameter_names:
        x = idata.posterior[name].values.reshape(-1)
        log.info("%s: mean %.6g sd %.3g", name, np.mean(x), np.std(x))
