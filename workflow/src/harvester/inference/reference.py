"""Reference distributions that TMCMC tempers from instead of the prior (``harvester.inference.tmcmc``).

A reference is a defensive mixture

    q(theta) = (1 - share) p(theta) + share g(theta),
    g(theta) = prod_f g_f(theta_f) * prod_{others} p(theta_j),

of the prior p and a product g of factors over disjoint sets of free variables (the variables
no factor covers keep their prior in g). With q normalised, TMCMC's product of mean weights
still estimates the evidence, and the weights p / q stay below 1 / (1 - share) (Hesterberg's
defensive importance sampling). Densities are in the model's own units; each covered variable
needs its prior as the model has it (``harvester.inference.priors.PriorSpec``).

Factors:

``GaussianFactor``
    a multivariate Gaussian over several variables, truncated to the prior's support (e.g. a
    nested baseline's posterior, widened, for the parameters a candidate shares with it).
``ScanFactor``
    a mixture of log-normals of x - lower for one variable, truncated below the prior's upper
    bound (e.g. a resonance frequency where a scan of the residual places it).

Both factors are truncated to the priors' support and normalised there: a draw outside it
would have no prior density (and no coordinate in PyMC's transformed space), and mass outside
it would bias the evidence low.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np
from scipy import stats
from scipy.special import logsumexp

from harvester.inference.priors import PriorSpec

log = logging.getLogger("harvester.inference")

__all__ = ["GaussianFactor", "Reference", "ScanFactor"]

LOG_SQRT_2PI = 0.5 * np.log(2.0 * np.pi)


class Factor(Protocol):
    names: tuple[str, ...]

    def log_density(self, x: np.ndarray) -> np.ndarray: ...

    def draw(self, rng: np.random.Generator, n: int) -> np.ndarray: ...


@dataclass(frozen=True)
class ScanFactor:
    """Mixture of log-normals of x - lower (normals of x if lower is -inf) for one variable:
    components at ``centres`` (x units) with log-widths ``widths`` and ``weights``, truncated
    to x < upper and normalised there."""

    name: str
    centres: tuple[float, ...]
    widths: tuple[float, ...]
    weights: tuple[float, ...]
    lower: float = -np.inf
    upper: float = np.inf

    def __post_init__(self) -> None:
        if not len(self.centres) == len(self.widths) == len(self.weights) > 0:
            raise ValueError("centres, widths and weights need the same, positive length")
        if min(self.widths) <= 0 or min(self.weights) < 0 or sum(self.weights) <= 0:
            raise ValueError("widths must be positive and weights non-negative, not all 0")
        if np.isfinite(self.lower) and min(self.centres) <= self.lower:
            raise ValueError(f"centres must lie above the lower bound {self.lower}")
        if self._log_inside() < np.log(0.01):
            raise ValueError(f"the scan lies almost wholly above the upper bound {self.upper}")

    @property
    def names(self) -> tuple[str, ...]:
        return (self.name,)

    @property
    def normalised_weights(self) -> np.ndarray:
        w = np.asarray(self.weights, dtype=float)
        return w / w.sum()

    def _y(self, x: np.ndarray) -> np.ndarray:
        if not np.isfinite(self.lower):
            return np.asarray(x, dtype=float)
        return np.log(np.maximum(np.asarray(x, dtype=float) - self.lower, 1e-300))

    def _log_inside(self) -> float:
        """log of the untruncated mixture's mass below ``upper``."""
        if not np.isfinite(self.upper):
            return 0.0
        mu = self._y(np.asarray(self.centres))
        z = (self._y(np.asarray(self.upper)) - mu) / np.asarray(self.widths, dtype=float)
        return float(logsumexp(stats.norm.logcdf(z), b=self.normalised_weights))

    def log_density(self, x: np.ndarray) -> np.ndarray:
        x = np.asarray(x, dtype=float).reshape(-1)
        y = self._y(x)[:, None]
        mu = self._y(np.asarray(self.centres))[None, :]
        sd = np.asarray(self.widths, dtype=float)[None, :]
        comp = -0.5 * ((y - mu) / sd) ** 2 - np.log(sd) - LOG_SQRT_2PI
        out = logsumexp(comp, axis=1, b=self.normalised_weights[None, :]) - self._log_inside()
        if np.isfinite(self.lower):
            out = np.where(x > self.lower, out - y[:, 0], -np.inf)
        return np.where(x < self.upper, out, -np.inf)

    def draw(self, rng: np.random.Generator, n: int) -> np.ndarray:
        """n draws below ``upper``: the untruncated mixture's, those above it drawn again."""
        x = self._draw_untruncated(rng, n)
        while np.any(above := x >= self.upper):
            x[above] = self._draw_untruncated(rng, int(above.sum()))
        return x[:, None]

    def _draw_untruncated(self, rng: np.random.Generator, n: int) -> np.ndarray:
        k = rng.choice(len(self.centres), size=n, p=self.normalised_weights)
        y = self._y(np.asarray(self.centres))[k] + \
            np.asarray(self.widths, dtype=float)[k] * rng.standard_normal(n)
        return self.lower + np.exp(y) if np.isfinite(self.lower) else y


#: Draws that estimate the share of a Gaussian factor inside the priors' support.
SUPPORT_DRAWS = 200_000


@dataclass(frozen=True)
class GaussianFactor:
    """N(mean, cov) over ``names``, truncated to lowers_j <= x_j < uppers_j (normalised
    there; no uppers: none)."""

    names: tuple[str, ...]
    mean: tuple[float, ...]
    cov: tuple[tuple[float, ...], ...]
    lowers: tuple[float, ...]
    uppers: tuple[float, ...] | None = None
    _chol: np.ndarray = field(init=False, repr=False, compare=False)
    _log_inside: float = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        k = len(self.names)
        cov = np.asarray(self.cov, dtype=float)
        if self.uppers is None:
            object.__setattr__(self, "uppers", (np.inf,) * k)
        if len(self.mean) != k or cov.shape != (k, k) or len(self.lowers) != k or \
                len(self.uppers) != k:
            raise ValueError("mean, cov, lowers and uppers must match names")
        try:
            chol = np.linalg.cholesky(cov)
        except np.linalg.LinAlgError:
            raise ValueError("cov is not positive definite") from None
        object.__setattr__(self, "_chol", chol)
        z = np.random.default_rng(0).standard_normal((SUPPORT_DRAWS, k))
        inside = np.mean(self._inside(np.asarray(self.mean) + z @ chol.T))
        if inside < 0.01:
            raise ValueError("the Gaussian factor lies almost wholly outside the support")
        object.__setattr__(self, "_log_inside", float(np.log(inside)))

    def _inside(self, x: np.ndarray) -> np.ndarray:
        return np.all((x >= np.asarray(self.lowers, dtype=float)[None, :])
                      & (x < np.asarray(self.uppers, dtype=float)[None, :]), axis=1)

    def log_density(self, x: np.ndarray) -> np.ndarray:
        x = np.atleast_2d(np.asarray(x, dtype=float))
        d = x - np.asarray(self.mean, dtype=float)[None, :]
        sol = np.linalg.solve(self._chol, d.T).T
        log_det = float(np.sum(np.log(np.diag(self._chol))))
        out = -0.5 * np.sum(sol**2, axis=1) - log_det - len(self.names) * LOG_SQRT_2PI
        return np.where(self._inside(x), out - self._log_inside, -np.inf)

    def draw(self, rng: np.random.Generator, n: int) -> np.ndarray:
        out = np.empty((0, len(self.names)))
        while len(out) < n:
            z = rng.standard_normal((2 * (n - len(out)) + 8, len(self.names)))
            x = np.asarray(self.mean) + z @ self._chol.T
            out = np.vstack([out, x[self._inside(x)]])
        return out[:n]

    @classmethod
    def from_samples(cls, names: tuple[str, ...], samples: np.ndarray,
                     lowers: tuple[float, ...], widen: float = 1.5,
                     uppers: tuple[float, ...] | None = None) -> "GaussianFactor":
        """The samples' mean and covariance, the sds multiplied by ``widen``."""
        s = np.atleast_2d(np.asarray(samples, dtype=float))
        cov = np.atleast_2d(np.cov(s, rowvar=False)) * widen**2
        cov += np.diag(np.maximum(np.diag(cov), 1e-300) * 1e-9)  # keep it positive definite
        return cls(tuple(names), tuple(s.mean(axis=0).tolist()),
                   tuple(tuple(r) for r in cov.tolist()), tuple(lowers), uppers)


@dataclass(frozen=True)
class Reference:
    """q = (1 - share) prior + share g (module docstring); ``priors`` gives the model's prior
    of every variable a factor covers."""

    priors: dict[str, PriorSpec]
    factors: tuple[Factor, ...]
    share: float = 0.5

    def __post_init__(self) -> None:
        if not 0.0 < self.share < 1.0:
            raise ValueError(f"share must lie in (0, 1), got {self.share}")
        names = [n for f in self.factors for n in f.names]
        if not names or len(set(names)) != len(names):
            raise ValueError(f"the factors must cover distinct variables, got {names}")
        missing = sorted(set(names) - set(self.priors))
        if missing:
            raise ValueError(f"no prior given for {missing}")

    @property
    def names(self) -> tuple[str, ...]:
        """The covered variables, in the column order of :meth:`log_ratio` and :meth:`draw`."""
        return tuple(n for f in self.factors for n in f.names)

    def _slices(self):
        start = 0
        for f in self.factors:
            yield f, slice(start, start + len(f.names))
            start += len(f.names)

    def log_ratio(self, x: np.ndarray) -> np.ndarray:
        """log q / prior at rows x (columns :attr:`names`, model units)."""
        x = np.atleast_2d(np.asarray(x, dtype=float))
        log_g = np.zeros(len(x))
        for f, cols in self._slices():
            log_g += f.log_density(x[:, cols])
        log_p = sum(self.priors[n].logpdf(x[:, j]) for j, n in enumerate(self.names))
        with np.errstate(invalid="ignore"):
            rel = np.where(np.isfinite(log_g), log_g - log_p, -np.inf)
        return np.logaddexp(np.log1p(-self.share), np.log(self.share) + rel)

    def draw(self, rng: np.random.Generator, n: int) -> np.ndarray:
        """n rows from g (columns :attr:`names`)."""
        return np.hstack([f.draw(rng, n) for f in self.factors]) if n else \
            np.empty((0, len(self.names)))

    def describe(self) -> dict:
        """A JSON-ready account of the reference (for logs and reports)."""
        out: dict = {"share": self.share, "variables": list(self.names), "factors": []}
        for f in self.factors:
            if isinstance(f, ScanFactor):
                w = f.normalised_weights
                out["factors"].append({
                    "kind": "scan", "variable": f.name,
                    "centres": [float(c) for c in f.centres], "weights": w.tolist(),
                    "log_width": float(f.widths[0]),
                    "heaviest": [float(f.centres[i]) for i in np.argsort(-w)[:3]]})
            elif isinstance(f, GaussianFactor):
                out["factors"].append({
                    "kind": "gaussian", "variables": list(f.names),
                    "mean": [float(m) for m in f.mean],
                    "sd": [float(np.sqrt(f.cov[i][i])) for i in range(len(f.names))]})
        return out


def support(priors: Mapping[str, PriorSpec], names) -> tuple[tuple[float, ...], ...]:
    """(lowers, uppers) of the priors of ``names``: where a reference may put particles."""
    return (tuple(float(priors[n].lower) for n in names),
            tuple(float(priors[n].upper) for n in names))


#: Share of a candidate's initial particles drawn from the reference rather than the prior.
REFERENCE_SHARE = 0.5
#: The nested model's posterior sds are widened by this factor in the reference.
REFERENCE_WIDEN = 1.5


def map_reference(point, priors: Mapping[str, PriorSpec]) -> Reference | None:
    """Where a baseline's TMCMC starts half its particles: a Gaussian at its MAP with the
    Laplace covariance widened by REFERENCE_WIDEN, sigma at the MAP's RMS residual with a
    fifth of it as sd (``map_fit.PointFit``); the other half from the prior. None when the
    Laplace covariance is not usable."""
    names = tuple(point.names)
    p = len(point.theta) - 1
    cov = np.zeros((p + 1, p + 1))
    cov[:p, :p] = np.asarray(point.cov) * REFERENCE_WIDEN**2
    cov[p, p] = (0.2 * point.theta[-1]) ** 2
    try:
        gaussian = GaussianFactor(names, tuple(map(float, point.theta)),
                                  tuple(map(tuple, cov)), *support(priors, names))
    except ValueError as err:
        log.warning("no Gaussian start at the MAP (%s): tempering from the prior", err)
        return None
    return Reference({n: priors[n] for n in names}, (gaussian,), REFERENCE_SHARE)
