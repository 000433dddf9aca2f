"""Priors of the electrical identification: the generator's constants, the two noise levels,
and the mechanical posterior of the open-circuit training record carried as the prior of the
mechanical parameters.

Generator (log-uniform: each a scale known only to within decades; ``PriorSpec``):

``K_e``   0.003-0.3 V s/rad, peak line-to-neutral back-EMF per rad/s. Small brushless PM
          machines of 10-500 W give 1-40 V per 1000 rpm line-to-line, K_e = 0.006-0.2 V s/rad;
          a decade either side of 0.03 covers them. The open-circuit record alone pins it.
``R_s``   0.05-20 ohm per phase: from a large machine's winding to a small high-voltage one;
          the divider R_L / (R_s + R_L) of the records at 1-10 ohm resolves it.
``L_s``   10 uH-10 mH per phase (``inductive`` only): small PM machines have L_s / R_s of
          0.1-5 ms. The evidence of ``inductive`` against ``resistive`` pays the Occam factor
          of this range (three decades); ``docs/electrical.md`` gives its effect.

Noise (one per channel, as the paper's sigma of eq. 10):

``sigma_acc``  the project's prior of sigma (config ``priors.sigma``: N(0.07, 0.03^2) m/s^2,
               truncated at 0), the same accelerometers through the same filter.
``sigma_V``    log-uniform 0.1-50 mV on the voltage magnitude: from a good isolation amplifier's
               noise to a quarter of the rig's largest record's RMS.

Mechanical (c_m, F_c, beta of the tanh model): the posterior of the paper study on its
open-circuit training record, approximated by a Gaussian in (ln c_m, ln F_c, ln beta), whose
mean and covariance are the posterior samples' (:func:`mechanical_prior`). Its correlations
are kept: c_m and F_c trade against each other on a shaker record. Because the training record
and the loaded records are independent, p(theta | training, loaded) is proportional to
p(loaded | theta) p(theta | training): the joint posterior of all records, at the cost of one
Gaussian approximation, and the evidence is p(loaded | structure, training).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from harvester.model.priors import PriorSpec

#: Mechanical parameters carried from the open-circuit posterior (tanh model, eq. 1).
MECHANICAL = ("c_m", "F_c", "beta")


def generator_priors(inductive: bool) -> dict[str, PriorSpec]:
    """Priors of K_e, R_s (and L_s when ``inductive``); reasoning in the module docstring."""
    specs = {"K_e": PriorSpec.log_uniform("K_e", 0.003, 0.3, "V s/rad"),
             "R_s": PriorSpec.log_uniform("R_s", 0.05, 20.0, "ohm")}
    if inductive:
        specs["L_s"] = PriorSpec.log_uniform("L_s", 1.0e-5, 1.0e-2, "H")
    return specs


def noise_priors(sigma_acc: Mapping) -> dict[str, PriorSpec]:
    """sigma_acc from the study's prior of sigma (config ``priors.sigma``), sigma_V
    log-uniform 0.1-50 mV."""
    return {"sigma_acc": PriorSpec("sigma_acc", float(sigma_acc["mean"]), float(sigma_acc["sd"]),
                                   "m/s^2"),
            "sigma_V": PriorSpec.log_uniform("sigma_V", 1.0e-4, 0.05, "V")}


@dataclass(frozen=True)
class MechanicalPrior:
    """Gaussian of (ln c_m, ln F_c, ln beta) with the known masses and spring (kg, kg, N/m)."""

    mean: np.ndarray
    cov: np.ndarray
    known: dict[str, float]

    def draw(self, n: int, rng: np.random.Generator) -> np.ndarray:
        """n draws of (c_m, F_c, beta)."""
        return np.exp(rng.multivariate_normal(self.mean, self.cov, size=n))

    def summary(self) -> dict[str, dict[str, float]]:
        """Median and the sd of ln x of each parameter."""
        sd = np.sqrt(np.diag(self.cov))
        return {n: {"median": float(np.exp(m)), "log_sd": float(s)}
                for n, m, s in zip(MECHANICAL, self.mean, sd)}


def mechanical_prior(samples: np.ndarray, known: Mapping[str, float],
                     inflate: float = 1.0) -> MechanicalPrior:
    """The prior from posterior samples (n, 3) of (c_m, F_c, beta); ``inflate`` scales the
    covariance (1: the posterior as it is)."""
    x = np.asarray(samples, dtype=float)
    if x.ndim != 2 or x.shape[1] != len(MECHANICAL) or not (np.isfinite(x).all() and
                                                            (x > 0).all()):
        raise ValueError(f"need positive samples of {MECHANICAL}, got shape {x.shape}")
    logs = np.log(x)
    cov = np.cov(logs, rowvar=False) * float(inflate)
    return MechanicalPrior(logs.mean(axis=0), cov,
                           {k: float(known[k]) for k in ("M", "m", "k")})
