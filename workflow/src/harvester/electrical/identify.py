"""TMCMC identification of each electrical structure, its evidence, and the weights of
Bayesian model averaging across structures (Green et al. 2015, eqs. 7, 11, 12)."""

from __future__ import annotations

import logging
from collections.abc import Mapping

import arviz as az
import numpy as np
import pandas as pd
import pymc as pm
from scipy.special import logsumexp

from harvester.electrical.priors import MECHANICAL, generator_priors, noise_priors
from harvester.electrical.problem import STRUCTURES, ElectricalProblem
from harvester.inference.batched import loglike_potential
from harvester.inference.identify import TMCMCSettings
from harvester.inference.posterior import pooled_log_evidence, set_known
from harvester.inference.pymc_model import prior_variable
from harvester.inference.tmcmc import run_tmcmc

log = logging.getLogger("harvester.electrical.identify")


def build_model(problem: ElectricalProblem, sigma_prior: Mapping) -> pm.Model:
    """PyMC model: (ln c_m, ln F_c, ln beta) ~ the mechanical prior, the generator's and the
    noise priors, and the joint likelihood of ``problem``."""
    mech = problem.mechanical
    specs = {**generator_priors(STRUCTURES[problem.structure]), **noise_priors(sigma_prior)}
    with pm.Model() as model:
        ln_mech = pm.MvNormal("ln_mechanical", mu=mech.mean, cov=mech.cov, shape=len(MECHANICAL))
        others = [prior_variable(specs[n]) for n in problem.parameter_names[len(MECHANICAL):]]
        loglike_potential("loaded_records", problem.loglike, [ln_mech, *others])
    return model


def identify(problem: ElectricalProblem, sigma_prior: Mapping,
             settings: TMCMCSettings) -> az.InferenceData:
    """Posterior samples and per-chain log evidence of one electrical structure."""
    model = build_model(problem, sigma_prior)
    log.info("TMCMC for %s: %s; %d particles x %d chains; records %s", problem.structure,
             ", ".join(problem.parameter_names), settings.particles, settings.chains,
             ", ".join(r.name for r in problem.records))
    idata = run_tmcmc(model, **settings.run_arguments())
    idata.posterior.attrs["structure"] = problem.structure
    idata.posterior.attrs["records"] = ",".join(r.name for r in problem.records)
    set_known(idata, problem.mechanical.known)
    return idata


def posterior_samples(idata: az.InferenceData) -> pd.DataFrame:
    """Pooled posterior samples in physical units: c_m, F_c, beta, K_e, R_s, L_s (0 in the
    resistive structure), sigma_acc, sigma_V."""
    post = idata.posterior
    ln_mech = post["ln_mechanical"].values.reshape(-1, len(MECHANICAL))
    out = {n: np.exp(ln_mech[:, j]) for j, n in enumerate(MECHANICAL)}
    for n in ("K_e", "R_s", "L_s", "sigma_acc", "sigma_V"):
        out[n] = post[n].values.reshape(-1) if n in post else np.zeros(ln_mech.shape[0])
    return pd.DataFrame(out)


def evidence_summary(idata: az.InferenceData) -> dict:
    """Per-chain log evidence and its standard error, pooled log evidence (log mean of the
    chains' evidences) with the spread of the chains as its error, stages, wall time (s)."""
    stats = idata.sample_stats
    per_chain = np.asarray(stats["log_evidence"].values, dtype=float)
    se = np.asarray(stats["log_evidence_se"].values, dtype=float) \
        if "log_evidence_se" in stats else np.full(per_chain.size, np.nan)
    pooled = pooled_log_evidence(per_chain)
    spread = float(np.std(per_chain, ddof=1) / np.sqrt(per_chain.size)) \
        if per_chain.size > 1 else float("nan")
    within = float(np.sqrt(np.sum(se ** 2)) / per_chain.size)
    return {"structure": idata.posterior.attrs.get("structure", ""),
            "log_evidence": pooled, "log_evidence_se": float(np.nanmax([spread, within])),
            "log_evidence_chains": per_chain.tolist(), "log_evidence_se_chains": se.tolist(),
            "stages": np.asarray(stats["n_stages"].values).tolist(),
            "wall_time_s": float(stats.attrs.get("wall_time_s", np.nan))}


def model_weights(evidence: Mapping[str, float]) -> dict[str, float]:
    """Posterior probabilities of the structures from their log evidences, equal prior
    probabilities (eq. 12 normalised): the weights of Bayesian model averaging."""
    names = list(evidence)
    logs = np.array([evidence[n] for n in names], dtype=float)
    w = np.exp(logs - logsumexp(logs))
    return dict(zip(names, w.tolist()))


def evidence_table(summaries: list[dict]) -> pd.DataFrame:
    """One row per structure: log evidence with its error, log Bayes factor to the best,
    BMA weight, stages and wall time."""
    weights = model_weights({s["structure"]: s["log_evidence"] for s in summaries})
    best = max(s["log_evidence"] for s in summaries)
    rows = [{"structure": s["structure"], "log_evidence": s["log_evidence"],
             "log_evidence_se": s["log_evidence_se"],
             "log_bayes_factor_to_best": s["log_evidence"] - best,
             "weight": weights[s["structure"]], "chains": len(s["log_evidence_chains"]),
             "wall_time_s": s["wall_time_s"]} for s in summaries]
    return pd.DataFrame(rows).sort_values("log_evidence", ascending=False)


def device_of(records, known: Mapping[str, float]) -> dict:
    """What a power prediction needs besides the posteriors: known M, m, k and the screw
    ratio G (rad/m) of the records' nameplate."""
    ratios = {round(r.G, 9) for r in records}
    if len(ratios) != 1:
        raise ValueError(f"the records disagree on the ball-screw lead: G = {sorted(ratios)}")
    return {"known": dict(known), "G": records[0].G}
