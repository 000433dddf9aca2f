"""Posterior summaries (Tables 3 and 5) and model evidence (eqs. 7, 11 and 12).

The functions take an ``arviz.InferenceData`` or what :func:`read_posterior` returns: anything
with a ``posterior`` and a ``sample_stats`` Dataset.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd
import xarray as xr
from scipy.special import logsumexp

if TYPE_CHECKING:
    import arviz as az

#: Columns of the posterior tables (Tables 3 and 5).
POSTERIOR_COLUMNS = ["parameter", "mean", "sd", "q2.5", "q97.5", "sd_adj", "q2.5_adj",
                     "q97.5_adj", "paper", "truth"]

#: The columns of an interval for correlated residuals (:func:`interval_columns`).
ADJUSTED_COLUMNS = ("sd_adj", "q2.5_adj", "q97.5_adj")


@dataclass(frozen=True)
class PosteriorFile:
    """The groups of a saved posterior (``posterior.nc``, an InferenceData in netCDF) that
    the study reads, loaded into memory."""

    posterior: xr.Dataset
    sample_stats: xr.Dataset


def read_posterior(path: str | Path) -> PosteriorFile:
    """The posterior and sample statistics of a ``posterior.nc``, read with xarray alone
    (arviz's import costs 2-3 s of every rule that only reads the samples)."""
    def group(name: str) -> xr.Dataset:
        with xr.open_dataset(path, group=name) as ds:
            return ds.load()
    return PosteriorFile(group("posterior"), group("sample_stats"))


def samples(idata: az.InferenceData, names: list[str] | tuple[str, ...]) -> np.ndarray:
    """Posterior samples pooled over chains, shape (samples, len(names))."""
    post = idata.posterior
    return np.column_stack([post[n].values.reshape(-1) for n in names])


def set_known(idata: az.InferenceData, known: dict[str, float]) -> None:
    """Store the values a posterior was conditioned on (M, m, k, ...) with it: the
    ``known`` attribute, "name=value,..." (netCDF attributes hold no mappings)."""
    idata.posterior.attrs["known"] = ",".join(f"{k}={float(v)!r}" for k, v in known.items())


def known_values(idata: az.InferenceData) -> dict[str, float]:
    """The values stored by :func:`set_known` (empty when there are none)."""
    items = [v for v in str(idata.posterior.attrs.get("known") or "").split(",") if v]
    return {name: float(value) for name, _, value in (i.partition("=") for i in items)}


def parameter_names(idata: az.InferenceData) -> list[str]:
    """Identified parameters in the order stored (physical parameters, sigma last)."""
    names = list(idata.posterior.attrs.get("parameter_names", "").split(",")) \
        if idata.posterior.attrs.get("parameter_names") else \
        [v for v in idata.posterior.data_vars if not v.endswith("__")]
    return [n for n in names if n]


def adjusted_draws(idata: az.InferenceData) -> dict[str, np.ndarray]:
    """The physical parameters' draws adjusted for correlated residuals, by name (the
    adjustment ``identify`` stored; empty when there is none)."""
    from harvester.inference.correlated_residuals import ATTRIBUTE, Adjustment
    text = idata.posterior.attrs.get(ATTRIBUTE)
    if not text:
        return {}
    adj = Adjustment.from_json(str(text))
    x = adj.apply(samples(idata, adj.names))
    return {name: x[:, j] for j, name in enumerate(adj.names)}


def interval_columns(x: np.ndarray, adjusted: np.ndarray | None) -> dict[str, float]:
    """mean, sd, 95 % interval of draws x (eq. (10)'s posterior) and, where given, the sd and
    95 % interval of the same draws adjusted for correlated residuals (NaN where not)."""
    out = {"mean": x.mean(), "sd": x.std(ddof=1) if x.size > 1 else np.nan,
           "q2.5": np.quantile(x, 0.025), "q97.5": np.quantile(x, 0.975)}
    out.update(dict.fromkeys(ADJUSTED_COLUMNS, np.nan) if adjusted is None else zip(
        ADJUSTED_COLUMNS, (adjusted.std(ddof=1), *np.quantile(adjusted, [0.025, 0.975]))))
    return out


def summary_table(idata: az.InferenceData, paper: dict[str, float],
                  truth: dict[str, float]) -> pd.DataFrame:
    """Posterior mean, sd and 95% interval of each parameter (eq. (10)'s, and adjusted for
    correlated residuals) beside the paper's and the truth."""
    adjusted = adjusted_draws(idata)
    rows = []
    for name in parameter_names(idata):
        x = idata.posterior[name].values.reshape(-1)
        rows.append({"parameter": name, **interval_columns(x, adjusted.get(name)),
                     "paper": paper.get(name, np.nan), "truth": truth.get(name, np.nan)})
    return pd.DataFrame(rows, columns=POSTERIOR_COLUMNS)


def evidence_table(evidences: dict[str, np.ndarray]) -> pd.DataFrame:
    """Rows (model, chain, log_evidence)."""
    rows = [{"model": m, "chain": c, "log_evidence": float(v)}
            for m, ev in evidences.items() for c, v in enumerate(ev)]
    return pd.DataFrame(rows, columns=["model", "chain", "log_evidence"])


def pooled_log_evidence(chains: np.ndarray) -> float:
    """Evidence pooled over chains: the log of the mean of the chains' evidences."""
    chains = np.asarray(chains, dtype=float)
    return float(logsumexp(chains) - np.log(len(chains)))


def bayes_factor_table(evidences: dict[str, np.ndarray], reference: str | None = None,
                       paper: dict[tuple[str, str], float] | None = None) -> pd.DataFrame:
    """Log Bayes factor of each model over ``reference`` (eq. 12, equal prior probabilities).

    The spread is the standard deviation over chains of the per-chain differences, pairing chains
    by index (chains are independent, so this is the spread of one-chain estimates).
    """
    models = list(evidences)
    reference = reference or models[0]
    ref = evidences[reference]
    rows = []
    for m in models:
        if m == reference:
            continue
        n = min(len(ref), len(evidences[m]))
        diff = evidences[m][:n] - ref[:n]
        rows.append({
            "model": m, "reference": reference,
            "log_bayes_factor": pooled_log_evidence(evidences[m]) - pooled_log_evidence(ref),
            "sd_over_chains": float(np.std(diff, ddof=1)) if n > 1 else np.nan,
            "min": float(diff.min()), "max": float(diff.max()),
            "paper": (paper or {}).get((m, reference), np.nan),
        })
    return pd.DataFrame(rows, columns=["model", "reference", "log_bayes_factor",
                                       "sd_over_chains", "min", "max", "paper"])


def posterior_truth(config_rig: dict, model: str) -> dict[str, float]:
    """The virtual rig's values of a structure's parameters, where the structure contains them.

    The rig's kinetic friction is the tanh law, so ``tanh`` has a truth for c_m, F_c and beta;
    the linear model's c_m is an equivalent damping with no true value. sigma has none either
    (it absorbs sensor noise and the rig's unmodelled stiction).
    """
    if model.split("+")[0] != "tanh" or config_rig["friction"]["law"] != "tanh":
        return {}
    f = config_rig["friction"]
    return {"c_m": float(config_rig["c_m"]), "F_c": float(f["F_c"]), "beta": float(f["beta"])}


def posterior_theta(idata: az.InferenceData) -> np.ndarray:
    """Posterior rows theta = (free parameters..., sigma), chains pooled."""
    return samples(idata, parameter_names(idata))


def per_chain_stage_lists(values, chains: int) -> list[np.ndarray]:
    """PyMC's SMC sample_stats entry -> one 1-D float array per chain.

    ``pm.sample_smc`` stores each statistic as an object array: (1, chains) of per-chain lists
    when chains ran different numbers of stages, (1, chains, stages) of numbers when they ran
    the same number, (1, stages) for one chain. All become ``chains`` rows.
    """
    rows = np.asarray(values, dtype=object).reshape(chains, -1)
    return [
        np.concatenate([np.atleast_1d(np.asarray(item, dtype=float)) for item in row])
        for row in rows
    ]


def log_evidence(idata: az.InferenceData) -> np.ndarray:
    """Log evidence log P(D|M) of each chain.

    Reads ``sample_stats.log_evidence`` (from `run_tmcmc`), or else the last finite entry of
    PyMC's ``sample_stats.log_marginal_likelihood`` (any ``pm.sample_smc`` kernel).
    """
    stats = idata.sample_stats
    if "log_evidence" in stats:
        return np.asarray(stats["log_evidence"].values, dtype=float).reshape(-1)
    raw = stats["log_marginal_likelihood"].values
    chains = idata.posterior.sizes["chain"]  # PyMC's sample_stats has a dummy chain dim
    out = []
    for row in per_chain_stage_lists(raw, chains):
        finite = row[np.isfinite(row)]
        out.append(finite[-1] if finite.size else np.nan)
    return np.array(out)
