"""What the diagnosis carries from one step to the next: a model sampled under its likelihood
(``ModelFit``), the priors of a candidate's added parameters on this device
(``candidate_priors``), and the detection's scan of a candidate's shape as a start for its fit
(``scan_factor``).

The round reads one way, detect -> rank -> screen -> confirm -> verdict: ``screen`` fits the
candidates by MAP and ``confirm`` samples them, and both take these from here, so that neither
imports the other's caller.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping
from dataclasses import dataclass, field

import arviz as az
import numpy as np

from harvester.inference.map_fit import ChainProblem
from harvester.diagnosis.detect.scores import Detection
from harvester.inference.correlated_residuals import correlation_adjustment
from harvester.inference.evidence import BridgeEstimate
from harvester.inference.importance import ImportanceEstimate
from harvester.inference.posterior import pooled_log_evidence
from harvester.inference.priors import PriorSpec
from harvester.inference.reference import Reference, ScanFactor, support
from harvester.model.priors import DeviceScale
from harvester.model.structures import ModelStructure
from harvester.model.terms import term

log = logging.getLogger("harvester.diagnosis")

#: A chain whose log evidence is this far below the best one missed the posterior's mode.
MISSED_MODE_NATS = 5.0
#: Smallest Monte Carlo standard error assumed for a pooled log evidence (nats): two chains'
#: scatter is a poor estimate of it, and the chains may share a bias their errors miss.
MIN_SE = 0.25
#: Smallest standard error assumed for a bridge-sampling log evidence (nats).
BRIDGE_MIN_SE = 0.1
#: Smallest standard error assumed for a log evidence from the chains a time budget let
#: finish, with a later chain stopped (``tmcmc.run_tmcmc``; nats): no second chain checks
#: it, and two chains that differ by up to ``ConfirmSettings.agreement_nats`` (1 nat) are
#: taken as they are. Two chains of the 27 accepted candidates of the held-out records
#: diagnosed in December 2026 differed by at most 0.37 nats.
CUT_MIN_SE = 1.0


@dataclass
class ModelFit:
    """A structure sampled by TMCMC under the diagnosis's likelihood, or, for a candidate
    that can only be judged untrusted (``confirm.judged_by_importance``), drawn by importance
    sampling (``importance``; then ``log_evidence_chains`` holds its one estimate)."""

    structure: ModelStructure
    problem: ChainProblem
    samples: np.ndarray  # rows (free parameters..., sigma)
    log_evidence_chains: np.ndarray
    idata: az.InferenceData | None = field(default=None, repr=False)
    priors: dict[str, PriorSpec] = field(default_factory=dict, repr=False)
    bridge: BridgeEstimate | None = None
    reference: Reference | None = None
    restarted: bool = False  # the reference start collapsed; sampled again from the prior
    #: (particles, spread of the chains' log evidences) of each run that was enlarged
    enlarged: list[tuple[int, float]] = field(default_factory=list)
    importance: ImportanceEstimate | None = None

    @property
    def chains_cut(self) -> int:
        """Chains the time budget stopped after the kept ones finished (0: none)."""
        if self.idata is None or "sample_stats" not in self.idata.groups():
            return 0
        return int(self.idata.sample_stats.attrs.get("chains_cut", 0))

    def cut_sentence(self) -> str | None:
        """How the time budget cut its TMCMC, where it did, in words."""
        if not self.chains_cut:
            return None
        attrs = self.idata.sample_stats.attrs
        kept = len(self.log_evidence_chains)
        return (f"{self.structure.name}: judged on {kept} of {kept + self.chains_cut} TMCMC "
                f"chains, the time budget having stopped chain {kept + 1} at stage "
                f"{attrs.get('cut_stage')} (tempering exponent {attrs.get('cut_beta', 0):.3g});"
                f" its evidence's error taken as at least {CUT_MIN_SE:g} nat")

    @property
    def names(self) -> tuple[str, ...]:
        return self.problem.parameter_names

    @property
    def log_evidence(self) -> float:
        """The bridge-sampling estimate where it was made, else the importance-sampling one
        where the fit was drawn by it, else TMCMC's pooled over chains."""
        if self.bridge is None and self.importance is not None:
            return self.importance.log_evidence
        return self.bridge.log_evidence if self.bridge else self.tmcmc_log_evidence

    @property
    def tmcmc_log_evidence(self) -> float:
        return pooled_log_evidence(self.log_evidence_chains)

    @property
    def log_evidence_se(self) -> float:
        """Standard error of ``log_evidence``: the bridge's (at least BRIDGE_MIN_SE), else
        TMCMC's (:meth:`tmcmc_log_evidence_se`); at least CUT_MIN_SE where the time budget
        stopped a chain (:attr:`chains_cut`)."""
        least = CUT_MIN_SE if self.chains_cut else 0.0
        if self.bridge is not None:
            return float(max(self.bridge.se, BRIDGE_MIN_SE, least))
        if self.importance is not None:
            return float(max(self.importance.se, BRIDGE_MIN_SE))
        return max(self.tmcmc_log_evidence_se, least)

    @property
    def tmcmc_log_evidence_se(self) -> float:
        """Monte Carlo standard error of the pooled log evidence: the larger of what the
        chains state (root sum of their squared errors over the number of chains) and their
        scatter over the root of their number, from the chains that found the posterior's
        main mode (within MISSED_MODE_NATS of the best chain); a chain far below missed it,
        which lowers the pooled value by at most log(chains), and is counted in
        ``missed_chains`` rather than as scatter. At least MIN_SE."""
        c = self.log_evidence_chains
        near = c[c >= c.max() - MISSED_MODE_NATS]
        scatter = float(np.std(near, ddof=1) / np.sqrt(len(near))) if len(near) > 1 else 0.0
        stated = self.stated_se_chains
        stated_se = float(np.sqrt(np.sum(np.square(stated))) / len(stated)) if stated else 0.0
        return float(max(scatter, stated_se, MIN_SE if len(c) > 1 else 0.0))

    @property
    def missed_chains(self) -> int:
        c = self.log_evidence_chains
        return int(np.sum(c < c.max() - MISSED_MODE_NATS))

    def evidence_dict(self) -> dict:
        """Both estimates of the log evidence, and which one ``log_evidence`` is."""
        method = "bridge" if self.bridge else "importance" if self.importance else "tmcmc"
        return {"log_evidence": self.log_evidence, "log_evidence_se": self.log_evidence_se,
                "log_evidence_method": method,
                "log_evidence_importance": self.importance.to_dict() if self.importance
                else None,
                "log_evidence_tmcmc": self.tmcmc_log_evidence,
                "log_evidence_chains": [float(x) for x in self.log_evidence_chains],
                "chains_missing_the_mode": self.missed_chains,
                "log_evidence_bridge": self.bridge.to_dict() if self.bridge else None,
                "log_evidence_se_chains": self.stated_se_chains,
                "chains_spread": self.chains_spread,
                "chains_cut": self.chains_cut,
                "tempered_from": self.reference.describe() if self.reference else None,
                "restarted_from_prior": self.restarted,
                "enlarged_after": [{"particles": n, "chains_spread": s}
                                   for n, s in self.enlarged]}

    @property
    def chains_spread(self) -> float:
        """Largest minus smallest of the chains' log evidences (nats)."""
        c = self.log_evidence_chains
        return float(np.max(c) - np.min(c)) if len(c) > 1 else 0.0

    @property
    def stated_se_chains(self) -> list[float]:
        """Each chain's own stated standard error of its log evidence (TMCMC's)."""
        if self.idata is None or "log_evidence_se" not in self.idata.sample_stats:
            return []
        return [float(x) for x in self.idata.sample_stats["log_evidence_se"].values]

    def adjusted_samples(self) -> tuple[np.ndarray, bool]:
        """(the samples with the physical parameters' draws adjusted for correlated
        residuals, sigma's kept; whether they were): the sandwich covariance about the
        posterior mean (``inference.correlated_residuals``), which the diagnosis's tempering
        by lambda approximates; the samples as drawn where it cannot be formed (logged)."""
        adj = correlation_adjustment(self.problem, self.samples, self.priors)
        if adj is None:
            return self.samples, False
        out = np.array(self.samples, dtype=float)
        out[:, :len(adj.names)] = adj.apply(out[:, :len(adj.names)])
        return out, True

    def summary(self) -> dict[str, dict[str, float]]:
        return {n: {"mean": float(self.samples[:, j].mean()),
                    "sd": float(self.samples[:, j].std(ddof=1))}
                for j, n in enumerate(self.names)}


def prior_dict(spec: PriorSpec) -> dict:
    """A prior as diagnosis.json gives it."""
    return {"family": spec.family, "mean": spec.mean, "sd": spec.sd, "lower": spec.lower,
            "upper": spec.upper, "unit": spec.unit, "described": spec.describe()}


def candidate_priors(effect: str, scale: DeviceScale, known: Mapping[str, float] | None = None
                     ) -> dict[str, PriorSpec]:
    """Priors of an added term's parameters on this device: each parameter's prior in the
    device's scales (its term file, ``harvester.model.priors.Prior``) read on ``scale``.
    ``known``: accepted for callers that pass the device's known values (``scale`` holds
    them)."""
    return {p.name: p.prior_on(scale) for p in term(effect).parameters}


def scan_factor(effect: str, detection: Detection | None,
                priors: Mapping[str, PriorSpec]) -> ScanFactor | None:
    """The candidate's ``Probe.start_shape`` where the detection's scan of it places it:
    log-normal components at the scanned values, one grid step wide (the median log
    spacing), weighted by exp(statistic / 2) summed over each value's signatures (the score
    test's likelihood ratio). None where the effect has no start shape or fewer than 3 values
    were scanned inside its prior."""
    probe = term(effect).probe
    if detection is None or probe.start_shape is None:
        return None
    name = probe.start_shape
    idx = [i for i, sig in enumerate(detection.signatures)
           if sig.effect == effect and name in sig.shape]
    values = np.array([detection.signatures[i].shape[name] for i in idx], dtype=float)
    z = np.asarray(detection.z, dtype=float)[idx]
    stat = z**2 if probe.signed else np.maximum(z, 0.0) ** 2
    (lower,), (upper,) = support(priors, (name,))
    inside = (values > lower) & (values < upper)  # the scan may reach beyond the prior
    values, stat = values[inside], stat[inside]
    grid = np.unique(values)
    if len(grid) < 3:
        return None
    half = np.array([np.logaddexp.reduce(0.5 * stat[values == v]) for v in grid])
    step = float(np.median(np.diff(np.log(grid))))
    try:
        return ScanFactor(name, tuple(grid.tolist()), (step,) * len(grid),
                          tuple(np.exp(half - half.max()).tolist()), lower, upper)
    except ValueError as err:  # the scan lies outside the prior
        log.warning("no scan start for %s (%s)", effect, err)
        return None
