"""Rule predictive: posterior predictive ensemble of a model for a record (training or unseen)."""

from harvester.data.daq import read_recording
from harvester.data.fileio import read_json
from harvester.inference.problems import make_problem
from harvester.inference.posterior import posterior_theta, read_posterior
from harvester.inference.predictive import posterior_predictive, save_band, thin
from harvester.runlog import rule_log

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    rec = read_recording(sm.input.data)
    idata = read_posterior(sm.input.posterior)
    filt = idata.posterior.attrs.get("output_filter")
    problem = make_problem(rec, idata.posterior.attrs["model"], read_json(sm.input.priors)["known"],
                           output_filter=None if filt is None else (float(filt[0]), int(filt[1])))
    theta = thin(posterior_theta(idata), sm.params.predictive["samples"], sm.params.predictive["seed"])
    start = sm.params.lead_in
    stop = len(rec) if sm.params.samples is None else start + sm.params.samples
    band = posterior_predictive(problem, theta, rec["base_acc"].to_numpy(), rec["time"].to_numpy())
    band.time, band.responses = band.time[start:stop], band.responses[:, start:stop]
    save_band(sm.output[0], band, rec["rel_acc"].to_numpy()[start:stop], sm.wildcards.model,
              "training" if sm.wildcards.record == "training" else "unseen")
    log.info("%d posterior samples simulated over %d samples", len(theta), stop - start)
