"""Benchmark: our TMCMC kernel against pm.sample_smc's default IMH kernel on the tanh model.

Both run in this process on the same data (the study's filtered training record) with equal
particle counts; printed: wall time, likelihood evaluations per second, log evidence, and their
ratios. Then the cost of one batched likelihood call per particle and per sample against the
bare compiled simulation loop. Run: `make benchmark` (or with --particles/--chains).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
import pymc as pm
import yaml

from harvester.data.daq import read_raw_record, to_accelerations
from harvester.inference.identify import make_problem
from harvester.inference.priors import prior_moments
from harvester.inference.pymc_model import build_model
from harvester.data.signals import filter_recording
from harvester.model.simulate import _simulate_batch, substeps
from harvester.inference.tmcmc import TMCMC, log_evidence, run_tmcmc

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


def timed(fn):
    start = time.perf_counter()
    out = fn()
    return out, time.perf_counter() - start


def run_ours(problem, priors, particles, chains, seed, cfg):
    problem.n_evaluations = 0
    idata, wall = timed(lambda: run_tmcmc(
        build_model(problem, priors), draws=particles, chains=chains, seed=seed,
        proposal_scale=cfg["proposal_scale"], target_cov=cfg["target_cov"],
        mcmc_steps=cfg["mcmc_steps"], target_accept=cfg.get("target_accept")))
    return wall, problem.n_evaluations, log_evidence(idata)


def run_builtin(problem, priors, particles, chains, seed):
    problem.n_evaluations = 0
    model = build_model(problem, priors)
    idata, wall = timed(lambda: pm.sample_smc(
        draws=particles, model=model, chains=chains, cores=1, random_seed=seed,
        progressbar=False, compute_convergence_checks=False))
    return wall, problem.n_evaluations, log_evidence(idata)


def per_sample_costs(problem, n=1000, repeats=3):
    """Seconds per particle and per (particle x sample) of a batched likelihood call and of the
    bare compiled loop (same particles, no Python around it)."""
    rng = np.random.default_rng(0)
    theta = np.column_stack([rng.normal(110, 20, n), rng.uniform(5, 15, n),
                             rng.uniform(50, 150, n), np.full(n, 0.1)])
    problem.loglike(theta)  # warm up
    _, t_like = timed(lambda: [problem.loglike(theta) for _ in range(repeats)])
    lay, params = problem.structure.layout, problem.layout_params(theta)
    nsub = substeps(lay, params, problem.dt)
    T = len(problem.base_acc)
    acc, zz, vv, ok = (np.empty((n, T)), np.empty((n, T)), np.empty((n, T)), np.zeros(n, bool))

    def bare():
        _simulate_batch(problem.base_acc, problem.dt, params, lay.codes, lay.param_offsets,
                        lay.state_offsets, lay.n_states, nsub, acc, zz, vv, ok, False)

    _, t_bare = timed(lambda: [bare() for _ in range(repeats)])
    per = lambda t: (t / repeats / n, t / repeats / n / T)  # noqa: E731
    return per(t_like), per(t_bare), float(nsub.mean())


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--particles", type=int, default=500)
    ap.add_argument("--chains", type=int, default=2)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    config = yaml.safe_load((ROOT / "config/config.yaml").read_text())
    problem, priors = study_problem(config)
    print(f"tanh model, {problem.n_data} data points, {args.particles} particles x "
          f"{args.chains} chains, one process\n")
    ours = run_ours(problem, priors, args.particles, args.chains, args.seed, config["tmcmc"])
    builtin = run_builtin(problem, priors, args.particles, args.chains, args.seed)
    print(f"{'kernel':<22}{'wall (s)':>10}{'evals':>10}{'evals/s':>10}{'log evidence (per chain)':>32}")
    for name, (wall, evals, ev) in (("ours (TMCMC)", ours), ("pm.sample_smc (IMH)", builtin)):
        print(f"{name:<22}{wall:>10.1f}{evals:>10d}{evals / wall:>10.0f}   "
              + " ".join(f"{e:.2f}" for e in ev))
    print(f"\nspeed-up (wall time, IMH / ours): {builtin[0] / ours[0]:.1f}x  (goal >= 20x)")
    print(f"likelihood evaluations per second, ours / IMH: "
          f"{(ours[1] / ours[0]) / (builtin[1] / builtin[0]):.1f}x")
    print(f"evaluations needed, IMH / ours: {builtin[1] / ours[1]:.1f}x")
    print(f"log evidence, ours - IMH (chain means): {ours[2].mean() - builtin[2].mean():+.2f} nats "
          f"(goal within 0.5)")
    (lp, ls), (bp, bs), nsub = per_sample_costs(problem)
    print(f"\nbatched likelihood call: {lp * 1e3:.3f} ms per particle, {ls * 1e9:.1f} ns per "
          f"particle-sample")
    print(f"bare compiled loop:      {bp * 1e3:.3f} ms per particle, {bs * 1e9:.1f} ns per "
          f"particle-sample ({nsub:.1f} RK4 sub-steps per sample)")
    print(f"likelihood / bare loop: {lp / bp:.2f}x")


if __name__ == "__main__":
    main()
