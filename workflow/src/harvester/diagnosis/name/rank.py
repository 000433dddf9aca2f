"""Rank the candidate effects cheaply, before any sampling.

Two kinds of evidence, both from the detection:

* the score: an effect whose signature matches the residual explains part of it; its
  weighted least-squares strength a_hat has standard error se;
* prior-to-posterior conflict: had the effect been present with strength a, the baseline's
  parameters would have absorbed the part of its signature they can mimic, moving by
  a * A (A from projecting the signature on the sensitivities). An effect whose A points from
  the prior to the posterior explains the conflict (friction driving c_m up, say).

Both are combined in one Gaussian approximation,

    Q(a) = sum_i ((theta_i - mu_i - a A_i) / s_i)^2 + ((a_hat - a) / se)^2,

theta the posterior mean, mu and s the prior mean and sd; a candidate's ``delta_chi2`` is
Q(0) - min_a Q(a) (a >= 0 unless the strength is signed), about twice the log-likelihood gain
of adding it before the Occam factor. Candidates whose best signatures are nearly collinear in
the weighted metric (|correlation| >= SIMILAR) are listed as similar: the data may not tell them
apart, and the evidence must.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from harvester.inference.map_fit import BaselineState
from harvester.diagnosis.detect.scores import CandidateScore, Detection
from harvester.inference.priors import PriorSpec
from harvester.inference.priors import default_prior
from harvester.model.terms import term

#: Correlation of two projected signatures above which their effects are called similar.
SIMILAR = 0.9
#: Score (delta_chi2) from which a candidate is fitted as a rival once a round is open.
RIVAL_DELTA_CHI2 = 1.0


@dataclass
class RankedCandidate:
    """One candidate effect with its cheap evidence."""

    effect: str
    score: CandidateScore
    delta_chi2: float
    conflict_relief: float  # part of delta_chi2 from moving the parameters back to the prior
    strength: float  # combined estimate a*
    similar: list[str] = field(default_factory=list)
    relief_alone: float = 0.0  # the conflict's relief with a fitted to the conflict alone

    @property
    def rank_score(self) -> float:
        return 0.5 * self.delta_chi2

    def to_dict(self) -> dict:
        return {"effect": self.effect, "signature": self.score.label,
                "z": self.score.z, "p_value": self.score.p_value,
                "explained_share": self.score.explained_share,
                "strength": self.score.strength, "strength_se": self.score.strength_se,
                "delta_chi2": self.delta_chi2, "conflict_relief": self.conflict_relief,
                "relief_alone": self.relief_alone, "similar": self.similar}


def _prior_offsets(state: BaselineState, priors: Mapping[str, PriorSpec]
                   ) -> tuple[np.ndarray, np.ndarray]:
    names = state.problem.structure.free_parameters
    d, s = [], []
    for j, name in enumerate(names):
        spec = priors.get(name) or default_prior(name)
        # in the parameter's own units: a log prior's centre and its spread there
        centre = float(spec.from_coordinate(spec.center))
        d.append(state.samples[:, j].mean() - centre)
        s.append(spec.sd if not spec.is_log else centre * (np.exp(spec.sd) - 1.0))
    return np.array(d), np.array(s)


def rank(detection: Detection, state: BaselineState, priors: Mapping[str, PriorSpec]
         ) -> list[RankedCandidate]:
    """Candidates sorted by delta_chi2 (largest first)."""
    d, s = _prior_offsets(state, priors)
    q0_prior = float(np.sum((d / s) ** 2))
    out = []
    for c in detection.candidates:
        sig = detection.signatures[c.index]
        A = detection.absorbed[c.index] if detection.absorbed.size else np.zeros_like(d)
        se = max(c.strength_se, 1e-300)
        num, den = float(np.sum(d * A / s**2)), float(np.sum(A**2 / s**2))

        def fitted(a: float) -> float:
            return a if sig.signed else max(a, 0.0)

        def prior_part(a: float) -> float:
            return float(np.sum(((d - a * A) / s) ** 2))

        a = fitted((num + c.strength / se**2) / (den + 1.0 / se**2))  # conflict and score
        a_alone = fitted(num / max(den, 1e-300))  # the conflict alone
        q0 = q0_prior + (c.strength / se) ** 2
        qa = prior_part(a) + ((c.strength - a) / se) ** 2
        out.append(RankedCandidate(c.effect, c, float(q0 - qa), q0_prior - prior_part(a),
                                   float(a), relief_alone=q0_prior - prior_part(a_alone)))
    # similarity of the best signatures
    G = detection.signature_dft
    if len(out) > 1 and G.size:
        idx = [r.score.index for r in out]
        gram = detection.metric.gram(G[idx])
        norm = np.sqrt(np.maximum(np.diag(gram), 1e-300))
        corr = gram / np.outer(norm, norm)
        for i, r in enumerate(out):
            r.similar = [out[j].effect for j in range(len(out))
                         if j != i and abs(corr[i, j]) >= SIMILAR]
    out.sort(key=lambda r: -r.delta_chi2)
    return out


def to_confirm(ranked: list[RankedCandidate], detection: Detection, top: int,
               min_delta_chi2: float = 4.0, similar_extra: int = 2) -> list[RankedCandidate]:
    """The best ``top`` candidates worth sampling: significant by their score test, or
    relieving a prior conflict, and with delta_chi2 of at least ``min_delta_chi2``; plus up to
    ``similar_extra`` eligible candidates whose signatures are similar to a chosen one's (the
    ranking cannot tell them apart, so the evidence must: a Coulomb law beside tanh and
    Stribeck laws, say); plus, when a prior conflict is flagged, the candidate that relieves it
    most with its strength fitted to the conflict alone (``relief_alone``): an effect the
    parameters absorb completely leaves no score to support it, or one of the wrong sign where
    the refit overshoots (quadratic damping taken up by c_m, say); the conflict is then its
    only trace, and the evidence decides."""
    eligible = [r for r in ranked
                if (r.score.p_value < detection.alpha
                    or (detection.conflict and r.conflict_relief > min_delta_chi2))
                and r.delta_chi2 >= min_delta_chi2]
    chosen = eligible[:top]
    names = {r.effect for r in chosen}
    similar = {e for r in chosen for e in r.similar}
    extra = [r for r in ranked if r.effect in similar and r.effect not in names
             and r.delta_chi2 >= min_delta_chi2][:similar_extra]
    names |= {r.effect for r in extra}
    relieving = [r for r in ranked if r.relief_alone > 0.0 and r.effect not in names]
    if detection.conflict and relieving:
        return chosen + extra + [max(relieving, key=lambda r: r.relief_alone)]
    return chosen + extra


def rivals(ranked: list[RankedCandidate], chosen: list[RankedCandidate],
           min_delta_chi2: float = RIVAL_DELTA_CHI2) -> list[RankedCandidate]:
    """Candidates beside ``chosen`` that a round's screen fits too: every other one whose
    score points towards it by at least one standard error (delta_chi2 >= 1).

    A score is a linear test of one probe shape; an effect of another shape scores low and
    can still explain the mismatch best. On the literature generator's hardening spring
    (|z|^4.7) the cubic spring scored z = 1.4 (p 0.16), while a mass error scored p 0.03 and
    alone was fitted: it was named with +199 nats, where the cubic spring's fit gains +521.
    The MAP fit of a rival costs seconds; what the evidence then says is the decision.
    """
    names = {r.effect for r in chosen}
    return [r for r in ranked if r.effect not in names and r.delta_chi2 >= min_delta_chi2]


def limit_rivals(effects: list[str], allowed: set[str]) -> list[str]:
    """The terms the ``effects`` stand for at a bound of their priors (``Term.limits``: a
    pre-sliding displacement of nothing is friction that sticks, or a sign law) that the
    structure can take (``allowed``) and that are not among them: a round screens them beside
    the effects, in that order. A score test probes one small step from the baseline; a term's
    limit can fit the record where its probe points the wrong way: on the frame as recorded the
    linear model's damping had taken the friction's work, sticking friction's score was
    negative (z = -4.2), and its best fit gained +1452 nats against hysteresis's +1621."""
    out: list[str] = []
    for effect in effects:
        for _, _, limit in term(effect).limits:
            if limit in allowed and limit not in effects and limit not in out:
                out.append(limit)
    return out


def behind_catch_all(order: list[str], failed: set[str], done: set[str],
                     allowed: set[str]) -> list[str]:
    """The terms a round's screen fits before a catch-all term that leads it is judged: where
    the first of ``order`` (the screened effects by bound) that did not fail (``failed``) is a
    catch-all (``Term.catch_all``: a mass error, a mode), the unprobed terms the structure can
    take (``allowed``; ``Term.unprobed``: the laws with memory) and the limits they stand for,
    those not in ``done`` (screened, or cut by the budget). A higher bar for the terms the
    library's grid names where none was put in (issue 63): a mass error or a mode was named
    where absent on 3 of 29 records each (535fb08). On the literature generator's Bouc-Wen
    friction as base_disp -> rel_disp a mode led the screen (+249 by its bound, above the
    band), a mass error was named (+189 nats), and hysteresis, which scored z = 0.07, gains
    +212 when fitted."""
    leader = next((e for e in order if e not in failed), None)
    if leader is None or not term(leader).catch_all:
        return []
    more = [e for e in sorted(allowed) if term(e).unprobed and e not in done]
    return more + [e for e in limit_rivals(more, allowed) if e not in done]
