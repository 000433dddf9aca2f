"""Detection and location alone, with the baseline's MAP and Laplace posterior instead of
TMCMC (seconds, not minutes): the first step of a diagnosis, for screening many recordings."""

from __future__ import annotations

from collections.abc import Mapping

import pandas as pd

from harvester.diagnosis.detect.scores import Detection, band_top, detect, estimate_temper
from harvester.diagnosis.detect.signatures import candidate_terms
from harvester.diagnosis.detect.spectral import recording_lowpass
from harvester.diagnosis.prepare.analysis import (check_recording, default_priors, model_input,
                                                  model_kinds, resample_for_model)
from harvester.diagnosis.prepare.settings import DiagnosisSettings
from harvester.inference.map_fit import BaselineState, baseline_state, chain_problem, fit_map
from harvester.inference.priors import PriorSpec
from harvester.inference.problems import make_problem
from harvester.model.structures import ModelStructure
from harvester.model.structures import structure as named_structure


def quick_detect(recording: pd.DataFrame, baseline: str | ModelStructure,
                 known: Mapping[str, float], priors: Mapping[str, PriorSpec] | None = None,
                 settings: DiagnosisSettings = DiagnosisSettings(), temper: float | None = None
                 ) -> tuple[Detection, BaselineState]:
    """Detection and location only, with the baseline's MAP and Laplace posterior instead of
    TMCMC (seconds, not minutes): the first step of :func:`diagnose` for screening many
    recordings. The whole recording after the lead-in is analysed (nothing held out)."""
    rec, dt = check_recording(recording, "<recording>", settings.lead_in_s, 0.0)
    base = named_structure(baseline) if isinstance(baseline, str) else baseline
    lowpass, _ = recording_lowpass(settings.lowpass_hz, rec.iloc[:, 1].to_numpy(),
                                   rec.iloc[:, 2].to_numpy(), 1.0 / dt)
    rec, _ = model_kinds(rec, None, lowpass, "<recording>", [])
    rec, _, dt, _ = resample_for_model(rec, None, dt, lowpass)
    fs = 1.0 / dt
    if settings.denoise_input:
        rec, _, _ = model_input(rec, None, fs, band_top(fs, lowpass), [])
    lead = int(round(settings.lead_in_s * fs))
    raw = make_problem(rec, base, known, window=(lead, len(rec)))
    if temper is None:
        mp = fit_map(chain_problem(raw, 1.0, lowpass, settings.filter_order), priors or {},
                     seed=settings.seed)
        temper = estimate_temper(mp.residual, raw.window, fs, band_top(fs, lowpass))
    problem = chain_problem(raw, temper, lowpass, settings.filter_order)
    mp = fit_map(problem, priors or {}, seed=settings.seed)
    specs = {**default_priors(base, float(mp.theta[-1]), problem.output_type.unit),
             **(priors or {})}
    state = baseline_state(problem, mp.samples(200, settings.seed))
    det = detect(state, problem.window, specs, candidate_terms(base.terms, settings.candidates),
                 settings.detection(), time=rec["time"].to_numpy())
    return det, state
