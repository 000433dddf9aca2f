"""The physics library as text (``harvester terms``): the base equation, each term's kind,
equation, parameters with units and default priors, and how model expressions are written."""

from __future__ import annotations

from collections.abc import Iterable, Mapping

from harvester.model.structures import STRUCTURES
from harvester.model.terms import BASE_PARAMETERS, Parameter, Term

BASE_EQUATION = "M z'' + c_m z' + k z + f = -m y''  (z = x - y; a force input F: = F)"


def _prior(p: Parameter) -> str:
    lower = "" if p.lower is None else f", >= {p.lower:g}"
    return f"N({p.prior_mean:g}, {p.prior_sd:g}^2{lower})"


def parameter_rows(parameters: Iterable[Parameter]) -> list[str]:
    """One aligned line per parameter: name, unit, default prior, description."""
    params = list(parameters)
    width = max((len(p.name) for p in params), default=0)
    unit_w = max((len(p.unit) for p in params), default=0)
    prior_w = max((len(_prior(p)) for p in params), default=0)
    return [f"    {p.name:<{width}}  {p.unit:<{unit_w}}  {_prior(p):<{prior_w}}  "
            f"{p.description}" for p in params]


def terms_text(terms: Mapping[str, Term]) -> str:
    """The library as readable text, terms in alphabetical order."""
    lines = ["Base equation (eq. 1 of Green et al. 2015):", f"    {BASE_EQUATION}",
             "  parameters (name, unit, default prior: Gaussian truncated below, description):",
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
