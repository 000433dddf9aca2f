"""Detect a mismatch between a recording and a baseline posterior, calibrated by simulation.

The question: are the baseline's residuals explained by its noise model, i.e. are they noise
unrelated to the motion, as they would be if the structure were right? Colour alone is not
evidence (the recordings are low-passed), so every statistic is computed in the frame of
``spectral.py`` (passband only, weighted by the inverse of the residual's smoothed spectrum,
with the part the baseline's parameters can absorb projected out) and calibrated by
``bootstrap`` replicates of what a correct model would leave: Gaussian noise with the
residual's spectrum (itself scattered as an estimate is) and its slowly varying level, plus
re-simulations of the fitted baseline showing what the preprocessing low-pass does to a
nonlinear structure (``filter_artifacts``). The signatures and sensitivities depend on the
simulated motion only, so a replicate's statistics need no new simulation.

The verdict is the score (Lagrange multiplier) test family: for each signature g of a
candidate effect (``signatures.py``), z = <g_perp, r> / sd with sd from the replicates,
one-sided for effects whose strength cannot be negative; an effect's statistic is the largest
z^2 over its shape grid and the family's the largest over effects; its p-value is the share of
replicates whose largest statistic is at least as large, or, where fewer than ten replicates
reach it, the generalised Pareto tail of the replicates (``inference.tail``), so that it can fall below
1 / (bootstrap + 1). False alarms on recordings of the
baseline itself stay at most alpha = 0.05 over 60 seeds (tests/test_diagnosis_calibration.py).

Locations (``locate.py``): shares of residual energy in time windows and state regions against
stationary replicates, and per frequency band the share the signatures explain. They say
where, not whether: sensor noise on the base channel seen through sticking and sliding makes the
residual's level follow the motion even when the structure is right, so energy shares are
reported (and flagged when significant and gross) but do not decide the verdict.

Prior-data conflicts (what the data alone say of a parameter, far in the tail of what its
prior predicts) are reported beside it: a missing effect that the parameters absorb leaves
white-looking residuals but drags the parameters away from what the initial modelling said;
the diagnosis then confirms candidates by evidence (``confirm.py``).
"""

from __future__ import annotations

import logging
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from harvester.data.signals import chain_cutoff
from harvester.inference.map_fit import BaselineState
from harvester.diagnosis.detect.locate import (FrequencyBands, MeasuredStandstill, Standardised,
                                        StateRegions, TimeWindows, standardise)
from harvester.diagnosis.detect.signatures import Signature, motion_scale, signatures
from harvester.inference.tail import TailP, tail_p
from harvester.diagnosis.detect.spectral import (Frame, Metric, Projector, level_envelope,
                                          noise_replicates, removed_input_psd)
from harvester.inference.priors import PriorSpec
from harvester.inference.priors import default_prior

log = logging.getLogger("harvester.diagnosis")



#: The analysed band ends at this fraction of the measurement chain's cut-off.
BAND_FRACTION = 0.9


def band_top(fs: float, lowpass_hz: float | None, fraction: float = BAND_FRACTION) -> float:
    """Upper edge (Hz) of the band the detection analyses: ``fraction`` x the cut-off of the
    measurement chain (the recording's low-pass, or the DAQ's anti-alias edge without one:
    :func:`~harvester.data.signals.chain_cutoff`)."""
    return fraction * chain_cutoff(fs, lowpass_hz)


@dataclass(frozen=True)
class DetectionSettings:
    """Calibration and location settings.

    bootstrap: noise replicates; artifact_components: re-simulations of the baseline that
    reproduce what the preprocessing low-pass does to a nonlinear structure (0: none), cycled
    over the replicates; alpha: false-alarm rate of the verdict; band_fraction: the
    analysed band ends at this fraction of the measurement chain's cut-off (:func:`band_top`);
    gross_region_ratio, gross_window_ratio: a region (window) counts towards the verdict only
    when it holds at least this many times its share of time (expected share) of the residual
    energy, besides being significant (see :func:`detect`); window_s: length of
    the time windows (s); conflict_alpha: family-wise level of the prior-data conflict flags
    (``prior_conflicts``); seed: replicates' random seed.
    """

    bootstrap: int = 400
    artifact_components: int = 60
    alpha: float = 0.05
    conflict_alpha: float = 0.01
    band_fraction: float = BAND_FRACTION
    window_s: float = 1.0
    gross_region_ratio: float = 1.5
    gross_window_ratio: float = 2.0
    seed: int = 0


@dataclass
class Conflict:
    """Prior-data conflict of one parameter: z of the data's estimate against the prior's
    prediction of it, its two-sided tail probability, and the flag (``prior_conflicts``); the
    means and sds are in the prior's coordinate (x, or ln x for log priors); ``at_edge``: the
    bound of the prior the posterior piles against, if any."""

    parameter: str
    prior_mean: float
    prior_sd: float
    posterior_mean: float
    posterior_sd: float
    z: float
    tail_probability: float
    conflict: bool
    at_edge: str | None = None

    def to_dict(self) -> dict:
        return dict(self.__dict__)


@dataclass
class CandidateScore:
    """An effect's best score over its shape grid."""

    effect: str
    label: str  # signature label of the best shape
    index: int  # index of that signature
    z: float
    statistic: float  # z^2 (one-sided where the strength is non-negative)
    p_value: float  # calibrated on the replicates (max over the effect's grid)
    strength: float  # weighted least-squares estimate of the strength at the best shape
    strength_se: float
    explained_share: float  # share of the (weighted) residual energy it explains


@dataclass
class Detection:
    """Everything the ranking, the report and the figures need."""

    frame: Frame
    temper: float
    alpha: float
    p_value: float
    family_p: dict[str, float]
    family_statistic: dict[str, float]
    family_tail: dict[str, TailP] = field(repr=False)  # how each family's p-value was found
    signatures: list[Signature] = field(repr=False)
    z: np.ndarray = field(repr=False)  # per signature
    absorbed: np.ndarray = field(repr=False)  # (signatures, P): parameter shift per unit strength
    gram: np.ndarray = field(repr=False)  # <g_perp, g_perp> per signature
    signature_dft: np.ndarray = field(repr=False)  # (signatures, bins) projected DFTs
    metric: Metric = field(repr=False)
    candidates: list[CandidateScore] = field(repr=False)
    conflicts: list[Conflict] = field(repr=False)
    windows: TimeWindows = field(repr=False)
    window_stats: Standardised = field(repr=False)
    regions: StateRegions = field(repr=False)
    region_stats: Standardised = field(repr=False)
    region_gain: Standardised = field(repr=False)  # observed = measured / model amplitude
    bands: FrequencyBands = field(repr=False)
    band_energy: np.ndarray = field(repr=False)  # residual energy per band
    band_explained: np.ndarray = field(repr=False)  # energy explained by the signatures
    band_explained_stats: Standardised = field(repr=False)
    spectrum: np.ndarray = field(repr=False)  # smoothed periodogram of the residual
    residual_dft: np.ndarray = field(repr=False)
    residual_band: np.ndarray = field(repr=False)  # band-limited residual over the window
    explained_band: np.ndarray = field(repr=False)  # its part explained by the signatures
    sigma: float = 0.0  # RMS residual over the window (m/s^2)

    @property
    def significant(self) -> bool:
        return self.p_value < self.alpha

    @property
    def conflict(self) -> bool:
        return any(c.conflict for c in self.conflicts)


def temper_from_spectrum(residual_dft: np.ndarray, spectrum: np.ndarray, frame: Frame,
                         quantile: float = 0.9) -> float:
    """lambda = effective fraction of independent samples for eq. (10) on this residual.

    The variance of the residual over the window divided by the variance white noise would
    have at the in-band level of the residual's spectrum (its ``quantile`` over the passband,
    so that the densest part of the band sets it). Band-limited white noise to B Hz gives
    about 2 B / fs (0.16 for 20 Hz at 256 Hz); a white residual gives 1.
    """
    total = 2.0 * np.sum(np.abs(residual_dft) ** 2)
    band = frame.mask > 0.5
    level = float(np.quantile(spectrum[band], quantile))
    lam = total / (frame.n * level)
    return float(np.clip(lam, 1.0 / frame.n, 1.0))


def estimate_temper(residual: np.ndarray, window: tuple[int, int], fs: float,
                    f_high: float) -> float:
    """lambda (``temper_from_spectrum``) of a residual over a window, band ending at f_high."""
    frame = Frame(fs, window[0], window[1], f_high)
    dft = frame.dft(residual)
    return temper_from_spectrum(dft, frame.smoothed_periodogram(dft), frame)


def data_estimate(prior_mean: float, prior_sd: float, post_mean: float, post_sd: float
                  ) -> tuple[float, float]:
    """(mean, sd) of the likelihood alone, recovered from a Gaussian prior and posterior:
    1/s_L^2 = 1/s_post^2 - 1/s_0^2, m_L = s_L^2 (m_post/s_post^2 - m_0/s_0^2); sd inf where the
    data say nothing the prior did not (posterior no narrower than the prior)."""
    if post_sd <= 0.0:
        return post_mean, 0.0
    precision = 1.0 / post_sd**2 - 1.0 / prior_sd**2
    if precision <= 0.0:
        return post_mean, float("inf")
    var = 1.0 / precision
    return float(var * (post_mean / post_sd**2 - prior_mean / prior_sd**2)), float(np.sqrt(var))


#: A posterior holding at least this share within EDGE_SHARE of its prior's range from a
#: bound (in the prior's coordinate) is piled against that edge.
EDGE_MASS = 0.5
EDGE_SHARE = 0.05


#: The bound cuts the posterior when it lies within this many posterior sds of its mean.
EDGE_SDS = 3.0


def at_prior_edge(spec: PriorSpec, x: np.ndarray) -> str | None:
    """'lower' or 'upper' where the posterior samples x pile against that bound of a prior
    with a finite range (a finding to report: the prior cut off what the data wanted), else
    None. Priors open on one side are judged on their finite bound, within EDGE_SHARE x 6
    of their scales."""
    low, high = spec.bounds
    if not (np.isfinite(low) or np.isfinite(high)) or len(x) < 2:
        return None
    u = spec.to_coordinate(np.asarray(x, dtype=float))
    width = (high - low) if np.isfinite(low) and np.isfinite(high) else 6.0 * spec.scale
    spread = max(float(np.std(u)), 1e-300)
    for side, bound, near in (("lower", low, u - low), ("upper", high, high - u)):
        # most samples near the bound on the prior's scale, and the bound within a few of the
        # posterior's own sds (it cuts the posterior: a narrow posterior far inside a broad
        # prior is not piled against the bound however near it looks on the prior's scale)
        if np.isfinite(bound) and np.mean(near < EDGE_SHARE * width) >= EDGE_MASS \
                and np.mean(near) < EDGE_SDS * spread:
            return side
    return None


def prior_conflicts(names: tuple[str, ...], samples: np.ndarray,
                    priors: Mapping[str, PriorSpec], settings: DetectionSettings
                    ) -> list[Conflict]:
    """Prior-data conflict of every physical parameter (sigma excluded).

    What the data alone say of a parameter (``data_estimate``) is compared with the prior's
    prediction of it, in the prior's own coordinate (x, or ln x for log-normal and
    log-uniform priors): z = (m_L - m_0) / sqrt(s_0^2 + s_L^2), N(0, 1) when the prior is
    right (a Gaussian prior-predictive check; a truncation is ignored, a log-uniform prior is
    taken as the Gaussian of its mean and sd in ln x). A parameter the data barely inform gets
    s_L large and z small, however far its posterior moved; one the data pin down is judged on
    its distance in prior sds. Flagged below the family-wise level ``conflict_alpha``
    (two-sided). A posterior piled against a bound of its prior is reported too
    (``at_prior_edge``).
    """
    from scipy.stats import norm

    out = []
    physical = [n for n in names if n != "sigma"]
    level = settings.conflict_alpha / max(len(physical), 1)
    for j, name in enumerate(names):
        if name == "sigma":
            continue
        spec = priors.get(name) or default_prior(name)
        x = spec.to_coordinate(samples[:, j])
        mean = float(np.mean(x))
        sd = float(np.std(x, ddof=1)) if len(x) > 1 else 0.0
        m_l, s_l = data_estimate(spec.center, spec.scale, mean, sd)
        z = 0.0 if not np.isfinite(s_l) else (m_l - spec.center) / float(np.hypot(spec.scale,
                                                                                   s_l))
        tail = float(2.0 * norm.sf(abs(z)))
        out.append(Conflict(name, spec.center, spec.scale, mean, sd, float(z), tail,
                            bool(tail < level), at_prior_edge(spec, samples[:, j])))
    return out


def filter_artifacts(state: BaselineState, frame: Frame, count: int,
                     rng: np.random.Generator) -> np.ndarray:
    """DFTs (count, bins) of the mismatch the preprocessing low-pass alone causes.

    A recording low-passed on both channels is not the model's response to the low-passed
    input: the input's content above the cut-off also moved the friction, and that leaks into
    the band. Each component draws what the filter may have removed from the input
    (``removed_input_psd``), and compares the baseline's response to the full input, filtered,
    with its response to the filtered input: the residual a correct model would leave.
    Empty when the recording went through no low-pass.
    """
    problem = state.problem
    if problem.lowpass_hz is None or count <= 0:
        return np.zeros((0, frame.freqs.size), dtype=complex)
    fs = 1.0 / problem.dt
    y = problem.base_acc
    n_rec = len(y)
    f_in, p_in = removed_input_psd(y, fs, problem.lowpass_hz, problem.filter_order)
    freqs = np.fft.rfftfreq(n_rec, problem.dt)
    amplitude = np.sqrt(np.interp(freqs, f_in, p_in) * fs / 2.0)
    out = np.empty((count, frame.freqs.size), dtype=complex)
    for i in range(count):
        extra = np.fft.irfft(np.fft.rfft(rng.standard_normal(n_rec)) * amplitude, n=n_rec)
        full = y + extra
        sims = [problem.simulate(state.theta, base_acc=u)
                for u in (full, problem.recording_filter(full))]
        if not all(s.ok[0] for s in sims):
            out[i] = 0.0
            continue
        output = problem.output_type.simulated  # the recording's output kind
        data = problem.chain(problem.recording_filter(output(sims[0])[0]))
        model = problem.chain(output(sims[1])[0])
        out[i] = frame.dft(data - model)
    return out


def gated_max(stats: Standardised, log_share_gate: np.ndarray) -> tuple[float, np.ndarray]:
    """Largest z among locations whose log share of energy exceeds the gate (else -inf),
    for the data and each replicate (whose shares are recovered from the z-scores)."""
    obs_ok = stats.observed >= log_share_gate
    obs = float(np.max(np.where(obs_ok, stats.z, -np.inf))) if stats.z.size else -np.inf
    rep_ok = stats.replicate_values >= log_share_gate[None, :]
    rep = np.max(np.where(rep_ok, stats.z_replicates, -np.inf), axis=1) if stats.z.size else \
        np.full(stats.z_replicates.shape[0], -np.inf)
    return obs, rep


@dataclass
class Whitened:
    """The residual in the detection's frame: weighted by the inverse of its smoothed
    spectrum, with what the baseline's parameters absorb projected out."""

    frame: Frame
    raw: np.ndarray          # DFT of the residual over the window
    jacobian: np.ndarray     # (P, bins) DFT of the sensitivities
    spectrum: np.ndarray     # smoothed periodogram of the residual
    metric: Metric
    projector: Projector
    residual: np.ndarray     # projected residual (1, bins)
    temper: float


def whiten(state: BaselineState, window: tuple[int, int], f_high: float) -> Whitened:
    """The frame, metric and projected residual of ``state`` over ``window``."""
    frame = Frame(1.0 / state.problem.dt, window[0], window[1], f_high)
    raw = frame.dft(state.residual)
    jac = frame.dft(state.jacobian.T)
    first = Projector(Metric(frame.mask), jac).apply(raw)
    spectrum = frame.smoothed_periodogram(first)
    metric = Metric(frame.mask / spectrum)
    proj = Projector(metric, jac)
    return Whitened(frame, raw, jac, spectrum, metric, proj, proj.apply(raw),
                    temper_from_spectrum(raw, spectrum, frame))


def replicates(state: BaselineState, w: Whitened, window: tuple[int, int],
               settings: DetectionSettings, rng: np.random.Generator
               ) -> tuple[np.ndarray, np.ndarray]:
    """Projected noise replicates: (level-following plus filter artefacts, for the score
    tests; stationary, for the energy-share locations)."""
    frame = w.frame
    envelope = level_envelope(state.residual[window[0]:window[1]], frame.fs, settings.window_s)
    artifacts = filter_artifacts(state, frame, min(settings.artifact_components,
                                                   settings.bootstrap), rng)
    noise_spectrum = w.spectrum
    if len(artifacts):
        art_power = frame.smoothed_mean(np.mean(np.abs(artifacts) ** 2, axis=0))
        noise_spectrum = np.maximum(w.spectrum - art_power, 0.5 * w.spectrum)
    reps = noise_replicates(noise_spectrum, frame, settings.bootstrap, rng, envelope)
    if len(artifacts):
        reps += artifacts[np.arange(settings.bootstrap) % len(artifacts)]
    stationary = noise_replicates(w.spectrum, frame, settings.bootstrap, rng)
    return w.projector.apply(reps), w.projector.apply(stationary)


@dataclass
class SignatureSet:
    """The candidates' signatures in the whitened frame."""

    signatures: list[Signature]
    projected: np.ndarray    # (signatures, bins) projected DFTs
    absorbed: np.ndarray     # (signatures, P) parameter shift per unit strength
    gram: np.ndarray         # <g_perp, g_perp> per signature


def signature_set(state: BaselineState, w: Whitened, window: tuple[int, int], f_high: float,
                  candidates: list[str]) -> SignatureSet:
    """Each candidate's signatures, projected like the residual."""
    sigs = signatures(state, motion_scale(state, window, f_high), candidates)
    if not sigs:
        return SignatureSet([], np.zeros((0, w.raw.size)), np.zeros((0, 0)), np.zeros(0))
    dft = w.frame.dft(np.array([s.values for s in sigs]))
    projected = w.projector.apply(dft)
    absorbed = w.projector.coefficients(dft) if w.projector.solve \
        else np.zeros((len(sigs), 0))
    weight = w.metric.weight
    gram = np.einsum("ij,ij->i", projected.real * weight, projected.real) + \
        np.einsum("ij,ij->i", projected.imag * weight, projected.imag)
    return SignatureSet(sigs, projected, absorbed, gram)


@dataclass
class ScoreTests:
    """The score test of every signature and the best per effect."""

    z: np.ndarray
    candidates: list[CandidateScore]
    statistic: float | None          # the family's largest effect statistic
    replicates: np.ndarray | None    # its replicates


def score_tests(w: Whitened, sigs: SignatureSet, reps: np.ndarray) -> ScoreTests:
    """z = <g_perp, r> / sd per signature; an effect's statistic is its largest z^2 (one-sided
    where its strength cannot be negative) over its shape grid (module docstring)."""
    if not sigs.signatures:
        return ScoreTests(np.zeros(0), [], None, None)
    s_obs = w.metric.inner(w.residual, sigs.projected)[0]
    s_rep = w.metric.inner(reps, sigs.projected)
    sd = s_rep.std(axis=0, ddof=1)
    sd = np.where(sd > 0, sd, np.inf)
    z, z_rep = s_obs / sd, s_rep / sd
    signed = np.array([s.signed for s in sigs.signatures])
    stat = np.where(signed, z**2, np.maximum(z, 0) ** 2)
    stat_rep = np.where(signed, z_rep**2, np.maximum(z_rep, 0) ** 2)
    total = float(w.metric.inner(w.residual, w.residual)[0, 0])
    scores, best_reps = [], []
    for effect in dict.fromkeys(s.effect for s in sigs.signatures):
        idx = np.array([i for i, s in enumerate(sigs.signatures) if s.effect == effect])
        best = int(idx[np.argmax(stat[idx])])
        best_reps.append(np.max(stat_rep[:, idx], axis=1))
        g2 = max(sigs.gram[best], 1e-300)
        scores.append(CandidateScore(
            effect=effect, label=sigs.signatures[best].label, index=best, z=float(z[best]),
            statistic=float(stat[best]), p_value=tail_p(stat[best], best_reps[-1]).p,
            strength=float(s_obs[best] / g2), strength_se=float(sd[best] / g2),
            explained_share=float(s_obs[best] ** 2 / g2 / total)))
    return ScoreTests(z, scores, float(max(c.statistic for c in scores)),
                      np.max(np.array(best_reps), axis=0))


@dataclass
class Where:
    """Shares of band-limited residual energy in time windows and state regions, and the
    measured-to-model amplitude per region."""

    windows: TimeWindows
    window_stats: Standardised
    regions: StateRegions
    region_stats: Standardised
    region_gain: Standardised
    series: np.ndarray               # band-limited residual over the window
    family: dict[str, tuple[float, np.ndarray]]  # gated statistics: observed, replicates


def where(state: BaselineState, w: Whitened, stationary: np.ndarray, time: np.ndarray,
          settings: DetectionSettings) -> Where:
    """Time windows and state regions against stationary replicates (``locate.py``)."""
    frame = w.frame
    series, series_rep = frame.band_limited(w.residual), frame.band_limited(stationary)
    windows = TimeWindows(frame, time, settings.window_s)
    w_stats = standardise(windows.statistic(series), windows.statistic(series_rep))
    regions = StateRegions(frame, state.rel_disp, state.rel_vel, state.rel_acc,
                           state.problem.base_acc, state.problem.input_type)
    standstill = MeasuredStandstill(frame, state.output, state.problem.output_type)
    # the regions' statistics are log(energy share); the standstill's is log(share / time
    # share) (its mask moves with the data), put on the same footing for the gate below
    obs = np.append(regions.statistic(series), standstill.statistic(series))
    rep = np.column_stack([regions.statistic(series_rep), standstill.statistic(series_rep)])
    r_stats = standardise(obs, rep)
    regions.add(standstill, float(np.mean(standstill.mask(series))))
    gain = region_gains(frame, state, regions, standstill, series, series_rep)
    # a window or region enters the verdict only if it also holds a gross excess of energy
    w_gate = np.log(settings.gross_window_ratio * windows.expected_share())
    r_gate = np.log(settings.gross_region_ratio * regions.time_share())
    r_gate[-1] = np.log(settings.gross_region_ratio)  # the standstill's statistic is a ratio
    family = {"windows": gated_max(w_stats, w_gate), "regions": gated_max(r_stats, r_gate)}
    return Where(windows, w_stats, regions, r_stats, gain, series, family)


def region_gains(frame: Frame, state: BaselineState, regions: StateRegions,
                 standstill: MeasuredStandstill, series: np.ndarray, series_rep: np.ndarray
                 ) -> Standardised:
    """Amplitude ratio measured / model in each region, 1 + <r, m> / <m, m> (0: the data do
    not move where the model does, as when the real device sticks)."""
    model_band = frame.band_limited(frame.dft(state.output))

    def gains(res: np.ndarray) -> np.ndarray:
        if res.ndim == 1:
            masks = np.vstack([regions.matrix, standstill.mask(res)[None, :]])
            return 1.0 + (masks @ (res * model_band)) / np.maximum(masks @ model_band**2, 1e-300)
        fixed = 1.0 + (res * model_band) @ regions.matrix.T / np.maximum(
            regions.matrix @ model_band**2, 1e-300)
        m = standstill.mask(res)
        still = 1.0 + np.sum(m * res * model_band, axis=1) / np.maximum(
            np.sum(m * model_band**2, axis=1), 1e-300)
        return np.column_stack([fixed, still])

    g_obs, g_rep = gains(series), gains(series_rep)
    stats = standardise(-np.abs(np.log(np.maximum(g_obs, 1e-3))),
                        -np.abs(np.log(np.maximum(g_rep, 1e-3))))
    return Standardised(g_obs, -stats.z, -stats.z_replicates, g_rep)


@dataclass
class BandShares:
    """Residual energy per frequency band and the share the signatures explain."""

    bands: FrequencyBands
    energy: np.ndarray
    explained: np.ndarray
    stats: Standardised
    explained_series: np.ndarray     # the explained part, band-limited


def band_shares(w: Whitened, sigs: SignatureSet, stationary: np.ndarray) -> BandShares:
    """Per band: the residual's energy and the part the signatures explain together
    (least squares in the metric), against the stationary replicates."""
    bands = FrequencyBands(w.frame)
    energy = bands.band_energy(w.residual)
    if sigs.signatures:
        gram = w.metric.gram(sigs.projected)
        norm = np.sqrt(np.maximum(np.diag(gram), 1e-300))
        pinv = np.linalg.pinv(gram / np.outer(norm, norm), rcond=1e-6) / np.outer(norm, norm)
        explained = (pinv @ w.metric.inner(sigs.projected, w.residual))[:, 0] @ sigs.projected
        explained_rep = (w.metric.inner(stationary, sigs.projected) @ pinv.T) @ sigs.projected
    else:
        explained = np.zeros_like(w.residual)
        explained_rep = np.zeros_like(stationary)
    band_expl = bands.band_energy(explained)
    band_expl_rep = bands.band_energy(explained_rep) / bands.band_energy(stationary).sum(
        axis=1, keepdims=True)
    stats = standardise(band_expl / energy.sum(), band_expl_rep)
    return BandShares(bands, energy, band_expl, stats, w.frame.band_limited(explained))


def detect(state: BaselineState, window: tuple[int, int], priors: Mapping[str, PriorSpec],
           candidates: list[str], settings: DetectionSettings = DetectionSettings(),
           time: np.ndarray | None = None) -> Detection:
    """Calibrated detection and location of a mismatch of the baseline over ``window``.

    The analysed band ends at ``settings.band_fraction`` x the measurement chain's cut-off
    (:func:`band_top`).
    """
    problem = state.problem
    if window[1] > len(state.residual):
        raise ValueError(f"window {window} beyond the problem's record ({len(state.residual)})")
    f_high = band_top(1.0 / problem.dt, problem.lowpass_hz, settings.band_fraction)
    time = np.arange(len(problem.rel_acc)) * problem.dt if time is None else time
    w = whiten(state, window, f_high)
    sigs = signature_set(state, w, window, f_high, candidates)
    reps, stationary = replicates(state, w, window, settings,
                                  np.random.default_rng(settings.seed))
    log.info("detection over %.1f-%.1f s, band %.2f-%.1f Hz, %d signatures, %d replicates",
             time[window[0]], time[window[1] - 1], w.frame.f_low, f_high,
             len(sigs.signatures), settings.bootstrap)
    scores = score_tests(w, sigs, reps)
    located = where(state, w, stationary, time, settings)
    family = dict(located.family)
    if scores.statistic is not None:
        family = {"library": (scores.statistic, scores.replicates), **family}
    family_tail = {f: tail_p(obs, rep, settings.seed) for f, (obs, rep) in family.items()}
    family_p = {f: t.p for f, t in family_tail.items()}
    shares = band_shares(w, sigs, stationary)
    conflicts = prior_conflicts(problem.parameter_names, state.samples, priors, settings)
    det = Detection(
        frame=w.frame, temper=w.temper, alpha=settings.alpha,
        p_value=family_p.get("library", 1.0), family_p=family_p, family_tail=family_tail,
        family_statistic={f: obs for f, (obs, _) in family.items()},
        signatures=sigs.signatures, z=scores.z, absorbed=sigs.absorbed, gram=sigs.gram,
        signature_dft=sigs.projected, metric=w.metric, candidates=scores.candidates,
        conflicts=conflicts, windows=located.windows, window_stats=located.window_stats,
        regions=located.regions, region_stats=located.region_stats,
        region_gain=located.region_gain, bands=shares.bands, band_energy=shares.energy,
        band_explained=shares.explained, band_explained_stats=shares.stats,
        spectrum=w.spectrum, residual_dft=w.residual, residual_band=located.series,
        explained_band=shares.explained_series,
        sigma=float(np.sqrt(np.mean(state.residual[window[0]:window[1]] ** 2))))
    log.info("detection: p = %.3g (%s); conflicts: %s", det.p_value,
             ", ".join(f"{f} p={p:.3g}" for f, p in family_p.items()),
             ", ".join(c.parameter for c in conflicts if c.conflict) or "none")
    return det
