"""Each model structure as a PyMC model: truncated Gaussian priors (Tables 2, 4) and eq. (10).

The likelihood is the simulator-backed, particle-batched ``Problem.loglike`` wrapped as a
PyTensor Op (``batched.py``), placed in the model's data log-probability so that SMC tempers it.
PyMC's own gradient-free samplers (``pm.sample_smc`` with its kernels, ``pm.Metropolis``) run it
too; our TMCMC kernel evaluates all particles in one call.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import pymc as pm

from harvester.batched import loglike_potential
from harvester.likelihood import Problem
from harvester.physics import BASE_PARAMETERS, TERMS
from harvester.priors import PriorSpec


def default_prior(name: str) -> PriorSpec:
    """The physics library's default prior of a parameter (used when config gives none)."""
    for p in BASE_PARAMETERS + tuple(q for t in TERMS.values() for q in t.parameters):
        if p.name == name:
            lower = -np.inf if p.lower is None else p.lower
            return PriorSpec(name=name, mean=p.prior_mean, sd=p.prior_sd, unit=p.unit, lower=lower)
    raise KeyError(f"no prior for parameter {name!r}")


def priors_for(problem: Problem, priors: Mapping[str, PriorSpec],
               names: Sequence[str] | None = None) -> dict[str, PriorSpec]:
    """Prior of each identified parameter (or of ``names``): from ``priors`` if given, else
    the library default."""
    names = problem.parameter_names if names is None else names
    return {n: priors[n] if n in priors else default_prior(n) for n in names}


def build_model(problem: Problem, priors: Mapping[str, PriorSpec]) -> pm.Model:
    """PyMC model with theta = (free physical parameters..., sigma) and likelihood eq. (10)."""
    specs = priors_for(problem, priors)
    with pm.Model(name="") as model:
        params = []
        for name in problem.parameter_names:
            s = specs[name]
            if np.isfinite(s.lower):
                rv = pm.TruncatedNormal(name, mu=s.mean, sigma=s.sd, lower=s.lower)
            else:
                rv = pm.Normal(name, mu=s.mean, sigma=s.sd)
            params.append(rv)
        loglike_potential("rel_acc", problem.loglike, params)
    return model
