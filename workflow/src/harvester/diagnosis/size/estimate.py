"""The size stage of a diagnosis: the missing force over the analysed window, each effect the
improved model named beside it with its own size (``missing_force``), the dictionary's periodic
shape fitted as a term of the model (``shape_terms``), and where a named mass's size is not
fixed by the record (:func:`mass_size_caveat`)."""

from __future__ import annotations

import logging
import time

import numpy as np

from harvester.diagnosis.detect.floor import Floor
from harvester.diagnosis.detect.signatures import motion_scale
from harvester.diagnosis.name.fits import ModelFit
from harvester.diagnosis.name.verdict import Conclusion
from harvester.diagnosis.prepare.analysis import Analysis, BaselineStart
from harvester.diagnosis.prepare.settings import DiagnosisSettings
from harvester.diagnosis.size.missing_force import MissingForce, NamedEffect, missing_force
from harvester.diagnosis.size.relevance import RelevanceFloor
from harvester.diagnosis.size.shape_terms import ShapeTermFit, shape_term_fit
from harvester.inference.map_fit import BaselineState
from harvester.model.structures import ModelStructure
from harvester.model.terms import term

log = logging.getLogger("harvester.diagnosis")


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


def mass_size_caveat(analysis: Analysis, diag: Conclusion) -> str | None:
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
