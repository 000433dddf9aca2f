"""The diagnosis of one recording: detect, locate, name and confirm missing physics.

:func:`diagnose` reads as the algorithm, one stage of the package (``prepare``, ``detect``,
``name``, ``size``, ``report``) after the other: prepare the recording
(``prepare.analysis.prepare``), start from the baseline's posterior
(``prepare.analysis.start_baseline``); then a pass (:func:`_pass`): rounds of detect -> rank ->
confirm (``name.rounds.run_rounds``), their conclusion (``name.verdict.conclude``), the fit on
unseen data before and after (``report.unseen``), the missing force with each named effect's
size (``size.estimate``); a :func:`second_pass` where the missing force has the shape of terms
the rounds did not try; the verdict judged against the fit (``name.verdict.judge``).
:func:`diagnose_recording` is the one call from a recording's file (its sidecar, the
friction's contact, the priors from the recording; ``prepare.recording``) that the command
line, the workflow and a Python user make alike; ``diagnose_study`` the study's training
window; ``write`` diagnosis.json, the figures and the summary page; ``quick_detect`` the
detection alone, for screening.
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
from harvester.diagnosis.detect.quick import quick_detect
from harvester.diagnosis.detect.signatures import candidate_terms
from harvester.diagnosis.name.budget import (Timeline, Unfinished, budget_dict, spent,
                                             with_deadline)
from harvester.diagnosis.name.fits import ModelFit
from harvester.diagnosis.name.rounds import Round, run_rounds
from harvester.diagnosis.name.verdict import (Conclusion, FitJudgement, Tie, conclude,
                                              decide_verdict, judge, nominated_terms)
from harvester.diagnosis.prepare.analysis import (Analysis, BaselineStart, check_recording,
                                                  default_priors, prepare, resample_for_model,
                                                  start_baseline, velocity_bound)
from harvester.diagnosis.prepare.redundant import without_redundant
from harvester.diagnosis.prepare.recording import DiagnosisInput, diagnosis_input
from harvester.diagnosis.prepare.settings import DiagnosisSettings
from harvester.diagnosis.report.document import UnseenFit
from harvester.diagnosis.report.unseen import fit_judgement, unseen_comparison
from harvester.diagnosis.size.estimate import estimate_missing_force, mass_size_caveat
from harvester.diagnosis.size.missing_force import MissingForce
from harvester.inference.priors import PriorSpec
from harvester.model.structures import ModelStructure

__all__ = ["Diagnosis", "DiagnosisSettings", "check_recording", "decide_verdict",
           "default_priors", "diagnose", "diagnose_recording", "diagnose_study", "quick_detect",
           "resample_for_model", "velocity_bound", "write"]

log = logging.getLogger("harvester.diagnosis")


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
    #: accepted effects whose own force is negligible, not in ``missing`` (``Conclusion``)
    negligible: list[str] = field(default_factory=list)
    budget: dict = field(default_factory=dict)  # ``name.budget.budget_dict``

    @property
    def indistinguishable(self) -> list[list[str]]:
        """The ties' effects (one list per tie)."""
        return [t.effects for t in self.ties]

    def to_dict(self) -> dict:
        from harvester.diagnosis.report.document import diagnosis_dict
        return diagnosis_dict(self)


def diagnose(recording: pd.DataFrame, baseline: str | ModelStructure,
             known: Mapping[str, float], priors: Mapping[str, PriorSpec] | None = None, *,
             posterior: az.InferenceData | None = None,
             validation: pd.DataFrame | None = None,
             settings: DiagnosisSettings = DiagnosisSettings(),
             out_dir: str | Path | None = None, source: str = "<recording>",
             started: float | None = None) -> Diagnosis:
    """Diagnose ``recording`` against ``baseline``; write diagnosis.json and figures to
    ``out_dir`` if given.

    ``known``: values of the layout parameters not identified (M, m, k); ``priors``: priors of
    the identified ones (missing ones: the library's; sigma's: scaled to the residual);
    ``posterior``: the baseline's posterior (InferenceData from ``identify``) to diagnose; when
    None the baseline is sampled here. ``validation``: an unseen record (same format) for the
    before/after comparison; without it the recording's last ``holdout_fraction`` is held out.
    ``started``: when the time budget began (``time.time()``; default now).
    """
    clock, timeline = time.perf_counter(), Timeline()
    record_s = float(np.ptp(recording["time"].to_numpy()))
    settings = with_deadline(settings, record_s, started)
    if started is not None:  # the recording read, the friction's contact and priors chosen
        timeline.steps.append(("input", max(time.time() - started, 0.0)))
    with timeline.step("prepare"):
        analysis = prepare(recording, validation, baseline, known, settings, source)
    settings, dropped = without_redundant(settings, analysis.known,
                                          analysis.detection_raw.input_type.force_input)
    for note in dropped:
        log.info("%s", note)
    analysis.notes.extend(dropped)
    with timeline.step("baseline"):
        start = start_baseline(analysis, priors, posterior, settings)
    passes = _pass(analysis, start, settings, timeline=timeline)
    passes = second_pass(analysis, start, settings, passes, timeline)
    rounds, found = passes.rounds, passes.found
    found = replace(found, unfinished=found.unfinished + passes.cut)
    search_s = time.perf_counter() - clock
    found = judge(found, rounds[0].detection, passes.fit, analysis.structure.name, settings,
                  passes.missing)
    missing = passes.missing
    diag = _diagnosis(analysis, start, rounds, passes.baseline_fit, found, passes.unseen,
                      settings, analysis.notes + passes.notes + found.notes + passes.more,
                      time.perf_counter() - clock)
    diag.missing_force = missing
    diag.budget = budget_dict(settings, record_s, search_s, found.unfinished, timeline)
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


def diagnose_recording(recording: str | Path, baseline: str, *,
                       validation: str | Path | None = None,
                       settings: DiagnosisSettings = DiagnosisSettings(),
                       lowpass_output_hz: float | None = None,
                       defaults: Mapping[str, float] | None = None, defaults_from: str = "",
                       out_dir: str | Path | None = None) -> Diagnosis:
    """Diagnose the recording's file (a CSV with its sidecar) against ``baseline``: the one
    call of ``harvester diagnose``, the Python API (``harvester.diagnose``) and any program.
    Every choice made before the diagnosis (the device from the sidecar and ``defaults``,
    the low-pass, the friction's contact where the sidecar is silent, the priors from the
    recording) is made by ``prepare.recording.diagnosis_input`` and said in the notes;
    ``out_dir``: write diagnosis.json, the figures and summary.html there."""
    given = diagnosis_input(recording, baseline, validation=validation, settings=settings,
                            lowpass_output_hz=lowpass_output_hz, defaults=defaults,
                            defaults_from=defaults_from)
    return diagnose_given(given, baseline, out_dir)


def diagnose_given(given: DiagnosisInput, baseline: str,
                   out_dir: str | Path | None = None) -> Diagnosis:
    """The diagnosis of a recording's file once its input is decided
    (``prepare.recording.diagnosis_input``; the command line decides it first, so that bad
    input is refused before anything is written): its notes open the diagnosis's."""
    diag = diagnose(given.recording, baseline, given.known, given.priors,
                    validation=given.validation, settings=given.settings,
                    source=given.source, started=given.started)
    diag.notes[:0] = given.notes
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
    cut: list[Unfinished] = field(default_factory=list)  # a second pass the budget stopped


def _pass(analysis: Analysis, start: BaselineStart, settings: DiagnosisSettings,
          nominated: tuple[str, ...] = (), timeline: Timeline | None = None,
          label: str = "") -> _Pass:
    """The rounds (``nominated`` effects screened in the first), their conclusion, the fit on
    unseen data and the missing force; each step timed on ``timeline`` (``label`` before
    its name)."""
    timeline = timeline or Timeline()
    with timeline.step(f"{label}rounds"):
        rounds, baseline_fit, unexplained, notes = run_rounds(analysis, start, settings,
                                                              nominated)
    found = conclude(rounds, unexplained, settings, analysis.f_high)
    with timeline.step(f"{label}fit on unseen data"):
        before, after, more = unseen_comparison(analysis, start, found.improved_fit, settings)
    fit = fit_judgement(start, rounds[0], before, after)
    with timeline.step(f"{label}missing force"):
        missing, missing_notes = estimate_missing_force(analysis, rounds[0].state, found,
                                                        settings, fit.floor, start)
    return _Pass(rounds, baseline_fit, found, (before, after), fit, missing, notes,
                 more + missing_notes)


def second_pass(analysis: Analysis, start: BaselineStart, settings: DiagnosisSettings,
                first: _Pass, timeline: Timeline | None = None) -> _Pass:
    """The second pass, where the first's missing force has the shape of library terms that
    its rounds did not try (``verdict.nominated_terms``: the detection's scores did not point
    to them): the rounds again with those terms screened in the first round, and a note
    saying why. The first pass where nothing is nominated."""
    nominated = nominated_terms(first.found, first.missing, candidate_terms(
        analysis.structure.terms, settings.candidates))
    if not nominated:
        return first
    best = first.missing.description.determined[0]
    if spent(settings):
        log.info("the missing force is %s: the library's %s not tried, and the time budget "
                 "is spent: no second pass", best.name, ", ".join(nominated))
        first.cut.append(Unfinished("second pass", f"{', '.join(nominated)} (the missing "
                                    f"force is {best.name})", "not screened"))
        return first
    log.info("the missing force is %s (%.0f sd out): the library's %s, of that shape, "
             "not tried; the rounds again with %s screened", best.name, best.standing_sd,
             ", ".join(nominated), "it" if len(nominated) == 1 else "them")
    again = _pass(analysis, start, settings, tuple(nominated), timeline, "second pass: ")
    again.notes.append(f"{', '.join(nominated)} screened because the missing force is "
                       f"{best.name} ({best.standing_sd:.0f} sd out), though the "
                       "detection's scores did not point to "
                       f"{'it' if len(nominated) == 1 else 'them'}")
    return again


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
        fit_judgement=found.fit, withheld=found.withheld, negligible=found.negligible)


def write(diag: Diagnosis, out_dir: str | Path, title: str | None = None) -> Path:
    """diagnosis.json, the figures and the summary page (``summary_page``, titled ``title``,
    default "Diagnosis of BASELINE") in ``out_dir``; returns the JSON's path."""
    from harvester.data.fileio import atomic_path, write_json
    from harvester.diagnosis.report.summary_page import summary_page
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    if diag.settings.figures:
        from harvester.diagnosis.report.figures import all_figures
        diag.notes.extend(all_figures(diag, out))
        if diag.missing_force is not None:
            from harvester.diagnosis.size.figures import all_latent_figures
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
