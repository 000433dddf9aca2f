"""The electrical identification of one structure from files to files: the step the workflow's
rule ``electrical_identify`` (and anyone with their own loaded records) calls."""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from pathlib import Path

from harvester.data.fileio import atomic_path, write_json
from harvester.electrical.identify import device_of, evidence_summary, identify, posterior_samples
from harvester.electrical.priors import MECHANICAL, mechanical_prior
from harvester.electrical.problem import ElectricalProblem
from harvester.electrical.records import load_record, read_meta
from harvester.inference.identify import TMCMCSettings
from harvester.inference.posterior import known_values, read_posterior, samples

log = logging.getLogger("harvester.electrical")


def identify_structure(records: Sequence[str | Path], metas: Sequence[str | Path],
                       mechanical: str | Path, structure: str, cfg: Mapping,
                       preprocess: Mapping, sigma_prior: Mapping, posterior: str | Path,
                       samples_csv: str | Path, evidence: str | Path) -> dict:
    """TMCMC of ``structure`` on the loaded records (CSV and JSON metadata), the mechanical
    posterior netCDF ``mechanical`` as the prior of the mechanical parameters (config
    ``electrical`` as ``cfg``, ``preprocess`` its low-pass); writes the posterior netCDF, its
    samples as CSV and the evidence summary JSON, and returns that summary."""
    lowpass = (float(preprocess["lowpass_hz"]), int(preprocess["filter_order"]))
    loaded = [load_record(csv, read_meta(meta), *lowpass, cfg["lead_in_s"], cfg["fit_seconds"])
              for csv, meta in zip(records, metas)]
    mech_post = read_posterior(mechanical)
    prior = mechanical_prior(samples(mech_post, list(MECHANICAL)), known_values(mech_post))
    log.info("mechanical prior (posterior of %s): %s", mechanical, prior.summary())
    problem = ElectricalProblem(loaded, structure, prior, lowpass,
                                oversample=int(cfg["oversample"]))
    idata = identify(problem, sigma_prior, TMCMCSettings.from_config(cfg["tmcmc"]))
    idata.to_netcdf(posterior)
    with atomic_path(samples_csv) as tmp:
        posterior_samples(idata).to_csv(tmp, index=False, float_format="%.9g")
    summary = evidence_summary(idata) | {"n_evaluations": problem.n_evaluations,
                                         "device": device_of(loaded, prior.known),
                                         "mechanical_prior": prior.summary()}
    write_json(summary, evidence)
    log.info("%s: log evidence %.2f +- %.2f, %d likelihood evaluations, %.0f s", structure,
             summary["log_evidence"], summary["log_evidence_se"], problem.n_evaluations,
             summary["wall_time_s"])
    return summary
