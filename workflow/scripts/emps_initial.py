"""Rule emps_initial: priors of M and Fv from the instrumented FRF fit, the rest from config."""

from dataclasses import asdict

import pandas as pd

from harvester import emps
from harvester.emps.figures import frf_figure
from harvester.data.fileio import atomic_path, write_json
from harvester.initial.frf import fit_linear_frf, frf_prior_specs
from harvester.inference.priors import prior_moments
from harvester.runlog import rule_log

with rule_log(snakemake) as log:  # noqa: F821
    sm = snakemake  # noqa: F821
    rec = emps.load_emps(sm.input.training)
    band = tuple(sm.params.frf["band_hz"])
    fit = fit_linear_frf(emps.to_recording(rec), emps.KNOWN, band, sm.params.frf["segment_s"],
                         reference="qg", source=sm.input.training)
    specs = frf_prior_specs(fit, emps.FREE_BASE, sm.params.frf["rel_sd"])
    specs.update(prior_moments(sm.params.priors, {}))
    log.info("FRF fit (k = 0 held): %s, residual %.3g", fit.values, fit.residual)
    # the temper of eq. (10): 1 / tau of the baseline's least-squares residual (kept for all models)
    baseline = emps.closed_loop_problem(rec, emps.BASELINE_TERMS, stride=sm.params.stride)
    values, residual = emps.closed_loop_fit(baseline, {n: s.mean for n, s in specs.items()})
    auto, tau = emps.temper_from(residual, sm.params.stride)
    temper = auto if sm.params.temper == "auto" else float(sm.params.temper)
    log.info("baseline least squares %s: RMS residual %.3g um, tau %.3g samples at stride %d, "
             "temper %.4g", values, 1e6 * residual.std(), tau, sm.params.stride, temper)
    write_json({"frf": fit.summary(), "known": emps.KNOWN, "temper": temper,
                "baseline_fit": {"values": values, "rms_residual_m": float(residual.std()),
                                 "tau_samples": tau, "stride": sm.params.stride},
                "priors": {n: asdict(s) for n, s in specs.items()}}, sm.output.priors)
    table = pd.DataFrame([{**asdict(s), "source": "FRF fit" if n in emps.FREE_BASE else "config"}
                          for n, s in specs.items()])
    with atomic_path(sm.output.table) as tmp:
        table.to_csv(tmp, index=False, float_format="%.6g")
    frf_figure(fit.freqs_hz, fit.h_measured, fit.h_model, fit.coherence, band, sm.output.figure,
               f"Initial modelling: M = {fit.values['M']:.1f} kg, c = {fit.values['c_m']:.0f} "
               "N s/m (k = 0)")
