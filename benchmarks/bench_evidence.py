"""Benchmark: the precision of the diagnosis's log evidence, TMCMC's alone and re-estimated by
bridge sampling from each chain's final population (``harvester.inference.evidence``).

One recording of the study's tanh device (``diagnosis.synthetic``, 0.04 m/s^2 sensors, 20 Hz
filter) and one model with a concealed-size added term, each sampled by ``chains``
independent TMCMC chains at the diagnosis's settings (``ConfirmSettings``: 150 particles in
the grid, 300 by default). For each model: the chains' scatter (sd) of TMCMC's log
evidence, the scatter of the per-chain bridge estimates and their mean stated standard
error, the ratio of the two scatters, and the likelihood evaluations the bridge added over
TMCMC's (each chain's own bridge); and the estimates from pairs of chains pooled, as the
diagnosis makes them, with their stated errors. Run:
`.venv/bin/python benchmarks/bench_evidence.py` (or with --particles/--chains).
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from harvester.inference.map_fit import chain_problem
from harvester.diagnosis.name.confirm import bridge_evidence
from harvester.diagnosis.name.results import ConfirmSettings
from harvester.synthetic.measured import TABLE1_KNOWN, TANH_TABLE5, measured_recording
from harvester.inference.identify import identify
from harvester.inference.problems import make_problem
from harvester.inference.posterior import posterior_theta, log_evidence
from harvester.inference.priors import PriorSpec
from harvester.inference.priors import priors_for
from harvester.model.structures import structure

FS = 256.0
PRIORS = {"c_m": PriorSpec("c_m", 110.0, 50.0, "N s/m"), "F_c": PriorSpec("F_c", 10.0, 5.0, "N"),
          "beta": PriorSpec("beta", 100.0, 100.0, "s/m"),
          "sigma": PriorSpec("sigma", 0.02, 0.02, "m/s^2"),
          "F_coulomb": PriorSpec("F_coulomb", 0.0, 2.0, "N")}


def per_chain(problem, model: str, settings: ConfirmSettings) -> dict[str, float]:
    """TMCMC and per-chain bridge log evidences of one model."""
    p = chain_problem(problem, problem.temper, problem.lowpass_hz, problem.filter_order,
                      structure=structure(model) if "+" not in model else
                      structure("tanh").with_term(model.split("+")[1]))
    start = time.perf_counter()
    before = p.n_evaluations
    idata = identify(p, PRIORS, settings.tmcmc())
    tmcmc_evals = p.n_evaluations - before
    tmcmc_s = time.perf_counter() - start
    ev = log_evidence(idata)
    rows = np.split(posterior_theta(idata), len(ev))
    used = priors_for(p, PRIORS)
    start = time.perf_counter()
    before = p.n_evaluations
    bridges = [bridge_evidence(p, used, r, np.zeros(1), settings.seed + i)
               for i, r in enumerate(rows)]
    bridge_evals = p.n_evaluations - before
    bridge_s = time.perf_counter() - start
    b = np.array([x.log_evidence for x in bridges])
    # as the diagnosis estimates: two chains pooled, the error the larger of the formula's
    # and the two chains' scatter
    pairs = [bridge_evidence(p, used, np.vstack(rows[i:i + 2]), np.zeros(2), settings.seed + i)
             for i in range(0, len(rows) - 1, 2)]
    return {"tmcmc_sd": float(np.std(ev, ddof=1)), "tmcmc_range": float(np.ptp(ev)),
            "bridge_sd": float(np.std(b, ddof=1)), "bridge_range": float(np.ptp(b)),
            "bridge_stated_se": float(np.mean([x.se for x in bridges])),
            "tmcmc_mean": float(np.mean(ev)), "bridge_mean": float(np.mean(b)),
            "extra_evaluations": bridge_evals / tmcmc_evals, "extra_time": bridge_s / tmcmc_s,
            "pairs": [(x.log_evidence, x.se) for x in pairs]}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--particles", type=int, default=150)
    ap.add_argument("--chains", type=int, default=4)
    ap.add_argument("--seconds", type=float, default=12.0)
    args = ap.parse_args()
    rec, _ = measured_recording(("tanh_friction",), {**TABLE1_KNOWN, **TANH_TABLE5},
                                args.seconds + 1.5, 11)
    raw = make_problem(rec, "tanh", TABLE1_KNOWN, window=(256, len(rec) - 128))
    problem = chain_problem(raw, 0.083, 20.0, 8)
    settings = ConfirmSettings(particles=args.particles, chains=args.chains, seed=5)
    print(f"{args.seconds:g} s tanh record, {args.particles} particles x {args.chains} chains "
          "per model, tempering 0.083 (the medium grid's)")
    for model in ("tanh", "tanh+coulomb_friction"):
        r = per_chain(problem, model, settings)
        print(f"{model:24s} TMCMC chains: sd {r['tmcmc_sd']:.2f} (range {r['tmcmc_range']:.2f}, "
              f"mean {r['tmcmc_mean']:.2f}); bridge per chain: sd {r['bridge_sd']:.3f} (range "
              f"{r['bridge_range']:.3f}, mean {r['bridge_mean']:.2f}, stated se "
              f"{r['bridge_stated_se']:.3f})")
        print(f"{'':24s} two chains pooled, as the diagnosis does: " + ", ".join(
            f"{v:.2f} +- {e:.2f}" for v, e in r["pairs"]))
        print(f"{'':24s} scatter ratio TMCMC / bridge: {r['tmcmc_sd'] / r['bridge_sd']:.1f}x; "
              f"bridge cost: {r['extra_evaluations']:.3f}x TMCMC's evaluations, "
              f"{r['extra_time']:.3f}x its time")


if __name__ == "__main__":
    main()
