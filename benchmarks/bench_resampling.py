"""Benchmark: a 500 Hz recording low-passed at 25 Hz, simulated at its own rate and resampled
by a ratio (``signals.resampling_ratio``: no integer factor reaches 12.8 x 25 Hz).

One recording of a tanh device (the scenario generator, 40 s, 0.04 m/s^2 sensor noise), both
ways in this process: wall time of one batched likelihood call over a particle cloud, the
MAP estimate and its Laplace sd, and the ratios. Run:
`.venv/bin/python benchmarks/bench_resampling.py` (or with --particles/--repeats).
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from harvester.inference.map_fit import chain_problem, fit_map
from harvester.synthetic.measured import TABLE1_KNOWN, TANH_TABLE5, measured_recording
from harvester.inference.problems import make_problem
from harvester.inference.priors import PriorSpec
from harvester.data.signals import resample_recording, resampling_ratio

FS, CUTOFF, ORDER = 500.0, 25.0, 8
PRIORS = {"c_m": PriorSpec("c_m", 170.0, 50.0, "N s/m"), "F_c": PriorSpec("F_c", 8.4, 5.0, "N"),
          "beta": PriorSpec("beta", 100.0, 100.0, "s/m")}


def problem_at(rec, fs: float):
    lead = int(round(1.0 * fs))
    p = make_problem(rec, "tanh", TABLE1_KNOWN, window=(lead, len(rec) - int(0.5 * fs)))
    return chain_problem(p, 1.0, CUTOFF, ORDER)


def time_loglike(problem, cloud: np.ndarray, repeats: int) -> float:
    problem.loglike(cloud[:2])  # compile and warm the caches
    start = time.perf_counter()
    for _ in range(repeats):
        problem.loglike(cloud)
    return (time.perf_counter() - start) / repeats


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--particles", type=int, default=300)
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()
    truth = {**TABLE1_KNOWN, **TANH_TABLE5}
    rec, _ = measured_recording(("tanh_friction",), truth, 40.0, 5, fs=FS, lowpass_hz=CUTOFF,
                                filter_order=ORDER, peak_m_s2=4.0)
    up, down = resampling_ratio(FS, CUTOFF)
    fs_new = FS * up / down
    problems = {f"{FS:.0f} Hz": problem_at(rec, FS),
                f"{fs_new:.1f} Hz ({up}/{down})": problem_at(resample_recording(rec, up, down),
                                                            fs_new)}
    rng = np.random.default_rng(0)
    names = ("c_m", "F_c", "beta")
    centre = np.array([truth[n] for n in names])
    cloud = np.column_stack([centre * (1 + 0.05 * rng.standard_normal((args.particles, 3))),
                             np.full(args.particles, 0.05)])
    rows = {}
    for label, prob in problems.items():
        wall = time_loglike(prob, cloud, args.repeats)
        fit = fit_map(prob, PRIORS)
        rows[label] = (prob.n_data, wall, fit.theta[:3], np.sqrt(np.diag(fit.cov)))
    print(f"tanh device (c_m, F_c, beta = {', '.join(f'{v:g}' for v in centre)}), 40 s at "
          f"{FS:.0f} Hz low-passed at {CUTOFF:g} Hz; {args.particles} particles\n")
    print(f"{'model rate':<22}{'samples':>9}{'loglike (s)':>13}   MAP (Laplace sd)")
    for label, (n, wall, theta, sd) in rows.items():
        est = ", ".join(f"{t:.4g} ({s:.2g})" for t, s in zip(theta, sd))
        print(f"{label:<22}{n:>9d}{wall:>13.3f}   {est}")
    (_, w0, t0, s0), (_, w1, t1, _) = rows.values()
    print(f"\nspeed-up of a likelihood call, {FS:.0f} Hz / resampled: {w0 / w1:.2f}x")
    print("MAP difference, resampled - full rate, in Laplace sd: "
          + ", ".join(f"{n} {d:+.2f}" for n, d in zip(names, (t1 - t0) / s0)))


if __name__ == "__main__":
    main()
