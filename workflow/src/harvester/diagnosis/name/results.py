"""What a confirmation is run with and what it gives: the settings of the candidates' TMCMC
and of their acceptance (:class:`ConfirmSettings`), and each candidate's evidence against the
nested model with what holds it back from a name (:class:`CandidateResult`).
``diagnosis.name.confirm`` samples and judges; ``limits`` and ``skips`` read these.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from harvester.data.sidecar import DEFAULT_RELATIVE_SD
from harvester.diagnosis.name.fits import ModelFit, prior_dict
from harvester.diagnosis.name.plausibility import Implied, contradictions
from harvester.inference.identify import TMCMCSettings
from harvester.model.terms import term


@dataclass(frozen=True)
class ConfirmSettings(TMCMCSettings):
    """TMCMC settings (``TMCMCSettings``, with the defaults below) and acceptance settings.

    proposal_scale 0.8 (not Ching & Chen's 0.2): with 0.2 the Metropolis moves accept 85 %
    and barely move, and the log evidence of the tanh model scatters by +-6 nats between
    chains; with 0.8 they accept about 30 % and the chains agree within 0.5 nat (150 particles,
    3 moves per stage; measured on a 10 s recording with a concealed end stop).

    bridge: re-estimate each model's evidence by bridge sampling from its final population
    (``harvester.inference.evidence``; about one TMCMC stage's likelihood evaluations) and compare
    models on it, with its own standard error; TMCMC's chains are still reported.

    reference: a candidate with a start shape tempers from :func:`candidate_reference` (False:
    from the prior, as the baseline and every other candidate do).

    mcmc_steps .. max_mcmc_steps, correlation_threshold: the kernel's moves per stage
    (``harvester.inference.tmcmc``: until the population decorrelates).

    agreement_nats, enlargements: the chains of a model must agree within agreement_nats;
    where they do not, the model is sampled again with twice the particles, at most
    ``enlargements`` times, and the fit says so (``ModelFit.enlarged``).

    family: the number of candidates the round could name (its acceptance shares alpha among
    them, ``acceptance_base``). With 1 (per candidate), an effect-free record of the literature
    grid named an offset force at +3.4 nats against a threshold of 3.3, among 11 candidates.

    device_sd, device_relative_sd: the uncertainty of the stated device (the sidecar's M_sd,
    m_sd, k_sd as (name, sd) pairs; else the relative sd of the value) that a candidate's
    implied device is held against (``plausibility``).

    noise_floor: the recording's own noise floor (output units, ``detect.floor``; None where
    none is measured): a term's displacement below it (``limits.unresolved``) is not named.

    candidates: the library terms the diagnosis may try (None: all), also where a candidate
    stands for another at a bound (``limits.limit_candidates``).
    """

    particles: int = 300
    chains: int = 2
    proposal_scale: float = 0.8
    mcmc_steps: int = 3
    bridge: bool = True
    reference: bool = True
    agreement_nats: float = 1.0
    enlargements: int = 2
    alpha: float = 0.05
    mc_sigmas: float = 2.0
    family: int = 1
    device_sd: tuple[tuple[str, float], ...] = ()
    device_relative_sd: float = DEFAULT_RELATIVE_SD
    noise_floor: float | None = None
    candidates: tuple[str, ...] | None = None

    def tmcmc(self, offset: int = 0) -> TMCMCSettings:
        """The sampler's settings alone, the seed moved by ``offset``."""
        sampler = {name: getattr(self, name) for name in TMCMCSettings.__dataclass_fields__}
        return TMCMCSettings(**sampler | {"seed": self.seed + offset})

    @property
    def base_threshold(self) -> float:
        """log(1/alpha): the Bayes factor by which one named model must beat another."""
        return float(np.log(1.0 / self.alpha))

    @property
    def acceptance_base(self) -> float:
        """log(family/alpha): the Bayes factor by which a candidate must beat the nested model
        when any of ``family`` candidates could have been named (the union bound)."""
        return float(np.log(max(self.family, 1) / self.alpha))


@dataclass
class CandidateResult:
    """The evidence for one augmented structure against the baseline."""

    effect: str
    fit: ModelFit
    delta_log_evidence: float
    delta_se: float
    threshold: float
    accepted: bool
    indistinguishable_from: list[str] = field(default_factory=list)
    #: added parameters whose posterior piles against a bound of their prior ('lower'/'upper')
    at_prior_edge: dict[str, str] = field(default_factory=dict)
    #: the stated device quantities its posterior implies (``plausibility``)
    device: list[Implied] = field(default_factory=list)
    #: displacements of the term the record does not resolve: name -> (posterior median,
    #: the record's resolution), both m (``limits.unresolved``)
    unresolved: dict[str, tuple[float, float]] = field(default_factory=dict)
    #: its resonances above the band the likelihood compares: name -> (posterior median, the
    #: band's top), both Hz (``limits.beyond_band``)
    beyond_band: dict[str, tuple[float, float]] = field(default_factory=dict)
    seconds: float = 0.0  # wall time of its confirmation (TMCMC, or the estimate it rests on)
    #: the terms it would stand for at a displacement the record does not resolve, each
    #: screened and short of its gain by more than the naming margin: term -> bound, nats
    #: (``limits.apart_from_limits``); the record then tells the law from them by its force
    limits_short: dict[str, float] = field(default_factory=dict)

    def _told(self, name: str, side: str) -> bool:
        """Whether the record tells the term from every term it stands for at that bound, a
        displacement it does not resolve (:attr:`limits_short`; a bound of another
        parameter is never waived: there the prior cut off what the record holds)."""
        others = term(self.effect).limit_terms(name, side)
        return name in self.unresolved and bool(others) \
            and all(o in self.limits_short for o in others)

    @property
    def at_limit(self) -> dict[str, str]:
        """Its parameters where the term stands for another (``Term.limits``): piled against
        a bound of the prior, or unresolved (taken at the lower limit); not those where the
        record tells it from its limits (:attr:`limits_short`)."""
        edges = {**self.at_prior_edge, **{n: "lower" for n in self.unresolved}}
        return {**{n: s for n, s in edges.items() if not self._told(n, s)},
                **{n: "upper" for n in self.beyond_band}}

    @property
    def untrusted_edges(self) -> dict[str, str]:
        """Its parameters piled against a bound of the prior that leave it untrusted: all
        but an unresolved displacement's lower bound, lying below what the record resolves,
        where the record tells it from its limits (:attr:`limits_short`)."""
        return {n: s for n, s in self.at_prior_edge.items() if not self._told(n, s)}

    @property
    def unshown(self) -> bool:
        """Whether the record does not show the term's physics: a displacement it does not
        resolve (unless its force tells it from its limits) or a resonance above its band."""
        hidden = [n for n in self.unresolved if not self._told(n, "lower")]
        return bool(hidden or self.beyond_band)

    def unresolved_sentence(self) -> str:
        """Why an unresolved term, or one whose resonance lies above the band, is not named,
        in words."""
        return "; ".join(
            [f"{self.effect}: its {n} of {x * 1e6:.3g} um lies below the {r * 1e6:.3g} um the "
             "record resolves (its noise floor at the likelihood's band): a contact stiffer "
             "than the record can see, taken as its limit, not named"
             for n, (x, r) in self.unresolved.items() if not self._told(n, "lower")]
            + [f"{self.effect}: its {n} of {x:.3g} Hz lies above the {b:.3g} Hz band the "
               "likelihood compares: the record shows no peak of it, only the rise of the "
               "band's top, which a filter or a sensor makes as well: not named"
               for n, (x, b) in self.beyond_band.items()])

    def passes(self) -> bool:
        """The acceptance rule (``confirm.judge``): its gain above the threshold, and
        nothing that holds it back: no parameter piled where the prior cut what the record
        holds (:attr:`untrusted_edges`), no physics the record does not show
        (:attr:`unshown`), no implied device the sidecar contradicts."""
        return bool(self.delta_log_evidence > self.threshold and not self.untrusted_edges
                    and not self.unshown and not self.contradicted)

    @property
    def contradicted(self) -> list[Implied]:
        """The implied quantities that contradict the sidecar (then it is not accepted)."""
        return contradictions(self.device)

    @property
    def refused_for_device(self) -> bool:
        """Whether its evidence would have accepted it but its implied device contradicts the
        sidecar."""
        return bool(self.contradicted) and not self.untrusted_edges \
            and self.delta_log_evidence > self.threshold

    @property
    def named(self) -> bool:
        """Accepted and no physically different candidate within the acceptance threshold."""
        return self.accepted and not self.indistinguishable_from

    def implies(self) -> str:
        """What the effect would mean physically: the term and its added parameters."""
        summ = self.fit.summary()
        units = {p.name: p.unit for p in term(self.effect).parameters}
        parts = [f"{n} {summ[n]['mean']:.3g} +- {summ[n]['sd']:.2g} {units[n]}".rstrip()
                 for n in term(self.effect).parameter_names if n in summ]
        return f"{term(self.effect).description}: " + ", ".join(parts)

    def to_dict(self) -> dict:
        added = term(self.effect).parameter_names
        summ = self.fit.summary()
        return {"effect": self.effect, "structure": self.fit.structure.name,
                **self.fit.evidence_dict(),
                "delta_log_evidence": self.delta_log_evidence,
                "delta_log_evidence_se": self.delta_se, "threshold": self.threshold,
                "seconds": self.seconds,
                "accepted": self.accepted, "named": self.named,
                "indistinguishable_from": self.indistinguishable_from,
                "at_prior_edge": self.at_prior_edge, "implies": self.implies(),
                "unresolved_m": {n: {"posterior_median": x, "resolution": r}
                                 for n, (x, r) in self.unresolved.items()},
                "limits_short": self.limits_short,
                "beyond_band_hz": {n: {"posterior_median": x, "band_top": b}
                                   for n, (x, b) in self.beyond_band.items()},
                "device": [d.to_dict() for d in self.device],
                "device_agrees": not self.contradicted,
                "parameters": summ,
                "added_parameters": {n: summ[n] for n in added if n in summ},
                "added_priors": {n: prior_dict(self.fit.priors[n]) for n in added
                                 if n in self.fit.priors}}
