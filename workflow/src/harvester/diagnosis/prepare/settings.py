"""The diagnosis's settings: what it spends and where (``DiagnosisSettings``)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, replace

from harvester.data.sidecar import DEFAULT_RELATIVE_SD, Sidecar
from harvester.data.units import SI, Units, read_units
from harvester.diagnosis.name.results import ConfirmSettings
from harvester.diagnosis.detect.scores import DetectionSettings
from harvester.diagnosis.size.relevance import RelevanceFloor


@dataclass(frozen=True)
class DiagnosisSettings:
    """Settings of :func:`diagnose` (defaults: a 40 s recording in minutes on 2 cores).

    particles, chains, seed: TMCMC; rounds: most effects added one after the other; screen:
    candidates fitted by MAP per round (the best by the detection's ranking,
    ``rank.to_confirm``), whose fits bound the evidence each can gain (``screen``); top:
    candidates sampled per round, the best by that bound, none that it rules out; bootstrap,
    artifact_components, alpha, window_s: detection (``DetectionSettings``); evidence_alpha:
    acceptance (``ConfirmSettings``); unexplained_alpha: a detection that no library effect
    explains counts as missing physics only below this p-value (an effect confirmed by
    evidence always does; see ``decide_verdict``); min_explained_share: a baseline that explains
    less of the unseen output than this share (1 - NRMSE^2) is "inadequate", unless its residual
    lies within ``floor_ratio`` of the recording's own noise floor (``floor.py``); floor_ratio:
    a residual RMS above this many times that floor is mismatch whatever the detection says;
    relevance_share, relevance_force_share: a named effect whose change of the unseen
    response (share of the output) lies below the first and whose force (share of the drive)
    below the second is "detectable but negligible", not missing physics
    (``relevance.RelevanceFloor``; relevance_share 0: off); missing_force: estimate the
    missing force of the baseline as a latent force, its shape and each named effect's size
    (``missing_force``);
    lead_in_s: start of the analysis (the model
    starts at rest); fit_seconds: most seconds of the recording TMCMC fits (None, the default:
    the whole window the detection analyses, all but the holdout); holdout_fraction: share of
    the recording's end kept unseen when no validation record is given; lowpass_hz: cut-off
    of the zero-phase low-pass the recording went through (None: found from its spectrum,
    ``spectral.recording_lowpass``; 0: none, and none looked for); filter_order: its order;
    candidates: library terms considered (None: all); predictive_samples: posterior samples
    simulated for the unseen-data comparison; figures: write figures;
    reference_start: half of each model's initial particles start where other evidence puts
    them, the baseline's at its MAP and Laplace covariance (``confirm.map_reference``), a
    candidate's at the nested model's posterior and, for a start shape (a mode's frequency),
    the detection's scan (``confirm.candidate_reference``); the tempering path changes, not
    the posterior or the evidence. False: every model from its prior. enlargements: how often
    a model whose two chains disagree by more than a nat is sampled again with twice the
    particles. denoise_input: drive the models with the base acceleration without its
    bins on the channel's noise floor, where it shows one (``data.input_noise``); False: as
    recorded. units: the recording's force and displacement units (the sidecar's ``units``,
    ``data.units``; default N and m): the labels of every size the diagnosis writes.
    device_sd: the stated device's uncertainties, (name, sd) pairs (the sidecar's M_sd, m_sd,
    k_sd); device_relative_sd: that of a quantity without one, relative to its value; a
    candidate whose posterior implies a device beyond them is not named (``plausibility``).
    budget, budget_s: the diagnosis's time budget (``name.budget``): a target in seconds of
    wall time for the whole diagnosis (None: from the recording's length,
    ``budget.budget_seconds``, 160 s for 10 s and 280 s for 40 s); the search for names gets
    what the later steps leave of it, and past that no candidate's TMCMC goes on and no further
    candidate, round or second pass starts; diagnosis.json says what was not finished. The
    baseline's own sampling, the fit on unseen data, the missing force and the figures are not
    cut. budget False: none (the study's setting: its results must not depend on the
    machine's speed). deadline: set by ``diagnose`` (``time.time()``, s), never given.
    """

    particles: int = ConfirmSettings.particles
    chains: int = ConfirmSettings.chains
    seed: int = 0
    rounds: int = 2
    screen: int = 6
    top: int = 3
    bootstrap: int = DetectionSettings.bootstrap
    artifact_components: int = DetectionSettings.artifact_components
    alpha: float = DetectionSettings.alpha
    evidence_alpha: float = ConfirmSettings.alpha
    unexplained_alpha: float = 0.001
    min_explained_share: float = 0.5
    floor_ratio: float = 3.0
    relevance_share: float = RelevanceFloor.response_share
    relevance_force_share: float = RelevanceFloor.force_share
    missing_force: bool = True
    window_s: float = DetectionSettings.window_s
    lead_in_s: float = 1.0
    fit_seconds: float | None = None
    holdout_fraction: float = 0.25
    lowpass_hz: float | None = None
    filter_order: int = 8
    candidates: tuple[str, ...] | None = None
    predictive_samples: int = 100
    enlargements: int = ConfirmSettings.enlargements
    figures: bool = True
    reference_start: bool = ConfirmSettings.reference
    denoise_input: bool = True
    units: Units = SI
    device_sd: tuple[tuple[str, float], ...] = ()
    device_relative_sd: float = DEFAULT_RELATIVE_SD
    budget: bool = True
    budget_s: float | None = None
    deadline: float | None = None

    @classmethod
    def fast(cls, **overrides) -> "DiagnosisSettings":
        """Cheaper settings for grids of many recordings only: one round, two candidates,
        fewer particles and replicates, 10 s fitted (:meth:`trades` says what they give up)."""
        base = dict(particles=150, rounds=1, screen=4, top=2, bootstrap=300, artifact_components=30,
                    fit_seconds=10.0, predictive_samples=40, enlargements=1)
        return cls(**{**base, **overrides})

    def trades(self) -> list[str]:
        """What these settings give up against the defaults, one line each (logged and
        written to diagnosis.json as ``traded_away``); empty for the defaults."""
        default = DiagnosisSettings()
        lines = []
        if self.budget and self.budget_s is not None:
            lines.append(f"a time budget of {self.budget_s:g} s (default: from the "
                         "recording's length)")
        if self.fit_seconds is not None:
            lines.append(f"TMCMC fits at most {self.fit_seconds:g} s of the analysed window "
                         "(default: all of it, as the detection)")
        for name, what in (("particles", "TMCMC particles per chain"),
                           ("chains", "TMCMC chains"),
                           ("rounds", "rounds of effects added in turn"),
                           ("screen", "candidates fitted by MAP per round"),
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
        unknown = sorted(set(cfg) - set(cls.__dataclass_fields__) - {"fast", "deadline"})
        if unknown:
            raise ValueError(f"diagnosis settings: unknown key(s) {unknown}")
        values = {k: (tuple(v) if k == "candidates" and v is not None else v)
                  for k, v in cfg.items() if k != "fast"}
        if "units" in values:  # a mapping, as a sidecar's
            values["units"] = read_units("diagnosis settings", values["units"])
        if "device_sd" in values:  # a mapping {M: sd, ...}
            values["device_sd"] = tuple((str(k), float(v))
                                        for k, v in dict(values["device_sd"]).items())
        return cls.fast(**values) if cfg.get("fast") else cls(**values)

    def with_sidecar(self, sidecar: Sidecar) -> "DiagnosisSettings":
        """These settings with what a recording's sidecar states of them: its units and the
        uncertainties of its M, m, k (``M_sd``...; ``plausibility``)."""
        return replace(self, units=sidecar.units, device_sd=tuple(sidecar.known_sd.items()))

    def detection(self) -> DetectionSettings:
        return DetectionSettings(bootstrap=self.bootstrap, alpha=self.alpha,
                                 window_s=self.window_s, seed=self.seed,
                                 artifact_components=self.artifact_components)

    def confirmation(self) -> ConfirmSettings:
        return ConfirmSettings(particles=self.particles, chains=self.chains, seed=self.seed,
                               enlargements=self.enlargements, alpha=self.evidence_alpha,
                               reference=self.reference_start, device_sd=self.device_sd,
                               device_relative_sd=self.device_relative_sd,
                               deadline=self.deadline, candidates=self.candidates)
