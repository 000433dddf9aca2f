"""Bayesian identification of one model structure by TMCMC: the study's and the CLI's entry point."""

from __future__ import annotations

import logging
from collections.abc import Mapping
from dataclasses import dataclass

import arviz as az

from harvester.inference import TMCMC_STARTS
from harvester.inference import correlated_residuals
from harvester.inference.likelihood import Problem
from harvester.inference.posterior import posterior_theta, set_known
from harvester.inference.priors import PriorSpec, priors_for
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
    #: "prior": every particle from the prior (Ching and Chen); "map": half of them at the
    #: model's MAP with its Laplace covariance widened (:func:`map_start`)
    start: str = "prior"
    #: wall-clock time (``time.time()``, s) past which a run stops (``tmcmc.OutOfTime``): a
    #: caller's time budget, set at run time (never from a config); None: none
    deadline: float | None = None

    def __post_init__(self) -> None:
        if self.start not in TMCMC_STARTS:
            raise ValueError(f"tmcmc start must be one of {TMCMC_STARTS}, got "
                             f"{self.start!r}")

    @classmethod
    def from_config(cls, cfg: Mapping) -> "TMCMCSettings":
        return cls(**{k: cfg[k] for k in cls.__dataclass_fields__
                      if k in cfg and k != "deadline"})

    def run_arguments(self) -> dict:
        """These settings as the keyword arguments of ``tmcmc.run_tmcmc``."""
        return dict(draws=self.particles, chains=self.chains, seed=self.seed,
                    proposal_scale=self.proposal_scale, target_cov=self.target_cov,
                    mcmc_steps=self.mcmc_steps, max_mcmc_steps=self.max_mcmc_steps,
                    correlation_threshold=self.correlation_threshold,
                    target_accept=self.target_accept, deadline=self.deadline)


def identify(problem: Problem, priors: Mapping[str, PriorSpec],
             settings: TMCMCSettings, reference: Reference | None = None,
             adjust: bool = True) -> az.InferenceData:
    """Posterior samples and log evidence of ``problem`` by TMCMC (ArviZ InferenceData).

    ``reference``: temper from it instead of the prior (``harvester.inference.tmcmc.Reference``); its
    prior must be the one ``priors`` gives its variable. Without one, ``settings.start`` "map"
    tempers from :func:`map_start`. With ``adjust`` the draws' adjustment for correlated
    residuals (``correlated_residuals``) is stored with them; the tables give both
    intervals."""
    if reference is None and settings.start == "map":
        reference = map_start(problem, priors, settings.seed)
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
    adjustment = correlated_residuals.correlation_adjustment(
        problem, posterior_theta(idata), priors_for(problem, priors)) if adjust else None
    if adjustment is not None:
        idata.posterior.attrs[correlated_residuals.ATTRIBUTE] = adjustment.to_json()
    return idata


def map_start(problem: Problem, priors: Mapping[str, PriorSpec], seed: int = 0
              ) -> Reference | None:
    """The reference a "map" start tempers from: half the particles at the model's MAP with
    its Laplace covariance widened, the other half from the prior (the diagnosis's start,
    ``inference.reference.map_reference``). The tempering then skips the stages that walk from
    the prior to the posterior (EMPS: 3 stages instead of 10, 0.2x the time); the evidence is
    still the model's, tempered from a normalised defensive mixture. None where the Laplace
    covariance is not usable (then from the prior)."""
    from harvester.inference.map_fit import fit_map
    from harvester.inference.reference import map_reference
    used = priors_for(problem, priors)
    return map_reference(fit_map(problem, used, seed=seed), used)
