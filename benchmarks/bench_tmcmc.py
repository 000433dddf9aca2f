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

Three comparisons, because the tool does not decide on TMCMC's own estimate: every evidence
the diagnosis compares is re-estimated by bridge sampling from the final population
(``harvester.inference.evidence``, ``diagnosis.name.confirm.bridge_evidence``), here from each
chain alone. (1) the kernels, each with its own product of mean weights; (2) what each tool
reports: ours re-estimated by bridge sampling (its time added) against IMH's own; (3) both
re-estimated by bridge sampling, which shows how much of (2) is the estimator, open to any
sampler's population, and how much the kernel. The variance of a few chains is itself
uncertain: each ratio's 90 % interval from the F distribution of two sample variances is
printed beside it.
"""

from __future__ import annotations

import argparse
import logging
import time
from pathlib import Path

import numpy as np
import pymc as pm
import yaml
from scipy import stats

from harvester.data.daq import read_raw_record, to_accelerations
from harvester.data.signals import filter_recording
from harvester.diagnosis.name.confirm import bridge_evidence
from harvester.inference.problems import make_problem
from harvester.inference.priors import prior_moments, priors_for
from harvester.inference.pymc_model import build_model
from harvester.inference.tmcmc import run_tmcmc
from harvester.inference.posterior import log_evidence, posterior_theta

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


def run(sampler, problem, priors, particles, chains, seed, cfg) -> dict:
    """Wall time per chain (s), likelihood evaluations per chain, log evidences, stated se,
    and each chain's bridge re-estimate with its time per chain (s)."""
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
    evals = problem.n_evaluations
    start = time.perf_counter()
    used = priors_for(problem, priors)
    rows = np.split(posterior_theta(idata), chains)
    bridge = np.array([bridge_evidence(problem, used, r, np.zeros(1), seed + i).log_evidence
                       for i, r in enumerate(rows)])
    return {"wall": wall / chains, "evals": evals / chains, "ev": log_evidence(idata), "se": se,
            "bridge": bridge, "bridge_wall": (time.perf_counter() - start) / chains}


def speedup(label: str, ours: tuple[float, np.ndarray], imh: tuple[float, np.ndarray]) -> None:
    """Print IMH's time x variance over ours, with its 90 % interval (F distribution)."""
    (w_o, ev_o), (w_i, ev_i) = ours, imh
    var_o, var_i = np.var(ev_o, ddof=1), np.var(ev_i, ddof=1)
    ratio = (w_i * var_i) / (w_o * var_o)
    lo, hi = (ratio / stats.f.ppf(q, len(ev_i) - 1, len(ev_o) - 1) for q in (0.95, 0.05))
    print(f"{label:<58}{ratio:>8.1f}x  (90 % {lo:.1f}-{hi:.1f}x; goal >= 20x)")


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
    res = {name: run(name, problem, priors, args.particles, args.chains, args.seed,
                     config["tmcmc"]) for name in ("ours", "imh")}
    labels = {"ours": "ours (TMCMC, adaptive)", "imh": "pm.sample_smc (IMH)"}
    print(f"{'kernel':<24}{'s/chain':>9}{'evals/chain':>13}{'evals/s':>9}{'sd':>7}"
          f"{'stated se':>11}{'bridge s':>10}{'bridge sd':>11}   log evidence per chain")
    for name, r in res.items():
        print(f"{labels[name]:<24}{r['wall']:>9.1f}{r['evals']:>13.0f}"
              f"{r['evals'] / r['wall']:>9.0f}{np.std(r['ev'], ddof=1):>7.3f}"
              + (f"{np.median(r['se']):>11.3f}" if np.isfinite(r["se"]).all() else f"{'-':>11}")
              + f"{r['bridge_wall']:>10.2f}"
              f"{np.std(r['bridge'], ddof=1):>11.3f}   " + " ".join(f"{e:.2f}" for e in r["ev"]))
        print(f"{'':<24}{'bridge re-estimates:':>60}   "
              + " ".join(f"{e:.2f}" for e in r["bridge"]))
    o, i = res["ours"], res["imh"]
    print(f"\nwall time per chain, IMH / ours: {i['wall'] / o['wall']:.1f}x")
    print("wall time at equal evidence precision (time x variance), IMH / ours:")
    speedup("  (1) the kernels, each its own estimate", (o["wall"], o["ev"]),
            (i["wall"], i["ev"]))
    speedup("  (2) what each reports: ours bridged, IMH its own",
            (o["wall"] + o["bridge_wall"], o["bridge"]), (i["wall"], i["ev"]))
    speedup("  (3) both bridged", (o["wall"] + o["bridge_wall"], o["bridge"]),
            (i["wall"] + i["bridge_wall"], i["bridge"]))
    print(f"log evidence, ours - IMH (chain means): {o['ev'].mean() - i['ev'].mean():+.2f} "
          f"nats; bridged: {o['bridge'].mean() - i['bridge'].mean():+.2f}")


if __name__ == "__main__":
    main()
