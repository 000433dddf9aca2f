"""The recording as the diagnosis analyses it, and the baseline it starts from.

:func:`prepare` checks the recording, finds the low-pass it went through, resamples it to
the rate the model needs, and cuts it into the lead-in (the model starts at rest), the
analysed window (what the detection and TMCMC see) and the held-out tail (unseen data when no
validation record is given). :func:`start_baseline` gives the baseline's posterior under the
diagnosis's likelihood (TMCMC, or a posterior the caller already has), the priors every
model of the diagnosis shares, and the tempering lambda of eq. (10).
"""

from __future__ import annotations

import logging
from collections.abc import Mapping
from dataclasses import dataclass, field, replace

import arviz as az
import numpy as np
import pandas as pd

from harvester.data.daq import RECORDING_COLUMNS
from harvester.data.errors import DataError
from harvester.data.input_noise import (NoiseFloor, SharedNoise, noise_floor, shared_noise,
                                       without_floor)
from harvester.data.signals import resample_recording, resampling_ratio, uniform_step
from harvester.inference.map_fit import ChainProblem, baseline_state, chain_problem, fit_map
from harvester.diagnosis.name.confirm import fit_structure
from harvester.inference.reference import map_reference
from harvester.diagnosis.name.fits import ModelFit
from harvester.diagnosis.detect.scores import band_top, estimate_temper
from harvester.diagnosis.prepare.settings import DiagnosisSettings
from harvester.diagnosis.detect.spectral import recording_lowpass
from harvester.inference.problems import make_problem
from harvester.inference.posterior import (log_evidence as idata_log_evidence,
                                          parameter_names as idata_parameter_names,
                                          posterior_theta)
from harvester.inference.likelihood import Problem
from harvester.inference.priors import PriorSpec, default_prior, priors_for
from harvester.model.structures import ModelStructure
from harvester.model.structures import structure as named_structure

log = logging.getLogger("harvester.diagnosis")

#: Fewest seconds of recording analysed after the lead-in.
MIN_ANALYSIS_S = 4.0
#: Margin of the sub-step velocity bound over the baseline's largest simulated |z'|.
V_BOUND_MARGIN = 3.0


def check_recording(df: pd.DataFrame, source: str = "<recording>", lead_in_s: float = 1.0,
                    holdout_fraction: float = 0.25) -> tuple[pd.DataFrame, float]:
    """The recording's columns, values and time base; returns (recording: time, its input
    and its output column, dt in s).

    Any kind of recording (``harvester.data.kinds``): input base_acc, base_disp or force,
    output rel_acc or rel_disp. It must hold the lead-in, MIN_ANALYSIS_S analysed seconds
    (plus the held-out share, ``holdout_fraction``, 0 when a validation record is given) and
    0.5 s of filter end effects. The checks are ``harvester.data.checks``'s (also absurd
    magnitudes and dead channels).
    """
    from harvester.data.checks import (check_duration, check_frame, check_live_channels,
                                       check_magnitudes)
    from harvester.data.recording import recording_kinds
    if not isinstance(df, pd.DataFrame):
        check_frame(df, source, RECORDING_COLUMNS)  # names what a table needs
    kinds = recording_kinds(df, source)
    columns = ("time", kinds.input_kind, kinds.output_kind)
    dt = check_frame(df, source, columns)
    check_magnitudes(df, kinds, source)
    check_live_channels(df, kinds, source)
    check_duration(df, dt, source, lead_in_s, MIN_ANALYSIS_S, holdout_fraction)
    out = df[list(columns)].astype(float).reset_index(drop=True)
    return out, dt


def model_kinds(rec: pd.DataFrame, validation: pd.DataFrame | None, lowpass_hz: float | None,
                source: str, notes: list[str]) -> tuple[pd.DataFrame, pd.DataFrame | None]:
    """The recordings in the kinds the model takes (``harvester.data.kinds.model_recording``:
    a base displacement differentiated into a base acceleration, band-limited at the
    recording's low-pass); copies, with what was done appended to ``notes``."""
    from harvester.data.kinds import model_recording
    rec, done = model_recording(rec, lowpass_hz, source)
    if validation is not None:
        validation, more = model_recording(validation, lowpass_hz, "<validation>")
        done += more
    for line in done:
        log.info("%s", line)
    notes.extend(done)
    return rec, validation


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


@dataclass
class Analysis:
    """A recording cut for the diagnosis: samples [lead, hold) analysed, [lead, fit_stop)
    fitted by TMCMC, [hold, end) held out; the problems of eq. (10) on both windows."""

    recording: pd.DataFrame
    validation: pd.DataFrame | None
    structure: ModelStructure
    known: dict[str, float]
    dt: float
    lowpass: float | None
    order: int
    lead: int
    hold: int
    fit_stop: int
    end: int
    detection_raw: Problem
    fit_raw: Problem
    notes: list[str] = field(default_factory=list)
    input_floor: NoiseFloor | None = None  # the base channel's noise floor, where it shows one
    #: where the output holds the input sensor's noise (``input_noise.shared_noise``)
    shared_input_noise: SharedNoise | None = None

    @property
    def time(self) -> np.ndarray:
        return self.recording["time"].to_numpy()

    @property
    def fs(self) -> float:
        return 1.0 / self.dt

    @property
    def f_high(self) -> float:
        """Upper edge of the band the diagnosis analyses (Hz)."""
        return band_top(self.fs, self.lowpass)

    @property
    def window(self) -> tuple[int, int]:
        return self.lead, self.hold

    @property
    def fit_window(self) -> tuple[int, int]:
        return self.lead, self.fit_stop

    def chain(self, problem: Problem, temper: float, **kwargs) -> ChainProblem:
        """``problem`` through the measurement chain, tempered by ``temper``."""
        return chain_problem(problem, temper, self.lowpass, self.order, **kwargs)


def prepare(recording: pd.DataFrame, validation: pd.DataFrame | None,
            baseline: str | ModelStructure, known: Mapping[str, float],
            settings: DiagnosisSettings, source: str) -> Analysis:
    """Check, resample and cut the recording (module docstring)."""
    rec, dt = check_recording(recording, source, settings.lead_in_s,
                              0.0 if validation is not None else settings.holdout_fraction)
    if validation is not None:
        validation, _ = check_recording(validation, "<validation>", settings.lead_in_s, 0.0)
    base = named_structure(baseline) if isinstance(baseline, str) else baseline
    output = rec.columns[2]  # check_recording: time, input, output
    lowpass, shared = recording_lowpass(settings.lowpass_hz, rec[rec.columns[1]].to_numpy(),
                                        rec[output].to_numpy(), 1.0 / dt)
    kind_notes: list[str] = [shared] if shared else []
    rec, validation = model_kinds(rec, validation, lowpass, source, kind_notes)
    rec, validation, dt, notes = resample_for_model(rec, validation, dt, lowpass)
    notes[:0] = kind_notes
    fs, n = 1.0 / dt, len(rec)
    floor, shared = None, None
    if settings.denoise_input:
        raw = rec
        rec, validation, floor = model_input(rec, validation, fs, band_top(fs, lowpass), notes)
        shared = input_noise_in_output(raw, fs, floor, known, notes)
    lead, hold, end = analysis_window(n, fs, settings.lead_in_s,
                                      0.0 if validation is not None else
                                      settings.holdout_fraction)
    fit_stop = hold if settings.fit_seconds is None else \
        min(hold, lead + int(round(settings.fit_seconds * fs)))
    detection_raw = make_problem(rec, base, known, window=(lead, hold))
    # its structure: the baseline with the base parameters ``known`` lacks set free
    base = detection_raw.structure
    out = Analysis(rec, validation, base, dict(known), dt, lowpass, settings.filter_order,
                   lead, hold, fit_stop, end, detection_raw,
                   make_problem(rec, base, known, window=(lead, fit_stop)), notes, floor, shared)
    t = out.time
    said = f"{lowpass:.1f} Hz" if lowpass else \
        "none found" if settings.lowpass_hz is None else "none (given)"
    log.info("recording %s: %.1f s at %.0f Hz; low-pass %s; analysed %.1f-%.1f s, TMCMC on "
             "%.1f-%.1f s", source, n * dt, fs, said, t[lead], t[hold - 1], t[lead],
             t[fit_stop - 1])
    for line in settings.trades():
        log.warning("these settings trade away: %s", line)
    return out


def analysis_window(n: int, fs: float, lead_in_s: float, holdout_fraction: float
                    ) -> tuple[int, int, int]:
    """(lead, hold, end) samples of a record of ``n`` samples at ``fs`` Hz: the analysis
    starts after the lead-in and stops half a second before the record's end (the zero-phase
    filters' end effects) or where the held-out tail (``holdout_fraction`` of the rest)
    starts."""
    lead = int(round(lead_in_s * fs))
    end = n - int(round(0.5 * fs))
    hold = lead + int(round((end - lead) * (1.0 - holdout_fraction)))
    return lead, hold, end


def model_input(rec: pd.DataFrame, validation: pd.DataFrame | None, fs: float, f_high: float,
                notes: list[str]) -> tuple[pd.DataFrame, pd.DataFrame | None, NoiseFloor | None]:
    """The recordings with the input the models are driven by (their second column: a base
    acceleration or a force): without its bins on the channel's noise floor where it shows
    one below ``f_high`` Hz (:mod:`harvester.data.input_noise`; the validation record with
    the training record's floor), else as recorded. Copies; the recordings passed in are not
    changed."""
    name = rec.columns[1]
    floor = noise_floor(rec[name].to_numpy(), fs, f_high)
    if floor is None:
        return rec, validation, None
    out = [r if r is None else r.assign(**{name: without_floor(r[name].to_numpy(), fs, floor)})
           for r in (rec, validation)]
    line = (f"{name} shows a white noise floor of {floor.rms:.3g} RMS over "
            f"{floor.band_hz[0]:.2g}-{floor.band_hz[1]:.3g} Hz ({floor.share:.0%} of the band, "
            f"{floor.dynamic_range:.3g} x below its strongest line): the models are driven by "
            "its bins above that floor, so that the input's noise does not reach the residual "
            "through them")
    log.info("%s", line)
    notes.append(line)
    return out[0], out[1], floor


def input_noise_in_output(rec: pd.DataFrame, fs: float, floor: NoiseFloor | None,
                          known: Mapping[str, float], notes: list[str]) -> SharedNoise | None:
    """Where the input shows a noise floor: the output's share of that noise
    (``input_noise.shared_noise``, on the recording as recorded), with a note where the
    output holds it with gain -1 (a difference with the input's own sensor; ``known``'s m / M
    where given, for a base input)."""
    if floor is None:
        return None
    name, output = rec.columns[1], rec.columns[2]
    found = shared_noise(rec[name].to_numpy(), rec[output].to_numpy(), fs, floor)
    ratio = known["m"] / known["M"] if name == "base_acc" and known.get("M") and \
        known.get("m") is not None else None
    if found is None or not found.shared(ratio):
        return None
    line = (f"{output} holds {name}'s sensor noise where {name} is noise alone (gain "
            f"{found.gain:.2f}, coherence {found.coherence:.2f} over {found.bins} bins): it is "
            "a difference with the input's own sensor, and an effect of the masses read from "
            "it is biased by that noise (errors in variables)")
    log.info("%s", line)
    notes.append(line)
    return found


def default_priors(structure: ModelStructure, sigma: float, unit: str = "m/s^2"
                   ) -> dict[str, PriorSpec]:
    """Library priors of the structure's parameters, sigma ~ TN(s, s) with s the MAP's RMS
    residual (the noise level differs between rigs; every model shares this prior), in
    ``unit``, the output kind's."""
    out = {n: default_prior(n) for n in structure.free_parameters}
    out["sigma"] = PriorSpec("sigma", sigma, sigma, unit, 0.0)
    return out


def velocity_bound(problem: Problem, theta: np.ndarray) -> float | None:
    """V_BOUND_MARGIN x the largest |z'| (m/s) of the structure at ``theta`` (one row) over
    the whole record, for the integrator's sub-step choice (``terms.step_rates``; its
    default, 1 m/s, makes stiff pre-sliding candidates take ten times the steps they need on
    a rig moving at centimetres per second). RK4 stays stable up to 5.6 times the bound."""
    sim = problem.simulate(np.atleast_2d(theta)[:1])
    if not sim.ok[0]:
        return None
    return float(V_BOUND_MARGIN * max(np.max(np.abs(sim.rel_vel[0])), 1e-3))


@dataclass
class BaselineStart:
    """The baseline the diagnosis starts from: its fit (None when a posterior was given),
    posterior samples, the priors every model shares, the tempering lambda, its log evidence
    and where that came from, and the likelihood on both windows."""

    fit: ModelFit | None
    samples: np.ndarray
    priors: dict[str, PriorSpec]
    temper: float
    log_evidence: float
    evidence_source: str
    detection_problem: ChainProblem
    fit_problem: ChainProblem


def start_baseline(analysis: Analysis, priors: Mapping[str, PriorSpec] | None,
                   posterior: az.InferenceData | None, settings: DiagnosisSettings
                   ) -> BaselineStart:
    """The baseline's posterior under the diagnosis's likelihood: its MAP sets the noise
    prior, the sub-step bound and lambda, then TMCMC; or the given ``posterior``."""
    a, priors = analysis, dict(priors or {})
    if posterior is None:
        mp = fit_map(a.chain(a.fit_raw, 1.0), priors, seed=settings.seed)
        a.detection_raw.v_bound = a.fit_raw.v_bound = velocity_bound(a.detection_raw, mp.theta)
        specs = {**default_priors(a.structure, float(mp.theta[-1]),
                                  a.fit_raw.output_type.unit), **priors}
        temper = estimate_temper(mp.residual, a.fit_window, a.fs, a.f_high)
        log.info("tempering lambda = %.3f (%.1f correlated samples per independent one)",
                 temper, 1.0 / temper)
        start = map_reference(mp, priors_for(a.fit_raw, specs)) if settings.reference_start \
            else None
        # the baseline's own sampling: never cut by the budget (no deadline)
        fit = fit_structure(a.chain(a.fit_raw, temper), a.structure, specs,
                            replace(settings.confirmation(), deadline=None), reference=start)
        return BaselineStart(fit, fit.samples, specs, temper, fit.log_evidence, "diagnosis",
                             a.chain(a.detection_raw, temper), a.chain(a.fit_raw, temper))
    samples = _posterior_samples(posterior, a.detection_raw.parameter_names)
    a.detection_raw.v_bound = a.fit_raw.v_bound = velocity_bound(a.detection_raw,
                                                                 samples.mean(axis=0))
    specs = {**default_priors(a.structure, float(np.mean(samples[:, -1])),
                              a.fit_raw.output_type.unit), **priors}
    state = baseline_state(a.chain(a.detection_raw, 1.0), samples)
    if state.note:
        a.notes.append(state.note)
    temper = estimate_temper(state.residual, a.window, a.fs, a.f_high)
    ev = float(np.mean(idata_log_evidence(posterior))) \
        if "sample_stats" in posterior.groups() else float("nan")
    return BaselineStart(None, samples, specs, temper, ev,
                         "given posterior (eq. 10 untempered, no measurement chain)",
                         a.chain(a.detection_raw, temper), a.chain(a.fit_raw, temper))


def _posterior_samples(idata: az.InferenceData, names: tuple[str, ...]) -> np.ndarray:
    stored = idata_parameter_names(idata)
    if list(stored) != list(names):
        raise ValueError(f"the posterior holds {stored}, the baseline needs {list(names)}")
    return posterior_theta(idata)
