"""Rule tmcmc: posterior and evidence of one model structure (netCDF)."""

from harvester.data.fileio import atomic_path, read_json
from harvester.inference.identify import TMCMCSettings, identify, make_problem
from harvester.inference.priors import PriorSpec
from harvester.data.daq import read_recording
from harvester.runlog import rule_log

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    prior_file = read_json(sm.input.priors)
    priors = {n: PriorSpec(**p) for n, p in prior_file["priors"].items()}
    start = sm.params.lead_in
    problem = make_problem(read_recording(sm.input.data), sm.wildcards.model, prior_file["known"],
                           window=(start, start + sm.params.samples),
                           output_filter=(sm.params.lowpass_hz, sm.params.filter_order))
    idata = identify(problem, priors, TMCMCSettings.from_config(sm.params.tmcmc))
    with atomic_path(sm.output[0]) as tmp:
        idata.to_netcdf(str(tmp))
    log.info("log evidence per chain: %s", idata.sample_stats["log_evidence"].values)
