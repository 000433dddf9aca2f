"""Posterior predictive simulation and validation metrics (paper Figures 7, 9, 10; the 1.3%).

For posterior samples theta_s = (physical parameters, sigma_s) the model response z''_s(t) is
simulated for a recorded base acceleration. Two kinds of bounds:

* ``parameter``: mean +- k sd over samples of z''_s(t): parameter uncertainty alone, as the
  paper's figures show;
* ``predictive``: the full predictive of eqs. (8)-(10), the mixture of N(z''_s(t), sigma_s^2),
  whose variance is var_s z''_s(t) + mean_s sigma_s^2.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.special import logsumexp

from harvester.inference.likelihood import Problem

#: Columns of results/tables/validation.csv.
VALIDATION_COLUMNS = ["model", "data", "bounds", "nrmse", "outside_1sigma", "outside_2sigma",
                      "outside_3sigma", "mlpd"]
#: Fraction of a Gaussian outside +-1, 2, 3 sd.
NOMINAL_OUTSIDE = {1: 0.31731, 2: 0.04550, 3: 0.00270}


@dataclass
class PredictiveBand:
    """Ensemble of simulated responses and its moments, all (samples, time) or (time,)."""

    time: np.ndarray
    responses: np.ndarray  # z''_s(t), m/s^2
    sigma: np.ndarray  # sigma_s, m/s^2

    @property
    def mean(self) -> np.ndarray:
        return self.responses.mean(axis=0)

    @property
    def sd_parameter(self) -> np.ndarray:
        return self.responses.std(axis=0, ddof=1)

    @property
    def sd_predictive(self) -> np.ndarray:
        return np.sqrt(self.sd_parameter**2 + np.mean(self.sigma**2))

    def sd(self, bounds: str) -> np.ndarray:
        if bounds == "parameter":
            return self.sd_parameter
        if bounds == "predictive":
            return self.sd_predictive
        raise ValueError(f"bounds must be 'parameter' or 'predictive', not {bounds!r}")


def thin(theta: np.ndarray, n: int, seed: int) -> np.ndarray:
    """A random subset of ``n`` posterior rows (all rows if there are no more than ``n``)."""
    if n >= len(theta):
        return theta
    rng = np.random.default_rng(seed)
    return theta[np.sort(rng.choice(len(theta), size=n, replace=False))]


def posterior_predictive(problem: Problem, theta: np.ndarray, base_acc: np.ndarray,
                         time: np.ndarray) -> PredictiveBand:
    """Simulate every row of ``theta`` (free parameters..., sigma) for the input ``base_acc``
    (the problem's input kind), giving the problem's output kind, filtered as its data were."""
    sim = problem.simulate(theta, base_acc)
    keep = sim.ok
    if not keep.any():
        raise RuntimeError("no posterior sample could be simulated for this input")
    out = problem.output_of(sim)
    return PredictiveBand(np.asarray(time), out[keep], np.asarray(theta)[keep, -1])


def nrmse(measured: np.ndarray, predicted: np.ndarray) -> float:
    """RMS error normalised by the RMS of the measured signal about its mean."""
    return float(np.sqrt(np.mean((measured - predicted) ** 2)) / np.std(measured))


def outside_fraction(measured: np.ndarray, mean: np.ndarray, sd: np.ndarray, k: float) -> float:
    """Fraction of samples outside mean +- k sd."""
    return float(np.mean(np.abs(measured - mean) > k * sd))


def mlpd(measured: np.ndarray, band: PredictiveBand, bounds: str) -> float:
    """Mean log predictive density per sample (nats).

    ``predictive``: the mixture over posterior samples of N(z''_s, sigma_s^2);
    ``parameter``: a Gaussian with the ensemble's mean and parameter-only sd.
    """
    if bounds == "predictive":
        r = measured[None, :] - band.responses
        s = band.sigma[:, None]
        logp = -0.5 * np.log(2 * np.pi * s**2) - 0.5 * (r / s) ** 2
        return float(np.mean(logsumexp(logp, axis=0) - np.log(len(band.sigma))))
    sd = np.maximum(band.sd_parameter, 1e-12)
    r = measured - band.mean
    return float(np.mean(-0.5 * np.log(2 * np.pi * sd**2) - 0.5 * (r / sd) ** 2))


def validation_rows(model: str, data: str, measured: np.ndarray,
                    band: PredictiveBand) -> list[dict]:
    """One row per kind of bounds, with the columns of :data:`VALIDATION_COLUMNS`."""
    rows = []
    for bounds in ("parameter", "predictive"):
        sd = band.sd(bounds)
        row = {"model": model, "data": data, "bounds": bounds,
               "nrmse": nrmse(measured, band.mean)}
        for k in (1, 2, 3):
            row[f"outside_{k}sigma"] = outside_fraction(measured, band.mean, sd, k)
        row["mlpd"] = mlpd(measured, band, bounds)
        rows.append(row)
    return rows


def validation_table(rows: list[dict]) -> pd.DataFrame:
    return pd.DataFrame(rows, columns=VALIDATION_COLUMNS)


def save_band(path, band: PredictiveBand, measured: np.ndarray, model: str, data: str) -> None:
    """Write an ensemble and the measured signal it is compared with (.npz), atomically."""
    from harvester.data.fileio import atomic_path
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as fh:
            np.savez_compressed(fh, time=band.time, responses=band.responses.astype(np.float32),
                                sigma=band.sigma, measured=measured, model=model, data=data)


def load_band(path) -> tuple[PredictiveBand, np.ndarray, str, str]:
    """Read what :func:`save_band` wrote: (band, measured, model, data)."""
    with np.load(path) as f:
        band = PredictiveBand(f["time"], f["responses"].astype(float), f["sigma"])
        return band, f["measured"], str(f["model"]), str(f["data"])
