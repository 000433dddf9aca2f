"""The library of physics: named terms that a model structure composes.

Every structure shares the base equation of motion, eq. (1) of Green et al. (2015),

    M z'' + c_m z' + k z + f(z') = -m y'',        z = x - y,

with c_m the translational viscous coefficient (N s/m). A term adds one named effect with its
own parameters, units and default prior. The force laws themselves live in ``simulate.py``
(compiled); each term here carries the integer code that selects its law there, so a new term
is one entry in :data:`TERMS` and one branch in the compiled right-hand side.

Sign convention: a positive force opposes positive z or z' (it is added to the left-hand side
of eq. 1). "Screw-side" forces act on the ball-screw velocity w (w = z' unless there is
backlash); "mass-side" forces act on the mass displacement z.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

#: Regularising velocity (m/s) for sign-like friction laws: sgn(v) ~ tanh(v / V_EPS).
V_EPS = 1.0e-3
#: Largest velocity (m/s) and displacement (m) assumed when bounding stiffness for step control.
V_BOUND = 1.0
Z_BOUND = 0.3


@dataclass(frozen=True)
class Parameter:
    """A physical parameter with its unit and default prior (Gaussian, truncated below)."""

    name: str
    unit: str
    prior_mean: float
    prior_sd: float
    lower: float | None = 0.0
    description: str = ""


@dataclass(frozen=True)
class Term:
    """A named effect: parameters, number of internal states, compiled law code."""

    name: str
    code: int
    parameters: tuple[Parameter, ...]
    n_states: int = 0
    equation: str = ""
    description: str = ""
    kind: str = "screw"  # "screw", "mass", "inertia", "mode" or "coupling"
    #: A refinement of one of these terms' laws, meaningless without one of them (a Stribeck
    #: excess is over a sliding friction): a candidate only where one is in the structure.
    refines: tuple[str, ...] = ()

    @property
    def parameter_names(self) -> tuple[str, ...]:
        return tuple(p.name for p in self.parameters)


BASE_PARAMETERS: tuple[Parameter, ...] = (
    Parameter("M", "kg", 12.8, 1.0, 0.0, "effective mass m + J (2 pi / l)^2, eq. (2)"),
    Parameter("m", "kg", 8.0, 0.5, 0.0, "oscillating mass"),
    Parameter("k", "N/m", 250.0, 25.0, 0.0, "spring stiffness"),
    Parameter("c_m", "N s/m", 170.0, 50.0, 0.0, "translational viscous damping b_m, eq. (3)"),
)

#: Laws of sliding friction (Dahl's saturates to Coulomb's): what a Stribeck excess or a
#: direction-dependent part refines.
SLIDING_FRICTION: tuple[str, ...] = ("tanh_friction", "coulomb_friction", "hysteresis")

_TERMS: tuple[Term, ...] = (
    Term("tanh_friction", 1, (
        Parameter("F_c", "N", 8.4, 5.0, 0.0, "friction force amplitude"),
        Parameter("beta", "s/m", 100.0, 100.0, 0.0, "steepness at velocity reversal"),
    ), equation="f = F_c tanh(beta w)", description="hyperbolic tangent friction (Table 4)"),
    Term("coulomb_friction", 2, (
        Parameter("F_coulomb", "N", 8.4, 5.0, 0.0, "Coulomb friction force"),
    ), equation="f = F_coulomb sgn(w), sgn regularised as tanh(w / 1 mm/s)",
        description="Coulomb (dry) friction"),
    Term("stribeck_friction", 3, (
        Parameter("F_stribeck", "N", 2.0, 2.0, 0.0, "excess of breakaway over sliding friction"),
        Parameter("v_stribeck", "m/s", 0.02, 0.02, 1e-4, "Stribeck velocity"),
    ), equation="f = F_stribeck exp(-(w / v_stribeck)^2) sgn(w)",
        description="Stribeck effect: friction falls from breakaway as sliding speeds up",
        refines=SLIDING_FRICTION),
    Term("asymmetric_friction", 4, (
        Parameter("F_asym", "N", 0.0, 2.0, None, "half the difference of down- and up-going friction"),
    ), equation="f = F_asym sgn(w)^2",
        description="direction-dependent friction (gravity preload on a vertical screw)",
        refines=SLIDING_FRICTION),
    Term("quadratic_damping", 5, (
        Parameter("c_quad", "N s^2/m^2", 0.0, 200.0, 0.0, "quadratic damping coefficient"),
    ), equation="f = c_quad w |w|", description="velocity-squared (fluid-like) damping"),
    Term("cubic_stiffness", 6, (
        Parameter("k_cubic", "N/m^3", 0.0, 2000.0, None, "cubic stiffness coefficient"),
    ), equation="f = k_cubic z^3", description="hardening/softening spring", kind="mass"),
    Term("end_stop", 7, (
        Parameter("gap_stop", "m", 0.05, 0.03, 0.0, "clearance before contact"),
        Parameter("k_stop", "N/m", 5000.0, 3000.0, 0.0, "contact stiffness"),
    ), equation="f = k_stop (|z| - gap_stop)_+ sgn(z)", description="end stop beyond a clearance",
        kind="mass"),
    Term("backlash", 8, (
        Parameter("gap_backlash", "m", 1e-5, 1e-5, 0.0,
                  "half dead zone in the screw-nut coupling (axial play of an unloaded ball "
                  "nut: a few to tens of micrometres)"),
        Parameter("k_backlash", "N/m", 1e7, 1e7, 1e6,
                  "axial contact stiffness of the screw-nut coupling (ball nuts: 1e7-1e9)"),
    ), n_states=2, equation="coupling force F_b = k_backlash dz(d, gap) + c_b d' in contact "
                            "(compressive only), c_b at damping ratio 0.5 on m J / (m + J); "
                            "J r'' = F_b - c_m r' - f(r')",
        description="dead zone between the mass and the screw-side inertia", kind="coupling"),
    Term("hysteresis", 9, (
        Parameter("F_hyst", "N", 2.0, 2.0, 1e-3, "saturation force of the pre-sliding branch"),
        Parameter("k_hyst", "N/m", 2e4, 2e4, 1.0, "pre-sliding (bristle) stiffness"),
    ), n_states=1, equation="Dahl: h' = k_hyst (w - |w| h / F_hyst), f = h",
        description="pre-sliding friction with memory (Dahl model)"),
    Term("unmodelled_mode", 10, (
        Parameter("f_mode", "Hz", 5.0, 3.0, 0.1, "natural frequency of the secondary mode"),
        Parameter("zeta_mode", "-", 0.05, 0.05, 1e-3, "damping ratio of the secondary mode"),
        Parameter("mass_mode", "kg", 0.5, 0.5, 0.0, "modal mass of the secondary mode"),
        Parameter("drive_base", "-", 0.5, 0.5, 0.0,
                  "share of the base acceleration in the mode's drive: 1 for a mode attached "
                  "to the mass (driven by its absolute acceleration x'' = z'' + y''), 0 for "
                  "one on the screw side (a rotor on a flexible coupling, driven by z'')"),
    ), n_states=2,
        equation="u'' + 2 zeta w_n u' + w_n^2 u = -(z'' + drive_base y''), force on the mass "
                 "m_2 (w_n^2 u + 2 zeta w_n u')",
        description="secondary resonance inside the band, on the mass or the screw side",
        kind="mode"),
    Term("offset_force", 12, (
        Parameter("F_offset", "N", 0.0, 5.0, None, "constant force (gravity, cable, bias)"),
    ), equation="f = F_offset", description="constant force offset", kind="mass"),
    Term("inertia_error", 11, (
        Parameter("dM", "kg", 0.0, 1.0, None, "error of the assumed effective mass"),
        Parameter("m_share", "-", 0.5, 0.5, 0.0,
                  "share of dM on the oscillating mass, which also drives the device (-m y''): "
                  "1 for a payload error, 0 for an error of the screw-side inertia "
                  "J (2 pi / l)^2 alone, above 1 when the two errors differ in sign"),
    ), equation="M -> M + dM, m -> m + m_share dM (eq. 2: M = m + J (2 pi / l)^2)",
        description="effective mass differs from the assumed value", kind="inertia"),
)

#: All terms by name.
TERMS: dict[str, Term] = {t.name: t for t in _TERMS}


def term(name: str) -> Term:
    """Look up a term by name, with the list of known names on error."""
    try:
        return TERMS[name]
    except KeyError:
        raise KeyError(f"unknown physics term {name!r}; known: {sorted(TERMS)}") from None


@dataclass(frozen=True)
class Layout:
    """Where each term's parameters and internal states sit in the packed arrays."""

    terms: tuple[Term, ...]
    codes: np.ndarray = field(repr=False)
    param_offsets: np.ndarray = field(repr=False)
    state_offsets: np.ndarray = field(repr=False)
    parameter_names: tuple[str, ...]
    n_states: int

    @classmethod
    def of(cls, term_names: tuple[str, ...] | list[str]) -> "Layout":
        terms = tuple(term(n) for n in term_names)
        names = [p.name for p in BASE_PARAMETERS]
        codes, p_off, s_off = [], [], []
        n_states = 2
        for t in terms:
            codes.append(t.code)
            p_off.append(len(names))
            s_off.append(n_states)
            names.extend(t.parameter_names)
            n_states += t.n_states
        if len(set(names)) != len(names):
            raise ValueError(f"terms {term_names} repeat a parameter name")
        return cls(terms, np.array(codes, dtype=np.int64), np.array(p_off, dtype=np.int64),
                   np.array(s_off, dtype=np.int64), tuple(names), n_states)

    def index(self, name: str) -> int:
        return self.parameter_names.index(name)


def step_rates(layout: Layout, params: np.ndarray, v_bound: float | None = None) -> np.ndarray:
    """Per-particle bound on the fastest rate (1/s) of the equations of motion.

    ``v_bound`` (m/s): the largest velocity assumed for the velocity-dependent rates (Dahl
    relaxation, quadratic damping); None: V_BOUND. A caller that knows the motion gives a
    tighter one.

    The largest of: damping rate (d force / d velocity) / mass, natural frequency
    sqrt(stiffness / mass) of every spring, contact, coupling and secondary mode, and the
    relaxation rate of internal friction states. Used only to choose the integrator's sub-step.
    """
    p = np.atleast_2d(np.asarray(params, dtype=float))
    v_bound = V_BOUND if v_bound is None else v_bound
    mass, m_osc = np.abs(p[:, 0]), np.abs(p[:, 1])
    for t, o in zip(layout.terms, layout.param_offsets):
        if t.name == "inertia_error":  # as the compiled right-hand side: M + dM, m + m_share dM
            mass, m_osc = mass + p[:, o], m_osc + p[:, o + 1] * p[:, o]
    mass = np.maximum(mass, 1e-3)
    damp = np.abs(p[:, 3]).copy()
    stiff = np.abs(p[:, 2]).copy()
    rate = np.zeros(p.shape[0])
    for t, o in zip(layout.terms, layout.param_offsets):
        a = np.abs(p[:, o])
        if t.name == "tanh_friction":
            damp += a * np.abs(p[:, o + 1])
        elif t.name in ("coulomb_friction", "asymmetric_friction"):
            damp += 2.0 * a / V_EPS
        elif t.name == "stribeck_friction":
            damp += a / V_EPS + 2.0 * a / np.maximum(np.abs(p[:, o + 1]), 1e-6)
        elif t.name == "quadratic_damping":
            damp += 2.0 * a * v_bound
        elif t.name == "cubic_stiffness":
            stiff += 3.0 * a * Z_BOUND**2
        elif t.name == "end_stop":
            stiff += np.abs(p[:, o + 1])
        elif t.name == "backlash":
            m = np.maximum(np.abs(m_osc), 1e-3)
            j = np.maximum(mass - m, 1e-3)
            reduced = m * j / (m + j)
            # x8: the contact switches on and off and RK4 drops to first order at each touch
            # (x4 left 1.2 % error in z'' through a 20 Hz low-pass in a rattling case, x8 0.3 %)
            rate = np.maximum(rate, 8.0 * np.sqrt(np.abs(p[:, o + 1]) / reduced))
            rate = np.maximum(rate, damp / j)
        elif t.name == "hysteresis":
            stiff += np.abs(p[:, o + 1])
            rate = np.maximum(rate, np.abs(p[:, o + 1]) * v_bound / np.maximum(a, 1e-6))
        elif t.name == "unmodelled_mode":
            wn = 2 * np.pi * a
            ratio = np.abs(p[:, o + 2]) / mass
            rate = np.maximum(rate, wn * np.sqrt(1 + ratio) * (1 + 2 * np.abs(p[:, o + 1])))
    return np.maximum.reduce([rate, damp / mass, np.sqrt(stiff / mass)])
