"""The physics library as text (``harvester terms``): the base equation, each term's kind,
equation, parameters with units and priors (on the paper's rig, with how they scale to another
device and why), and how model expressions are written."""

from __future__ import annotations

from collections.abc import Iterable, Mapping

from harvester.model.structures import STRUCTURES
from harvester.model.terms import BASE_PARAMETERS, Parameter, Term

BASE_EQUATION = "M z'' + c_m z' + k z + f = -m y''  (z = x - y; a force input F: = F)"


def _prior(p: Parameter) -> str:
    spec = p.prior_on()
    scale = p.prior.scale if isinstance(p.prior.scale, str) else (
        "device" if p.prior.scale is not None else "")
    return spec.describe() + (f" (scales with {scale})" if scale else "")


def parameter_rows(parameters: Iterable[Parameter]) -> list[str]:
    """Per parameter: name, unit, prior on the paper's rig, description, and why that prior."""
    params = list(parameters)
    width = max((len(p.name) for p in params), default=0)
    unit_w = max((len(p.unit) for p in params), default=0)
    out = []
    for p in params:
        out.append(f"    {p.name:<{width}}  {p.unit:<{unit_w}}  {p.description}")
        out.append(f"    {'':<{width}}  {'':<{unit_w}}  prior: {_prior(p)}")
        if p.prior.why:
            out.append(f"    {'':<{width}}  {'':<{unit_w}}  why: {p.prior.why}")
    return out


def terms_text(terms: Mapping[str, Term]) -> str:
    """The library as readable text, terms in alphabetical order."""
    lines = ["Base equation (eq. 1 of Green et al. 2015):", f"    {BASE_EQUATION}",
             "  parameters (name, unit, description; prior on the paper's rig):",
             *parameter_rows(BASE_PARAMETERS), ""]
    for name in sorted(terms):
        t = terms[name]
        refines = f"; refines {', '.join(t.refines)}" if t.refines else ""
        lines += [f"{t.name} ({t.kind}{refines}): {t.description}", f"    {t.equation}",
                  *parameter_rows(t.parameters), ""]
    lines += [("Model expressions: a base structure and terms joined by '+', e.g. "
               "tanh+cubic_stiffness."),
              "  base structures: " + ", ".join(f"{k} ({' + '.join(v) or 'no term'})"
                                                for k, v in STRUCTURES.items())]
    return "\n".join(lines)
