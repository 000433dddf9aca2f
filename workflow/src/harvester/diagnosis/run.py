"""The diagnosis of one recording: detect, locate, name and confirm missing physics.

``diagnose`` runs the whole loop on a recording (time, base_acc, rel_acc) and a baseline
structure: fit the baseline (or take its posterior), detect and locate the mismatch
(``detect``), rank the library's effects (``rank``), confirm the best few by TMCMC and evidence
(``confirm``), adopt the best accepted one and repeat (``rounds``), then compare the baseline
and the improved model on unseen data (a validation record, or the recording's last quarter).
``diagnose_study`` does the same for the study and writes diagnosis.json and figures.
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

from harvester.data.daq import RECORDING_COLUMNS
from harvester.diagnosis.baseline import BaselineState, baseline_state, chain_problem, fit_map
from harvester.diagnosis.confirm import (CandidateResult, ConfirmSettings, ModelFit, confirm,
                                         fit_structure)
from harvester.diagnosis.detect import Detection, DetectionSettings, detect, estimate_temper
from harvester.diagnosis.rank import RankedCandidate, rank, to_confirm
from harvester.diagnosis.report import UnseenFit, unseen_fit
from harvester.diagnosis.signatures import candidate_terms, motion_scale
from harvester.diagnosis.spectral import filter_cutoff
from harvester.data.errors import DataError
from harvester.inference.identify import make_problem, posterior_theta
from harvester.inference.likelihood import Problem
from harvester.inference.posterior import parameter_names as idata_parameter_names
from harvester.inference.priors import PriorSpec
from harvester.data.signals import resample_recording, resampling_ratio, uniform_step
from harvester.model.structures import ModelStructure, structure as named_structure
from harvester.inference.tmcmc import log_evidence as idata_log_evidence

log = logging.getLogger("harvester.diagnosis")

#: Fewest seconds of recording analysed after the lead-in.
MIN_ANALYSIS_S = 4.0


@dataclass(frozen=True)
class DiagnosisSettings:
    """Settings of :func:`diagnose` (defaults: a 40 s recording in minutes on 2 cores).

    particles, chains, seed: TMCMC; rounds: most effects added one after the other; top:
    candidates sampled per round; bootstrap, artifact_components, alpha, window_s: detection
    (``DetectionSettings``); evidence_alpha, indistinguishable_nats: acceptance
    (``ConfirmSettings``); unexplained_alpha: a detection that no library effect explains
    counts as missing physics only below this p-value (an effect confirmed by evidence
    always does; see ``decide_verdict``); lead_in_s: start of the analysis (the model starts at rest);
    fit_seconds: most seconds of the recording TMCMC fits (None, the default: the whole window
    the detection analyses, all but the holdout); holdout_fraction: share of the recording's end kept unseen when no validation
    record is given; lowpass_hz: cut-off of the zero-phase low-pass the recording went
    through (None: found from its spectrum, ``spectral.filter_cutoff``); filter_order: its
    order; candidates: library terms considered (None: all); predictive_samples: posterior
    samples simulated for the unseen-data comparison; figures: write figures;
    reference_start: a candidate with a start shape (the secondary mode) tempers from the
    detection's scan and the nested model's posterior (``confirm.candidate_reference``);
    False: every candidate from its prior. enlargements: how often a model whose two chains
    disagree by more than a nat is sampled again with twice the particles.
    """

    particles: int = 300
    chains: int = 2
    seed: int = 0
    rounds: int = 2
    top: int = 3
    bootstrap: int = 400
    artifact_components: int = 60
    alpha: float = 0.05
    evidence_alpha: float = 0.05
    indistinguishable_nats: float = 2.0
    unexplained_alpha: float = 0.001
    window_s: float = 1.0
    lead_in_s: float = 1.0
    fit_seconds: float | None = None
    holdout_fraction: float = 0.25
    lowpass_hz: float | None = None
    filter_order: int = 8
    candidates: tuple[str, ...] | None = None
    predictive_samples: int = 100
    enlargements: int = 2
    figures: bool = True
    reference_start: bool = True

    @classmethod
    def fast(cls, **overrides) -> "DiagnosisSettings":
        """Cheaper settings for grids of many recordings only: one round, two candidates,
        fewer particles and replicates, 10 s fitted (:meth:`trades` says what they give up)."""
        base = dict(particles=150, rounds=1, top=2, bootstrap=300, artifact_components=30,
                    fit_seconds=10.0, predictive_samples=40, enlargements=1)
        return cls(**{**base, **overrides})

    def trades(self) -> list[str]:
        """What these settings give up against the defaults, one line each (logged and
        written to diagnosis.json as ``traded_away``); empty for the defaults."""
        default = DiagnosisSettings()
        lines = []
        if self.fit_seconds is not None:
            lines.append(f"TMCMC fits at most {self.fit_seconds:g} s of the analysed window "
                         "(default: all of it, as the detection)")
        for name, what in (("particles", "TMCMC particles per chain"),
                           ("chains", "TMCMC chains"),
                           ("rounds", "rounds of effects added in turn"),
                           ("top", "candidates sampled per round"),
                           ("bootstrap", "noise replicates of the detection"),
                           ("artifact_components", "filter-artefact replicates"),
                           ("predictive_samples", "posterior samples of the unseen-data fit"),
                           ("enlargements", "re-runs with more particles where chains disagree")):
            ours, theirs = getattr(self, name), getattr(default, name)
            if ours < theirs:
                lines.append(f"{ours} {what} (default {theirs})")
        return lines

    @classmethod
    def from_config(cls, cfg: Mapping) -> "DiagnosisSettings":
        """From a config section (keys as the fields; ``fast: true`` starts from ``fast()``)."""
        unknown = sorted(set(cfg) - set(cls.__dataclass_fields__) - {"fast"})
        if unknown:
            raise ValueError(f"diagnosis settings: unknown key(s) {unknown}")
        values = {k: (tuple(v) if k == "candidates" and v is not None else v)
                  for k, v in cfg.items() if k != "fast"}
        return cls.fast(**values) if cfg.get("fast") else cls(**values)

    def detection(self) -> DetectionSettings:
        return DetectionSettings(bootstrap=self.bootstrap, alpha=self.alpha,
                                 window_s=self.window_s, seed=self.seed,
                                 artifact_components=self.artifact_components)

    def confirmation(self) -> ConfirmSettings:
        return ConfirmSettings(particles=self.particles, chains=self.chains, seed=self.seed,
                               enlargements=self.enlargements, alpha=self.evidence_alpha,
                               indistinguishable_nats=self.indistinguishable_nats,
                               reference=self.reference_start)


@dataclass
class Round:
    """One pass of detect -> rank -> confirm on the current structure."""

    structure: str
    detection: Detection
    state: BaselineState
    ranked: list[RankedCandidate]
    confirmed: list[CandidateResult] = field(default_factory=list)

    @property
    def accepted(self) -> CandidateResult | None:
        acc = [r for r in self.confirmed if r.accepted]
        return acc[0] if acc else None


@dataclass
class Diagnosis:
    """Result of :func:`diagnose` (``to_dict`` gives diagnosis.json)."""

    verdict: str
    missing: list[str]
    indistinguishable: list[list[str]]
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

    def to_dict(self) -> dict:
        from harvester.diagnosis.report import diagnosis_dict
        return diagnosis_dict(self)


# --------------------------------------------------------------------------- input checks


def check_recording(df: pd.DataFrame, source: str = "<recording>", lead_in_s: float = 1.0,
                    holdout_fraction: float = 0.25) -> tuple[pd.DataFrame, float]:
    """The recording's columns, values and time base; returns (recording, dt in s).

    It must hold the lead-in, MIN_ANALYSIS_S analysed seconds (plus the held-out share,
    ``holdout_fraction``, 0 when a validation record is given) and 0.5 s of filter end effects.
    The checks are ``harvester.data.checks``'s (also absurd magnitudes and dead channels).
    """
    from harvester.data.checks import (check_duration, check_frame, check_live_channels,
                                       check_magnitudes)
    from harvester.data.recording import RecordingKinds
    dt = check_frame(df, source, RECORDING_COLUMNS)
    kinds = RecordingKinds("base_acc", "rel_acc")
    check_magnitudes(df, kinds, source)
    check_live_channels(df, kinds, source)
    check_duration(df, dt, source, lead_in_s, MIN_ANALYSIS_S, holdout_fraction)
    out = df[list(RECORDING_COLUMNS)].astype(float).reset_index(drop=True)
    return out, dt


def resample_for_model(rec: pd.DataFrame, validation: pd.DataFrame | None, dt: float,
                       lowpass_hz: float | None
                       ) -> tuple[pd.DataFrame, pd.DataFrame | None, float, list[str]]:
    """(recording, validation, dt, notes) at the rate the model is simulated: a recording
    low-passed at ``lowpass_hz`` and sampled faster than ``signals.RATE_PER_CUTOFF`` x that
    is resampled (``signals.resampling_ratio``; 1024 Hz with a 20 Hz filter -> 256 Hz, 500 Hz
    with a 25 Hz filter -> 333 Hz). The validation record, at the same rate, is resampled
    alike."""
    up, down = resampling_ratio(1.0 / dt, lowpass_hz)
    if up == down:
        return rec, validation, dt, []
    if validation is not None:
        dt_v = uniform_step(validation["time"].to_numpy(dtype=float), "<validation>")
        if abs(dt_v - dt) > 1e-6 * dt:
            raise DataError("<validation>", f"sampled every {dt_v:.9g} s, the recording every "
                            f"{dt:.9g} s: give both at the same rate", column="time")
        validation = resample_recording(validation, up, down)
    new_dt = dt * down / up
    note = (f"recording resampled from {1.0 / dt:.4g} Hz to {1.0 / new_dt:.4g} Hz "
            f"(low-pass at {lowpass_hz:.1f} Hz)")
    log.info(note)
    return resample_recording(rec, up, down), validation, new_dt, [note]


def _posterior_samples(idata: az.InferenceData, names: tuple[str, ...]) -> np.ndarray:
    stored = idata_parameter_names(idata)
    if list(stored) != list(names):
        raise ValueError(f"the posterior holds {stored}, the baseline needs {list(names)}")
    return posterior_theta(idata)


def default_priors(structure: ModelStructure, sigma: float) -> dict[str, PriorSpec]:
    """Library priors of the structure's parameters, sigma ~ TN(s, s) with s the MAP's RMS
    residual (the noise level differs between rigs; every model shares this prior)."""
    from harvester.inference.priors import default_prior
    out = {n: default_prior(n) for n in structure.free_parameters}
    out["sigma"] = PriorSpec("sigma", sigma, sigma, "m/s^2", 0.0)
    return out


#: Margin of the sub-step velocity bound over the baseline's largest simulated |z'|.
V_BOUND_MARGIN = 3.0


def velocity_bound(problem: Problem, theta: np.ndarray) -> float | None:
    """V_BOUND_MARGIN x the largest |z'| (m/s) of the structure at ``theta`` (one row) over
    the whole record, for the integrator's sub-step choice (``physics.step_rates``; its
    default, 1 m/s, makes stiff pre-sliding candidates take ten times the steps they need on
    a rig moving at centimetres per second). RK4 stays stable up to 5.6 times the bound."""
    sim = problem.simulate(np.atleast_2d(theta)[:1])
    if not sim.ok[0]:
        return None
    return float(V_BOUND_MARGIN * max(np.max(np.abs(sim.rel_vel[0])), 1e-3))


# --------------------------------------------------------------------------- the loop


def decide_verdict(p_value: float, accepted: bool, unexplained_alpha: float) -> str:
    """"missing_physics" when an added effect is confirmed by evidence, or when the
    detection's p-value is below ``unexplained_alpha`` although nothing explains it; else
    "adequate".

    The detection at ``alpha`` only screens: on data the baseline explains, it fires in about
    alpha of recordings, and a verdict on it alone would cry wolf at that rate. Evidence
    acceptance is calibrated by itself (``confirm``: P(B > 1/alpha) <= alpha under the
    baseline), so the false-alarm rate is at most P(accepted) + unexplained_alpha. The
    detection's replicate p-value cannot fall below 1 / (bootstrap + 1): the default 0.001
    needs 1000 replicates, so with fewer the verdict rests on evidence alone. (Measured: on
    8 s analysed records of the baseline itself, 2 of 5 reached the smallest p-value of 200
    and 300 replicates: the replicate null is too light-tailed there to trust a lone
    detection.) Either way ``unexplained_mismatch`` in diagnosis.json reports a significant
    detection that no effect explains.
    """
    return "missing_physics" if accepted or p_value < unexplained_alpha else "adequate"


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
    rec, dt = check_recording(recording, source, settings.lead_in_s,
                              0.0 if validation is not None else settings.holdout_fraction)
    if validation is not None:
        validation, _ = check_recording(validation, "<validation>", settings.lead_in_s, 0.0)
    base = named_structure(baseline) if isinstance(baseline, str) else baseline
    lowpass = settings.lowpass_hz or filter_cutoff(rec["rel_acc"].to_numpy(), 1.0 / dt)
    rec, validation, dt, notes = resample_for_model(rec, validation, dt, lowpass)
    fs = 1.0 / dt
    n = len(rec)
    lead = int(round(settings.lead_in_s * fs))
    # the analysis stops half a second before the record's end (the zero-phase filters'
    # end effects) or where the held-out tail starts
    end = n - int(round(0.5 * fs))
    hold = end if validation is not None else \
        lead + int(round((end - lead) * (1.0 - settings.holdout_fraction)))
    fit_stop = hold if settings.fit_seconds is None else \
        min(hold, lead + int(round(settings.fit_seconds * fs)))
    t = rec["time"].to_numpy()
    order = settings.filter_order
    f_high = 0.9 * (lowpass or 0.5 * fs)
    log.info("recording %s: %.1f s at %.0f Hz; low-pass %s; analysed %.1f-%.1f s, TMCMC on "
             "%.1f-%.1f s", source, n * dt, fs,
             f"{lowpass:.1f} Hz" if lowpass else "none found", t[lead], t[hold - 1], t[lead],
             t[fit_stop - 1])
    for line in settings.trades():
        log.warning("these settings trade away: %s", line)

    raw_det = make_problem(rec, base, known, window=(lead, hold))
    raw_fit = make_problem(rec, base, known, window=(lead, fit_stop))
    cs = settings.confirmation()

    # ---- the baseline's posterior and the tempering lambda
    baseline_fit: ModelFit | None = None
    if posterior is None:
        mp = fit_map(chain_problem(raw_fit, 1.0, lowpass, order), priors or {}, seed=settings.seed)
        raw_det.v_bound = raw_fit.v_bound = velocity_bound(raw_det, mp.theta)
        specs = {**default_priors(base, float(mp.theta[-1])), **(priors or {})}
        temper = estimate_temper(mp.residual, (lead, fit_stop), fs, f_high)
        log.info("tempering lambda = %.3f (%.1f correlated samples per independent one)",
                 temper, 1.0 / temper)
        baseline_fit = fit_structure(chain_problem(raw_fit, temper, lowpass, order), base,
                                     specs, cs)
        samples = baseline_fit.samples
        base_ev, ev_source = baseline_fit.log_evidence, "diagnosis"
    else:
        samples = _posterior_samples(posterior, raw_det.parameter_names)
        raw_det.v_bound = raw_fit.v_bound = velocity_bound(raw_det, samples.mean(axis=0))
        sig = float(np.mean(samples[:, -1]))
        specs = {**default_priors(base, sig), **(priors or {})}
        state0 = baseline_state(chain_problem(raw_det, 1.0, lowpass, order), samples)
        temper = estimate_temper(state0.residual, (lead, hold), fs, f_high)
        base_ev = float(np.mean(idata_log_evidence(posterior))) \
            if "sample_stats" in posterior.groups() else float("nan")
        ev_source = "given posterior (eq. 10 untempered, no measurement chain)"
    det_problem = chain_problem(raw_det, temper, lowpass, order)
    fit_problem = chain_problem(raw_fit, temper, lowpass, order)
    ds = settings.detection()

    # ---- rounds of detect -> rank -> confirm
    rounds: list[Round] = []
    current, current_fit, current_samples = base, baseline_fit, samples
    unexplained = False
    for r in range(settings.rounds + 1):
        state = baseline_state(chain_problem(det_problem, temper, lowpass, order,
                                             structure=current), current_samples)
        cands = candidate_terms(current.terms, settings.candidates)
        det = detect(state, (lead, hold), specs, cands, replace(ds, seed=ds.seed + r), time=t)
        ranked = rank(det, state, specs)
        rnd = Round(current.name, det, state, ranked)
        rounds.append(rnd)
        if r == settings.rounds or not (det.significant or det.conflict):
            break
        chosen = to_confirm(ranked, det, settings.top)
        if not chosen:
            if det.significant:
                notes.append(f"round {r + 1}: mismatch detected (p = {det.p_value:.3g}) but no "
                             "library effect explains enough of it to be worth sampling")
                unexplained = True
            break
        if current_fit is None:
            current_fit = fit_structure(fit_problem, current, specs, cs)
            if r == 0:
                baseline_fit = current_fit
        scale = motion_scale(state, (lead, hold), det.frame.f_high)
        rnd.confirmed = confirm(current_fit, [c.effect for c in chosen], specs, cs, scale,
                                seed_offset=1000 * (r + 1), detection=det)
        best = rnd.accepted
        if best is None:
            if det.significant:
                unexplained = True
                notes.append(f"round {r + 1}: mismatch detected (p = {det.p_value:.3g}); "
                             "no candidate sampled gained enough evidence")
            break
        specs = {**best.fit.priors, **specs}
        current, current_fit, current_samples = best.fit.structure, best.fit, best.fit.samples
        if det.significant:
            unexplained = False

    first = rounds[0].detection
    accepted = [rnd.accepted for rnd in rounds if rnd.accepted is not None]
    missing: list[str] = []
    groups: list[list[str]] = []
    for acc in accepted:
        missing.append(acc.effect)
        if acc.indistinguishable_from:
            groups.append([acc.effect, *acc.indistinguishable_from])
            missing.extend(e for e in acc.indistinguishable_from if e not in missing)
    last = rounds[-1].detection
    if accepted and last.significant:
        unexplained = True
        notes.append(f"after adding {', '.join(a.effect for a in accepted)} a mismatch remains "
                     f"(p = {last.p_value:.3g})")
    verdict = decide_verdict(first.p_value, bool(accepted), settings.unexplained_alpha)
    if first.significant and not accepted and verdict == "adequate":
        notes.append(f"weak mismatch (p = {first.p_value:.3g}) that no library effect explains "
                     f"by evidence; below the bar for an unexplained verdict "
                     f"(p < {settings.unexplained_alpha:g})")
    if verdict == "adequate" and first.conflict:
        notes.append("prior-posterior conflict on " + ", ".join(
            c.parameter for c in first.conflicts if c.conflict) + " that no library effect "
            "resolves: check the initial modelling and priors")

    improved_fit = accepted[-1].fit if accepted else None
    improved = improved_fit.structure if improved_fit else base

    # ---- before / after on unseen data
    before = after = None
    try:
        if validation is not None:
            vlead = int(round(settings.lead_in_s / dt))
            vb, vr = validation["base_acc"].to_numpy(), validation["rel_acc"].to_numpy()
            vt = validation["time"].to_numpy()
            section, data = (vlead, len(validation) - int(round(0.5 * fs))), "validation"
        elif hold < end - 8:
            vb, vr, vt = rec["base_acc"].to_numpy(), rec["rel_acc"].to_numpy(), t
            section, data = (hold, end), "holdout"
        else:
            section = None
        if section is not None:
            before = unseen_fit(det_problem, samples, vb, vr, vt, section, data,
                                settings.predictive_samples, settings.seed)
            if improved_fit is not None:
                after = unseen_fit(improved_fit.problem, improved_fit.samples, vb, vr, vt,
                                   section, data, settings.predictive_samples, settings.seed)
            else:
                after = before
    except RuntimeError as err:
        notes.append(f"unseen-data comparison failed: {err}")

    diag = Diagnosis(
        verdict=verdict, missing=missing, indistinguishable=groups,
        unexplained=bool(unexplained), baseline=base,
        improved=improved, rounds=rounds, baseline_fit=baseline_fit, improved_fit=improved_fit,
        baseline_log_evidence=(baseline_fit.log_evidence if baseline_fit else base_ev),
        baseline_evidence_source=("diagnosis" if baseline_fit else ev_source),
        unseen_before=before, unseen_after=after, temper=temper, lowpass_hz=lowpass,
        likelihood_lowpass_hz=det_problem.band_hz,
        window_s=(float(t[lead]), float(t[hold - 1])),
        fit_window_s=(float(t[lead]), float(t[fit_stop - 1])), settings=settings,
        priors=specs, seconds=time.perf_counter() - clock, time=t, notes=notes)
    log.info("verdict: %s%s (%.0f s)", verdict,
             f"; missing {', '.join(missing)}" if missing else "", diag.seconds)
    if out_dir is not None:
        write(diag, out_dir)
    return diag


def quick_detect(recording: pd.DataFrame, baseline: str | ModelStructure,
                 known: Mapping[str, float], priors: Mapping[str, PriorSpec] | None = None,
                 settings: DiagnosisSettings = DiagnosisSettings(), temper: float | None = None
                 ) -> tuple[Detection, BaselineState]:
    """Detection and location only, with the baseline's MAP and Laplace posterior instead of
    TMCMC (seconds, not minutes): the first step of :func:`diagnose` for screening many
    recordings. The whole recording after the lead-in is analysed (nothing held out)."""
    rec, dt = check_recording(recording, "<recording>", settings.lead_in_s, 0.0)
    base = named_structure(baseline) if isinstance(baseline, str) else baseline
    lowpass = settings.lowpass_hz or filter_cutoff(rec["rel_acc"].to_numpy(), 1.0 / dt)
    rec, _, dt, _ = resample_for_model(rec, None, dt, lowpass)
    fs = 1.0 / dt
    lead = int(round(settings.lead_in_s * fs))
    raw = make_problem(rec, base, known, window=(lead, len(rec)))
    if temper is None:
        mp = fit_map(chain_problem(raw, 1.0, lowpass, settings.filter_order), priors or {},
                     seed=settings.seed)
        temper = estimate_temper(mp.residual, raw.window, fs, 0.9 * (lowpass or 0.5 * fs))
    problem = chain_problem(raw, temper, lowpass, settings.filter_order)
    mp = fit_map(problem, priors or {}, seed=settings.seed)
    specs = {**default_priors(base, float(mp.theta[-1])), **(priors or {})}
    state = baseline_state(problem, mp.samples(200, settings.seed))
    det = detect(state, problem.window, specs, candidate_terms(base.terms, settings.candidates),
                 settings.detection(), time=rec["time"].to_numpy())
    return det, state


def write(diag: Diagnosis, out_dir: str | Path) -> Path:
    """diagnosis.json and the figures in ``out_dir``; returns the JSON's path."""
    from harvester.data.fileio import write_json
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    if diag.settings.figures:
        from harvester.diagnosis.figures import all_figures
        diag.notes.extend(all_figures(diag, out))
    path = out / "diagnosis.json"
    write_json(diag.to_dict(), path)
    log.info("wrote %s", path)
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
    diagnosis's; with a validation record nothing of the training record is held out. ``posterior``: the study's TMCMC posterior of the baseline (optional;
    the diagnosis samples its own under its likelihood otherwise).
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
