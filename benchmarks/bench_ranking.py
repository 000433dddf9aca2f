"""The detection's linearised ranking against each candidate's MAP, on grid records.

For each record (a grid scenario's CSV beside its JSON, as ``snakemake detection_all``
writes them) it prints, per candidate effect: the ranking's delta chi^2 (``diagnosis.rank``,
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
from harvester.diagnosis.analysis import check_recording, default_priors, resample_for_model
from harvester.diagnosis.baseline import baseline_state, chain_problem, fit_map
from harvester.diagnosis.confirm import candidate_priors
from harvester.diagnosis.detect import detect, estimate_temper
from harvester.diagnosis.rank import rank
from harvester.diagnosis.settings import DiagnosisSettings
from harvester.diagnosis.signatures import candidate_terms, motion_scale
from harvester.diagnosis.spectral import filter_cutoff
from harvester.inference.problems import make_problem
from harvester.model.structures import structure


def objective(problem, fit) -> float:
    """lambda n/2 log(n sigma^2) at a MAP, sigma its RMS residual over the problem's window
    through the measurement chain (nats, up to a constant)."""
    sigma = float(fit.theta[-1])
    return 0.5 * problem.temper * problem.n_data * float(np.log(problem.n_data * sigma**2))


def compare(csv: str, effects: tuple[str, ...], lead_in_s: float = 1.0) -> None:
    truth = read_json(csv.replace(".csv", ".json"))
    known, base = truth["known"], structure(truth["baseline"])
    rec, dt = check_recording(read_recording(csv), csv, lead_in_s, 0.0)
    lowpass = filter_cutoff(rec["rel_acc"].to_numpy(), 1.0 / dt)
    rec, _, dt, _ = resample_for_model(rec, None, dt, lowpass)
    lead = int(round(lead_in_s / dt))

    def problem_of(struct, temper):
        raw = make_problem(rec, struct, known, window=(lead, len(rec)))
        return chain_problem(raw, temper, lowpass, 8)

    first = fit_map(problem_of(base, 1.0), {}, seed=0)
    temper = estimate_temper(first.residual, (lead, len(rec)), 1.0 / dt,
                             0.9 * (lowpass or 0.5 / dt))
    problem = problem_of(base, temper)
    specs = default_priors(base, float(first.theta[-1]))
    mp = fit_map(problem, specs, seed=0)
    state = baseline_state(problem, mp.samples(200, 0))
    settings = DiagnosisSettings(lead_in_s=lead_in_s, candidates=effects)
    det = detect(state, problem.window, specs, candidate_terms(base.terms, effects),
                 settings.detection(), time=rec["time"].to_numpy())
    scale = motion_scale(state, problem.window, det.frame.f_high)
    fits = []
    for r in rank(det, state, specs):
        clock = time.perf_counter()
        cand = problem_of(structure(f"{base.name}+{r.effect}"), temper)
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
