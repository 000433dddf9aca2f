"""The missing force's shapes fitted as terms of the model: the baseline with a shape of the
dictionary added to its equation of motion, fitted by MAP along the model's own response.

The smoother (``latent``) reads the missing force against the states it estimates from the
record; on an acceleration record of a small motion it knows z only to a fraction of a
millimetre, and a force that varies with z on a finer scale cannot be read there (a cogging
record of the literature generator: z 86 um RMS, known to +-124 um, period 0.1 mm; its
description was "no missing force beyond its uncertainty" and the diagnosis named a
pre-sliding hysteresis, whose stiffness at rest matched the detent's about a well). The
model's own z, simulated from the recorded input, carries no such uncertainty: the same
record fitted with a force periodic in z added to the tanh baseline found the period within
0.2 % (0.0998 mm against 0.0996), +186 nats over the baseline against the names' model's
+91 (docs/latent-force.md).

One shape is fitted so: periodic in z (``model.terms.periodic_force``, not a library name).
Its likelihood is a comb in the period and the phase, and a force that moves the motion's
rest positions (a detent beside friction) is not found by linearising about the baseline's
motion, so the fit starts from a grid (:func:`period_grid`: half a period over the motion's
span apart, phases and two amplitudes) evaluated in one batch of simulations, its best rows
refined in the phase and the amplitude (:func:`_refined`), and the MAP is solved from the
best of those. The result is its Laplace log evidence over the baseline's
(``map_fit.laplace_log_evidence``) and, where the diagnosis named effects, the improved
model's by the same measure, so that the two are compared in one currency
(``verdict.withheld_names``).
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field

import numpy as np

from harvester.data.units import SI, Units
from harvester.inference.map_fit import ChainProblem, PointFit, chain_problem, fit_map
from harvester.diagnosis.name.fits import ModelFit, candidate_priors
from harvester.inference.priors import PriorSpec
from harvester.model.priors import DeviceScale

log = logging.getLogger("harvester.diagnosis")

#: The term a shape is fitted as.
PERIODIC = "periodic_force"
#: Periods of the grid per period over the motion's span (half a period apart: the comb's
#: teeth are one period over the span wide).
PERIOD_STEP = 0.5
#: Most periods in the grid (its step widens beyond).
MAX_PERIODS = 120
#: Phases and amplitudes (x the motion's force scale) of the grid at each period.
PHASES = 6
AMPLITUDES = (0.5, 1.5)
#: The coarse grid's best rows refined (:func:`_refined`), and the refinement's values of
#: the period, the phase and the amplitude about each.
REFINE_ROWS = 3
REFINE_PERIODS = 5
REFINE_PHASES = 12
REFINE_AMPLITUDES = 5
#: Rows the MAP is solved from (each solve a few hundred simulations: on the cogging record
#: below, five solves took 43 s of a 49 s fit beside another diagnosis).
STARTS = 2
#: Laplace log evidence over the baseline (nats) from which the fitted shape stands. On 40
#: effect-free records of the literature grid it gained -11.6 nats at the median and +9.3
#: at most (``benchmarks/bench_shape_null.py``); on 13 records of library effects the
#: baseline lacks, up to +18.2 (a Duffing spring; any missing force lends a flexible shape
#: something); on the two cogging records +205 and +901 (``benchmarks/bench_shape_terms.py``,
#: docs/latent-force.md).
STAND_NATS = 50.0
#: Nats by which the shape must beat the named effects' model, both by their MAP's Laplace
#: evidence, to withhold their names: wider than the naming margin of sampled evidences
#: (log 20, ``confirm``) for two Laplace approximations, one of a likelihood with a comb of
#: optima in the period.
BEAT_NATS = 20.0


@dataclass
class ShapeTermFit:
    """A shape of the dictionary fitted as a term: its parameters (SI), its Laplace log
    evidence over the baseline, and, where effects were named, the improved model's."""

    shape: str
    term: str
    parameters: dict[str, float]
    gain_nats: float
    baseline: str
    named: str | None = None
    named_gain_nats: float | None = None
    periods_scanned: int = 0
    seconds: float = 0.0
    units: Units = field(default=SI, repr=False)

    @property
    def stands(self) -> bool:
        """Whether the shape gains STAND_NATS or more over the baseline."""
        return bool(self.gain_nats >= STAND_NATS)

    @property
    def beats_names(self) -> bool:
        """Whether it stands and beats the named effects' model by more than BEAT_NATS."""
        return bool(self.stands and self.named_gain_nats is not None
                    and self.gain_nats - self.named_gain_nats > BEAT_NATS)

    def sentence(self) -> str:
        """"a force periodic in z, period 0.0927 mm, amplitude 0.622 N, fitted as a term
        along the model's own motion: +240 nats over tanh (Laplace); not in the library"."""
        scale, disp = self.units.small("displacement")
        p = self.parameters
        return (f"a force periodic in z, period {scale * p['period_m']:.3g} {disp}, amplitude "
                f"{p['amplitude_N']:.3g} {self.units.label('N')}, fitted as a term along the "
                f"model's own motion: {self.gain_nats:+.0f} nats over {self.baseline} "
                "(Laplace); not in the library")

    def to_dict(self) -> dict:
        return {"shape": self.shape, "term": self.term, "parameters": self.parameters,
                "gain_nats": self.gain_nats, "baseline": self.baseline, "named": self.named,
                "named_gain_nats": self.named_gain_nats, "stands": self.stands,
                "beats_names": self.beats_names, "periods_scanned": self.periods_scanned,
                "seconds": self.seconds, "sentence": self.sentence()}


def _span(z: np.ndarray) -> float:
    """The motion's span (m): its 1-99 % range."""
    return float(np.subtract(*np.quantile(z, [0.99, 0.01])))


def period_grid(z: np.ndarray, v: np.ndarray, f_high: float,
                specs: dict[str, PriorSpec]) -> np.ndarray:
    """Periods (m) to start from: within P_periodic's prior and above the period a force
    at the RMS velocity would have at the band's top (v_rms / f_high: finer, it lies beyond
    the analysed band), PERIOD_STEP of a period over the motion's span (:func:`_span`)
    apart, MAX_PERIODS at most."""
    span = _span(z)
    prior = specs["P_periodic"]
    low = max(prior.lower, float(np.sqrt(np.mean(v**2))) / f_high)
    high = prior.upper
    if not span > 0.0 or not high > low:
        return np.empty(0)
    n_low, n_high = span / high, span / low
    step = max(PERIOD_STEP, (n_high - n_low) / MAX_PERIODS)
    return span / np.arange(max(n_low, step), n_high + 1e-9, step)


def _grid_rows(base: np.ndarray, periods: np.ndarray, amplitudes: np.ndarray,
               phases: int) -> np.ndarray:
    """Rows (baseline's parameters, a, b, P): each period at ``phases`` phases and each of
    ``amplitudes`` (N)."""
    angles = np.arange(phases) * 2.0 * np.pi / phases
    out = [np.r_[base, amp * np.sin(ph), amp * np.cos(ph), P]
           for P in periods for ph in angles for amp in amplitudes]
    return np.array(out)


def _best_rows(problem: ChainProblem, rows: np.ndarray, keep: int) -> np.ndarray:
    """The ``keep`` rows of least residual, one batch of simulations."""
    sse, ok = problem.residual_sums(np.column_stack([rows, np.ones(len(rows))]))
    sse = np.where(ok & np.isfinite(sse), sse, np.inf)
    return rows[np.argsort(sse)[:keep]]


def _refined(base: np.ndarray, coarse: np.ndarray, span: float) -> np.ndarray:
    """Rows about each of the ``coarse`` grid's best rows: its period +-half the coarse step
    (REFINE_PERIODS values), REFINE_PHASES phases, REFINE_AMPLITUDES about its amplitude.
    Where the force moves the motion, the likelihood has local optima in the phase and the
    amplitude at the right period: a linear device's 5 N force of period 15 mm, started from
    the coarse grid's best row (16.5 mm), was fitted at 15.0 mm with a third of its phase and
    c_m 21 % high, its residual 26 x the noise."""
    out = []
    for row in coarse:
        a, b, P = row[-3:]
        n = span / P
        periods = span / (n + np.linspace(-0.5, 0.5, REFINE_PERIODS) * PERIOD_STEP)
        amplitudes = np.hypot(a, b) * np.geomspace(0.5, 2.0, REFINE_AMPLITUDES)
        out.append(_grid_rows(base, periods[periods > 0], amplitudes, REFINE_PHASES))
    return np.vstack(out)


def fit_periodic(problem: ChainProblem, priors: dict[str, PriorSpec], base: PointFit,
                 z: np.ndarray, v: np.ndarray, scale: DeviceScale, f_high: float,
                 seed: int = 0) -> tuple[PointFit, int] | None:
    """The baseline ``problem`` with a periodic force added, at its MAP from the grid's best
    rows (module docstring); (fit, periods scanned), or None without a grid. ``z``, ``v``:
    the baseline's simulated motion over the window (m, m/s)."""
    p = problem
    added = chain_problem(p, p.temper, p.lowpass_hz, p.filter_order,
                          structure=p.structure.with_term(PERIODIC))
    specs = {**candidate_priors(PERIODIC, scale), **priors}
    periods = period_grid(z, v, f_high, specs)
    if periods.size == 0:
        return None
    shared = base.theta[:-1]
    coarse = _best_rows(added, _grid_rows(shared, periods, scale.force * np.array(AMPLITUDES),
                                          PHASES), REFINE_ROWS)
    best = _best_rows(added, np.vstack([coarse, _refined(shared, coarse, _span(z))]), STARTS)
    # and the baseline itself (no force), solved from where it beats the grid's rows: from
    # those alone an effect-free record's fit ended 214 nats below the baseline
    none = np.r_[shared, 0.0, 0.0, periods[len(periods) // 2]]
    fit = fit_map(added, specs, n_starts=8, seed=seed, start=np.vstack([best, none]),
                  solves=STARTS)
    return fit, len(periods)


def shape_term_fit(problem: ChainProblem,
                   priors: dict[str, PriorSpec], samples: np.ndarray, z: np.ndarray,
                   v: np.ndarray, scale: DeviceScale, f_high: float,
                   improved: ModelFit | None, units: Units = SI, seed: int = 0
                   ) -> ShapeTermFit | None:
    """The periodic shape fitted as a term (:func:`fit_periodic`) against the baseline
    (``problem`` under ``priors``, started from its ``samples``' mean) and the ``improved``
    model (the named effects' fit, None without), both by their MAP's Laplace evidence;
    None where no period can be scanned."""
    clock = time.perf_counter()
    base = fit_map(problem, priors, seed=seed, start=samples.mean(axis=0)[:-1])
    found = fit_periodic(problem, priors, base, z, v, scale, f_high, seed)
    if found is None:  # the Silverbox: two periods within +-2 RMS would lie beyond the band
        log.info("the periodic shape is not fitted as a term: no period of its prior lies "
                 "within the band at the motion's RMS velocity")
        return None
    fit, n = found
    values = dict(zip(fit.names, fit.theta))
    a, b, P = values["a_periodic"], values["b_periodic"], values["P_periodic"]
    named_gain = None
    if improved is not None:  # on the baseline's data: its TMCMC window may be shorter
        named = fit_map(chain_problem(problem, problem.temper, problem.lowpass_hz,
                                      problem.filter_order, structure=improved.structure),
                        improved.priors, seed=seed, start=improved.samples.mean(axis=0)[:-1])
        named_gain = named.log_evidence_laplace - base.log_evidence_laplace
    out = ShapeTermFit("periodic in z", PERIODIC,
                       {"period_m": float(P), "amplitude_N": float(np.hypot(a, b)),
                        "phase_rad": float(np.arctan2(b, a))},
                       float(fit.log_evidence_laplace - base.log_evidence_laplace),
                       problem.structure.name,
                       None if improved is None else improved.structure.name, named_gain, n,
                       time.perf_counter() - clock, units)
    log.info("fitted as a term: %s (%d periods scanned; %.1f s)%s", out.sentence(), n,
             out.seconds, "" if named_gain is None else
             f"; {out.named}: {named_gain:+.0f} nats by the same measure")
    return out
