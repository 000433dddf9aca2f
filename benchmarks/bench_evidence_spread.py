"""The spread of a candidate model's log evidence over independent chains, at the diagnosis's
default settings, on candidates with hard posteriors.

For each effect (a secondary mode: a narrow peak in frequency; an end stop: a kink at the
clearance) a 40 s recording of the concealed-effect generator (``harvester.synthetic.
scenarios``) at a contribution of ``--ratio`` x the noise RMS is prepared as the diagnosis
prepares it (the baseline's MAP, tempering, posterior and detection over the analysed window),
and the candidate (baseline + effect) is sampled by ``confirm.candidate_fit`` with the
diagnosis's default ConfirmSettings but ``--chains`` chains and no re-runs. Printed per effect:
each chain's log evidence and stated standard error, their standard deviation (goal: below 0.5
nats), the median stated error, and the wall time; then the same for the estimate the
diagnosis decides on, bridge sampling from each chain's final population
(``harvester.inference.evidence.chains_bridge_log_evidence``), and the pooled bridge estimate
with its stated error.

Run: ``python benchmarks/bench_evidence_spread.py`` (``make benchmark``; about 10 minutes per
effect on 2 cores).
"""

from __future__ import annotations

import argparse
import logging
import time
from dataclasses import replace

import numpy as np

from harvester.inference.map_fit import baseline_state, chain_problem, fit_map
from harvester.diagnosis.name.confirm import candidate_fit, fit_structure
from harvester.diagnosis.detect.scores import detect, estimate_temper
from harvester.diagnosis.run import DiagnosisSettings, default_priors, velocity_bound
from harvester.diagnosis.detect.signatures import candidate_terms, motion_scale
from harvester.diagnosis.detect.spectral import filter_cutoff
from harvester.inference.problems import make_problem
from harvester.synthetic.scenarios import ScenarioSettings, make_scenario


def prepared(effect: str, ratio: float, seed: int, settings: DiagnosisSettings):
    """(baseline fit, detection, motion scale, priors) as ``diagnose`` has them in round 1."""
    scen = make_scenario(effect, ratio, seed, ScenarioSettings(duration_s=40.0), masking=False)
    rec, fs = scen.recording, 256.0
    known = {k: scen.truth["device"][k] for k in ("M", "m", "k")}
    lowpass = filter_cutoff(rec["rel_acc"].to_numpy(), fs)
    lead, end = int(settings.lead_in_s * fs), len(rec) - int(0.5 * fs)
    hold = lead + int(round((end - lead) * (1.0 - settings.holdout_fraction)))
    raw = make_problem(rec, scen.truth["baseline"], known, window=(lead, hold))
    mp = fit_map(chain_problem(raw, 1.0, lowpass, 8), {}, seed=0)
    raw.v_bound = velocity_bound(raw, mp.theta)
    specs = default_priors(raw.structure, float(mp.theta[-1]))
    temper = estimate_temper(mp.residual, (lead, hold), fs, 0.9 * lowpass)
    problem = chain_problem(raw, temper, lowpass, 8)
    cs = settings.confirmation()
    base = fit_structure(problem, raw.structure, specs, cs)
    state = baseline_state(problem, base.samples)
    det = detect(state, (lead, hold), specs, candidate_terms(raw.structure.terms),
                 settings.detection(), time=rec["time"].to_numpy())
    return base, det, motion_scale(state, (lead, hold), det.frame.f_high), specs


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--effects", nargs="+", default=["unmodelled_mode", "end_stop"])
    ap.add_argument("--chains", type=int, default=8)
    ap.add_argument("--ratio", type=float, default=1.0)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    logging.getLogger("pymc").setLevel(logging.ERROR)
    settings = DiagnosisSettings(seed=args.seed)
    for effect in args.effects:
        base, det, scale, specs = prepared(effect, args.ratio, args.seed, settings)
        cs = replace(settings.confirmation(), chains=args.chains, enlargements=0)
        start = time.perf_counter()
        fit = candidate_fit(base, effect, specs, cs, scale, det, seed_offset=101)
        wall = time.perf_counter() - start
        ev, se = fit.log_evidence_chains, np.array(fit.stated_se_chains)
        print(f"{fit.structure.name}: {args.chains} chains of "
              f"{fit.idata.posterior.sizes['draw']} particles, {wall:.0f} s")
        print("  log evidence per chain: " + " ".join(f"{e:.2f}" for e in ev))
        print("  stated se per chain:    " + " ".join(f"{s:.2f}" for s in se))
        print(f"  sd over chains {np.std(ev, ddof=1):.3f} nats (goal below 0.5), median stated "
              f"se {np.median(se):.3f}, baseline {base.log_evidence:.2f}, gain "
              f"{fit.tmcmc_log_evidence - base.tmcmc_log_evidence:+.2f} nats")
        if fit.bridge is not None:
            own = np.asarray(fit.bridge.chain_log_evidence)
            print("  bridge per chain:       " + " ".join(f"{e:.2f}" for e in own))
            print(f"  bridge sd over chains {np.std(own, ddof=1):.3f} nats; pooled "
                  f"{fit.bridge.log_evidence:.2f} +- {fit.bridge.se:.2f} (formula "
                  f"{fit.bridge.formula_se:.2f}); {len(own)} of {args.chains} chains kept")


if __name__ == "__main__":
    main()
