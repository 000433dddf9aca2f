"""The periodic shape fitted as a term of the model (``diagnosis.size.shape_terms``) against the
name the library should give (issue 43): on records of the literature grid with a library
effect, how far the shape's gain stays below the named model's (a name it would withhold
wrongly), and on records of forms outside the library, whether it stands with the right
period.

Each record (``--records`` files with the generator's truth beside them, or the grid's
``--scenarios`` at ``--seeds``, made as ``bench_outside_library.make_record`` makes them) is
read as the diagnosis reads it (``diagnosis.prepare.analysis.model_input``, ``initial.recording``'s
priors with the grid's sigma prior), its tanh baseline fitted by MAP over the first 75 % less
half a second after a 1 s lead-in, tempered for correlated residuals
(``detect.estimate_temper``); then the first correct name's model by MAP (none for a form
outside the library) and the shape (``shape_term_fit``), both by Laplace evidence over the
baseline. The MAP stands in for the diagnosis's sampled baseline, so the gains are the
screen's, not the confirmation's. One row per record: scenario, its correct name, the named
model's gain, the shape's gain, its period and the truth's, whether it stands and whether it
beats the name.

    python benchmarks/bench_shape_terms.py [--records A.csv B.csv ...]
        [--scenarios duffing ... --seeds 0 1 --ratio 0.5 --out DIR]
"""

from __future__ import annotations

import argparse
import json
import logging
import tempfile
import time
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pandas as pd

from bench_outside_library import make_record
from harvester.data.signals import uniform_step
from harvester.diagnosis.prepare.analysis import model_input
from harvester.inference.map_fit import baseline_state, chain_problem, fit_map
from harvester.diagnosis.detect.scores import band_top, estimate_temper
from harvester.diagnosis.name.fits import candidate_priors
from harvester.diagnosis.size.shape_terms import shape_term_fit
from harvester.diagnosis.detect.signatures import motion_scale
from harvester.grid.information import REFIT_SIGMA
from harvester.inference.problems import make_problem
from harvester.initial.recording import recording_priors


def fitted(csv: Path) -> str:
    """One record's row (module docstring)."""
    clock = time.perf_counter()
    truth = json.loads(csv.with_suffix(".json").read_text())
    lit, known = truth["literature"], truth["known"]
    rec = pd.read_csv(csv)
    fs = 1.0 / uniform_step(rec["time"].to_numpy())
    f_high = band_top(fs, None)
    window = (int(round(fs)), int(0.75 * len(rec)) - int(round(0.5 * fs)))
    rec, _, _ = model_input(rec, None, fs, f_high, [])
    priors = recording_priors(rec, known, {"sigma": REFIT_SIGMA}, str(csv))

    def problem(name: str, temper: float):
        return chain_problem(make_problem(rec, name, known, window=window), temper, None)

    base = fit_map(problem("tanh", 1.0), priors, seed=0)
    temper = estimate_temper(base.residual, window, fs, f_high)
    plain = problem("tanh", temper)
    base = fit_map(plain, priors, seed=0, start=base.theta[:-1])
    state = baseline_state(plain, base.samples(40))
    scale = motion_scale(state, window, f_high)
    names = lit["correct_names"][:1]
    improved = None
    if names:
        specs = {**priors, **candidate_priors(names[0], scale)}
        named = problem(f"tanh+{names[0]}", temper)
        point = fit_map(named, specs, seed=0)
        improved = SimpleNamespace(problem=named, priors=specs, samples=point.samples(4),
                                   structure=named.structure)
    fit = shape_term_fit(plain, priors, base.samples(40), state.rel_disp[slice(*window)],
                         state.rel_vel[slice(*window)], scale, f_high, improved)
    period = (lit["effect"].get("parameters") or {}).get("period_m", float("nan"))
    named_gain = np.nan if fit is None or fit.named_gain_nats is None else fit.named_gain_nats
    gain = np.nan if fit is None else fit.gain_nats
    found = np.nan if fit is None else fit.parameters["period_m"]
    return (f"{csv.stem:30s} {(names or ['-'])[0]:20s} {named_gain:9.1f} {gain:9.1f} "
            f"{1e3 * found:10.4g} {1e3 * period:10.4g} "
            f"{'yes' if fit is not None and fit.stands else 'no':6s} "
            f"{'yes' if fit is not None and fit.beats_names else 'no':5s} "
            f"{time.perf_counter() - clock:6.0f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--records", nargs="+", type=Path, default=[])
    parser.add_argument("--scenarios", nargs="+", default=[])
    parser.add_argument("--seeds", nargs="+", type=int, default=[0, 1])
    parser.add_argument("--ratio", type=float, default=0.5)
    parser.add_argument("--out", type=Path, default=None, help="records (default: temp)")
    args = parser.parse_args()
    logging.getLogger("harvester").setLevel(logging.WARNING)
    out = args.out or Path(tempfile.mkdtemp(prefix="shape_terms_"))
    out.mkdir(parents=True, exist_ok=True)
    records = list(args.records)
    for seed in args.seeds if args.scenarios else []:
        for name in args.scenarios:
            csv = out / f"{name}_r{args.ratio:g}_s{seed}.csv"
            records.append(csv if csv.with_suffix(".json").is_file()
                           else make_record(name, seed, args.ratio, out)[0])
    print(f"{'record':30s} {'correct name':20s} {'named':>9s} {'shape':>9s} "
          f"{'period_mm':>10s} {'truth_mm':>10s} stands beats {'s':>6s}", flush=True)
    for csv in records:
        print(fitted(csv), flush=True)


if __name__ == "__main__":
    main()
