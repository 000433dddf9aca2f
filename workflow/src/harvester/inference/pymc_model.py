"""Each model structure as a PyMC model: truncated Gaussian priors (Tables 2, 4) and eq. (10).

The likelihood is the simulator-backed, particle-batched ``Problem.loglike`` wrapped as a
PyTensor Op (``batched.py``), placed in the model's data log-probability so that SMC tempers it.
PyMC's own gradient-free samplers (``pm.sample_smc`` with its kernels, ``pm.Metropolis``) run it
too; our TMCMC kernel evaluates all particles in one call.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pymc as pm

from harvester.inference.batched import loglike_potential
from harvester.inference.likelihood import Problem
from harvester.inference.priors import PriorSpec, priors_for


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
