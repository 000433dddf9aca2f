"""The identification problem of a recording: which base parameters are free, whether eq. (1)
can fix their scale, and the :class:`~harvester.inference.likelihood.Problem` itself. Building
a problem needs no sampler, so reading a recording into one does not import PyMC."""

from __future__ import annotations

from collections.abc import Mapping

import pandas as pd

from harvester.data.kinds import model_recording
from harvester.data.recording import input_output
from harvester.inference.likelihood import DAQ_OVERSAMPLE, Problem
from harvester.model.structures import ModelStructure, structure
from harvester.model.terms import BASE_PARAMETERS


def free_base_parameters(model: ModelStructure, known: Mapping[str, float],
                         input_kind: str = "base_acc") -> tuple[str, ...]:
    """Base parameters (M, m, k, c_m) identified for ``model`` given the ``known`` values.

    The structure's own ``free_base`` plus every base parameter that ``known`` does not give
    (the sidecar's unknowns are identified too). For a force input the base is fixed and m
    does not enter eq. (1) (unless the structure has ``backlash``, which splits M into m and
    the screw side), so m is neither identified nor needed.
    """
    needs_m = input_kind == "base_acc" or "backlash" in model.terms
    free = list(model.free_base)
    for p in BASE_PARAMETERS:
        if p.name in free or p.name in known or (p.name == "m" and not needs_m):
            continue
        free.append(p.name)
    return tuple(p.name for p in BASE_PARAMETERS if p.name in free)


def check_identifiable(free_base: tuple[str, ...], input_kind: str) -> None:
    """ValueError if eq. (1) cannot fix the scale of the base parameters.

    With a base-acceleration input, dividing eq. (1) by M leaves only m/M, k/M, c_m/M (and the
    friction forces over M): one base parameter must be known (e.g. m, weighed).
    """
    if input_kind == "base_acc" and set(free_base) >= {"M", "m", "k", "c_m"}:
        raise ValueError("with a base_acc input, eq. (1) fixes only m/M, k/M and c_m/M: give at "
                         "least one of M, m, k, c_m as known (e.g. the weighed mass m)")


def make_problem(recording: pd.DataFrame, model: str | ModelStructure, known: Mapping[str, float],
                 window: tuple[int, int] | None = None, stride: int = 1,
                 output_filter: tuple[float, int] | None = None,
                 oversample: int = DAQ_OVERSAMPLE) -> Problem:
    """The identification problem for a recording (columns time, an input, an output).

    The recording's columns declare the kinds (``harvester.data.recording``): input ``base_acc``
    or ``force`` (a ``base_disp`` is differentiated into ``base_acc`` first,
    ``harvester.data.kinds.model_recording``), output ``rel_acc`` or ``rel_disp``. Base parameters (M, m, k, c_m) missing
    from ``known`` are identified (:func:`free_base_parameters`); their priors come from
    ``harvester.initial.frf.initial_priors``. For a force input a missing m is set to 0
    (it does not enter eq. 1). ``stride``: the likelihood uses every stride-th sample.
    ``output_filter`` (cut-off Hz, order): the zero-phase low-pass the recording went through,
    applied to the simulated output too. ``oversample``: the model's z'' is sampled as a data
    acquisition does (:data:`harvester.inference.likelihood.DAQ_OVERSAMPLE`; 1: point samples).
    """
    s = structure(model) if isinstance(model, str) else model
    recording, _ = model_recording(recording, output_filter[0] if output_filter else None)
    kinds, u, y, dt = input_output(recording)
    free = free_base_parameters(s, known, kinds.input_kind)
    check_identifiable(free, kinds.input_kind)
    if free != s.free_base:
        s = ModelStructure(s.name, s.terms, free)
    known = dict(known)
    if "m" not in free and "m" not in known:
        known["m"] = 0.0
    return Problem(s, u, y, dt, known, window, input_kind=kinds.input_kind,
                   output_kind=kinds.output_kind, stride=stride, output_filter=output_filter,
                   oversample=oversample)
