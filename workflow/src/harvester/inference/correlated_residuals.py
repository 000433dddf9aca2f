"""Posterior intervals that hold when the residuals are correlated in time.

Eq. (10) counts every residual as independent. A low-passed record's residuals are not: at
256 Hz after the study's 20 Hz low-pass they are correlated over about 6 samples, and on the
virtual rig the posterior sds of eq. (10) fell 2.5-3 x short of the estimates' scatter over
40 draws of the sensor error (docs/measurements.md, "Intervals for correlated residuals").

The adjustment keeps eq. (10)'s posterior (its mean, the evidence, the tables' means) and
rescales its draws about their mean, the curvature adjustment of Ribatet, Cooley and Davison
(2012, Statistica Sinica 22, 813-845) for a misspecified likelihood:

* the working likelihood's curvature at the posterior mean is A = SSE'' / (2 sigma^2), by
  central differences (Gauss-Newton's J^T J / sigma^2, J the model output's Jacobian on the
  fitted samples, leaves out the residuals' own curvature, which a misspecified model keeps
  large);
* the variance of its score is V = J^T R J / sigma^4, R the residuals' covariance: a Toeplitz
  matrix of their autocovariance, tapered by a Bartlett window out to a lag of at least 4
  n^(1/3) (Andrews 1991's rate for that window) and at least Sokal's automatic window (5 x the
  integrated autocorrelation time): a residual that rings (the Silverbox's, at 200 Hz) has an
  autocorrelation that Sokal's sum reads as short;
* the estimate's covariance is then the sandwich A^-1 V A^-1, and the adjusted posterior
  precision is the priors' curvature at the posterior mean plus A V^-1 A (whatever power
  ``Problem.temper`` the sampled likelihood had: the sandwich is that of the estimate).

With white residuals and a model that fits, V = A and nothing changes. Only the physical
parameters are adjusted; sigma's draws are left as they are.
"""

from __future__ import annotations

import json
import logging
import math
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # the tables read an Adjustment without the simulator's import
    from harvester.inference.likelihood import Problem
    from harvester.model.priors import PriorSpec

log = logging.getLogger("harvester.inference.correlated_residuals")

#: The posterior attribute (JSON) that holds an :class:`Adjustment`.
ATTRIBUTE = "correlated_residuals"

#: Sokal's window: the autocovariance is summed out to the first lag M >= SOKAL_C x tau(M).
SOKAL_C = 5.0
MIN_LAG = 10

#: The Bartlett taper reaches at least LAG_RATE x n^(1/3) lags.
LAG_RATE = 4.0

#: Finite-difference step of the Jacobian, in posterior sds.
STEP_SDS = 0.05


@dataclass(frozen=True)
class Adjustment:
    """theta_adjusted = center + matrix (theta - center), for the physical parameters ``names``.

    ``tau``: the residuals' integrated autocorrelation time (samples); ``max_lag``: the last
    lag of their autocovariance used; ``inflation``: adjusted sd / eq. (10)'s sd per parameter.
    """

    names: tuple[str, ...]
    center: tuple[float, ...]
    matrix: tuple[tuple[float, ...], ...]
    tau: float
    max_lag: int
    inflation: tuple[float, ...]

    def apply(self, theta: np.ndarray) -> np.ndarray:
        """Adjusted draws (rows of the physical parameters in ``names`` order)."""
        c = np.asarray(self.center)
        return c + (np.atleast_2d(theta) - c) @ np.asarray(self.matrix).T

    def to_json(self) -> str:
        return json.dumps(asdict(self))

    @classmethod
    def from_json(cls, text: str) -> "Adjustment":
        d = json.loads(text)
        return cls(names=tuple(d["names"]), center=tuple(d["center"]),
                   matrix=tuple(tuple(r) for r in d["matrix"]), tau=float(d["tau"]),
                   max_lag=int(d["max_lag"]), inflation=tuple(d["inflation"]))


def autocovariance(r: np.ndarray, max_lag: int) -> np.ndarray:
    """Biased autocovariance of r (mean removed) at lags 0..max_lag."""
    r = np.asarray(r, dtype=float) - np.mean(r)
    n = r.size
    spec = np.fft.rfft(r, 2 * n)
    return np.fft.irfft(spec * np.conj(spec))[:max_lag + 1] / n


def sokal_window(r: np.ndarray) -> tuple[float, int]:
    """(integrated autocorrelation time tau in samples, window M): the first M with
    M >= SOKAL_C tau(M), tau(M) = 1 + 2 sum_{k<=M} rho_k (Sokal 1997); M at least MIN_LAG and
    at most a tenth of the record."""
    cap = max(MIN_LAG, r.size // 10)
    rho = autocovariance(r, cap)
    rho = rho / rho[0]
    tau = 1.0 + 2.0 * np.cumsum(rho[1:])
    lags = np.arange(1, cap + 1)
    hit = np.nonzero(lags >= SOKAL_C * tau)[0]
    m = int(lags[hit[0]]) if hit.size else cap
    return float(max(tau[m - 1], 1.0 / r.size)), max(m, MIN_LAG)


def lag_window(r: np.ndarray) -> tuple[float, int]:
    """(tau, the Bartlett taper's last lag): Sokal's window, at least LAG_RATE n^(1/3) lags,
    at most a tenth of the record."""
    tau, m = sokal_window(r)
    floor = math.ceil(LAG_RATE * r.size ** (1.0 / 3.0))
    return tau, min(max(m, floor), max(MIN_LAG, r.size // 10))


def sandwich(jac: np.ndarray, r: np.ndarray, max_lag: int) -> tuple[np.ndarray, np.ndarray]:
    """(H, V) of the Gaussian working likelihood with sigma^2 = mean(r^2): H = J^T J / s^2,
    V = J^T R J / s^4, R Toeplitz in r's autocovariance with a Bartlett taper to ``max_lag``.
    jac: (n, p) derivative of the model output on the fitted samples."""
    s2 = float(np.mean(np.square(r)))
    gam = autocovariance(r, max_lag)
    jtj = jac.T @ jac
    v = gam[0] * jtj
    for k in range(1, max_lag + 1):
        g = jac[k:].T @ jac[:-k]
        v += (1.0 - k / (max_lag + 1.0)) * gam[k] * (g + g.T)
    return jtj / s2, v / s2 ** 2


def adjustment_matrix(post_cov: np.ndarray, h: np.ndarray, v: np.ndarray,
                      prior_precision: np.ndarray | None = None) -> np.ndarray:
    """C with C post_cov C^T = the adjusted posterior covariance, (prior precision +
    H V^-1 H)^-1: the likelihood's curvature replaced by the inverse of the sandwich (Ribatet
    et al. 2012's curvature adjustment), the prior's kept (zero where not given: the data
    dominate)."""
    adj_prec = h @ np.linalg.solve(v, h)
    if prior_precision is not None:
        adj_prec = adj_prec + prior_precision
    adj_cov = np.linalg.inv(0.5 * (adj_prec + adj_prec.T))
    return np.linalg.cholesky(adj_cov) @ np.linalg.inv(np.linalg.cholesky(post_cov))


def prior_precision(priors: Mapping[str, PriorSpec], names: Sequence[str],
                    x: np.ndarray) -> np.ndarray:
    """Diagonal precision of independent priors at x: minus the second derivative of each
    log density (central differences), at least zero (a log-uniform prior's is negative)."""
    out = np.zeros(len(names))
    for j, (name, value) in enumerate(zip(names, x)):
        spec = priors.get(name)
        if spec is None:
            continue
        step = 1e-3 * max(abs(float(value)), float(spec.sd) * 1e-3, 1e-300)
        f = [float(spec.logpdf(value + k * step)) for k in (-1, 0, 1)]
        if all(np.isfinite(f)):
            out[j] = max(-(f[0] - 2.0 * f[1] + f[2]) / step ** 2, 0.0)
    return np.diag(out)


def output_jacobian(problem: Problem, center: np.ndarray, steps: np.ndarray,
                    sigma: float) -> tuple[np.ndarray, np.ndarray]:
    """(residual at center (n,), derivative of the residual (n, p)) on the likelihood's samples,
    central differences in one batched simulation; NaN rows where a simulation failed."""
    p = center.size
    rows = np.repeat(center[None, :], 2 * p + 1, axis=0)
    rows[1:p + 1][np.arange(p), np.arange(p)] += steps
    rows[p + 1:][np.arange(p), np.arange(p)] -= steps
    r = problem.residuals(np.column_stack([rows, np.full(len(rows), sigma)]))
    return r[0], ((r[1:p + 1] - r[p + 1:]) / (2.0 * steps[:, None])).T


def sse_curvature(problem: Problem, center: np.ndarray, steps: np.ndarray,
                  sigma: float) -> np.ndarray:
    """Hessian (p, p) of the sum of squared residuals at ``center`` by central differences
    of step ``steps`` (one batched simulation of 2 p^2 + 1 rows: the centre, +-h_i, and the
    four corners of each pair). Unlike Gauss-Newton's 2 J^T J it keeps the residuals' own
    curvature, which a misspecified model (a linear model of a friction device) leaves large."""
    p = center.size
    eye = np.diag(steps)
    pairs = [(i, j) for i in range(p) for j in range(i + 1, p)]
    offsets = [np.zeros(p), *eye, *(-eye)]
    offsets += [si * eye[i] + sj * eye[j] for i, j in pairs
                for si, sj in ((1, 1), (1, -1), (-1, 1), (-1, -1))]
    rows = center + np.array(offsets)
    r = problem.residuals(np.column_stack([rows, np.full(len(rows), sigma)]))
    sse = np.sum(r * r, axis=1)  # the residuals the Jacobian and the meat are taken of
    hess = np.diag((sse[1:p + 1] - 2.0 * sse[0] + sse[p + 1:2 * p + 1]) / steps ** 2)
    for k, (i, j) in enumerate(pairs):
        pp, pm, mp, mm = sse[2 * p + 1 + 4 * k:2 * p + 5 + 4 * k]
        hess[i, j] = hess[j, i] = (pp - pm - mp + mm) / (4.0 * steps[i] * steps[j])
    return hess


def likelihood_curvature(problem: Problem, center: np.ndarray, sd: np.ndarray, sigma: float,
                         gauss_newton: np.ndarray, s2: float) -> np.ndarray:
    """The sandwich's bread: the likelihood's curvature at the posterior mean, SSE'' / (2 s^2)
    (:func:`sse_curvature`, steps of half a posterior sd); Gauss-Newton's where that is not
    positive definite or not finite (a failed simulation in the stencil)."""
    bread = sse_curvature(problem, center, 0.5 * sd, sigma) / (2.0 * s2)
    if np.all(np.isfinite(bread)) and np.all(np.linalg.eigvalsh(bread) > 0):
        return bread
    log.info("%s: the curvature by differences is not positive definite; Gauss-Newton's is "
             "used", problem.structure.name)
    return gauss_newton


#: A bound of the prior within this many posterior sds of the mean cuts the posterior.
CUT_SDS = 3.0


def cut_by_bound(priors: Mapping[str, PriorSpec], names: Sequence[str], center: np.ndarray,
                 sd: np.ndarray) -> list[str]:
    """The parameters whose posterior a finite bound of their prior cuts (within CUT_SDS sds
    of the mean): a rescaling about the mean, which assumes a Gaussian, does not hold there
    (EMPS's c_quad, mean 32 and sd 31 against its bound at 0, read 11 x)."""
    out = []
    for name, m, s in zip(names, center, sd):
        spec = priors.get(name)
        if spec is not None and any(np.isfinite(b) and abs(m - b) < CUT_SDS * s
                                    for b in (spec.lower, spec.upper)):
            out.append(name)
    return out


def correlation_adjustment(problem: Problem, theta: np.ndarray,
                           priors: Mapping[str, PriorSpec] | None = None) -> Adjustment | None:
    """The adjustment of posterior draws ``theta`` (rows: the problem's parameters, sigma last)
    for the residuals' correlation, keeping the curvature of ``priors`` (by name) at the
    posterior mean; None (logged) where it cannot be formed: too few draws, a
    parameter whose draws do not vary (a collapsed population) or whose posterior its prior's
    bound cuts (:func:`cut_by_bound`), a failed simulation near the posterior mean, or a
    singular curvature (a parameter the output does not depend on)."""
    names = problem.parameter_names[:-1]
    x = np.asarray(theta, dtype=float)[:, :len(names)]
    if x.shape[0] < 2 * len(names) + 2 or not names:
        return None
    center, cov = x.mean(axis=0), np.atleast_2d(np.cov(x, rowvar=False))
    sd = np.sqrt(np.diag(cov))
    why = None
    still = ~(sd > 1e-9 * np.maximum(np.abs(center), 1e-300))
    cut = cut_by_bound(priors or {}, names, center, sd)
    if still.any():
        why = f"the draws of {', '.join(n for n, s in zip(names, still) if s)} do not vary"
    elif cut:
        why = f"the prior's bound cuts the posterior of {', '.join(cut)}"
    else:
        sigma = float(np.mean(np.asarray(theta)[:, -1]))
        r, jac = output_jacobian(problem, center, STEP_SDS * sd, sigma)
        if not (np.all(np.isfinite(r)) and np.all(np.isfinite(jac))):
            why = "a simulation near the posterior mean failed"
    if why is None:
        tau, lag = lag_window(r)
        h, v = sandwich(jac, r, lag)
        bread = likelihood_curvature(problem, center, sd, sigma, h, float(np.mean(np.square(r))))
        try:
            mat = adjustment_matrix(cov, bread, v, prior_precision(priors or {}, names, center))
        except np.linalg.LinAlgError:
            why = "the curvature is singular (the output does not depend on every parameter)"
    if why is not None:
        log.warning("%s: no interval adjustment for correlated residuals (%s)",
                    problem.structure.name, why)
        return None
    inflation = np.sqrt(np.diag(mat @ cov @ mat.T)) / sd
    log.info("%s: residuals' integrated autocorrelation time %.2g samples (lags to %d); "
             "intervals for correlated residuals %s x eq. (10)'s", problem.structure.name, tau,
             lag, ", ".join(f"{n} {f:.2f}" for n, f in zip(names, inflation)))
    return Adjustment(tuple(names), tuple(map(float, center)),
                      tuple(tuple(map(float, row)) for row in mat), tau, lag,
                      tuple(map(float, inflation)))
