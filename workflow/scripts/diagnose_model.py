"""Rule diagnose_model: the diagnosis of one identified model on the study's training record."""

import arviz as az

from harvester.data.daq import read_recording
from harvester.diagnosis.run import DiagnosisSettings, diagnose_study
from harvester.data.fileio import read_json
from harvester.inference.priors import PriorSpec
from harvester.runlog import rule_log

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    prior_file = read_json(sm.input.priors)
    priors = {n: PriorSpec(**p) for n, p in prior_file["priors"].items()}
    settings = DiagnosisSettings(**sm.params.diagnosis, lowpass_hz=sm.params.lowpass_hz,
                                 filter_order=sm.params.filter_order)
    diag = diagnose_study(read_recording(sm.input.data), sm.wildcards.model, prior_file["known"],
                          priors, read_recording(sm.input.validation), settings,
                          out_dir=sm.output.json.rsplit("/", 1)[0],
                          posterior=az.from_netcdf(sm.input.posterior),
                          lead_in=sm.params.lead_in, samples=sm.params.samples)
    log.info("verdict %s, missing %s", diag.verdict, diag.missing)
