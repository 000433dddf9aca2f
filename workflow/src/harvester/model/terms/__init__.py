"""The library of physics: named terms that a model structure composes.

Every structure shares the base equation of motion, eq. (1) of Green et al. (2015),

    M z'' + c_m z' + k z + f(z') = -m y'',        z = x - y,

with c_m the translational viscous coefficient (N s/m). A term adds one named effect. Each
term is one object in one file of this package (``model/terms/<name>.py``, a module-level
``TERM``), holding everything about it: its parameters with units and priors (written in the
device's own scales, ``harvester.model.priors``, so that they travel to any device; why each
is plausible is the module docstring's last section, ``Priors:``), its equation, its force
law (plain arithmetic that ``harvester.model.codegen`` compiles into each structure's
kernel), the bound on its stiffness that sets the integrator's step, its probe (how the
diagnosis switches a little of it on to see its signature) and its description. The registry
(:data:`TERMS`) collects every module of the package and refuses a term that lacks any of
these (:func:`register`); ``docs/adding-a-term.md`` walks through adding one.

Sign convention: a positive force opposes positive z or z' (it is added to the left-hand side
of eq. 1). Kinds of term and the signature of their force law:

``screw``     f = force(w, *params) on the ball-screw side, w its velocity (w = z' unless
              the structure has a ``coupling``); with internal states h:
              f = force(w, *h, *params), h' = state_rates(w, *h, *params); states that
              follow the path of the screw's displacement alone (rate-independent
              hysteresis) may give h -> displacement_update(h, dx, *params), their exact
              value after a monotone displacement dx, which the integrator then uses
``mass``      f = force(z, *params) on the mass, a function of its displacement
``inertia``   (M, m) = masses(M, m, *params): changes the effective and oscillating masses
``mode``      a secondary mode with states (u, u'): f = force(u, u', *params) on the mass,
              (u', u'') = state_rates(u, u', a, y'', *params), a the mass's z''; its
              ``masses`` take the modal mass out of the rigid part's
``coupling``  a dead zone between the mass and the screw-side inertia (states d, d'):
              f_b = force(d, d', M, m, *params) transmitted between them
``ground``    f = force(x', *params) on the mass, x' = z' + y' its own (absolute) velocity: a
              contact fixed to the ground (Marino and Cicirello's frame), beside what acts
              on the base; y' is the base acceleration's integral less its linear trend
              (``harvester.model.simulate.base_velocity``), 0 with a force input (the base
              is the ground there)
``stick``     dry friction that holds, on the screw-side velocity w: while sliding,
              f = sgn(w) force(|w|, *params) (the magnitude at speed |w| >= 0); stuck
              (w = 0 exactly) while the force it must supply stays within the holding level
              static(*params) (N). The stick terms of a structure add their magnitudes and
              their levels; the integrator switches between the stuck and sliding equations
              at events located within the step (``harvester.model.codegen``,
              ``docs/sticking-friction.md``)
"""

from __future__ import annotations

import importlib
import importlib.util
import pkgutil
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from types import ModuleType

import numpy as np

from harvester.model.priors import REFERENCE_DEVICE, DeviceScale, Prior, PriorSpec

#: Regularising velocity (m/s) for sign-like friction laws: sgn(v) ~ tanh(v / V_EPS).
V_EPS = 1.0e-3
#: Largest velocity (m/s) assumed when bounding stiffness for step control.
V_BOUND = 1.0
#: Largest displacement per unit of that velocity (s): a motion whose speed stays below v_bound
#: moves at most v_bound / (2 pi f) at frequency f; 1 / (2 pi 0.5 Hz), the lowest frequency a
#: record of these devices resolves (below it the spring k holds the mass). 1 m/s: 0.32 m.
Z_PER_V = 1.0 / (2.0 * np.pi * 0.5)
Z_BOUND = Z_PER_V * V_BOUND

KINDS = ("screw", "mass", "inertia", "mode", "coupling", "stick", "ground")

#: The device quantities a sidecar may state that a term may imply (``Term.device``).
DEVICE_QUANTITIES = ("M", "m", "k")

#: The heading of a term module's docstring section that gives each prior's reasoning.
PRIORS_HEADING = "Priors:"


@dataclass(frozen=True)
class Parameter:
    """A physical parameter: its unit, its prior (in the device's scales) and what it is."""

    name: str
    unit: str
    prior: Prior
    description: str = ""

    def prior_on(self, device: DeviceScale = REFERENCE_DEVICE) -> PriorSpec:
        """The parameter's prior on a device (the reference device: its default)."""
        return self.prior.spec(self.name, self.unit, device)


#: A grid of shape values (parameter -> value) from the device's scales.
ShapeGrid = Callable[[DeviceScale], list[dict[str, float]]]


@dataclass(frozen=True)
class Probe:
    """How the diagnosis switches on a small amount of a term to see its signature.

    strength: the parameter whose zero switches the effect off; amount(device): the probe
    strength; signed: the strength may be negative (two-sided test); shapes(device): grid of
    the term's other parameters (others at their prior's centre); reference: "baseline" (effect
    off = the baseline itself) or "zero" (the term kept with strength 0, when zero strength
    still changes the structure, as a backlash coupling does); amount_is_shape: the strength
    itself is scanned (backlash clearance). ``start_shape``: a shape parameter whose
    posterior is a peak too narrow for a few hundred prior draws to hit (a resonance's
    frequency): the candidate's TMCMC starts part of its particles where the detection's scan
    places it.
    """

    strength: str
    amount: Callable[[DeviceScale], float]
    signed: bool = False
    shapes: ShapeGrid = field(default=lambda d: [{}])
    reference: str = "baseline"
    amount_is_shape: bool = False
    start_shape: str | None = None


@dataclass(frozen=True)
class RateBound:
    """A term's share of the bound on the fastest rate of the equations (``step_rates``):
    damping added to d force / d velocity (N s/m), stiffness added to d force / d
    displacement (N/m), and a rate of its own (1/s), each per particle."""

    damping: np.ndarray | float = 0.0
    stiffness: np.ndarray | float = 0.0
    rate: np.ndarray | float = 0.0


@dataclass(frozen=True)
class Motion:
    """What a rate bound may know of the motion: the effective and oscillating masses (kg,
    after any ``inertia`` term) and the largest velocity (m/s) and displacement (m)."""

    mass: np.ndarray
    m_osc: np.ndarray
    v_bound: float = V_BOUND
    z_bound: float = Z_BOUND


@dataclass(frozen=True)
class Term:
    """A named effect: parameters, equation, compiled force law and its step bound.

    ``force`` (and ``state_rates``, ``masses``) are plain functions of floats, in the
    signature of the term's ``kind`` (module docstring), using only arithmetic and
    ``harvester.model.fastmath`` so that the compiler vectorises them. ``rate_bound(p,
    motion)`` gets the parameters as a dict of arrays (one value per particle) and returns a
    :class:`RateBound`. ``probe``: how the diagnosis sees the term (:class:`Probe`).
    ``refines``: a refinement of one of these terms' laws, meaningless without one of them (a
    Stribeck excess is over a sliding friction): a candidate only where one is in the
    structure. ``alike``: terms that describe the same physics in another form (a tanh law and
    Coulomb friction): naming either is naming the effect (:func:`same_physics`). ``n_states``:
    internal states the term adds. ``displacement_update`` (a ``screw`` term with one state
    whose law is rate-independent): the state after a monotone screw displacement dx, exact,
    so that the integrator advances the state by it and the state's own relaxation rate does
    not bound the step. ``limits``: (parameter, 'lower' | 'upper', term): at that bound of the
    parameter's prior the term stands for another (a pre-sliding displacement below what the
    data resolve is Coulomb friction; a mode far above the band is a mass). A posterior piled
    there is not trusted, and the diagnosis samples the other term in its place.
    ``nameable``: False for a shape of the missing force's dictionary fitted as a term
    (``diagnosis.size.shape_terms``): it describes what the library lacks and is never a
    candidate the diagnosis names. ``device``: the device quantities a sidecar states (M, m,
    k, :data:`DEVICE_QUANTITIES`) that the term's parameters change, as a function of every
    parameter's value (a mapping; arrays over posterior draws) returning {quantity: value}:
    an inertia error's M + dM and m + m_share dM. The diagnosis holds them against the
    sidecar (``diagnosis.name.plausibility``); None: the term implies none of them.
    ``restates``: device quantities (of :data:`DEVICE_QUANTITIES`) that the term only
    restates (a mass error: M and m): where the baseline identifies every one of them the
    recording depends on (none given), the term adds no physics, its gain being those
    quantities' prior conflict, and it is not a candidate (``diagnosis.prepare.redundant``).
    ``resolved``: parameters that are displacements (m) the record must resolve for the term
    to be its physics (a pre-sliding displacement): where the posterior puts one below the
    smallest displacement the record tells from its noise, the term is taken at that
    parameter's lower limit (``limits``), not named (``diagnosis.name.limits.unresolved``).
    ``in_band``: parameters that are frequencies (Hz) of a resonance the record must show:
    where the posterior puts one above the band the likelihood compares, the record holds no
    peak of it and the term is not named (``diagnosis.name.limits.beyond_band``).
    ``unprobed``: the score test cannot see the term (a law with memory: its probe's loop, at
    a guessed pre-sliding displacement and a small strength, can point away from a loop the
    record holds). ``catch_all``: a term flexible enough to stand for physics the round did
    not fit (a mass error scales the whole inertial force, a mode adds a resonance anywhere in
    the band): a round whose screen it leads fits the ``unprobed`` terms before judging it
    (``diagnosis.name.rank.behind_catch_all``).
    ``static`` (a ``stick`` term): its share of the holding level (N), a function of its
    parameters. ``transition`` (a ``stick`` term whose law changes fast at low speed, a
    Stribeck decay): (speed, slope) = transition(*params), the speed (m/s) below which the
    law changes and its steepest slope there (N s/m); the integrator cuts its sub-steps to
    that slope only while sliding slower (``harvester.model.stick``), so ``rate_bound`` leaves
    it out.
    """

    name: str
    kind: str
    parameters: tuple[Parameter, ...]
    equation: str
    description: str
    force: Callable
    rate_bound: Callable[[dict, Motion], RateBound]
    probe: Probe
    n_states: int = 0
    state_rates: Callable | None = None
    masses: Callable | None = None
    displacement_update: Callable | None = None
    static: Callable | None = None
    transition: Callable | None = None
    refines: tuple[str, ...] = ()
    alike: tuple[str, ...] = ()
    limits: tuple[tuple[str, str, str], ...] = ()
    resolved: tuple[str, ...] = ()
    in_band: tuple[str, ...] = ()
    unprobed: bool = False
    catch_all: bool = False
    restates: tuple[str, ...] = ()
    nameable: bool = True
    device: Callable[[Mapping], dict] | None = None
    source: str = field(default="", compare=False)  # the file that defines the term

    def limit(self, parameter: str, side: str) -> str | None:
        """The term this one stands for where ``parameter`` piles against ``side`` of its
        prior (``limits``: the first listed), or None."""
        return next(iter(self.limit_terms(parameter, side)), None)

    def limit_terms(self, parameter: str, side: str) -> tuple[str, ...]:
        """Every term this one stands for at that bound, in the order ``limits`` lists them
        (a pre-sliding displacement of nothing: friction that sticks, or a sign law)."""
        return tuple(t for p, s, t in self.limits if (p, s) == (parameter, side))

    @property
    def parameter_names(self) -> tuple[str, ...]:
        return tuple(p.name for p in self.parameters)


#: Eq. (1)'s own parameters, with the paper's rig's Table 1 values as default priors (a
#: recording's initial modelling replaces them: ``harvester.initial``).
BASE_PARAMETERS: tuple[Parameter, ...] = (
    Parameter("M", "kg", Prior("normal", 12.8, 1.0),
              "effective mass m + J (2 pi / l)^2, eq. (2)"),
    Parameter("m", "kg", Prior("normal", 8.0, 0.5), "oscillating mass"),
    Parameter("k", "N/m", Prior("normal", 250.0, 25.0), "spring stiffness"),
    Parameter("c_m", "N s/m", Prior("normal", 170.0, 50.0),
              "translational viscous damping b_m, eq. (3)"),
)

#: Laws of sliding friction (Dahl's saturates to Coulomb's): what a Stribeck excess or a
#: direction-dependent part refines.
SLIDING_FRICTION: tuple[str, ...] = ("tanh_friction", "coulomb_friction", "hysteresis")
#: Laws of dry friction that hold (``stick`` kind): what a sticking Stribeck excess refines.
STICKING_FRICTION: tuple[str, ...] = ("sticking_friction",)


def is_friction(t: Term) -> bool:
    """Whether a term is a friction law: a sliding law (``SLIDING_FRICTION``, Dahl's
    pre-sliding ``hysteresis`` among them; ``STICKING_FRICTION``), a refinement of one
    (Stribeck, asymmetry) or a contact on the ground (``ground``)."""
    sliding = SLIDING_FRICTION + STICKING_FRICTION
    return t.kind == "ground" or t.name in sliding or bool(set(t.refines) & set(sliding))


def check_term(t: Term) -> None:
    """ValueError naming what a term lacks (the registry's conditions)."""
    problems = []
    if t.kind not in KINDS:
        problems.append(f"kind {t.kind!r} is not one of {KINDS}")
    for what in ("equation", "description"):
        if not getattr(t, what):
            problems.append(f"no {what}")
    if not callable(t.force) or not callable(t.rate_bound):
        problems.append("force and rate_bound must be functions")
    if not isinstance(t.probe, Probe) or t.probe.strength not in t.parameter_names:
        problems.append("a probe (Probe) whose strength is one of its parameters")
    needs_rates = t.kind == "mode" or (t.kind == "screw" and t.n_states > 0)
    if needs_rates and not callable(t.state_rates):
        problems.append("a term with internal states needs state_rates")
    if t.displacement_update is not None and not (
            t.kind == "screw" and t.n_states == 1 and callable(t.displacement_update)):
        problems.append("displacement_update is for a screw term with one state")
    if (t.kind == "stick") != callable(t.static):
        problems.append("a stick term, and only one, gives static (its holding level)")
    if t.transition is not None and t.kind != "stick":
        problems.append("transition is for a stick term")
    if t.kind in ("stick", "ground") and t.n_states:
        problems.append(f"a {t.kind} term has no states of its own")
    if t.kind in ("inertia", "mode") and not callable(t.masses):
        problems.append(f"an {t.kind} term needs masses")
    if t.device is not None and not callable(t.device):
        problems.append("device must be a function of the parameters' values")
    if t.kind in ("mode", "coupling") and t.n_states != 2:
        problems.append(f"a {t.kind} term has 2 states, not {t.n_states}")
    for p in t.parameters:
        if not p.unit or not p.description or not isinstance(p.prior, Prior) or not p.prior.why:
            problems.append(f"parameter {p.name} needs a unit, a description and a Prior with "
                            f"its reasoning (why: an entry of the module docstring's "
                            f"{PRIORS_HEADING} section)")
            continue
        try:
            p.prior_on()
        except ValueError as err:
            problems.append(f"parameter {p.name}: {err}")
    names = [p.name for p in t.parameters]
    if not set(t.resolved) <= {p.name for p in t.parameters if p.unit == "m"}:
        problems.append(f"resolved {t.resolved}: parameters of the term in metres")
    if not set(t.in_band) <= {p.name for p in t.parameters if p.unit == "Hz"}:
        problems.append(f"in_band {t.in_band}: parameters of the term in Hz")
    for parameter, side, other in t.limits:
        if parameter not in names or side not in ("lower", "upper") or other == t.name:
            problems.append(f"limit ({parameter}, {side}, {other}): a parameter of the term, "
                            "'lower' or 'upper', and another term")
    bad = [n for n in names if not n.isidentifier() or n.startswith("_")]
    if bad:
        problems.append(f"parameter names {bad} must be identifiers not starting with '_'")
    if len(set(names)) != len(names):
        problems.append("repeated parameter names")
    if problems:
        raise ValueError(f"physics term {t.name!r} ({t.source}): " + "; ".join(problems))


#: All terms by name (filled by :func:`register` from the modules of this package).
TERMS: dict[str, Term] = {}


def register(t: Term) -> Term:
    """Add a term to the library after :func:`check_term`; a name may be registered once."""
    check_term(t)
    clash = [p for p in t.parameter_names for o in TERMS.values() if o.name != t.name
             and p in o.parameter_names] + [p for p in t.parameter_names
                                            if p in {b.name for b in BASE_PARAMETERS}]
    if clash:
        raise ValueError(f"physics term {t.name!r}: parameter names {sorted(set(clash))} are "
                         "already taken (names must be unique across the library)")
    if t.name in TERMS and TERMS[t.name] is not t:
        raise ValueError(f"physics term {t.name!r} is registered twice")
    TERMS[t.name] = t
    return t


def prior_reasons(doc: str | None, where: str = "") -> dict[str, str]:
    """The reasoning of each parameter's prior from a module docstring's section that starts
    with a line ``Priors:`` and runs to the docstring's end: an entry per parameter,
    ``- name: reasoning``, its continuation lines indented. ``{}`` without the section."""
    lines = (doc or "").splitlines()
    heads = [i for i, line in enumerate(lines) if line.strip() == PRIORS_HEADING]
    if not heads:
        return {}
    reasons: dict[str, list[str]] = {}
    entry: list[str] | None = None  # the entry that continuation lines extend
    for number, line in enumerate(lines[heads[0] + 1:], heads[0] + 2):
        text = line.strip()
        if text.startswith("- ") and ":" in text:
            name, first = text[2:].split(":", 1)
            entry = reasons[name.strip().strip("`")] = [first.strip()]
        elif text and entry is not None and line.startswith(" "):
            entry.append(text)
        elif text:
            raise ValueError(f"{where}: line {number} of the docstring's {PRIORS_HEADING} "
                             f"section reads {text[:40]!r}; expected '- <parameter>: "
                             "<reasoning>' or an indented continuation")
    return {name: " ".join(parts) for name, parts in reasons.items()}


def with_reasons(t: Term, doc: str | None) -> Term:
    """The term with each prior's ``why`` read from its module docstring (:func:`prior_reasons`);
    a reason for a parameter the term does not have, or given twice, is an error."""
    reasons = prior_reasons(doc, t.source or t.name)
    unknown = sorted(set(reasons) - set(t.parameter_names))
    twice = sorted(p.name for p in t.parameters if p.name in reasons and p.prior.why)
    if unknown or twice:
        raise ValueError(f"physics term {t.name!r} ({t.source}): the docstring's "
                         f"{PRIORS_HEADING} section names {unknown or twice}, which "
                         + ("are not its parameters" if unknown else "already have a why="))
    parameters = tuple(replace(p, prior=replace(p.prior, why=reasons[p.name]))
                       if p.name in reasons else p for p in t.parameters)
    return replace(t, parameters=parameters)


def _register_module(module: ModuleType, stem: str) -> Term:
    """Register a term module's ``TERM``, which must be named for the file (``<stem>.py``),
    with its priors' reasoning from the module docstring (:func:`with_reasons`)."""
    t = getattr(module, "TERM", None)
    if not isinstance(t, Term):
        raise ValueError(f"{module.__file__} defines no TERM (a harvester.model.terms.Term)")
    if t.name != stem:
        raise ValueError(f"{module.__file__} defines the term {t.name!r}; the file must be "
                         f"named for it ({t.name}.py)")
    module.TERM = with_reasons(t, module.__doc__)
    return register(module.TERM)


def _discover() -> None:
    """Register every module of this package (a new file here is a new term)."""
    for info in sorted(pkgutil.iter_modules(__path__), key=lambda m: m.name):
        _register_module(importlib.import_module(f"{__name__}.{info.name}"), info.name)


def load_term_file(path: str | Path) -> Term:
    """Register the term of a file outside this package (``<name>.py`` defining ``TERM``),
    with the checks the package's own terms pass; returns it. For a term kept beside a
    project rather than in ``model/terms/`` (``docs/adding-a-term.md``)."""
    path = Path(path)
    spec = importlib.util.spec_from_file_location(f"harvester_term_{path.stem}", path)
    if spec is None or spec.loader is None:
        raise ValueError(f"{path}: not a Python file")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return _register_module(module, path.stem)


def same_physics(a: str, b: str) -> bool:
    """Whether two terms describe the same physics (equal, or ``alike`` either way)."""
    return a == b or b in TERMS[a].alike or a in TERMS[b].alike


def term(name: str) -> Term:
    """Look up a term by name, with the list of known names on error."""
    try:
        return TERMS[name]
    except KeyError:
        raise KeyError(f"unknown physics term {name!r}; known: {sorted(TERMS)}") from None


def step_rates(terms: tuple[Term, ...], params: dict[str, np.ndarray],
               v_bound: float | None = None) -> np.ndarray:
    """Per-particle bound on the fastest rate (1/s) of the equations of motion.

    ``params`` maps every parameter of the base and the terms to an array (one value per
    particle); ``v_bound`` (m/s): the largest velocity assumed for velocity-dependent rates
    (quadratic damping), and Z_PER_V x it the largest displacement (a cubic
    spring); None: V_BOUND. A caller that knows the motion gives
    a tighter one. The largest of: damping rate (d force / d velocity) / mass, natural
    frequency sqrt(stiffness / mass) of every spring, contact and mode, and each term's own
    rate. Used only to choose the integrator's sub-step.
    """
    mass, m_osc = np.abs(params["M"]), np.abs(params["m"])
    for t in terms:
        if t.masses is not None:
            mass, m_osc = t.masses(mass, m_osc, *(params[n] for n in t.parameter_names))
    v = V_BOUND if v_bound is None else v_bound
    motion = Motion(np.maximum(mass, 1e-3), m_osc, v, Z_PER_V * v)
    damp, stiff = np.abs(params["c_m"]).copy(), np.abs(params["k"]).copy()
    rate = np.zeros_like(damp)
    for t in terms:
        b = t.rate_bound({n: params[n] for n in t.parameter_names}, motion)
        damp = damp + b.damping
        stiff = stiff + b.stiffness
        rate = np.maximum(rate, b.rate)
    return np.maximum.reduce([rate, damp / motion.mass, np.sqrt(stiff / motion.mass)])


_discover()
