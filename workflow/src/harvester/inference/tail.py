"""p-values of a statistic against simulated replicates, resolved below 1 / (B + 1).

A rank among B replicates cannot say less than 1 / (B + 1): with the detection's 400 replicates
no p-value falls below 0.0025, and a verdict asking p < 0.001 could never be reached. Where
few replicates reach the observed value, the tail of the replicates is modelled instead
(Knijnenburg, Wessels, Reinders and Shmulevich 2009, "Fewer permutations, more accurate
P-values", Bioinformatics 25: i161): the N_exc largest replicates, as exceedances y over a
threshold t, follow a generalised Pareto distribution (Pickands 1975)

    P(T > t + y | T > t) = (1 + xi y / s) ** (-1 / xi)       (exp(-y / s) at xi = 0),

so p = N_exc / B * P(T > x | T > t). The shape xi and scale s are fitted by probability-weighted
moments (Hosking and Wallis 1987, closed form, vectorised for the goodness-of-fit bootstrap);
the fit is kept when the Anderson-Darling test does not reject it at GOF_ALPHA (a parametric
bootstrap of the statistic), else N_exc is reduced by EXC_STEP and tried again, down to
MIN_EXCEEDANCES. With no acceptable fit the rank p-value stands, and says so. A negative fitted
xi would end the tail at a finite value and give p = 0 beyond it; the maximum of squared
Gaussian scores lies in the Gumbel domain (xi = 0), so where the fitted xi is negative p is
computed from the exponential tail (xi = 0, scale the exceedances' mean): an extrapolation that
errs towards larger p-values.

The largest of many squared scores (the detection's statistic) has an exponential-like tail
(xi near 0); tests/test_tail.py checks the tail p-value against the exact one of such a
maximum, and benchmarks/bench_tail.py against 20 times more replicates of a real detection.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Below this many replicates at least as large as the observed value, the tail is modelled.
MIN_RANK_COUNT = 10
#: Largest number of exceedances fitted, and at most this share of the finite replicates.
MAX_EXCEEDANCES = 100
MAX_EXCEEDANCE_SHARE = 0.25
#: Fewest exceedances a fit may rest on, and the step between the sizes tried.
MIN_EXCEEDANCES = 30
EXC_STEP = 10
#: The Anderson-Darling test rejects a fit below this p-value; its bootstrap draws.
GOF_ALPHA = 0.05
GOF_DRAWS = 400
#: Plotting position of the probability-weighted moments (Hosking and Wallis 1987).
PWM_OFFSET = 0.35


@dataclass(frozen=True)
class TailP:
    """A p-value and how it was found: method "rank" (share of replicates at least as large)
    or "tail" (generalised Pareto fit of the largest ``exceedances`` over ``threshold``, shape
    ``xi``, scale ``scale``, goodness-of-fit p ``gof_p``); ``floor``: 1 / (B + 1), the
    smallest rank p-value of B replicates; ``rank``: the rank p-value (what p was before the
    tail was modelled); ``note``: why the rank stands where it does."""

    p: float
    method: str
    replicates: int
    floor: float
    rank: float = float("nan")
    exceedances: int = 0
    threshold: float = float("nan")
    xi: float = float("nan")
    scale: float = float("nan")
    gof_p: float = float("nan")
    note: str = ""

    def to_dict(self) -> dict:
        return dict(self.__dict__)


def rank_p(observed: float, replicates: np.ndarray) -> float:
    """(1 + #{T_b >= observed}) / (1 + B); 1 for an observed value of -inf."""
    if observed == -np.inf:
        return 1.0
    return float((1.0 + np.sum(replicates >= observed)) / (1.0 + replicates.size))


def pwm_fit(y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(xi, scale) of a generalised Pareto distribution by probability-weighted moments,
    for exceedances ``y`` (..., n) over 0, each row on its own (Hosking and Wallis 1987:
    a0 = mean y, a1 = mean (1 - p_i) y_(i), p_i = (i - 0.35) / n; xi = 2 - a0 / (a0 - 2 a1),
    s = 2 a0 a1 / (a0 - 2 a1)); valid for xi < 0.5."""
    y = np.sort(np.asarray(y, dtype=float), axis=-1)
    n = y.shape[-1]
    p = (np.arange(1, n + 1) - PWM_OFFSET) / n
    a0 = y.mean(axis=-1)
    a1 = np.mean((1.0 - p) * y, axis=-1)
    d = np.maximum(a0 - 2.0 * a1, 1e-300)
    return 2.0 - a0 / d, 2.0 * a0 * a1 / d


def gpd_sf(y: np.ndarray, xi, scale) -> np.ndarray:
    """P(Y > y) of the generalised Pareto distribution (0 beyond its end when xi < 0)."""
    y = np.maximum(np.asarray(y, dtype=float), 0.0)
    xi = np.asarray(xi, dtype=float)
    scale = np.asarray(scale, dtype=float)
    small = np.abs(xi) < 1e-9
    safe_xi = np.where(small, 1.0, xi)
    base = np.maximum(1.0 + safe_xi * y / scale, 0.0)
    with np.errstate(divide="ignore"):
        power = np.where(base > 0.0, base ** (-1.0 / safe_xi), 0.0)
    return np.where(small, np.exp(-y / scale), power)


def anderson_darling(y: np.ndarray, xi, scale) -> np.ndarray:
    """A^2 of exceedances ``y`` (..., n) against the fitted distribution, per row."""
    y = np.sort(np.asarray(y, dtype=float), axis=-1)
    n = y.shape[-1]
    xi = np.asarray(xi, dtype=float)[..., None]
    scale = np.asarray(scale, dtype=float)[..., None]
    sf = np.clip(gpd_sf(y, xi, scale), 1e-300, 1.0 - 1e-16)
    cdf = 1.0 - sf
    i = np.arange(1, n + 1)
    terms = (2 * i - 1) * (np.log(cdf) + np.log(sf[..., ::-1]))
    return -n - terms.sum(axis=-1) / n


def gpd_sample(rng: np.random.Generator, xi: float, scale: float, shape) -> np.ndarray:
    """Draws of the generalised Pareto distribution by inversion."""
    u = rng.uniform(size=shape)
    if abs(xi) < 1e-9:
        return -scale * np.log(u)
    return scale * (u ** (-xi) - 1.0) / xi


def gof_p(y: np.ndarray, xi: float, scale: float, draws: int = GOF_DRAWS,
          seed: int = 0) -> float:
    """Parametric-bootstrap p-value of the Anderson-Darling statistic of a PWM fit (each
    bootstrap sample refitted, so the estimation is accounted for)."""
    observed = float(anderson_darling(y, xi, scale))
    sim = gpd_sample(np.random.default_rng(seed), xi, scale, (draws, len(y)))
    sim_xi, sim_scale = pwm_fit(sim)
    a2 = anderson_darling(sim, sim_xi, sim_scale)
    return float((1.0 + np.sum(a2 >= observed)) / (1.0 + draws))


def tail_p(observed: float, replicates: np.ndarray, seed: int = 0) -> TailP:
    """The p-value of ``observed`` among ``replicates`` (module docstring): the rank where
    MIN_RANK_COUNT replicates reach it, else the generalised Pareto tail."""
    reps = np.asarray(replicates, dtype=float).ravel()
    b = reps.size
    floor = 1.0 / (1.0 + b)
    rank = rank_p(observed, reps)
    count = int(np.sum(reps >= observed)) if observed != -np.inf else b
    if count >= MIN_RANK_COUNT:
        return TailP(rank, "rank", b, floor, rank)
    finite = np.sort(reps[np.isfinite(reps)])[::-1]
    top = min(MAX_EXCEEDANCES, int(MAX_EXCEEDANCE_SHARE * finite.size))
    if top < MIN_EXCEEDANCES:
        return TailP(rank, "rank", b, floor, rank, note=f"{finite.size} finite replicates: too "
                     f"few for a tail fit; the p-value cannot fall below {floor:.2g}")
    for n_exc in range(top, MIN_EXCEEDANCES - 1, -EXC_STEP):
        threshold = 0.5 * (finite[n_exc - 1] + finite[n_exc])
        y = finite[:n_exc] - threshold
        xi, scale = (float(v) for v in pwm_fit(y))
        if not (np.isfinite(xi) and scale > 0.0 and xi < 0.5):
            continue
        fit_p = gof_p(y, xi, scale, seed=seed)
        if fit_p >= GOF_ALPHA:
            xi_p, scale_p = (xi, scale) if xi >= 0.0 else (0.0, float(np.mean(y)))
            p = n_exc / b * float(gpd_sf(observed - threshold, xi_p, scale_p))
            return TailP(p, "tail", b, floor, rank, n_exc, float(threshold), xi, scale, fit_p)
    return TailP(rank, "rank", b, floor, rank, note="no generalised Pareto fit of the "
                 "replicates' tail passed the Anderson-Darling test; the p-value cannot fall "
                 f"below {floor:.2g}")
