"""Model structures: compositions of physics terms, with which parameters are identified.

``linear`` is the paper's M1 (f = 0, "Bayesian equivalent linearisation"); ``tanh`` is M2
(f = F_c tanh(beta z')). The diagnosis extends a structure with further terms by name.
A structure's :class:`Layout` says where each parameter sits in the packed parameter vector
that the simulator takes: eq. (1)'s M, m, k, c_m, then each term's parameters in order.
"""

from __future__ import annotations

from dataclasses import dataclass

from harvester.model.terms import BASE_PARAMETERS, Term, term


@dataclass(frozen=True)
class Layout:
    """The packed parameter vector of a composition of terms (base parameters first)."""

    terms: tuple[Term, ...]
    parameter_names: tuple[str, ...]
    n_states: int

    @classmethod
    def of(cls, term_names: tuple[str, ...] | list[str]) -> "Layout":
        terms = tuple(term(n) for n in term_names)
        if len({t.name for t in terms}) != len(terms):
            raise ValueError(f"terms {list(term_names)} repeat a term")
        if sum(t.kind == "coupling" for t in terms) > 1:
            raise ValueError(f"terms {list(term_names)} hold more than one coupling")
        names = [p.name for p in BASE_PARAMETERS] + [p for t in terms for p in t.parameter_names]
        if len(set(names)) != len(names):
            raise ValueError(f"terms {list(term_names)} repeat a parameter name")
        return cls(terms, tuple(names), 2 + sum(t.n_states for t in terms))

    @property
    def names(self) -> tuple[str, ...]:
        """The terms' names, in order."""
        return tuple(t.name for t in self.terms)

    def index(self, name: str) -> int:
        return self.parameter_names.index(name)


#: The paper's structures (term names added to the base eq. 1).
STRUCTURES: dict[str, tuple[str, ...]] = {
    "linear": (),
    "tanh": ("tanh_friction",),
}

#: Base parameters identified by default; M, m, k are taken as known (Table 1), as in the paper.
DEFAULT_FREE_BASE: tuple[str, ...] = ("c_m",)


@dataclass(frozen=True)
class ModelStructure:
    """A named composition of terms and the list of parameters it identifies."""

    name: str
    terms: tuple[str, ...]
    free_base: tuple[str, ...] = DEFAULT_FREE_BASE

    @property
    def layout(self) -> Layout:
        return Layout.of(self.terms)

    @property
    def free_parameters(self) -> tuple[str, ...]:
        """Identified physical parameters in layout order (sigma comes last, separately)."""
        extra = tuple(p for t in self.terms for p in term(t).parameter_names)
        return self.free_base + extra

    def with_term(self, term_name: str) -> "ModelStructure":
        """The structure with one more term (name ``<self>+<term>``)."""
        term(term_name)
        if term_name in self.terms:
            raise ValueError(f"{self.name} already has {term_name}")
        return ModelStructure(f"{self.name}+{term_name}", self.terms + (term_name,), self.free_base)


def structure(name: str, free_base: tuple[str, ...] = DEFAULT_FREE_BASE) -> ModelStructure:
    """A structure by name: a key of STRUCTURES or ``base+term1+term2``."""
    base, *extra = name.split("+")
    if base not in STRUCTURES:
        raise KeyError(f"unknown model structure {base!r}; known: {sorted(STRUCTURES)}")
    s = ModelStructure(base, STRUCTURES[base], free_base)
    for t in extra:
        s = s.with_term(t)
    return s
