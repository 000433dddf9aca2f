"""What the diagnosis concludes: the verdict, the effects it names, and the ties it cannot
break.

Three verdicts (``decide_verdict``): "adequate"; "missing_physics" (an effect named by
evidence, or a mismatch no library effect explains: a detection below ``unexplained_alpha``, or
a residual far above the recording's own noise floor, ``floor.py``); "inadequate" (the baseline
leaves most of the unseen output unexplained, whatever the library can name; the headline then
says whether the library explains the mismatch, part of it or none). The headline (``judge``)
states the verdict, the share of the unseen output the baseline explains and the noise floor it
was judged against.

An effect is *named* only when it is accepted by evidence and every physically different
candidate trails it by more than the acceptance threshold (``confirm.mark_ties``); otherwise
the verdict lists the tie: what each candidate would mean physically, and which experiment
would separate them with the expected evidence gap (``separate``). A wrong name misleads more
than no name: the names (and ties) are withheld when the missing force, seen without the
library, has a shape that the added terms do not (``withheld_names``); the verdict then says
what the missing force looks like.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from dataclasses import dataclass, field, replace

from harvester.data.units import SI, Units
from harvester.diagnosis.name.budget import Unfinished
from harvester.diagnosis.name.results import CandidateResult
from harvester.diagnosis.name.fits import ModelFit
from harvester.diagnosis.detect.scores import Detection
from harvester.diagnosis.detect.floor import Floor
from harvester.diagnosis.size.missing_force import MissingForce
from harvester.diagnosis.size.relevance import MIN_SHARE_EXPLAINED, OwnForce, negligible_beside
from harvester.diagnosis.name.rounds import Round, rough_rivals
from harvester.diagnosis.name.separate import Separation, separations
from harvester.diagnosis.size.shapes import beyond_uncertainty, has_its_shape, library_terms
from harvester.diagnosis.prepare.settings import DiagnosisSettings

log = logging.getLogger("harvester.diagnosis")

#: Rivals of a tie whose separating experiments are computed (the closest first).
TIE_RIVALS = 2
#: The smoother's noise at this share of the baseline's sigma or more: its bound, the whole
#: residual taken as noise.
NOISE_AT_BOUND = 0.99


def latent_unread(missing: MissingForce | None, fit: FitJudgement, limit: float) -> bool:
    """Whether the missing force could not be read rather than found absent: the smoother put
    the whole residual in its noise (its noise sd at its bound, the baseline's sigma) and
    found no force beyond its band, while the residual lies above ``limit`` x the recording's
    own noise floor. Its model, the baseline's dynamics driven by a smooth force, does not
    fit such a residual (the frame at 450 g: its log marginal likelihood fell from 553 at
    the baseline's sigma to below -1200 at the floor's 2e-5 m, at every length scale and
    amplitude tried), so "no missing force" would be said of a mismatch 15 x the floor."""
    if missing is None or not fit.above(limit):
        return False
    lf = missing.latent
    return (lf.noise_sd >= NOISE_AT_BOUND * lf.baseline_noise_sd
            and not beyond_uncertainty(lf))


def decide_verdict(p_value: float, accepted: bool, unexplained_alpha: float, *,
                   explained: float | None = None, min_explained: float = 0.5,
                   above_floor: bool | None = None, within_floor: bool | None = None,
                   shown: bool | None = None) -> str:
    """"inadequate" when the baseline explains less than ``min_explained`` of the unseen
    output (``explained`` = 1 - NRMSE^2) and its residual is not shown to lie at the noise
    floor (``within_floor``); else "missing_physics" when an added effect is confirmed by
    evidence, the detection's p-value is below ``unexplained_alpha`` although nothing explains
    it, or the residual lies far above the recording's own noise floor (``above_floor``);
    else "adequate".

    The detection at ``alpha`` only screens: on data the baseline explains, it fires in about
    alpha of recordings, and a verdict on it alone would cry wolf at that rate. Evidence
    acceptance is calibrated by itself (``confirm``: P(B > 1/alpha) <= alpha under the
    baseline), so the false-alarm rate is at most P(accepted) + unexplained_alpha. The
    detection's p-value reaches below 1 / (bootstrap + 1) by its replicates' tail
    (``inference.tail``), so ``unexplained_alpha`` is reachable at any number of replicates. The
    floor and the share explained do not rest on the replicates, which take the residual's own
    level: a residual that is the whole signal cannot hide in them.

    Without an accepted effect, ``shown`` (:func:`mismatch_shown`) False, a residual at the
    noise floor and no missing force beyond its uncertainty, keeps a detection's p-value
    alone from making the verdict: a mismatch no figure of the diagnosis shows is not
    missing physics (issue 63: a quadratic damper's record, residual 0.975 x the floor).
    """
    if explained is not None and explained < min_explained and not within_floor:
        return "inadequate"
    if accepted or above_floor or (p_value < unexplained_alpha and shown is not False):
        return "missing_physics"
    return "adequate"


#: The residual RMS over the noise floor above which the residual shows a mismatch by itself.
FLOOR_SHOWS = 1.0


def mismatch_shown(fit: "FitJudgement", missing: MissingForce | None) -> bool | None:
    """Whether the diagnosis's own figures show a mismatch: True where the residual lies
    above the noise floor (FLOOR_SHOWS x) or the missing force stands out of its uncertainty
    (its description readable, or its shape fitted as a term speaks); False where the
    residual lies within the floor and the missing force, estimated, does not; None where
    either is unmeasured (no floor, no missing force)."""
    if fit.above(FLOOR_SHOWS):
        return True
    if missing is not None and (missing.description.readable or missing.shape_speaks):
        return True
    if fit.within(FLOOR_SHOWS) and missing is not None:
        return False
    return None


@dataclass(frozen=True)
class FitJudgement:
    """How much of the output the baseline explains, and against what noise.

    explained, improved: 1 - NRMSE^2 of the baseline's and the improved model's predictive
    means on unseen data (``unseen``: "validation" or "holdout"; None without unseen data);
    residual_rms: the baseline's residual RMS over the analysed window, through the
    measurement chain (output units); floor: the recording's own noise floor over the same
    band (``floor.output_floor``, None where the recording shows none).
    """

    explained: float | None
    nrmse: float | None
    unseen: str | None
    residual_rms: float
    floor: Floor | None
    improved: float | None = None

    @property
    def ratio(self) -> float | None:
        """residual RMS / floor RMS."""
        return None if self.floor is None or self.floor.rms <= 0 else \
            self.residual_rms / self.floor.rms

    def above(self, limit: float) -> bool | None:
        """The residual is above ``limit`` x the floor, and the floor's estimate cannot be
        too low for that (an upper bound or an estimate); None where undetermined."""
        r = self.ratio
        if r is None or r <= limit or self.floor.bound == "lower":
            return None if r is None or self.floor.bound == "lower" else False
        return True

    def within(self, limit: float) -> bool | None:
        """The residual is within ``limit`` x the floor, and the floor's estimate cannot be
        too high for that (a lower bound or an estimate); None where undetermined."""
        r = self.ratio
        if r is None or self.floor.bound == "upper":
            return None
        return bool(r <= limit)

    def library_share(self) -> float | None:
        """Share of the baseline's unexplained output that the improved model explains."""
        if self.explained is None or self.improved is None or self.explained >= 1.0:
            return None
        return (self.improved - self.explained) / (1.0 - self.explained)

    def to_dict(self, limit: float) -> dict:
        return {"explained_share": self.explained, "nrmse": self.nrmse, "unseen_data": self.unseen,
                "improved_explained_share": self.improved,
                "library_explains_share": self.library_share(),
                "residual_rms": self.residual_rms,
                "noise_floor": None if self.floor is None else self.floor.to_dict(),
                "residual_over_floor": self.ratio, "above_floor": self.above(limit),
                "within_floor": self.within(limit)}


@dataclass
class Tie:
    """Candidates the recording cannot tell apart: what each implies, and the experiments
    that would (best first)."""

    effects: list[str]
    implies: dict[str, str]
    separations: list[Separation] = field(default_factory=list)

    def to_dict(self) -> dict:
        return {"effects": self.effects, "implies": self.implies,
                "separating_experiments": [s.to_dict() for s in self.separations],
                "recommended": self.separations[0].experiment if self.separations else None}


@dataclass
class Conclusion:
    """The verdict, the effects named (each alone), the ties, whether a detected mismatch is
    left unexplained, notes, the improved model's fit (the last accepted), whether an effect
    was accepted, the fit judgement, the verdict's one-line headline (``judge``) and the fit
    of the last round that named its effect (where a named effect's strength is read: a later
    tie's model need not describe it)."""

    verdict: str
    missing: list[str]
    ties: list[Tie]
    unexplained: bool
    notes: list[str]
    improved_fit: ModelFit | None
    accepted: bool = False
    fit: FitJudgement | None = None
    headline: str = ""
    named_fit: ModelFit | None = None
    withheld: list[str] = field(default_factory=list)
    #: candidates that fit better than the names but could not be sampled (their likelihood
    #: jumps: ``rounds.rough_rivals``)
    unsampled: list[str] = field(default_factory=list)
    #: every effect the rounds screened or sampled (the evidence's verdict on it is in)
    tried: set[str] = field(default_factory=set)
    #: candidates the evidence would accept whose implied device contradicts the sidecar
    #: (``plausibility``), each's sentence
    refused: list[str] = field(default_factory=list)
    #: steps of the search the time budget cut (``budget``): neither named nor rejected
    unfinished: list[Unfinished] = field(default_factory=list)
    #: effects accepted by evidence whose own force is negligible beside a relevant name
    #: (``relevance.negligible_beside``); not in ``missing``
    negligible: list[str] = field(default_factory=list)


def conclude(rounds: list[Round], unexplained: bool, settings: DiagnosisSettings,
             f_high: float) -> Conclusion:
    """What the rounds found (module docstring); the verdict on the detection and evidence
    alone, until ``judge`` weighs the fit on unseen data and the noise floor."""
    first, last = rounds[0].detection, rounds[-1].detection
    accepted = [rnd.accepted for rnd in rounds if rnd.accepted is not None]
    missing = [a.effect for a in accepted if a.named]
    ties = [tie_of(rnd.accepted, rnd, f_high) for rnd in rounds
            if rnd.accepted is not None and not rnd.accepted.named]
    notes = []
    if accepted and last.significant:
        unexplained = True
        notes.append(f"after adding {', '.join(a.effect for a in accepted)} a mismatch remains "
                     f"(p = {last.p_value:.3g})")
    refused = []
    for rnd in rounds:
        for r in rnd.confirmed:
            cut = r.fit.cut_sentence() if r.fit is not None else None
            if cut:
                notes.append(cut)
            if r.untrusted_edges:
                notes.append(f"{r.effect}: the posterior of {', '.join(r.untrusted_edges)} "
                             "piles against its prior's bound; the candidate is not trusted")
            if r.limits_short:
                notes.append(limits_short_sentence(r))
            if r.unshown:
                notes.append(f"{r.unresolved_sentence()} ({r.effect} gained "
                             f"{r.delta_log_evidence:+.1f} nats)")
            if r.refused_for_device:  # the headline says the furthest out, the notes all
                refused.append(max(r.contradicted, key=lambda d: d.z).sentence())
                notes.append(f"{'; '.join(d.sentence() for d in r.contradicted)} ({r.effect} "
                             f"gained {r.delta_log_evidence:+.1f} nats, enough to be "
                             "accepted): not named, the next candidates were tried")
    verdict = decide_verdict(first.p_value, bool(accepted), settings.unexplained_alpha)
    named = [a.fit for a in accepted if a.named]
    return Conclusion(verdict, missing, ties, bool(unexplained), notes,
                      accepted[-1].fit if accepted else None, bool(accepted),
                      named_fit=named[-1] if named else None,
                      unsampled=[c.effect for rnd in rounds for c in rough_rivals(rnd)],
                      tried=tried_effects(rounds), refused=refused,
                      unfinished=[u for rnd in rounds for u in rnd.unfinished])


def limits_short_sentence(r) -> str:
    """Why a candidate whose displacement the record does not resolve, or whose posterior
    piles where it becomes its limits, still stands (``CandidateResult.limits_short``)."""
    where = [f"its {n} of {x * 1e6:.3g} um lies below the {res * 1e6:.3g} um the record "
             "resolves" + (", its posterior piled against the prior's bound there"
                           if n in r.at_prior_edge else "")
             for n, (x, res) in r.unresolved.items()]
    limits = ", ".join(f"{e} {b:+.1f}" for e, b in r.limits_short.items())
    return (f"{r.effect}: {'; '.join(where)}, where the law becomes {' or '.join(r.limits_short)}"
            f"; their best fits ({limits} nats at most) fall short of its "
            f"{r.delta_log_evidence:+.1f} by more than the naming margin: the record tells the "
            "law from them by its force, and that displacement is an upper bound, not a value")


def tried_effects(rounds: list[Round]) -> set[str]:
    """The effects the rounds screened by their best fit or sampled."""
    out = {r.effect for rnd in rounds for r in rnd.confirmed}
    return out | {c.effect for rnd in rounds if rnd.screen is not None
                  for c in rnd.screen.candidates}


def withheld_names(found: Conclusion, missing: MissingForce | None) -> str | None:
    """Why the effects named and tied are withheld, or None: they are relevant, the missing
    force can be read, and the added terms' force together lacks its shape
    (``shapes.has_its_shape``): the frame's hysteresis, the best shape friction, keeps its
    name; a Stribeck friction and a mode whose force explains 1.5 % of a friction level
    drifting in time (14.5 %, the literature generator's friction drift) do not. A shape the
    library holds whose terms the rounds screened or sampled (``Conclusion.tried``) does not
    overrule the evidence, which fitted those terms to the record itself: LuGre's and
    Bouc-Wen's hysteresis were withheld for "odd in z" at 31 % and 14 % of an acceleration
    record's latent force, whose cubic spring and end stop had fallen short by evidence.
    Before that, a shape fitted as a term of the model (``MissingForce.fitted_shape``) that
    beats the named effects' model by evidence (``ShapeTermFit.beats_names``) withholds
    them too: it sees z where the smoother cannot (a cogging record's detent, named a
    pre-sliding hysteresis)."""
    shaped = None if missing is None else missing.fitted_shape
    if shaped is not None and shaped.beats_names and (found.missing or found.ties):
        names = found.missing + [e for t in found.ties for e in t.effects]
        return (f"{' + '.join(names)} accepted by evidence, but {shaped.sentence()}, fits the "
                f"record better than {shaped.named} by "
                f"{shaped.gain_nats - shaped.named_gain_nats:.0f} nats (Laplace, each at its "
                "best fit), a shape none of them has: not named")
    sizes = [] if missing is None else [s for s in missing.sizes if not s.negligible]
    if not sizes or not (found.missing or found.ties):
        return None
    desc, share = missing.description, sizes[0].explains
    if has_its_shape(desc, [s.term for s in sizes], share):
        return None
    terms = library_terms(desc.best.name)
    if set(terms) & found.tried:
        return None  # the evidence judged that shape's terms on this record: its say stands
    has = (f" (the library's {' / '.join(terms)}, of this shape, was not accepted by evidence)"
           if terms else " (outside the library)")
    return (f"{' + '.join(s.term for s in sizes)} accepted by evidence, but their force "
            f"explains {100 * share:.0f} % of the missing force against "
            f"{100 * desc.best.share:.0f} % for {desc.best.name}{has}, a shape none of them "
            "has: not named")


def nominated_terms(found: Conclusion, missing: MissingForce | None,
                    candidates: Sequence[str]) -> list[str]:
    """Library terms the missing force's shape points to that the rounds never tried: where
    no name stands (none accepted, or withheld for lacking the force's shape), the force
    can be read and its best determined shape is one the library holds (``library_terms``),
    those of its terms among ``candidates`` (the terms the structure can take) that were
    neither screened nor sampled (a tie stands as a name). A score test sees one probe
    shape and can miss the term that has the force's own: in the study's Silverbox group
    the cubic spring was not screened while the missing force read odd in z, k_3 = 3.76
    V/V^3, standing 101 sd out. The evidence then decides (``diagnosis.run``)."""
    stands = (found.missing or found.ties) and withheld_names(found, missing) is None
    if missing is None or stands:
        return []
    desc = missing.description
    if not desc.readable or not desc.determined:
        return []
    return [t for t in library_terms(desc.determined[0].name)
            if t in candidates and t not in found.tried]


def explains_little(sizes: Sequence, library_share: float | None) -> list[str]:
    """Mark each named effect of relevant size (``EffectSize``) that explains too little of
    what is missing (``EffectSize.little``): its own force less than MIN_SHARE_EXPLAINED of
    the missing force (``EffectSize.explains``) and the improved model less than it of the
    baseline's unexplained unseen output (``library_share``, where measured). Returns a note
    for each: such a name is not relevant missing physics."""
    notes = []
    for s in sizes:
        unseen = library_share is not None and library_share >= MIN_SHARE_EXPLAINED
        s.little = not s.negligible and s.explains < MIN_SHARE_EXPLAINED and not unseen
        if s.little:
            on_unseen = ("" if library_share is None else f" and the improved model "
                         f"{100 * max(library_share, 0.0):.1f} % of the unexplained unseen "
                         "output")
            notes.append(f"{s.term}: its force explains {100 * max(s.explains, 0.0):.1f} % of "
                         f"the missing force{on_unseen}; a name needs "
                         f"{100 * MIN_SHARE_EXPLAINED:.1f} % of either to be relevant "
                         "missing physics: not relevant")
    return notes


def judge(found: Conclusion, first: Detection, fit: FitJudgement, baseline: str,
          settings: DiagnosisSettings, missing: MissingForce | None = None) -> Conclusion:
    """The verdict with the fit on unseen data, the noise floor and the named effects'
    relevance weighed in (``decide_verdict``), its notes and headline. ``missing``: the
    missing force with each named effect's size (``missing_force``); an accepted effect
    counts as missing physics only if one of them is relevant. Sizes are labelled in
    ``settings.units`` (the recording's)."""
    limit = settings.floor_ratio
    above, within = fit.above(limit), fit.within(limit)
    sizes = missing.sizes if missing is not None else []
    beside = negligible_beside(sizes)
    found = replace(found, missing=[e for e in found.missing if e not in beside],
                    negligible=[e for e in found.missing if e in beside])
    little = explains_little(sizes, fit.library_share())
    relevant = not sizes or any(not s.negligible and not s.little for s in sizes)
    shown = mismatch_shown(fit, missing)
    verdict = decide_verdict(first.p_value, found.accepted and relevant,
                             settings.unexplained_alpha, explained=fit.explained,
                             min_explained=settings.min_explained_share,
                             above_floor=above, within_floor=within, shown=shown)
    notes, unexplained = list(found.notes), found.unexplained
    notes += [f"detectable but negligible: {s.sentence()}" for s in sizes if s.negligible]
    notes += little
    if (first.p_value < settings.unexplained_alpha and not (found.accepted and relevant)
            and shown is False):
        notes.append(f"the detection's p = {first.p_value:.3g} is below "
                     f"{settings.unexplained_alpha:g}, but the residual lies within the noise "
                     f"floor ({fit.ratio:.3g} x) and the missing force within its uncertainty: "
                     "no mismatch the diagnosis can show, not missing physics")
    why = withheld_names(found, missing)
    if why is not None:
        notes.append(why)
        unexplained = True
        found = replace(found, missing=[], ties=[],
                        withheld=found.missing + [e for t in found.ties for e in t.effects])
    if above and not found.accepted:
        unexplained = True
        notes.append(f"the residual is {fit.ratio:.3g} x the recording's noise floor "
                     f"({fit.floor.method}): a mismatch that no library effect explains")
    notes += context_notes(verdict, first, fit, baseline, settings, missing)
    return replace(found, verdict=verdict, unexplained=bool(unexplained), notes=notes, fit=fit,
                   headline=headline(verdict, found, fit, baseline, limit, missing,
                                     settings.units))


def context_notes(verdict: str, first: Detection, fit: FitJudgement, baseline: str,
                  settings: DiagnosisSettings, missing: MissingForce | None) -> list[str]:
    """What the verdict stands beside, in words: a weak mismatch or a prior conflict left
    under an adequate verdict, a noise floor that limits what any model explains, a missing
    force the smoother could not read or that stands out below the bar, a line it leaves, no
    floor measured."""
    limit, within = settings.floor_ratio, fit.within(settings.floor_ratio)
    notes: list[str] = []
    if first.significant and verdict == "adequate":
        notes.append(f"weak mismatch (p = {first.p_value:.3g}) that no library effect explains "
                     f"by evidence; below the bar for an unexplained verdict "
                     f"(p < {settings.unexplained_alpha:g})")
    if verdict == "adequate" and first.conflict:
        notes.append("prior-posterior conflict on " + ", ".join(
            c.parameter for c in first.conflicts if c.conflict) + " that no library effect "
            "resolves: check the initial modelling and priors")
    if fit.explained is not None and fit.explained < settings.min_explained_share and within:
        notes.append(f"{baseline} explains only {fit.explained:.0%} of the unseen output, but its "
                     "residual lies at the recording's noise floor: the noise limits what any "
                     "model can explain")
    if latent_unread(missing, fit, limit):
        notes.append(f"the missing force could not be read: the smoother took the whole "
                     f"residual as noise ({missing.latent.noise_sd:.3g}, the baseline's sigma) "
                     f"while it is {fit.ratio:.3g} x the recording's noise floor; its model, the "
                     "baseline driven by a smooth force, does not fit this residual (not: "
                     "nothing is missing)")
    if verdict == "adequate" and missing is not None and missing.description.readable:
        notes.append("below the verdict's bar, the missing force still stands out of its "
                     f"uncertainty: {missing.description.sentence}")
    if verdict == "adequate" and missing is not None and missing.shape_speaks:
        notes.append(f"below the verdict's bar, {missing.sentence()}")
    if missing is not None and missing.residual_line is not None:
        notes.append(missing.residual_line.sentence())
    if fit.floor is None:
        notes.append("no noise floor of the recording's own could be measured (no repeated "
                     "periods, quiet lead-in or white band): the verdict rests on the "
                     "detection's replicates and on the share of unseen data explained")
    return notes


def _level(effect: str, fit: ModelFit | None, units: Units = SI) -> str:
    """A named effect with what it is, when a friction law, and its fitted strength (the
    term's probe parameter, posterior mean +- sd, in its unit in ``units``): "hysteresis
    (friction, F_hyst 0.661 +- 0.0049 N)", "... V" for a recording in volts. A name alone
    when the improved fit lacks the parameter."""
    from harvester.model.terms import is_friction, term
    t = term(effect)
    what = "friction, " if is_friction(t) else ""
    s = fit.summary().get(t.probe.strength) if fit is not None else None
    if s is None:
        return f"{effect} (friction)" if what else effect
    unit = units.label({p.name: p.unit for p in t.parameters}[t.probe.strength])
    return (f"{effect} ({what}{t.probe.strength} {s['mean']:.3g} +- {s['sd']:.2g} "
            f"{unit})").replace(" )", ")")


def _named(found: Conclusion, missing: MissingForce | None, units: Units = SI) -> str:
    """The effects named and tied, with their size where the missing force gave it. One
    effect's size is its term's own force along its own simulated response, with its 95 %
    interval (``relevance.term_force_rms``; about its mean where the record leaves the mean
    to the term's form, ``relevance.OwnForce.mean_unfixed``); several effects' sized from one
    fit, their own forces summed with their interval (``missing_force.together_force``);
    several effects' (or one without that) is the
    improved model's force beyond the baseline's along the smoothed states
    (``views.effect_force``), theirs together, said once. Along states uncertain by
    millimetres an impact term's force is not its own: a named end stop read 9.97 N RMS
    there (371 % of the drive) and 0.189 N along its own response. Labelled in ``units``; a
    named effect's strength is read from the last round that named one (``named_fit``)."""
    fit = found.named_fit or found.improved_fit
    groups = [" / ".join(g) for g in [[_level(e, fit, units)] for e in found.missing]
              + [t.effects for t in found.ties]]
    sizes = [s for s in missing.sizes if not s.beside] if missing is not None else []
    if not sizes:
        return ", ".join(groups)
    s, force = sizes[0], units.label("force")
    both = missing.together
    if len(sizes) == 1 and s.own_share_of_drive is not None:
        return ", ".join(groups) + _own_said(s.own, force, s.own_share_of_drive, s.label,
                                             "its")
    if len(sizes) > 1 and both is not None and s.drive_rms_N:
        label = next((x.label for x in sizes if not x.negligible), s.label)
        return ", ".join(groups) + _own_said(both, force, both.fixed[0] / s.drive_rms_N,
                                             label, "their")
    together = "together " if len(sizes) > 1 else ""
    return (", ".join(groups) + f" ({together}{s.force_rms_N:.3g} {force} "
            f"RMS, {s.share_of_drive:.2%} of the drive, {s.label})")


def _own_said(own: OwnForce, force: str, share: float, label: str, whose: str) -> str:
    """" (its own force X N RMS, 95 % a-b, P % of the drive, label)": about the mean where
    the record leaves the mean to the form (``relevance.OwnForce.fixed``), ``share`` of the
    drive; "together their" for several terms' summed force."""
    (mid, lo, hi), unfixed = own.fixed, own.mean_unfixed
    what = f"RMS about {whose} mean" if unfixed else "RMS"
    mean = (f", {whose} mean {own.mean[0]:.3g} {force} the form's, not the record's"
            if unfixed else "")
    lead = "together their" if whose == "their" else "its"
    return (f" ({lead} own force {mid:.3g} {force} {what}, 95 % {lo:.3g}-{hi:.3g}{mean}, "
            f"{share:.2%} of the drive, {label})")


def headline(verdict: str, found: Conclusion, fit: FitJudgement, baseline: str,
             limit: float, missing: MissingForce | None = None, units: Units = SI) -> str:
    """One line: the verdict, the share of the unseen output the baseline explains, and the
    noise floor it was judged against; sizes labelled in ``units`` (the recording's)."""
    parts = [verdict]
    if fit.explained is not None:
        parts.append(f"{baseline} explains {max(fit.explained, 0.0):.0%} of the {fit.unseen} "
                     f"output (NRMSE {fit.nrmse:.3g})")
    else:
        parts.append(f"{baseline}: no unseen data to judge its fit on")
    if fit.floor is not None:
        parts.append(f"residual {fit.ratio:.3g} x the noise floor {fit.floor.rms:.3g} "
                     f"({fit.floor.method.replace('_', ' ')}, {fit.floor.bound} bound; "
                     f"mismatch above {limit:g} x)")
    else:
        parts.append("no independent noise floor measured")
    if found.missing or found.ties:
        # accepted effects below the relevance floor leave the verdict adequate
        label = "missing" if verdict != "adequate" else "detectable but negligible"
        parts.append(f"{label}: " + _named(found, missing, units))
    if found.withheld:
        parts.append(f"no library name: {', '.join(found.withheld)} lack the missing force's "
                     "shape")
    parts += [f"not named: {r}" for r in found.refused]
    if found.unsampled:
        one = len(found.unsampled) == 1
        parts.append(f"{', '.join(found.unsampled)} "
                     + ("fits better at its best fit but could not be sampled (its likelihood "
                        "jumps)" if one else "fit better at their best fits but could not be "
                        "sampled (their likelihoods jump)"))
    if found.unfinished:
        parts.append("the time budget ran out, these not decided: "
                     + "; ".join(u.sentence() for u in found.unfinished))
    share = fit.library_share()
    if verdict != "adequate":
        parts.append(_library_phrase(share, found.accepted, bool(found.unfinished)))
        shaped = missing is not None and missing.shape_speaks
        if not found.accepted and not shaped and latent_unread(missing, fit, limit):
            parts.append("the missing force: not readable by the smoother (its noise took the "
                         "whole residual)")
        elif (not found.accepted or found.withheld or found.refused) and missing is not None:
            parts.append(f"the missing force: {missing.sentence()}")
    return "; ".join(parts)


def _library_phrase(share: float | None, accepted: bool, cut: bool = False) -> str:
    """Whether the library explains the mismatch, part of it or none (``cut``: the time
    budget left candidates undecided)."""
    if not accepted:
        return ("no library effect decided within the time budget" if cut
                else "the library explains none of the mismatch")
    if share is None:
        return "the library explains part of the mismatch (no unseen data to say how much)"
    if share >= 0.8:
        return f"the library explains most of the mismatch ({share:.0%} of the unexplained output)"
    if share >= 0.2:
        return f"the library explains part of the mismatch ({share:.0%} of the unexplained output)"
    return f"the library explains little of the mismatch ({max(share, 0.0):.0%})"


def tie_of(best: CandidateResult, rnd: Round, f_high: float) -> Tie:
    """The tie around ``best`` in its round, with separating experiments against its
    closest rivals (TIE_RIVALS)."""
    results = {r.effect: r for r in rnd.confirmed}
    rivals = [e for e in best.indistinguishable_from if e in results][:TIE_RIVALS]
    effects = [best.effect, *best.indistinguishable_from]
    tie = Tie(effects, {e: results[e].implies() for e in effects if e in results})
    for rival in rivals:
        try:
            tie.separations += separations({best.effect: best.fit,
                                            rival: results[rival].fit}, f_high)
        except (RuntimeError, ValueError) as err:
            log.warning("separating %s from %s failed: %s", best.effect, rival, err)
    tie.separations.sort(key=lambda s: -s.decisive if s.decisive == s.decisive else 0.0)
    log.info("tie: %s; %s", " / ".join(effects),
             f"best separated by {tie.separations[0].experiment}" if tie.separations else
             "no separating experiment computed")
    return tie
