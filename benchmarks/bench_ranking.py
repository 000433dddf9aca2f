"""The detection's linearised ranking against each candidate's MAP, on grid records.

For each record (a grid scenario's CSV beside its JSON, as ``snakemake detection_all``
writes them) it prints, per candidate effect: the ranking's delta chi^2 (``diagnosis.name.rank``,
the signatures linearised at a small strength) and the gain of the candidate's posterior mode
over the baseline's best (``baseline.fit_map``: profiled sigma, the tempered objective
lambda n/2 log RSS, in nats; the baseline's MAP is also started from each candidate's values
of its parameters, since a candidate's fit can find a better baseline), with the MAP's added
parameters and cost. A ranking
that the MAP reverses is one where the linearisation misleads the choice of candidates.

    python benchmarks/bench_ranking.py results/detection/literature/scenarios/lugre/r0.5_s0.csv \
        --effects hysteresis,unmodelled_mode,inertia_error,cubic_stiffness
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from harvester.data.daq import read_recording
from harvester.data.fileio import read_json
from harvester.diagnosis.prepare.analysis import default_priors
from harvester.inference.map_fit import chain_problem, fit_map
from harvester.diagnosis.name.fits import candidate_priors
from harvester.diagnosis.name.rank import rank
from harvester.diagnosis.run import quick_detect
from harvester.diagnosis.prepare.settings import DiagnosisSettings
from harvester.diagnosis.detect.signatures import motion_scale
from harvester.model.structures import structure


def objective(problem, fit) -> float:
    """lambda n/2 log(n sigma^2) at a MAP, sigma its RMS residual over the problem's window
    through the measurement chain (nats, up to a constant)."""
    sigma = float(fit.theta[-1])
    return 0.5 * problem.temper * problem.n_data * float(np.log(problem.n_data * sigma**2))


def compare(csv: str, effects: tuple[str, ...], lead_in_s: float = 1.0) -> None:
    truth = read_json(csv.replace(".csv", ".json"))
    known, base = truth["known"], structure(truth["baseline"])
    settings = DiagnosisSettings(lead_in_s=lead_in_s, candidates=effects)
    det, state = quick_detect(read_recording(csv), base, known, settings=settings)
    problem = state.problem
    specs = default_priors(base, float(state.theta[-1]))
    mp = fit_map(problem, specs, seed=0)
    scale = motion_scale(state, problem.window, det.frame.f_high)
    fits = []
    for r in rank(det, state, specs):
        clock = time.perf_counter()
        cand = chain_problem(problem, problem.temper, problem.lowpass_hz, problem.filter_order,
                             structure=structure(f"{base.name}+{r.effect}"))
        fit = fit_map(cand, {**specs, **candidate_priors(r.effect, scale, known)}, seed=0)
        fits.append((r, cand, fit, time.perf_counter() - clock))
    best = _best_baseline(problem, specs, mp, [f for _, _, f, _ in fits])
    print(f"== {csv}: {truth.get('effect')} (detection p = {det.p_value:.3g}; the baseline's "
          f"MAP from its own starts is {objective(problem, mp) - best:.1f} nats short of its "
          "best from the candidates' starts)")
    for r, cand, fit, seconds in fits:
        added = {n: float(f"{v:.4g}") for n, v in zip(fit.names, fit.theta[:-1])
                 if n not in mp.names}
        print(f"  {r.score.label:58s} delta chi2 {r.delta_chi2:7.1f}  MAP gain "
              f"{best - objective(cand, fit):8.1f}  ({fit.n_simulations} simulations, "
              f"{seconds:.1f} s) {added}")


def _best_baseline(problem, specs, mp, fits) -> float:
    """The baseline's lowest objective: its MAP, and its MAP started from each candidate's
    values of the baseline's parameters (a candidate's fit can find a better baseline)."""
    values = [objective(problem, mp)]
    for fit in fits:
        start = np.array([dict(zip(fit.names, fit.theta))[n] for n in mp.names])
        values.append(objective(problem, fit_map(problem, specs, seed=0, start=start)))
    return min(values)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("records", nargs="+")
    parser.add_argument("--effects", default="hysteresis,unmodelled_mode,inertia_error,"
                                              "cubic_stiffness")
    args = parser.parse_args()
    for csv in args.records:
        compare(csv, tuple(args.effects.split(",")))


if __name__ == "__main__":
    main()
