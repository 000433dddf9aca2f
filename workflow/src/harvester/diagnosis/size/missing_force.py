"""The missing force in one call, for the diagnosis run and its diagnosis.json: the latent force
of the baseline (``latent``), its shape (``shapes``), its views (``views``), each named
effect's force beside it with its size and relevance (``relevance``), a line the force leaves
in the recording (``lines``), and the figures (``figures``)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from harvester.data.units import SI, Units
from harvester.inference.map_fit import BaselineState
from harvester.diagnosis.size.latent import LatentForce, latent_force
from harvester.diagnosis.size.views import Binned, EffectForce, effect_force, views
from harvester.diagnosis.size.lines import ResidualLine, residual_line
from harvester.diagnosis.size.relevance import (EffectSize, OwnForce, RelevanceFloor, drive_rms,
                                           effect_size, own_span, response_change, ridge,
                                           term_force_rms)
from harvester.diagnosis.size.shapes import ShapeDescription, describe
from harvester.diagnosis.size.shape_terms import ShapeTermFit
from harvester.model.structures import ModelStructure


@dataclass(frozen=True)
class NamedEffect:
    """A term the diagnosis named and the improved model that holds it: its structure and
    parameters (free parameters, sigma last optional); and the posterior the term's own size
    is read from (``sized``: its structure, by default ``structure``; ``samples``: rows of its
    free parameters, sigma last optional; None: no size interval), with ``adjusted`` saying
    whether those samples were adjusted for correlated residuals."""

    term: str
    structure: ModelStructure
    theta: np.ndarray
    samples: np.ndarray | None = None
    sized: ModelStructure | None = None
    adjusted: bool = False


@dataclass
class MissingForce:
    """The missing force, its shape and views, and the named effects beside it."""

    latent: LatentForce
    description: ShapeDescription
    views: dict[str, Binned]
    effects: list[EffectForce] = field(default_factory=list)
    sizes: list[EffectSize] = field(default_factory=list)
    figure_files: list[str] = field(default_factory=list)
    #: a sensor's or the acquisition's line the force leaves in the recording (``lines``)
    residual_line: ResidualLine | None = None
    #: several named terms' own forces summed, over the one fit that holds them all
    #: (:func:`together_force`)
    together: OwnForce | None = None
    #: the dictionary's periodic shape fitted as a term of the model (``shape_terms``)
    fitted_shape: ShapeTermFit | None = None

    def sentence(self) -> str:
        """What the missing force looks like: the description's sentence, or the shape
        fitted as a term's where it stands and the smoother could not read the force, or
        where it beat the named effects (``verdict.withheld_names``)."""
        return self.fitted_shape.sentence() if self.shape_speaks else self.description.sentence

    @property
    def shape_speaks(self) -> bool:
        """Whether the shape fitted as a term is what the diagnosis says of the missing force:
        it stands, and it beat the named effects or the smoother could not read the force
        (beside names whose model beats it, it is a flexible shape taking part of their
        force: +321 nats on the frame at 250 g against the hysteresis model's +420)."""
        fs = self.fitted_shape
        return bool(fs is not None and fs.stands
                    and (fs.beats_names or not self.description.readable))

    def to_dict(self) -> dict:
        """diagnosis.json's ``missing_force`` entry."""
        return {"latent_force": self.latent.to_dict(),
                "shape": self.description.to_dict(),
                "views": {k: v.to_dict() for k, v in self.views.items()},
                "named_effects": [{**ef.to_dict(), **size.to_dict()}
                                  for ef, size in zip(self.effects, self.sizes)],
                "figures": self.figure_files,
                "residual_line": (None if self.residual_line is None
                                  else self.residual_line.to_dict()),
                "together": (None if self.together is None else
                             {"terms": [e.term for e in self.effects],
                              **self.together.to_dict()}),
                "fitted_shape": (None if self.fitted_shape is None else
                                 {**self.fitted_shape.to_dict(), "speaks": self.shape_speaks})}


def missing_force(state: BaselineState, window: tuple[int, int] | None = None,
                  named: Sequence[NamedEffect] = (), unseen_input: np.ndarray | None = None,
                  unseen_window: slice | None = None, floor: RelevanceFloor = RelevanceFloor(),
                  out_dir: str | Path | None = None, units: Units = SI,
                  record_input: np.ndarray | None = None, **latent_kwargs) -> MissingForce:
    """Everything of the missing force for a baseline ``state`` (module docstring);
    ``unseen_input`` (the held-out or validation input, ``unseen_window`` of it) gives each
    named effect's change of the predicted response; ``record_input`` (the whole record's
    input; default the state's, cut after its window) the span of each named term's own
    force (``term_force_rms``); ``units``: the recording's (the labels of every size,
    ``data.units``); figures in ``out_dir`` if given."""
    lf = latent_force(state, window, units=units, **latent_kwargs)
    desc = describe(lf)
    out = MissingForce(lf, desc, views(lf), residual_line=residual_line(lf))
    # the drive over the named terms' own forces' span, for their share of it
    u, start = own_span(state.problem, record_input)
    span_drive = drive_rms(lf, u[start:])
    for effect in named:
        ef = effect_force(lf, effect.structure, effect.theta, state.problem.known, effect.term)
        response = None
        if unseen_input is not None:
            response = response_change(state.problem, state.theta, effect.structure,
                                       effect.theta, unseen_input,
                                       unseen_window or slice(None))
        own, on_ridge = None, None
        if effect.samples is not None:
            sized = effect.sized or effect.structure
            own = term_force_rms(state.problem, sized, effect.samples, effect.term,
                                 record_input=record_input)
            on_ridge = ridge(sized, effect.samples, effect.term)
        out.effects.append(ef)
        out.sizes.append(effect_size(lf, ef, floor, response, desc.share_of(ef.change), own,
                                     on_ridge, effect.adjusted, span_drive))
    out.together = together_force(state.problem, named, record_input)
    if out_dir is not None:
        from harvester.diagnosis.size.figures import all_latent_figures
        out.figure_files = all_latent_figures(lf, desc, out_dir, out.effects,
                                              [s.explains for s in out.sizes])
    return out


def together_force(problem, named: Sequence[NamedEffect],
                   record_input: np.ndarray | None = None) -> OwnForce | None:
    """Several named terms' own forces summed (``term_force_rms``), over the posterior of
    the one fit that sized them all; None for fewer than two or where they were sized from
    different fits. Two terms can share what one form outside the library does: a power-law
    spring (p = 4.68) named as a cubic spring and a mass error, each's own force not the
    law's, their sum along the smoothed states 0.00493 N against the law's 0.00497."""
    if len(named) < 2 or named[0].samples is None:
        return None
    first = named[0]
    if any(e.samples is not first.samples or e.sized is not first.sized for e in named):
        return None
    return term_force_rms(problem, first.sized or first.structure, first.samples,
                          [e.term for e in named], record_input=record_input)
