"""Bayesian identification of one model structure by TMCMC: the study's and the CLI's entry point."""

from __future__ import annotations

import logging
from collections.abc import Mapping
from dataclasses import dataclass

import arviz as az

from harvester.inference.likelihood import Problem
from harvester.inference.posterior import set_known
from harvester.inference.priors import PriorSpec
from harvester.inference.pymc_model import build_model
from harvester.inference.tmcmc import Reference, run_tmcmc

log = logging.getLogger("harvester.inference.identify")


@dataclass(frozen=True)
class TMCMCSettings:
    """Sampler settings (config section ``tmcmc``)."""

    particles: int = 1000
    chains: int = 4
    proposal_scale: float = 0.2
    target_cov: float = 1.0
    target_accept: float | None = None
    mcmc_steps: int = 2
    max_mcmc_steps: int | None = 30
    correlation_threshold: float = 0.1
    seed: int = 0

    @classmethod
    def from_config(cls, cfg: Mapping) -> "TMCMCSettings":
        return cls(**{k: cfg[k] for k in cls.__dataclass_fields__ if k in cfg})

    def run_arguments(self) -> dict:
        """These settings as the keyword arguments of ``tmcmc.run_tmcmc``."""
        return dict(draws=self.particles, chains=self.chains, seed=self.seed,
                    proposal_scale=self.proposal_scale, target_cov=self.target_cov,
                    mcmc_steps=self.mcmc_steps, max_mcmc_steps=self.max_mcmc_steps,
                    correlation_threshold=self.correlation_threshold,
                    target_accept=self.target_accept)


def identify(problem: Problem, priors: Mapping[str, PriorSpec],
             settings: TMCMCSettings, reference: Reference | None = None) -> az.InferenceData:
    """Posterior samples and log evidence of ``problem`` by TMCMC (ArviZ InferenceData).

    ``reference``: temper from it instead of the prior (``harvester.inference.tmcmc.Reference``); its
    prior must be the one ``priors`` gives its variable."""
    model = build_model(problem, priors)
    log.info("TMCMC for %s: parameters %s, %d particles x %d chains, %d data points",
             problem.structure.name, ", ".join(problem.parameter_names), settings.particles,
             settings.chains, problem.n_data)
    idata = run_tmcmc(model, reference=reference, **settings.run_arguments())
    idata.posterior.attrs["parameter_names"] = ",".join(problem.parameter_names)
    idata.posterior.attrs["model"] = problem.structure.name
    idata.posterior.attrs["terms"] = ",".join(problem.structure.terms)
    set_known(idata, problem.known)
    if problem.output_filter is not None:
        idata.posterior.attrs["output_filter"] = list(problem.output_filter)
    idata.posterior.attrs["free_base"] = ",".join(problem.structure.free_base)
    idata.posterior.attrs["input_kind"] = problem.input_kind
    idata.posterior.attrs["output_kind"] = problem.output_kind
    return idata
