"""Each model structure as a PyMC model: its priors (``harvester.model.priors``) and eq. (10).

The likelihood is the simulator-backed, particle-batched ``Problem.loglike`` wrapped as a
PyTensor Op (``batched.py``), placed in the model's data log-probability so that SMC tempers it.
PyMC's own gradient-free samplers (``pm.sample_smc`` with its kernels, ``pm.Metropolis``) run it
too; our TMCMC kernel evaluates all particles in one call.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pymc as pm
import pytensor.tensor as pt
from pymc.distributions.transforms import Interval

from harvester.inference.batched import loglike_potential
from harvester.inference.likelihood import Problem
from harvester.inference.priors import PriorSpec, priors_for


def prior_variable(spec: PriorSpec):
    """The PyMC random variable of a prior (in a model context), named for its parameter: a
    TruncatedNormal (or Normal without a lower bound), a LogNormal, or a log-uniform written as
    exp(Uniform(ln lower, ln upper)) with the interval transform of its support."""
    if spec.family == "lognormal":
        return pm.LogNormal(spec.name, mu=np.log(spec.mean), sigma=spec.sd)
    if spec.family == "loguniform":
        lo, hi = spec.lower, spec.upper
        return pm.CustomDist(spec.name, lo, hi, dist=_log_uniform, transform=Interval(lo, hi))
    if np.isfinite(spec.lower) or np.isfinite(spec.upper):
        return pm.TruncatedNormal(spec.name, mu=spec.mean, sigma=spec.sd,
                                  lower=spec.lower if np.isfinite(spec.lower) else None,
                                  upper=spec.upper if np.isfinite(spec.upper) else None)
    return pm.Normal(spec.name, mu=spec.mean, sigma=spec.sd)


def _log_uniform(lower, upper, size):
    return pt.exp(pm.Uniform.dist(pt.log(lower), pt.log(upper), size=size))


def build_model(problem: Problem, priors: Mapping[str, PriorSpec]) -> pm.Model:
    """PyMC model with theta = (free physical parameters..., sigma) and likelihood eq. (10)."""
    specs = priors_for(problem, priors)
    with pm.Model(name="") as model:
        params = [prior_variable(specs[name]) for name in problem.parameter_names]
        loglike_potential("rel_acc", problem.loglike, params)
    return model
