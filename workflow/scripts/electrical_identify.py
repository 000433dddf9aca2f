"""Rule electrical_identify: TMCMC of one electrical structure on the loaded records, the
mechanical posterior of the open-circuit training record as prior (harvester.electrical)."""

import arviz as az
import numba
from harvester.data.fileio import atomic_path, write_json
from harvester.electrical.identify import (
    device_of,
    evidence_summary,
    identify,
    posterior_samples,
)
from harvester.electrical.priors import MECHANICAL, mechanical_prior
from harvester.electrical.problem import ElectricalProblem
from harvester.electrical.records import load_record, read_meta
from harvester.inference.identify import TMCMCSettings
from harvester.inference.posterior import samples
from harvester.runlog import rule_log

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    numba.set_num_threads(max(1, min(sm.threads, numba.config.NUMBA_NUM_THREADS)))
    cfg, pre = sm.params.electrical, sm.params.preprocess
    lowpass = (float(pre["lowpass_hz"]), int(pre["filter_order"]))
    records = [load_record(csv, read_meta(meta), *lowpass, cfg["lead_in_s"], cfg["fit_seconds"])
               for csv, meta in zip(sm.input.records, sm.input.metas)]
    mech_post = az.from_netcdf(sm.input.mechanical)
    known = dict(kv.split("=") for kv in mech_post.posterior.attrs["known"].split(","))
    prior = mechanical_prior(samples(mech_post, list(MECHANICAL)),
                             {k: float(v) for k, v in known.items()})
    log.info("mechanical prior (posterior of %s): %s", sm.input.mechanical, prior.summary())
    problem = ElectricalProblem(records, sm.wildcards.structure, prior, lowpass,
                                oversample=int(cfg["oversample"]))
    idata = identify(problem, sm.params.sigma_prior, TMCMCSettings.from_config(cfg["tmcmc"]))
    idata.to_netcdf(sm.output.posterior)
    with atomic_path(sm.output.samples) as tmp:
        posterior_samples(idata).to_csv(tmp, index=False, float_format="%.9g")
    summary = evidence_summary(idata) | {"n_evaluations": problem.n_evaluations,
                                         "device": device_of(records, prior.known),
                                         "mechanical_prior": prior.summary()}
    write_json(summary, sm.output.evidence)
    log.info("%s: log evidence %.2f +- %.2f, %d likelihood evaluations, %.0f s",
             sm.wildcards.structure, summary["log_evidence"], summary["log_evidence_se"],
             problem.n_evaluations, summary["wall_time_s"])
