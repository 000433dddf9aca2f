"""Benchmark: our TMCMC kernel against pm.sample_smc's IMH kernel on the tanh model, at equal
evidence precision.

Both sample the study's problem (the tanh model on the filtered training record, the config's
priors with the paper's Table 1 means) in this process, with the same particles and chains.
A sampler's log evidence has a Monte Carlo variance that falls as 1 / (its cost), so the
wall time each needs for one precision is its wall time per chain x the variance of its
chains' log evidences; the ratio of those is the speed-up at equal precision (goal: at least
20 x). Also printed: each kernel's chains, their spread, our stated standard errors, the
likelihood evaluations and their rate. Run: ``make benchmark`` (``--particles``,
``--chains``; the IMH kernel takes several minutes per chain).
"""

from __future__ import annotations

import argparse
import logging
import time
from pathlib import Path

import numpy as np
import pymc as pm
import yaml

from harvester.data.daq import read_raw_record, to_accelerations
from harvester.data.signals import filter_recording
from harvester.inference.problems import make_problem
from harvester.inference.priors import prior_moments
from harvester.inference.pymc_model import build_model
from harvester.inference.tmcmc import run_tmcmc
from harvester.inference.posterior import log_evidence

ROOT = Path(__file__).resolve().parents[1]


def study_problem(config: dict):
    raw, meta = read_raw_record(ROOT / "data/raw/training.csv", ROOT / "data/raw/training.json")
    pre = config["preprocess"]
    rec = filter_recording(to_accelerations(raw, meta), pre["lowpass_hz"], pre["filter_order"])
    start = pre["training_lead_in"]
    rig = config["rig"]
    known = {"M": rig["M"], "m": rig["m"], "k": rig["k"]}
    problem = make_problem(rec, "tanh", known, window=(start, start + pre["training_samples"]),
                           output_filter=(pre["lowpass_hz"], pre["filter_order"]))
    table1 = {"c_m": 170.0, "F_c": 8.4}  # the paper's Table 1 means, for a fixed benchmark
    return problem, prior_moments(config["priors"], table1)


def run(sampler, problem, priors, particles, chains, seed, cfg):
    """(wall time per chain (s), likelihood evaluations per chain, log evidences, stated se)."""
    problem.n_evaluations = 0
    model = build_model(problem, priors)
    start = time.perf_counter()
    if sampler == "ours":
        idata = run_tmcmc(model, draws=particles, chains=chains, seed=seed,
                          proposal_scale=cfg["proposal_scale"], target_cov=cfg["target_cov"],
                          mcmc_steps=cfg["mcmc_steps"], target_accept=cfg.get("target_accept"))
        se = idata.sample_stats["log_evidence_se"].values
    else:
        idata = pm.sample_smc(draws=particles, model=model, chains=chains, cores=1,
                              random_seed=seed, progressbar=False,
                              compute_convergence_checks=False)
        se = np.full(chains, np.nan)
    wall = time.perf_counter() - start
    return wall / chains, problem.n_evaluations / chains, log_evidence(idata), se


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--particles", type=int, default=500)
    ap.add_argument("--chains", type=int, default=6)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    logging.getLogger("pymc").setLevel(logging.ERROR)
    config = yaml.safe_load((ROOT / "config/config.yaml").read_text())
    problem, priors = study_problem(config)
    print(f"tanh model, {problem.n_data} data points, {args.particles} particles x "
          f"{args.chains} chains each, one process\n")
    results = {name: run(name, problem, priors, args.particles, args.chains, args.seed,
                         config["tmcmc"]) for name in ("ours", "imh")}
    labels = {"ours": "ours (TMCMC, adaptive)", "imh": "pm.sample_smc (IMH)"}
    print(f"{'kernel':<24}{'s/chain':>9}{'evals/chain':>13}{'evals/s':>9}{'sd':>7}"
          f"{'stated se':>11}   log evidence per chain")
    for name, (wall, evals, ev, se) in results.items():
        print(f"{labels[name]:<24}{wall:>9.1f}{evals:>13.0f}{evals / wall:>9.0f}"
              f"{np.std(ev, ddof=1):>7.3f}{np.nanmedian(se):>11.3f}   "
              + " ".join(f"{e:.2f}" for e in ev))
    (w_o, _, ev_o, _), (w_i, _, ev_i, _) = results["ours"], results["imh"]
    var_o, var_i = np.var(ev_o, ddof=1), np.var(ev_i, ddof=1)
    print(f"\nwall time per chain, IMH / ours: {w_i / w_o:.1f}x")
    print(f"wall time at equal evidence precision (time x variance), IMH / ours: "
          f"{(w_i * var_i) / (w_o * var_o):.1f}x  (goal >= 20x)")
    print(f"log evidence, ours - IMH (chain means): {ev_o.mean() - ev_i.mean():+.2f} nats")


if __name__ == "__main__":
    main()
