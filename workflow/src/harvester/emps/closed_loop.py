"""EMPS: the Electro-Mechanical Positioning System benchmark, identified in closed loop.

The EMPS (Janot, Gautier and Brunot 2019; ``data/emps/SOURCE.md``) is a prismatic
joint driven by a DC motor through a ball screw: eq. (1) with a force input, no spring and no
base motion,

    M q'' + Fv q' + Fc sgn(q') + OF = F,        F = gtau vir,

i.e. our terms with k = 0, c_m = Fv, ``coulomb_friction`` (F_coulomb = Fc) and ``offset_force``
(F_offset = OF). The drive runs under digital position control at 1 kHz; from the recorded
qm, qg and vir the controller is (``check_controller``: 0.24 % RMS residual on DATA_EMPS)

    vir_k = kv (kp (qg_k - qm_k) - (qm_k - qm_{k-2}) / (2 dt)) + d_k,

with the force gtau vir_k held over the sample (zero-order hold). d_k is a voltage added to the
controller output: zero in DATA_EMPS; in DATA_EMPS_PULSES the pulses, pulses_N x 1.014 V
(the recorded vir exceeds the control law by 5.07 V while pulses_N = 5).

Why the closed loop is simulated. The plant integrates (k = 0): simulated open loop from the
recorded force, any force error integrates twice and the position drifts (published parameters:
6.8 mm RMS, 19 mm at worst over the 25 s record, against 1.7 um RMS in closed loop). The
controller holds the real drive on the reference; simulating the same controller around the
model keeps the model on it too, and what the parameters change is the tracking error qg - q
(hundreds of micrometres), which the encoder (0.05 um) resolves. So the likelihood is
the tool's "simulation error" formulation: the exogenous inputs are the reference qg and the
added voltage d, the model output is the position q, compared with the measured qm:
:class:`ClosedLoopProblem`, a :class:`~harvester.inference.likelihood.Problem` whose simulation is
:func:`simulate_closed_loop`. The benchmark authors' own method, inverse dynamics with least
squares on a filtered, differentiated qm (IDIM-LS), is :func:`idim_ls`, reported beside it.

The simulation runs at the controller's 1 kHz (the digital loop, its two-sample velocity and
the zero-order hold matter at the micrometre level, so the input is not decimated); the
likelihood compares every ``stride``-th sample (10: 100 Hz, five times the closed loop's 19 Hz
natural frequency), which keeps the information below 50 Hz. The residual is still correlated
at that spacing (over tau ~ 16-21 strided samples), so eq. (10) is tempered by 1 / tau, tau
estimated once from the viscous baseline's least-squares residual (:func:`temper_from`), as
the diagnosis does: evidence differences and posterior widths then count independent
information once.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from harvester.emps.data import EmpsRecord, ServoLoop, disturbance_voltage
from harvester.inference.correlated_residuals import sokal_window
from harvester.inference.likelihood import Problem
from harvester.model.simulate import Simulation, run_servo
from harvester.model.structures import Layout, ModelStructure
from harvester.model.terms import term

log = logging.getLogger("harvester.emps")

#: Known base parameters of the EMPS: no spring, no base motion (m does not enter).
KNOWN: dict[str, float] = {"m": 0.0, "k": 0.0}
#: Base parameters identified: M and the viscous coefficient.
FREE_BASE: tuple[str, ...] = ("M", "c_m")
#: Viscous-only baseline: M q'' + Fv q' + OF = F.
BASELINE_TERMS: tuple[str, ...] = ("offset_force",)
#: Fewest RK4 sub-steps per 1 ms sample: one step is within 3 nm (max) of 16 steps on DATA_EMPS
#: (tests/test_emps.py), against a 1.7 um residual; stability is kept by RATE_H regardless.
MIN_SUBSTEPS = 1


#: A closed-loop simulation: position (rel_disp, to ground), velocity, acceleration and the
#: force gtau vir_k applied over each sample (``force``, N).
ClosedLoopSimulation = Simulation


def simulate_closed_loop(layout: Layout, params: np.ndarray, reference: np.ndarray,
                         disturbance: np.ndarray, loop: ServoLoop, dt: float, q0: float = 0.0,
                         n_substeps: int | np.ndarray | None = None,
                         min_substeps: int = MIN_SUBSTEPS) -> Simulation:
    """The model of ``layout`` (force input, base fixed) inside the digital position loop.

    ``reference`` qg (m) and ``disturbance`` d (V) are sampled every ``dt`` s; the model
    starts at rest at q0 (m). ``params`` is (particles, layout parameters) or one vector.
    Sub-steps per sample: as :func:`harvester.model.simulate.substeps` (rate x h <= RATE_H, for
    stability) but at least ``min_substeps`` instead of 4, or ``n_substeps`` if given. The
    integrator is the structure's compiled kernel with the ``servo`` driver
    (``harvester.model.codegen``).
    """
    _, sim = run_servo(layout, params, reference, disturbance, loop, dt, q0, n_substeps,
                       min_substeps)
    return sim


@dataclass
class ClosedLoopProblem(Problem):
    """A :class:`Problem` whose model runs inside the EMPS position loop.

    ``input`` is the position reference qg (m), ``output`` the measured position qm (m,
    output kind ``rel_disp``, to ground); ``disturbance`` (V) is added to the controller
    output; the model starts at rest at qm[0]. Likelihood: eq. (10) on every ``stride``-th
    sample of the position in ``window``.
    """

    loop: ServoLoop | None = None
    disturbance: np.ndarray | None = None
    min_substeps: int = MIN_SUBSTEPS

    def _check_kinds(self) -> None:
        if self.input_kind != "position_reference" or self.output_kind != "rel_disp":
            raise ValueError("a ClosedLoopProblem has input_kind 'position_reference' and "
                             "output_kind 'rel_disp'")
        if self.loop is None:
            raise ValueError("a ClosedLoopProblem needs the servo loop (gains)")
        if self.disturbance is None:
            self.disturbance = np.zeros_like(self.input)
        self.disturbance = np.asarray(self.disturbance, dtype=float)

    def residual_sums(self, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(sum of squared position residuals, ok) per row of theta, without trajectories."""
        sse, sim = run_servo(self.structure.layout, self.layout_params(theta), self.input,
                             self.disturbance, self.loop, self.dt, float(self.output[0]),
                             min_substeps=self.min_substeps, observed=self.observed,
                             window=self.window, stride=self.stride, outputs=False)
        return sse, sim.ok

    def simulate(self, theta: np.ndarray, input: np.ndarray | None = None, *,
                 base_acc: np.ndarray | None = None) -> Simulation:
        if input is not None or base_acc is not None:
            raise ValueError("simulate another record with problem.for_record(record)")
        return simulate_closed_loop(self.structure.layout, self.layout_params(theta),
                                    self.input, self.disturbance, self.loop, self.dt,
                                    q0=float(self.output[0]), min_substeps=self.min_substeps)

    def for_record(self, record: EmpsRecord, window: tuple[int, int] | None = None
                   ) -> "ClosedLoopProblem":
        """The same model and known values on another record (e.g. the validation file)."""
        return closed_loop_problem(record, self.structure, self.known, window, self.stride,
                                   temper=self.temper)


def closed_loop_problem(record: EmpsRecord, model: ModelStructure | Sequence[str],
                        known: Mapping[str, float] | None = None,
                        window: tuple[int, int] | None = None, stride: int = 10,
                        disturbance: np.ndarray | None = None,
                        temper: float = 1.0) -> ClosedLoopProblem:
    """The closed-loop identification problem of an EMPS record.

    ``model``: a structure, or the terms added to eq. (1) (names of ``physics.TERMS``), with
    M and c_m identified and k = 0, m = 0 known (:data:`KNOWN`) unless ``known`` says
    otherwise. ``disturbance`` defaults to :func:`disturbance_voltage` (the pulses);
    ``temper`` multiplies eq. (10) (1 / tau of the residual, :func:`temper_from`).
    """
    if not isinstance(model, ModelStructure):
        terms = tuple(model)
        model = ModelStructure(emps_model_name(terms), terms, FREE_BASE)
    known = {**KNOWN, **(known or {})}
    d = disturbance_voltage(record) if disturbance is None else disturbance
    return ClosedLoopProblem(model, record.qg, record.qm, record.dt, known, window,
                             input_kind="position_reference", output_kind="rel_disp",
                             stride=stride, temper=temper, loop=record.loop, disturbance=d)


def closed_loop_fit(problem: ClosedLoopProblem, start: Mapping[str, float]
                    ) -> tuple[dict[str, float], np.ndarray]:
    """Least-squares output-error fit of the physical parameters (sigma left out).

    Starts from ``start`` (e.g. the prior means); returns the fitted values and the residual
    qm - q on the whole record. Used to set the likelihood's temper (:func:`temper_from`).
    """
    from scipy import optimize
    names = problem.structure.free_parameters
    x0 = np.array([start[n] for n in names], dtype=float)
    scale = np.maximum(np.abs(x0), 1.0)

    def residual(x: np.ndarray) -> np.ndarray:
        pred = problem.predict(np.append(x * scale, 1.0)[None, :])[0]
        r = (pred - problem.output)[problem.samples]
        return np.where(np.isfinite(r), r, 1.0) / np.std(problem.observed)

    sol = optimize.least_squares(residual, x0 / scale, x_scale=1.0)
    values = dict(zip(names, map(float, sol.x * scale)))
    pred = problem.predict(np.append(sol.x * scale, 1.0)[None, :])[0]
    return values, problem.output - pred


def correlation_time(x: np.ndarray) -> float:
    """Integrated autocorrelation time tau = 1 + 2 sum_k rho(k) (samples), Sokal's window
    (``inference.correlated_residuals.sokal_window``), at least 1.

    tau correlated samples are worth one independent one: eq. (10) on them counts each piece
    of information tau times, so the likelihood is tempered by 1 / tau.
    """
    return max(sokal_window(np.asarray(x, dtype=float))[0], 1.0)


def temper_from(residual: np.ndarray, stride: int) -> tuple[float, float]:
    """(temper = 1 / tau, tau) of a residual sampled every ``stride`` samples."""
    tau = correlation_time(np.asarray(residual)[::stride])
    return 1.0 / tau, tau


def emps_model_name(terms: Sequence[str]) -> str:
    """'viscous' for the baseline terms, 'viscous+<extra terms>' otherwise."""
    extra = [t for t in terms if t not in BASELINE_TERMS]
    return "+".join(["viscous", *extra])


def model_terms(name: str) -> tuple[str, ...]:
    """Inverse of :func:`emps_model_name`: 'viscous+coulomb_friction' -> terms."""
    base, *extra = name.split("+")
    if base != "viscous":
        raise ValueError(f"EMPS model names start with 'viscous', got {name!r}")
    for t in extra:
        term(t)
    return BASELINE_TERMS + tuple(extra)


