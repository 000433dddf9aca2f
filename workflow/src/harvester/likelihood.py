"""The identification problem: data, a model structure and the Gaussian likelihood of eqs. (8)-(10).

Each sample of the relative acceleration is modelled as N(z''_hat_i(theta), sigma^2),
independent (eq. 9), so log L = -N/2 log(2 pi sigma^2) - sum_i r_i^2 / (2 sigma^2), eq. (10),
with sigma identified alongside the physical parameters. The model is simulated from the start
of the record (from rest) and the likelihood uses the samples in ``window``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from harvester.simulate import Simulation, simulate
from harvester.structures import ModelStructure


@dataclass
class Problem:
    """What the sampler needs: theta = (free parameters..., sigma) -> log-likelihood."""

    structure: ModelStructure
    base_acc: np.ndarray  # y'' (m/s^2), whole record
    rel_acc: np.ndarray  # measured z'' (m/s^2), whole record
    dt: float  # s
    known: dict[str, float]  # values of the layout parameters that are not identified
    window: tuple[int, int] | None = None  # samples [start, stop) used by the likelihood
    n_evaluations: int = field(default=0, init=False)

    def __post_init__(self) -> None:
        self.base_acc = np.asarray(self.base_acc, dtype=float)
        self.rel_acc = np.asarray(self.rel_acc, dtype=float)
        if self.base_acc.shape != self.rel_acc.shape:
            raise ValueError("base_acc and rel_acc differ in length")
        layout = self.structure.layout
        missing = [n for n in layout.parameter_names
                   if n not in self.structure.free_parameters and n not in self.known]
        if missing:
            raise ValueError(f"no value for known parameters {missing} of {self.structure.name}")
        start, stop = self.window or (0, len(self.rel_acc))
        self.window = (int(start), int(stop))
        if not 0 <= start < stop <= len(self.rel_acc):
            raise ValueError(f"window {self.window} outside the record of {len(self.rel_acc)} samples")
        self._free_idx = np.array([layout.index(n) for n in self.structure.free_parameters])
        self._template = np.array([self.known.get(n, np.nan) for n in layout.parameter_names])

    @property
    def parameter_names(self) -> tuple[str, ...]:
        """Names of theta's columns: the free physical parameters, then sigma."""
        return self.structure.free_parameters + ("sigma",)

    @property
    def n_data(self) -> int:
        return self.window[1] - self.window[0]

    @property
    def observed(self) -> np.ndarray:
        return self.rel_acc[self.window[0]:self.window[1]]

    def layout_params(self, theta: np.ndarray) -> np.ndarray:
        """Full layout parameter matrix (particles, layout params) from theta (particles, P)."""
        theta = np.atleast_2d(theta)
        full = np.tile(self._template, (theta.shape[0], 1))
        full[:, self._free_idx] = theta[:, : len(self._free_idx)]
        return full

    def simulate(self, theta: np.ndarray, base_acc: np.ndarray | None = None) -> Simulation:
        """Simulated response for each row of theta, to the training or another base input."""
        yb = self.base_acc if base_acc is None else base_acc
        return simulate(self.structure.layout, self.layout_params(theta), yb, self.dt)

    def loglike(self, theta: np.ndarray) -> np.ndarray:
        """Log-likelihood, eq. (10), for each row of theta; -inf where simulation failed."""
        theta = np.atleast_2d(np.asarray(theta, dtype=float))
        self.n_evaluations += theta.shape[0]
        sigma = theta[:, -1]
        sim = self.simulate(theta)
        start, stop = self.window
        r = sim.rel_acc[:, start:stop] - self.observed
        n = self.n_data
        with np.errstate(invalid="ignore", divide="ignore"):
            ll = -0.5 * n * np.log(2 * np.pi * sigma**2) - 0.5 * np.sum(r * r, axis=1) / sigma**2
        ll[~sim.ok | ~(sigma > 0) | ~np.isfinite(ll)] = -np.inf
        return ll
