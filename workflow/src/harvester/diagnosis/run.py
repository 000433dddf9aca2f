"""The diagnosis of one recording: detect, locate, name and confirm missing physics.

:func:`diagnose` reads as the algorithm: prepare the recording (``analysis.prepare``), start
from the baseline's posterior (``analysis.start_baseline``), add effects in rounds of detect
-> rank -> confirm (``rounds.run_rounds``), conclude what is missing and what cannot be told
apart (``verdict.conclude``), and compare the baseline and the improved model on unseen data.
``diagnose_study`` does the same for the study's training window and writes diagnosis.json
and figures; ``quick_detect`` is the detection alone, for screening.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path

import arviz as az
import numpy as np
import pandas as pd

from harvester.data.signals import uniform_step
from harvester.diagnosis.analysis import (Analysis, BaselineStart, check_recording,
                                          default_priors, model_input, model_kinds, prepare,
                                          resample_for_model,
                                          start_baseline, velocity_bound)
from harvester.diagnosis.baseline import BaselineState, baseline_state, chain_problem, fit_map
from harvester.diagnosis.fits import ModelFit
from harvester.diagnosis.detect import Detection, band_top, detect, estimate_temper
from harvester.diagnosis.report import UnseenFit, unseen_fit
from harvester.diagnosis.rounds import Round, run_rounds
from harvester.diagnosis.settings import DiagnosisSettings
from harvester.diagnosis.signatures import candidate_terms, motion_scale
from harvester.diagnosis.spectral import recording_lowpass
from harvester.diagnosis.floor import Floor, output_floor
from harvester.diagnosis.missing_force import MissingForce, NamedEffect, missing_force
from harvester.diagnosis.shape_terms import ShapeTermFit, shape_term_fit
from harvester.diagnosis.relevance import RelevanceFloor
from harvester.diagnosis.verdict import (Conclusion, FitJudgement, Tie, conclude,
                                          decide_verdict, judge, nominated_terms)
from harvester.inference.problems import make_problem
from harvester.inference.priors import PriorSpec
from harvester.model.structures import ModelStructure
from harvester.model.structures import structure as named_structure
from harvester.model.terms import term

__all__ = ["Diagnosis", "DiagnosisSettings", "check_recording", "decide_verdict",
           "default_priors", "diagnose", "diagnose_study", "quick_detect",
           "resample_for_model", "velocity_bound", "write"]

log = logging.getLogger("harvester.diagnosis")


def mass_size_caveat(analysis: Analysis, diag: "Diagnosis") -> str | None:
    """Where an effect of the masses is named or tied on a record whose output holds the
    input sensor's noise (``analysis.shared_input_noise``): that its size is not fixed by the
    record (errors in variables: on six of the literature grid's mass-error records its dM
    lay 0.6-2.4 posterior sds from the truth and its force interval missed it on the two
    1.9-2.4 sd away; made again without the shared noise, 0.2-0.8 sd, every interval held
    it, docs/measurements.md)."""
    names = list(diag.missing) + [e for t in diag.ties for e in t.effects]
    mass = sorted({n for n in names if term(n).kind == "inertia"})
    if analysis.shared_input_noise is None or not mass:
        return None
    return (f"{', '.join(mass)}: the record does not fix its size; its output holds the "
            "input sensor's noise, which biases a mass error's dM and m_share (errors in "
            "variables: on six of the literature grid's mass-error records dM lay up to 2.4 "
            "posterior sds from the truth, docs/measurements.md); a relative sensor, or an "
            "output sensor independent of the input's, would fix it")


@dataclass
class Diagnosis:
    """Result of :func:`diagnose` (``to_dict`` gives diagnosis.json). ``missing``: the
    effects named, each alone; ``ties``: effects the recording cannot tell apart."""

    verdict: str
    missing: list[str]
    ties: list[Tie]
    unexplained: bool
    baseline: ModelStructure
    improved: ModelStructure
    rounds: list[Round]
    baseline_fit: ModelFit | None
    improved_fit: ModelFit | None
    baseline_log_evidence: float
    baseline_evidence_source: str
    unseen_before: UnseenFit | None
    unseen_after: UnseenFit | None
    temper: float
    lowpass_hz: float | None
    likelihood_lowpass_hz: float | None
    window_s: tuple[float, float]
    fit_window_s: tuple[float, float]
    settings: DiagnosisSettings
    priors: dict[str, PriorSpec]
    seconds: float
    time: np.ndarray = field(repr=False)
    notes: list[str] = field(default_factory=list)
    figure_files: list[str] = field(default_factory=list)
    headline: str = ""
    fit_judgement: FitJudgement | None = None
    missing_force: MissingForce | None = None
    withheld: list[str] = field(default_factory=list)

    @property
    def indistinguishable(self) -> list[list[str]]:
        """The ties' effects (one list per tie)."""
        return [t.effects for t in self.ties]

    def to_dict(self) -> dict:
        from harvester.diagnosis.report import diagnosis_dict
        return diagnosis_dict(self)


def diagnose(recording: pd.DataFrame, baseline: str | ModelStructure,
             known: Mapping[str, float], priors: Mapping[str, PriorSpec] | None = None, *,
             posterior: az.InferenceData | None = None,
             validation: pd.DataFrame | None = None,
             settings: DiagnosisSettings = DiagnosisSettings(),
             out_dir: str | Path | None = None, source: str = "<recording>") -> Diagnosis:
    """Diagnose ``recording`` against ``baseline``; write diagnosis.json and figures to
    ``out_dir`` if given.

    ``known``: values of the layout parameters not identified (M, m, k); ``priors``: priors of
    the identified ones (missing ones: the library's; sigma's: scaled to the residual);
    ``posterior``: the baseline's posterior (InferenceData from ``identify``) to diagnose; when
    None the baseline is sampled here. ``validation``: an unseen record (same format) for the
    before/after comparison; without it the recording's last ``holdout_fraction`` is held out.
    """
    clock = time.perf_counter()
    analysis = prepare(recording, validation, baseline, known, settings, source)
    start = start_baseline(analysis, priors, posterior, settings)
    passes = _pass(analysis, start, settings)
    nominated = nominated_terms(passes.found, passes.missing, candidate_terms(
        analysis.structure.terms, settings.candidates))
    if nominated:
        best = passes.missing.description.determined[0]
        log.info("the missing force is %s (%.0f sd out): the library's %s, of that shape, "
                 "not tried; the rounds again with %s screened", best.name, best.standing_sd,
                 ", ".join(nominated), "it" if len(nominated) == 1 else "them")
        passes = _pass(analysis, start, settings, tuple(nominated))
        passes.notes.append(f"{', '.join(nominated)} screened because the missing force is "
                            f"{best.name} ({best.standing_sd:.0f} sd out), though the "
                            "detection's scores did not point to "
                            f"{'it' if len(nominated) == 1 else 'them'}")
    rounds, found = passes.rounds, passes.found
    found = judge(found, rounds[0].detection, passes.fit, analysis.structure.name, settings,
                  passes.missing)
    missing = passes.missing
    diag = _diagnosis(analysis, start, rounds, passes.baseline_fit, found, passes.unseen,
                      settings, analysis.notes + passes.notes + found.notes + passes.more,
                      time.perf_counter() - clock)
    diag.missing_force = missing
    caveat = mass_size_caveat(analysis, diag)
    if caveat:
        log.info("%s", caveat)
        diag.notes.append(caveat)
    log.info("verdict: %s%s (%.0f s)", diag.headline,
             "".join(f"; cannot tell apart {' / '.join(t.effects)}" for t in diag.ties),
             diag.seconds)
    if out_dir is not None:
        write(diag, out_dir)
    return diag


@dataclass
class _Pass:
    """The rounds and what is read from them before the verdict: their conclusion, the fit
    on unseen data, its judgement, the missing force; notes of the rounds and of the rest."""

    rounds: list
    baseline_fit: ModelFit | None
    found: Conclusion
    unseen: tuple
    fit: FitJudgement
    missing: MissingForce | None
    notes: list[str]
    more: list[str]


def _pass(analysis: Analysis, start: BaselineStart, settings: DiagnosisSettings,
          nominated: tuple[str, ...] = ()) -> _Pass:
    """The rounds (``nominated`` effects screened in the first), their conclusion, the fit on
    unseen data and the missing force."""
    rounds, baseline_fit, unexplained, notes = run_rounds(analysis, start, settings, nominated)
    found = conclude(rounds, unexplained, settings, analysis.f_high)
    before, after, more = unseen_comparison(analysis, start, found.improved_fit, settings)
    fit = fit_judgement(start, rounds[0], before, after)
    missing, missing_notes = estimate_missing_force(analysis, rounds[0].state, found, settings,
                                                    fit.floor, start)
    return _Pass(rounds, baseline_fit, found, (before, after), fit, missing, notes,
                 more + missing_notes)


def _diagnosis(a: Analysis, start: BaselineStart, rounds: list[Round],
               baseline_fit: ModelFit | None, found: Conclusion, unseen: tuple,
               settings: DiagnosisSettings, notes: list[str], seconds: float) -> Diagnosis:
    t = a.time
    improved = found.improved_fit.structure if found.improved_fit else a.structure
    return Diagnosis(
        verdict=found.verdict, missing=found.missing, ties=found.ties,
        unexplained=found.unexplained, baseline=a.structure, improved=improved, rounds=rounds,
        baseline_fit=baseline_fit, improved_fit=found.improved_fit,
        baseline_log_evidence=(baseline_fit.log_evidence if baseline_fit
                               else start.log_evidence),
        baseline_evidence_source="diagnosis" if baseline_fit else start.evidence_source,
        unseen_before=unseen[0], unseen_after=unseen[1], temper=start.temper,
        lowpass_hz=a.lowpass, likelihood_lowpass_hz=start.detection_problem.band_hz,
        window_s=(float(t[a.lead]), float(t[a.hold - 1])),
        fit_window_s=(float(t[a.lead]), float(t[a.fit_stop - 1])), settings=settings,
        priors=start.priors, seconds=seconds, time=t, notes=notes, headline=found.headline,
        fit_judgement=found.fit, withheld=found.withheld)


def fit_judgement(start: BaselineStart, first: Round, before: UnseenFit | None,
                  after: UnseenFit | None) -> FitJudgement:
    """The baseline's share of the unseen output explained (1 - NRMSE^2), the improved
    model's, and the baseline's residual over the analysed window against the recording's own
    noise floor in the likelihood's band (``floor.output_floor``)."""
    p = start.detection_problem
    found = output_floor(p.base_acc, p.rel_acc, p.measured_chain, p.window, 1.0 / p.dt,
                         p.band_hz)
    share = None if before is None else 1.0 - before.nrmse ** 2
    improved = None if after is None else 1.0 - after.nrmse ** 2
    return FitJudgement(share, None if before is None else before.nrmse,
                        None if before is None else before.data, first.detection.sigma, found,
                        improved)


def estimate_missing_force(a: Analysis, state: BaselineState, found: Conclusion,
                           settings: DiagnosisSettings, floor: Floor | None = None,
                           start: BaselineStart | None = None
                           ) -> tuple[MissingForce | None, list[str]]:
    """The baseline's missing force (``missing_force``) over the analysed window, with each
    effect the improved model added beside it and its size on the unseen input (the validation
    record's or the held-out tail's); None with a note where it cannot be estimated. On a
    record that fixes the slow motion (a displacement) the smoother's noise is the
    recording's own ``floor`` where it shows one (``floor.py``; at most the baseline's
    sigma), so that what the baseline leaves beyond the noise is force (``latent``). With the
    baseline's ``start``, the dictionary's periodic shape is also fitted as a term of the
    model (``shape_terms``), against the baseline and the improved model."""
    if not settings.missing_force:
        return None, []
    named = named_effects(a.structure, found)
    rec, window = ((a.validation, slice(int(round(settings.lead_in_s / a.dt)), None))
                   if a.validation is not None else (a.recording, slice(a.hold, a.end)))
    clock = time.perf_counter()
    try:
        out = missing_force(state, (a.lead, a.hold), named, rec.iloc[:, 1].to_numpy(), window,
                            RelevanceFloor(settings.relevance_force_share,
                                           settings.relevance_share,
                                           settings.relevance_share > 0),
                            units=settings.units,
                            record_input=a.recording.iloc[:, 1].to_numpy(),
                            noise_floor=None if floor is None else floor.rms)
    # a coupling term (backlash) has no force on the mass alone (term_forces); a model that
    # cannot be simulated at its posterior mean or on the unseen input (latent, relevance);
    # a smoother whose covariance is not positive definite: each leaves the diagnosis without
    # its missing force, said in a note; anything else (a ValueError among them) is a bug
    except (NotImplementedError, RuntimeError, np.linalg.LinAlgError) as err:
        log.warning("missing force not estimated: %s", err)
        return None, [f"missing force not estimated: {err}"]
    log.info("missing force: %s (%.1f s)", out.description.sentence, time.perf_counter() - clock)
    if start is not None:
        out.fitted_shape = fitted_shape(a, state, start, found.improved_fit, settings)
    return out, []


def fitted_shape(a: Analysis, state: BaselineState, start: BaselineStart,
                 improved: ModelFit | None, settings: DiagnosisSettings
                 ) -> ShapeTermFit | None:
    """The dictionary's periodic shape fitted as a term of the model (``shape_terms``) over
    the detection's window, against the baseline and the ``improved`` model (the named
    effects'; None without); None with a warning where a simulation fails."""
    window = (a.lead, a.hold)
    try:
        return shape_term_fit(start.detection_problem, start.priors, start.samples,
                              state.rel_disp[a.lead:a.hold], state.rel_vel[a.lead:a.hold],
                              motion_scale(state, window, a.f_high), a.f_high,
                              improved, settings.units, settings.seed)
    except (RuntimeError, np.linalg.LinAlgError) as err:
        log.warning("the periodic shape was not fitted as a term: %s", err)
        return None


def named_effects(baseline: ModelStructure, found: Conclusion) -> list[NamedEffect]:
    """Each term the improved model added, beside that model; its own size read from the fit
    of the round that named it (``found.named_fit``; a later tie's model need not describe
    it: a Duffing spring's k_cubic moved from 1.02e6 to 1.34e6 N/m^3 beside a tied inertia
    error, truth 1.11e6), else from the improved model's, with the draws adjusted for
    correlated residuals (``ModelFit.adjusted_samples``)."""
    imp = found.improved_fit
    if imp is None:
        return []
    adjusted = {}
    out = []
    for t in [t for t in imp.structure.terms if t not in baseline.terms]:
        fit = found.named_fit if (found.named_fit is not None and t in found.missing
                                  and t in found.named_fit.structure.terms) else imp
        if id(fit) not in adjusted:
            adjusted[id(fit)] = fit.adjusted_samples()
        samples, done = adjusted[id(fit)]
        out.append(NamedEffect(t, imp.structure, imp.samples.mean(axis=0), samples,
                               fit.structure, done))
    return out


def unseen_comparison(a: Analysis, start: BaselineStart, improved: ModelFit | None,
                      settings: DiagnosisSettings
                      ) -> tuple[UnseenFit | None, UnseenFit | None, list[str]]:
    """The baseline and the improved model on unseen data: the validation record, or the
    recording's held-out tail (none when too short)."""
    if a.validation is not None:
        v = a.validation
        lead = int(round(settings.lead_in_s / a.dt))
        u, y, t = v.iloc[:, 1].to_numpy(), v.iloc[:, 2].to_numpy(), v["time"].to_numpy()
        section, data = (lead, len(v) - int(round(0.5 * a.fs))), "validation"
    elif a.hold < a.end - 8:
        rec = a.recording
        u, y, t = rec.iloc[:, 1].to_numpy(), rec.iloc[:, 2].to_numpy(), a.time
        section, data = (a.hold, a.end), "holdout"
    else:
        return None, None, []
    n, seed = settings.predictive_samples, settings.seed
    try:
        before = unseen_fit(start.detection_problem, start.samples, u, y, t, section, data, n,
                            seed)
        after = before if improved is None else unseen_fit(
            improved.problem, improved.samples, u, y, t, section, data, n, seed)
    except RuntimeError as err:
        return None, None, [f"unseen-data comparison failed: {err}"]
    return before, after, []


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


def write(diag: Diagnosis, out_dir: str | Path, title: str | None = None) -> Path:
    """diagnosis.json, the figures and the summary page (``summary_page``, titled ``title``,
    default "Diagnosis of BASELINE") in ``out_dir``; returns the JSON's path."""
    from harvester.data.fileio import atomic_path, write_json
    from harvester.diagnosis.summary_page import summary_page
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    if diag.settings.figures:
        from harvester.diagnosis.figures import all_figures
        diag.notes.extend(all_figures(diag, out))
        if diag.missing_force is not None:
            from harvester.diagnosis.latent_figures import all_latent_figures
            mf = diag.missing_force
            mf.figure_files = all_latent_figures(mf.latent, mf.description, out, mf.effects,
                                                 [s.explains for s in mf.sizes])
            diag.figure_files.extend(mf.figure_files)
    path = out / "diagnosis.json"
    doc = diag.to_dict()
    write_json(doc, path)
    with atomic_path(out / "summary.html") as tmp:
        tmp.write_text(summary_page(doc, out, title or f"Diagnosis of {diag.baseline.name}"))
    log.info("wrote %s and summary.html", path)
    return path


def diagnose_study(recording_df: pd.DataFrame, baseline: str, known: Mapping[str, float],
                   priors: Mapping[str, PriorSpec], validation_df: pd.DataFrame | None,
                   settings: DiagnosisSettings, out_dir: str | Path,
                   posterior: az.InferenceData | None = None,
                   lead_in: int | None = None, samples: int | None = None) -> Diagnosis:
    """The study's step for one baseline (a Snakemake rule's body).

    ``lead_in``/``samples`` (config preprocess.training_lead_in / training_samples) restrict
    the analysis to the study's training window: the recording is cut half a second after
    lead_in + samples (the filters' end effects fall there) and the lead-in becomes the
    diagnosis's; with a validation record nothing of the training record is held out.
    ``posterior``: the study's TMCMC posterior of the baseline (optional; the diagnosis
    samples its own under its likelihood otherwise).
    """
    rec = recording_df
    if lead_in is not None:
        fs = 1.0 / uniform_step(rec["time"].to_numpy())
        stop = len(rec) if samples is None else \
            min(len(rec), lead_in + samples + int(round(0.5 * fs)))
        rec = rec.iloc[:stop].reset_index(drop=True)
        settings = replace(settings, lead_in_s=lead_in / fs,
                           fit_seconds=None if settings.fit_seconds is None else
                           max(settings.fit_seconds, (stop - lead_in) / fs))
    return diagnose(rec, baseline, known, priors, posterior=posterior, validation=validation_df,
                    settings=settings, out_dir=out_dir, source="training recording")
