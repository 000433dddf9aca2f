"""Benchmark: a candidate's TMCMC tempered from the prior against tempered from its reference
(``confirm.candidate_reference``: the nested model's posterior and the detection's scan).

The record is the medium detection grid's secondary-mode scenario, seed 0 (``harvester.
scenarios``: a rotor on a flexible coupling at 6.57 Hz, contribution half the noise RMS, 30 s),
diagnosed as the grid does (fast settings: 150 particles, 15 s fitted). The tanh baseline is
sampled once; the candidate tanh + unmodelled_mode is then sampled ``--repeats`` times from
each start (2 chains each, as the diagnosis does). Printed per run: the candidate's log
evidence gain over the baseline (bridge sampling), TMCMC's chain estimates, the f_mode
posterior, stages, likelihood evaluations and wall time; then, over the runs, how often the
mode was found (f_mode within 0.3 Hz of the truth) and the ratios of evaluations and time.
Run: `.venv/bin/python benchmarks/bench_reference.py` (about 10 minutes on 2 cores).
"""

from __future__ import annotations

import argparse
import logging
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import yaml

from harvester.grid.scoring import SIGMA_PRIOR
from harvester.inference.map_fit import baseline_state, chain_problem, fit_map
from harvester.diagnosis.name.confirm import confirm, fit_structure
from harvester.diagnosis.name.results import ConfirmSettings
from harvester.diagnosis.detect.scores import DetectionSettings, detect, estimate_temper
from harvester.diagnosis.run import default_priors
from harvester.diagnosis.detect.signatures import motion_scale
from harvester.inference.problems import make_problem
from harvester.inference.priors import PriorSpec
from harvester.synthetic.scenarios import ScenarioSettings, make_scenario
from harvester.model.structures import structure

EFFECT = "unmodelled_mode"
ROOT = Path(__file__).resolve().parents[1]


def record():
    """The medium grid's scenario, made as its rule makes it (config rig, preprocess,
    detection)."""
    cfg = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
    det = cfg["detection"]
    settings = ScenarioSettings.from_config(
        cfg, duration_s=float(det["grids"]["medium"]["duration_s"]),
        lead_in_s=float(det["lead_in_s"]), seed=int(det["seed"]))
    sc = make_scenario(EFFECT, 0.5, 0, settings, rig_cfg=cfg["rig"], masking=False)
    return sc.recording, sc.truth


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--particles", type=int, default=150)
    args = ap.parse_args()
    logging.getLogger("pymc").setLevel(logging.ERROR)
    rec, truth = record()
    f_true = truth["shape"]["f_mode"]
    fs = 256.0
    lead, stop = 256, 256 + int(15 * fs)
    raw = make_problem(rec, "tanh", truth["known"], window=(lead, stop))
    priors = {"sigma": PriorSpec(name="sigma", **SIGMA_PRIOR)}
    mp = fit_map(chain_problem(raw, 1.0, 20.0, 8), priors)
    temper = estimate_temper(mp.residual, (lead, stop), fs, 18.0)
    problem = chain_problem(raw, temper, 20.0, 8)
    base_structure = structure("tanh")
    specs = {**default_priors(base_structure, float(mp.theta[-1])), **priors}
    cs = ConfirmSettings(particles=args.particles, chains=2, seed=0)
    base = fit_structure(problem, base_structure, specs, cs)
    state = baseline_state(problem, base.samples)
    det = detect(state, (lead, stop), specs, [EFFECT], DetectionSettings(bootstrap=100))
    scale = motion_scale(state, (lead, stop), det.frame.f_high)
    print(f"mode at {f_true:.2f} Hz, half the noise RMS; baseline log evidence "
          f"{base.log_evidence:.2f} +- {base.log_evidence_se:.2f}; {args.particles} particles "
          f"x 2 chains per run (the candidate's: x2)")
    found, evals, secs = {}, {}, {}
    for start, use in (("prior", False), ("reference", True)):
        found[start], evals[start], secs[start] = [], [], []
        for k in range(args.repeats):
            clock = time.perf_counter()
            (res,) = confirm(base, [EFFECT], specs, replace(cs, reference=use), scale,
                             seed_offset=1000 + 17 * k, detection=det)
            secs[start].append(time.perf_counter() - clock)
            stats = res.fit.idata.sample_stats
            evals[start].append(int(stats["n_evals_total"].sum()))
            post = res.fit.summary()["f_mode"]
            found[start].append(abs(post["mean"] - f_true) < 0.3 and post["sd"] < 0.3)
            print(f"{start:9s} run {k}: gain {res.delta_log_evidence:+7.2f} +- {res.delta_se:.2f}"
                  f" nats; TMCMC chains " + ", ".join(f"{v:.2f}" for v in
                                                     res.fit.log_evidence_chains)
                  + f"; f_mode {post['mean']:.2f} +- {post['sd']:.2f} Hz; stages "
                  f"{int(stats['n_stages'].max())}, {evals[start][-1]} evaluations, "
                  f"{secs[start][-1]:.0f} s")
    print(f"mode found: from the prior {sum(found['prior'])}/{args.repeats}, from the "
          f"reference {sum(found['reference'])}/{args.repeats}")
    print(f"reference / prior: likelihood evaluations "
          f"{np.mean(evals['reference']) / np.mean(evals['prior']):.2f}x, time "
          f"{np.mean(secs['reference']) / np.mean(secs['prior']):.2f}x")


if __name__ == "__main__":
    main()
