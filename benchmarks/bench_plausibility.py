"""The device a mass error implies on literature records, against their sidecars (issue 63).

For each record ``NAME:SEED:RATIO[:K_SCALE]`` of the literature generator
(``harvester.synthetic.literature.generate(NAME, SEED, ratio=RATIO)``, its sidecar's k scaled
by K_SCALE: a spring mis-stated), tanh + inertia_error is fitted by MAP to its first
``--seconds`` after the 1 s lead-in (the diagnosis's likelihood without its low-pass or
tempering, Laplace draws), and the effective and oscillating masses it implies are held
against the sidecar's (``diagnosis.name.plausibility``: the default uncertainty, the 3 sd bar).
One block per record: the fitted dM, the true masses, each implied mass's sentence and z.

    python benchmarks/bench_plausibility.py secondary_mode:0:3 none:0:1:2.0 ...
        [--seconds 12]

About 20-60 s per record on 2 shared cores (the first compiles the structure).
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from harvester.diagnosis.prepare.analysis import default_priors
from harvester.inference.map_fit import chain_problem, fit_map
from harvester.diagnosis.name.plausibility import implied_device, measured_device
from harvester.inference.problems import make_problem
from harvester.model.structures import structure
from harvester.synthetic.literature import generate


def implied(name: str, seed: int, ratio: float, k_scale: float, seconds: float) -> None:
    """Fit one record and print what its mass error implies."""
    clock = time.perf_counter()
    g = generate(name, seed=seed, ratio=ratio)
    known = {**g.sidecar, "k": k_scale * g.sidecar["k"]}
    rec = g.recording
    fs = 1.0 / float(rec.time[1] - rec.time[0])
    rec = rec.iloc[:int((1.0 + seconds) * fs)].reset_index(drop=True)
    s = structure("tanh+inertia_error")
    problem = chain_problem(make_problem(rec, s, known, window=(int(fs), len(rec))), 1.0,
                            None, 8)
    priors = {k: v for k, v in default_priors(s, 1.0).items() if k != "sigma"}
    mp = fit_map(problem, priors, n_starts=16)
    dM = mp.theta[list(s.free_parameters).index("dM")]
    print(f"{name} seed {seed} ratio {ratio:g} k x {k_scale:g}: dM {dM:.4g} kg; sidecar M "
          f"{known['M']:.4g}, m {known['m']:.4g}; true {g.truth.get('true_masses')} "
          f"({time.perf_counter() - clock:.1f} s)", flush=True)
    for d in implied_device("inertia_error", s, mp.samples(200), known, measured_device(known)):
        print(f"    z {d.z:.2f}: {d.sentence()}", flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("records", nargs="+", help="NAME:SEED:RATIO[:K_SCALE]")
    ap.add_argument("--seconds", type=float, default=12.0)
    args = ap.parse_args()
    for spec in args.records:
        name, seed, ratio, *k = spec.split(":")
        implied(name, int(seed), float(ratio), float(k[0]) if k else 1.0, args.seconds)


if __name__ == "__main__":
    np.seterr(all="ignore")
    main()
