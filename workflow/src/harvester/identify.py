"""Bayesian identification of one model structure by TMCMC: the study's and the CLI's entry point."""

from __future__ import annotations

import logging
from collections.abc import Mapping
from dataclasses import dataclass

import arviz as az
import numpy as np
import pandas as pd

from harvester.likelihood import Problem
from harvester.priors import PriorSpec
from harvester.pymc_models import build_model
from harvester.structures import ModelStructure, structure
from harvester.tmcmc import run_tmcmc

log = logging.getLogger("harvester.identify")


@dataclass(frozen=True)
class TMCMCSettings:
    """Sampler settings (config section ``tmcmc``)."""

    particles: int = 1000
    chains: int = 4
    seed: int = 0
    proposal_scale: float = 0.2
    target_cov: float = 1.0
    mcmc_steps: int = 2

    @classmethod
    def from_config(cls, cfg: Mapping) -> "TMCMCSettings":
        return cls(**{k: cfg[k] for k in cls.__dataclass_fields__ if k in cfg})


def make_problem(recording: pd.DataFrame, model: str | ModelStructure, known: Mapping[str, float],
                 window: tuple[int, int] | None = None) -> Problem:
    """The identification problem for a recording (columns time, base_acc, rel_acc)."""
    s = structure(model) if isinstance(model, str) else model
    t = recording["time"].to_numpy()
    dt = float(np.median(np.diff(t)))
    return Problem(s, recording["base_acc"].to_numpy(), recording["rel_acc"].to_numpy(), dt,
                   dict(known), window)


def identify(problem: Problem, priors: Mapping[str, PriorSpec],
             settings: TMCMCSettings) -> az.InferenceData:
    """Posterior samples and log evidence of ``problem`` by TMCMC (ArviZ InferenceData)."""
    model = build_model(problem, priors)
    log.info("TMCMC for %s: parameters %s, %d particles x %d chains, %d data points",
             problem.structure.name, ", ".join(problem.parameter_names), settings.particles,
             settings.chains, problem.n_data)
    idata = run_tmcmc(model, draws=settings.particles, chains=settings.chains, seed=settings.seed,
                      proposal_scale=settings.proposal_scale, target_cov=settings.target_cov,
                      mcmc_steps=settings.mcmc_steps)
    idata.posterior.attrs["parameter_names"] = ",".join(problem.parameter_names)
    idata.posterior.attrs["model"] = problem.structure.name
    idata.posterior.attrs["terms"] = ",".join(problem.structure.terms)
    idata.posterior.attrs["known"] = ",".join(f"{k}={v!r}" for k, v in problem.known.items())
    return idata


def posterior_theta(idata: az.InferenceData) -> np.ndarray:
    """Posterior rows theta = (free parameters..., sigma), chains pooled."""
    from harvester.posterior import parameter_names, samples
    return samples(idata, parameter_names(idata))
