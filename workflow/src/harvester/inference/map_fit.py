"""The baseline model as the diagnosis sees it: a tempered likelihood, a quick MAP fit, the
baseline's own parameter sensitivities and the residual of its posterior mean.

Tempered likelihood. Eq. (10) treats every sample as independent, but the recordings are
low-passed (20 Hz at 256 Hz in the study), so neighbouring residuals are strongly correlated
and eq. (10) counts each piece of information several times. The diagnosis compares models
with the power likelihood

    L_lambda(theta) = L(theta) ** lambda,      lambda = effective share of independent samples,

which for a signal inside the band of flat (band-limited white) noise is the Whittle
(frequency-domain Gaussian) likelihood: eq. (10) scaled to the number of independent samples
(about 2 B / fs for a band of B Hz). lambda is estimated once from the baseline's residual
spectrum (``detect.temper_from_spectrum``) and kept for every model compared.

Measurement chain. Both channels of the recordings went through a zero-phase low-pass; the
simulated z'' did not, and friction puts content above the cut-off that the data cannot
have. ``ChainProblem`` passes the simulated and measured z'' through the same low-pass, whose
cut-off lies below the recording's (``ANALYSIS_FRACTION``): in the recording filter's
transition band the data have been filtered twice (once by the rig, once here) and the model
once, and no model of the chain removes that for every input (the simulated response to the
low-passed input already carries the filter's linear part; its friction harmonics do not).
A recording that went through no low-pass still went through its DAQ's anti-alias filter,
whose edge the model's acquisition places at its own (``signals.chain_cutoff``).
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

import numpy as np
from scipy import optimize

from harvester.inference.likelihood import DAQ_OVERSAMPLE, Problem, gaussian_loglike
from harvester.model.simulate import Acquisition
from harvester.inference.priors import PriorSpec
from harvester.inference.priors import priors_for
from harvester.data.signals import chain_cutoff, lowpass

log = logging.getLogger("harvester.diagnosis")

#: Cut-off of the likelihood's low-pass as a fraction of the recording's. Noise-free records at
#: the true parameters (40 s, order-8 filters): with the low-pass at the recording's cut-off
#: the RMS residual was 0.017 and 0.022 m/s^2 on tanh-friction devices with beta sigma_v = 8
#: and 85 (another simulator, 25 Hz filter; filtered sensor noise 0.016) and 0.009 on the
#: scenario generator's Table 5 device (noise 0.022); at 0.8 it was 0.003, 0.009 and 0.0045,
#: with the noise 8 % lower.
ANALYSIS_FRACTION = 0.8


class FitStopped(RuntimeError):
    """fit_map stopped by its caller's ``stop`` (a time budget) before its end: no fit."""


@dataclass
class ChainProblem(Problem):
    """:class:`~harvester.inference.likelihood.Problem` with the measurement chain and a tempered eq. (10).

    The recordings went through a zero-phase low-pass (``lowpass_hz``, ``filter_order``;
    None: only their DAQ's anti-alias filter); the simulated z'' did not, and its content
    above the cut-off (friction harmonics) has no counterpart in the data. So both the
    simulated and the measured z'' go through a zero-phase Butterworth low-pass of that order
    at ``band_fraction`` x the chain's cut-off (``chain``; the cut-off is ``lowpass_hz``, or
    without one the model DAQ's anti-alias edge, :func:`~harvester.data.signals.chain_cutoff`)
    before the residual is formed, and the log-likelihood of eq. (10) is multiplied by
    ``temper`` = lambda.
    """

    temper: float = 1.0
    lowpass_hz: float | None = None
    filter_order: int = 8
    band_fraction: float = ANALYSIS_FRACTION

    def __post_init__(self) -> None:
        super().__post_init__()
        self._observed_chain = self.measured_chain[self.samples]

    @property
    def band_hz(self) -> float:
        """Cut-off of the likelihood's low-pass (Hz): ``band_fraction`` x the measurement
        chain's cut-off (:func:`~harvester.data.signals.chain_cutoff`)."""
        return self.band_fraction * chain_cutoff(1.0 / self.dt, self.lowpass_hz)

    def _lowpass(self, x: np.ndarray, cutoff: float | None) -> np.ndarray:
        if cutoff is None:
            return np.asarray(x, dtype=float)
        return lowpass(x, 1.0 / self.dt, cutoff, self.filter_order)

    def chain(self, x: np.ndarray) -> np.ndarray:
        """The likelihood's low-pass (``band_hz``) along the last axis."""
        return self._lowpass(x, self.band_hz)

    @property
    def measured_chain(self) -> np.ndarray:
        """The measured z'' over the whole record as the residual takes it: through the
        acquisition's filter (:attr:`acquired_output`) and the chain."""
        return self.chain(self.acquired_output)

    def recording_filter(self, x: np.ndarray) -> np.ndarray:
        """The recording's own low-pass (``lowpass_hz``) along the last axis."""
        return self._lowpass(x, self.lowpass_hz)

    @property
    def observed(self) -> np.ndarray:
        return self._observed_chain

    def predicted(self, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(the output through the chain over the whole record (N, n), ok (N,)) for rows of
        theta: z'' or z as the recording's output kind says (``OutputKind.simulated``)."""
        sim = self.simulate(np.atleast_2d(theta))
        acc = np.where(sim.ok[:, None], self.output_type.simulated(sim), 0.0)
        out = self.chain(acc)
        out[~sim.ok] = np.nan
        return out, sim.ok

    def residuals(self, theta: np.ndarray) -> np.ndarray:
        """Measured minus predicted output over the window, both through the chain
        (N, n_data)."""
        pred, _ = self.predicted(theta)
        return self.observed[None, :] - pred[:, self.samples]

    @property
    def acquisition(self) -> Acquisition:
        """The DAQ's oversampling and the likelihood's low-pass (``band_hz``)."""
        return Acquisition(self.oversample, (self.band_hz, self.filter_order))


#: Samples simulated beyond the window's end so that the zero-phase filter's end effect
#: falls outside the window.
CHAIN_PAD_S = 0.5


def chain_problem(problem: Problem, temper: float = 1.0, lowpass_hz: float | None = None,
                  filter_order: int = 8, structure=None,
                  band_fraction: float | None = None) -> ChainProblem:
    """A :class:`ChainProblem` on the data and window of ``problem`` (optionally another
    structure), its records cut CHAIN_PAD_S after the window's end: the simulation runs from
    rest at the first sample, so later samples never change the likelihood. ``band_fraction``
    None: ``problem``'s own if it is a ChainProblem, else ``ANALYSIS_FRACTION``.
    """
    if band_fraction is None:
        band_fraction = getattr(problem, "band_fraction", ANALYSIS_FRACTION)
    start, stop = problem.window
    end = min(len(problem.rel_acc), stop + int(round(CHAIN_PAD_S / problem.dt)))
    return ChainProblem(structure or problem.structure, problem.base_acc[:end],
                        problem.rel_acc[:end], problem.dt, dict(problem.known), (start, stop),
                        input_kind=problem.input_kind, output_kind=problem.output_kind,
                        temper=float(temper), v_bound=problem.v_bound, lowpass_hz=lowpass_hz,
                        filter_order=filter_order, oversample=DAQ_OVERSAMPLE,
                        band_fraction=band_fraction)


# --------------------------------------------------------------------------- MAP fit


@dataclass
class PointFit:
    """A posterior mode (MAP) of the baseline and its Laplace approximation.

    theta: (free parameters..., sigma); cov: Laplace covariance of the free physical parameters;
    residual: measured - simulated z'' over the whole record (m/s^2).
    """

    theta: np.ndarray
    cov: np.ndarray
    residual: np.ndarray
    names: tuple[str, ...]
    n_simulations: int = 0
    log_evidence_laplace: float = float("nan")  # :func:`laplace_log_evidence` (nats)

    def samples(self, n: int, seed: int = 0) -> np.ndarray:
        """Draws from the Laplace approximation (physical parameters), sigma held at its mode."""
        rng = np.random.default_rng(seed)
        p = len(self.theta) - 1
        draws = rng.multivariate_normal(self.theta[:p], self.cov, size=n, method="eigh")
        return np.column_stack([draws, np.full(n, self.theta[-1])])


@dataclass(frozen=True)
class PriorCoordinates:
    """Each free parameter in its prior's coordinate, u = (g(theta) - centre) / scale, g the
    identity (normal priors) or ln (log-normal, log-uniform): the MAP fit and its Laplace
    approximation work in u, where a normal or log-normal prior is a standard normal and a
    log-uniform one is flat between its bounds (``harvester.model.priors``)."""

    specs: tuple[PriorSpec, ...]

    @classmethod
    def of(cls, problem: Problem, priors: Mapping[str, PriorSpec]) -> "PriorCoordinates":
        names = problem.structure.free_parameters
        specs = priors_for(problem, priors, names)
        return cls(tuple(specs[n] for n in names))

    @property
    def center(self) -> np.ndarray:
        return np.array([s.center for s in self.specs])

    @property
    def scale(self) -> np.ndarray:
        return np.array([s.scale for s in self.specs])

    @property
    def penalty(self) -> np.ndarray:
        """1 where the prior is a Gaussian in u, 0 where it is flat."""
        return np.array([0.0 if s.is_flat else 1.0 for s in self.specs])

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        low = np.array([(s.bounds[0] - s.center) / s.scale for s in self.specs])
        high = np.array([(s.bounds[1] - s.center) / s.scale for s in self.specs])
        return low, high

    def u(self, theta: np.ndarray) -> np.ndarray:
        """Prior coordinates of one parameter vector (the free physical parameters)."""
        return np.array([(s.to_coordinate(x) - s.center) / s.scale
                         for x, s in zip(np.asarray(theta, dtype=float), self.specs)])

    def theta(self, u: np.ndarray) -> np.ndarray:
        """Parameter values of rows of u."""
        g = self.center + np.atleast_2d(u) * self.scale
        return np.column_stack([s.from_coordinate(g[:, j]) for j, s in enumerate(self.specs)])

    def dtheta_du(self, u: np.ndarray) -> np.ndarray:
        """d theta / d u at one u (a vector)."""
        theta = self.theta(u)[0]
        return np.array([th * s.scale if s.is_log else s.scale
                         for th, s in zip(theta, self.specs)])

    def u_rows(self, theta: np.ndarray) -> np.ndarray:
        """Prior coordinates of rows of parameter values."""
        theta = np.atleast_2d(np.asarray(theta, dtype=float))
        return np.column_stack([(s.to_coordinate(theta[:, j]) - s.center) / s.scale
                                for j, s in enumerate(self.specs)])

    def log_prior(self, u: np.ndarray) -> np.ndarray:
        """The prior's log density in u per coordinate, (rows, parameters): log pi(theta)
        + log |d theta / d u| (-inf outside the support)."""
        theta = self.theta(u)
        out = np.empty_like(theta)
        for j, s in enumerate(self.specs):
            with np.errstate(divide="ignore", invalid="ignore"):
                jac = np.log(np.abs(theta[:, j]) * s.scale) if s.is_log else np.log(s.scale)
                out[:, j] = s.logpdf(theta[:, j]) + jac
        return np.where(np.isfinite(out), out, -np.inf)

    def draw(self, rng: np.random.Generator, n: int) -> np.ndarray:
        """n rows of u from the priors."""
        if n == 0:
            return np.empty((0, len(self.specs)))
        return self.u_rows(np.column_stack([s.distribution().rvs(size=n, random_state=rng)
                                            for s in self.specs]))


def fit_map(problem: ChainProblem, priors: Mapping[str, PriorSpec], n_starts: int = 48,
            seed: int = 0, start: np.ndarray | None = None, solves: int = 1,
            stop: Callable[[], bool] | None = None) -> PointFit:
    """Posterior mode of the free physical parameters, sigma profiled (sigma = RMS residual).

    Minimises lambda n/2 log(sum r^2) + 1/2 sum_j w_j u_j^2 over u within the priors' bounds
    (u the prior coordinates, :class:`PriorCoordinates`; w_j = 0 for a flat prior; lambda =
    ``problem.temper``, r through the measurement chain), by trust-region least squares,
    started from the best ``solves`` of ``n_starts`` prior draws, the prior's centre and
    ``start`` (free physical parameters, a vector or rows of them, optional) evaluated in one
    batched simulation, keeping the best end. Jacobians by forward differences, one batched
    simulation each. ``stop``: asked before each batched simulation; once it says so the fit
    ends with :class:`FitStopped` (a time budget spent).
    """
    coords = PriorCoordinates.of(problem, priors)
    w = coords.penalty
    temper, n = problem.temper, problem.n_data
    count = [0]

    def resid_u(us: np.ndarray) -> np.ndarray:
        if stop is not None and stop():
            raise FitStopped(f"{problem.structure.name}: MAP fit stopped after {count[0]} "
                             "simulations")
        theta = np.column_stack([coords.theta(us), np.ones(len(np.atleast_2d(us)))])
        count[0] += len(theta)
        return problem.residuals(theta)

    def objective_rows(us: np.ndarray) -> np.ndarray:
        return _objective(resid_u(us), us, w, temper, n)

    extra = None if start is None else np.array([coords.u(row) for row in np.atleast_2d(start)])
    ends = [_least_squares(resid_u, u0, coords, temper, n)
            for u0 in _best_starts(coords, n_starts, seed, objective_rows, extra, solves)]
    u = ends[int(np.argmin(objective_rows(np.array(ends))))] if len(ends) > 1 else ends[0]
    sigma_prior = priors.get("sigma")  # None: no Laplace evidence (sigma has no default)
    return _point_fit(problem, coords, u, resid_u, temper, n, count, sigma_prior)


def _objective(r: np.ndarray, us: np.ndarray, w: np.ndarray, temper: float, n: int
               ) -> np.ndarray:
    """fit_map's objective of rows u from their residual rows r: minus the log posterior in u
    with sigma profiled, up to a constant (nats; inf where a simulation failed)."""
    with np.errstate(invalid="ignore", divide="ignore"):
        val = 0.5 * temper * n * np.log(np.sum(r * r, axis=1)) + 0.5 * np.sum(w * us * us,
                                                                              axis=1)
    return np.where(np.isfinite(val), val, np.inf)


#: A MAP within this share of its prior's width (in prior coordinates) of a bound lies on it.
ON_BOUND = 1e-4
#: The step inward, as a share of the width, over which the slope at a bound is taken.
SLOPE_STEP = 2e-3
#: Nats by which the posterior falls, at the MAP's slope, over EDGE_SHARE of the prior's
#: width from the bound, beyond which it is sure to pile there: 95 % of an exponential's mass.
PILE_NATS = float(np.log(20.0))


def bound_pull(problem: ChainProblem, priors: Mapping[str, PriorSpec], point: PointFit,
               names: tuple[str, ...], edge_share: float) -> dict[str, tuple[str, float]]:
    """Parameters of ``names`` whose MAP (``point``) lies on a bound of their prior: {name:
    (side, nats the log posterior falls over ``edge_share`` of the prior's width from the
    bound)}. Where it falls by more than PILE_NATS the posterior must pile against the bound.

    The slope is that of fit_map's objective along the parameter, inward over SLOPE_STEP of
    the width, the others held at the MAP. At a constrained optimum that is the slope of the
    profile posterior too (the envelope theorem), and a log-concave profile falls at least as
    fast as its tangent, so the marginal posterior has at least 1 - exp(-drop) of its mass
    within ``edge_share`` of the width from the bound. A flat direction (a bristle damping
    the record cannot see, whose MAP drifted to its bound) has no slope: its posterior
    spreads over the prior."""
    coords = PriorCoordinates.of(problem, priors)
    low, high = coords.bounds()
    u = coords.u(point.theta[:-1])
    free = list(problem.structure.free_parameters)
    rows, sides = [u], []
    for name in names:
        j = free.index(name)
        # a prior open on one side is judged on 6 of its scales, as ``detect.at_prior_edge``
        width = high[j] - low[j] if np.isfinite(high[j] - low[j]) else 6.0
        for side, bound, inward in (("lower", low[j], 1.0), ("upper", high[j], -1.0)):
            if np.isfinite(bound) and abs(u[j] - bound) <= ON_BOUND * width:
                step = u.copy()
                step[j] += inward * SLOPE_STEP * width
                rows.append(step)
                sides.append((name, side))
    if not sides:
        return {}
    us = np.array(rows)
    theta = np.column_stack([coords.theta(us), np.ones(len(us))])
    value = _objective(problem.residuals(theta), us, coords.penalty, problem.temper,
                       problem.n_data)
    return {name: (side, float((v - value[0]) / SLOPE_STEP * edge_share)
                   if np.isfinite(v) else np.inf)
            for (name, side), v in zip(sides, value[1:])}


def _best_starts(coords: PriorCoordinates, n_starts: int, seed: int, objective,
                 extra: np.ndarray | None = None, keep: int = 1) -> np.ndarray:
    """The best ``keep`` rows (best first) of the prior's centre, ``n_starts`` draws from the
    priors and ``extra`` (rows of u; rows with a non-finite value are left out)."""
    low, high = coords.bounds()
    rng = np.random.default_rng(seed)
    p = len(low)
    flat = coords.penalty == 0.0
    draws = rng.standard_normal((n_starts, p))
    draws[:, flat] = rng.uniform(np.maximum(low, -3.0), np.minimum(high, 3.0),
                                 (n_starts, p))[:, flat]
    inside = lambda x: np.clip(x, low + 1e-6, high - 1e-6)  # noqa: E731
    rows = [inside(np.zeros(p)), inside(draws)]
    if extra is not None:
        extra = np.atleast_2d(extra)
        rows.append(inside(extra[np.all(np.isfinite(extra), axis=1)]))
    candidates = np.vstack(rows)
    return candidates[np.argsort(objective(candidates), kind="stable")[:max(keep, 1)]]


def _least_squares(resid_u, u0: np.ndarray, coords: PriorCoordinates, temper: float,
                   n: int) -> np.ndarray:
    """Trust-region least squares on [sqrt(lambda) r / s ; sqrt(w) u], s the RMS residual at
    the start of each solve (sigma profiled), re-profiled between solves."""
    w = np.sqrt(coords.penalty)
    low, high = coords.bounds()
    p = len(u0)
    state: dict[str, float] = {}

    def residuals(u: np.ndarray) -> np.ndarray:
        r = resid_u(u[None, :])[0]
        if not np.all(np.isfinite(r)):
            return np.full(n + p, 1e6)
        s = state.setdefault("s", float(np.sqrt(np.mean(r * r))))
        return np.concatenate([np.sqrt(temper) * r / s, w * u])

    def jacobian(u: np.ndarray) -> np.ndarray:
        h = 1e-4 * np.maximum(1.0, np.abs(u))
        r = resid_u(np.vstack([u, u + np.diag(h)]))
        jr = (r[1:] - r[0]).T / h * np.sqrt(temper) / state["s"]
        jr[~np.isfinite(jr)] = 0.0
        return np.vstack([jr, np.diag(w)])

    u = u0
    for _ in range(4):  # re-profile sigma between solves
        state.clear()
        residuals(u)
        sol = optimize.least_squares(residuals, u, jac=jacobian, bounds=(low, high),
                                     method="trf", x_scale=1.0, max_nfev=60)
        moved = np.max(np.abs(sol.x - u))
        u = sol.x
        if moved < 1e-4:
            break
    return u


def _point_fit(problem: ChainProblem, coords: PriorCoordinates, u: np.ndarray, resid_u,
               temper: float, n: int, count: list[int], sigma_prior: PriorSpec | None
               ) -> PointFit:
    """The MAP's PointFit with its Laplace covariance (lambda J^T J / sigma^2 + diag(w))^-1 in
    u (J = d model / d u), mapped to the parameters (a tiny floor keeps flat, uninformed
    directions finite)."""
    theta_phys = coords.theta(u)[0]
    r = resid_u(u[None, :])[0]
    sigma = float(np.sqrt(np.mean(r * r)))
    h = 1e-4 * np.maximum(1.0, np.abs(u))
    rows = resid_u(np.vstack([u, u + np.diag(h)]))
    jm = -(rows[1:] - rows[0]).T / h  # d model / d u, (n, p)
    jm[~np.isfinite(jm)] = 0.0
    prec = temper * jm.T @ jm / sigma**2 + np.diag(np.maximum(coords.penalty, 1e-6))
    d = coords.dtheta_du(u)
    cov = np.linalg.inv(prec) * np.outer(d, d)
    log.info("MAP of %s: %s, sigma = %.4g (%d simulations)", problem.structure.name,
             ", ".join(f"{nm}={v:.4g}" for nm, v in zip(problem.structure.free_parameters,
                                                        theta_phys)), sigma, count[0])
    pred, _ = problem.predicted(np.append(theta_phys, sigma))
    residual = problem.measured_chain - pred[0]
    evidence = float("nan") if sigma_prior is None else laplace_log_evidence(
        coords, u, temper * jm.T @ jm / sigma**2, sigma, temper, n, sigma_prior)
    return PointFit(np.append(theta_phys, sigma), cov, residual, problem.parameter_names,
                    count[0], evidence)


def laplace_log_evidence(coords: PriorCoordinates, u: np.ndarray, fisher: np.ndarray,
                         sigma: float, temper: float, n: int, sigma_prior: PriorSpec) -> float:
    """Laplace approximation of the log evidence of the tempered eq. (10) at a MAP (nats):

        log Z ~ log L(u, sigma) + log pi(u) + log pi(sigma) + (p + 1)/2 log 2 pi
                + 1/2 log det H_u^-1 + 1/2 log (sigma^2 / (2 lambda n)),

    L at sigma = the RMS residual, pi(u) the priors' densities in u (log pi_theta plus the log
    Jacobians), H_u = ``fisher`` (lambda J^T J / sigma^2) plus the prior's precision in u: 1 per
    parameter, also for a log-uniform prior, whose u spans sqrt(12) with unit variance (an
    uninformed direction then counts as the prior's width, not as infinite). Exact for a
    Gaussian posterior; on a curved or bounded one only an estimate."""
    log_prior = float(coords.log_prior(u).sum()) + float(sigma_prior.logpdf(sigma))
    log_like = temper * gaussian_loglike(n * sigma**2, n, sigma)
    _, logdet = np.linalg.slogdet(fisher + np.eye(len(u)))
    p = len(u)
    return float(log_like + log_prior + 0.5 * (p + 1) * np.log(2.0 * np.pi) - 0.5 * logdet
                 + 0.5 * np.log(sigma**2 / (2.0 * temper * n)))


# --------------------------------------------------------------------------- sensitivities


def sensitivities(problem: ChainProblem, theta: np.ndarray, scale: np.ndarray) -> np.ndarray:
    """d output(t) / d theta_j (through the chain) over the record by central differences.

    theta: (free physical parameters..., sigma); scale: a typical spread of each free
    parameter (posterior sd); the step is 0.05 scale. One batched simulation.
    Returns (samples, P) in the output's unit per unit of each parameter.
    """
    theta = np.asarray(theta, dtype=float)
    p = len(problem.structure.free_parameters)
    h = 0.05 * np.asarray(scale, dtype=float)[:p]
    h = np.where(h > 0, h, 1e-3 * np.maximum(np.abs(theta[:p]), 1e-6))
    rows = []
    for j in range(p):
        up, down = theta.copy(), theta.copy()
        up[j] += h[j]
        down[j] -= h[j]
        rows += [up, down]
    pred, ok = problem.predicted(np.array(rows))
    pred = np.where(ok[:, None], pred, 0.0)
    return np.column_stack([(pred[2 * j] - pred[2 * j + 1]) / (2 * h[j]) for j in range(p)])


@dataclass
class BaselineState:
    """The baseline at its posterior mean: simulated state, residual and sensitivities.

    All arrays over the problem's (possibly shortened) record; z'', the model's output (of
    the recording's output kind: z'' or z, ``harvester.data.kinds``) and the residual through
    the measurement chain; ``theta`` = (free parameters..., sigma); ``theta_sd`` the
    posterior sd of each; ``samples`` posterior draws (rows like theta); ``note`` says where
    theta is not the posterior mean (:func:`representative`), None where it is.
    """

    problem: ChainProblem
    theta: np.ndarray
    theta_sd: np.ndarray
    samples: np.ndarray
    rel_disp: np.ndarray
    rel_vel: np.ndarray
    rel_acc: np.ndarray
    residual: np.ndarray
    jacobian: np.ndarray = field(repr=False)
    output: np.ndarray | None = field(default=None, repr=False)  # None: rel_acc is the output
    note: str | None = None

    def __post_init__(self) -> None:
        if self.output is None:
            self.output = self.rel_acc

    @property
    def names(self) -> tuple[str, ...]:
        return self.problem.parameter_names


def representative(problem: ChainProblem, samples: np.ndarray) -> tuple[np.ndarray, str | None]:
    """(theta at which the baseline's state is read, a note or None): the posterior mean
    where it can be simulated over the problem's record, else the posterior sample that fits
    the record best (highest likelihood; the note says how many samples could be simulated).

    The mean of simulable samples need not be simulable: a posterior with two modes (chains
    that found different ones) has its mean between them, and samples drawn on the TMCMC
    window may blow up over the longer record the detection reads (a softening spring whose
    well the larger motion leaves). Raises RuntimeError where no sample can be simulated.
    """
    theta = samples.mean(axis=0)
    if problem.simulate(theta).ok[0]:
        return theta, None
    ll = problem.loglike(samples)
    good = np.isfinite(ll)
    name = problem.structure.name
    if not good.any():
        raise RuntimeError(f"neither the posterior mean of {name} nor any of its "
                           f"{len(samples)} posterior samples can be simulated over the record")
    note = (f"the posterior mean of {name} cannot be simulated over the record "
            f"({int(good.sum())} of {len(samples)} posterior samples can); its state, "
            "residual and sensitivities are read at the posterior sample that fits the "
            "record best")
    log.warning("%s", note)
    return samples[int(np.argmax(np.where(good, ll, -np.inf)))].copy(), note


def baseline_state(problem: ChainProblem, samples: np.ndarray) -> BaselineState:
    """The baseline's state at a representative of its posterior (:func:`representative`:
    the posterior mean, or where that cannot be simulated the best-fitting sample, said in
    ``note``), its simulated response and residual, and the sensitivities there."""
    samples = np.atleast_2d(np.asarray(samples, dtype=float))
    theta, note = representative(problem, samples)
    sd = samples.std(axis=0, ddof=1) if len(samples) > 1 else np.abs(theta) * 0.01
    sim = problem.simulate(theta)
    if not sim.ok[0]:  # a sample that simulated in the batch but not alone
        raise RuntimeError(f"{problem.structure.name} cannot be simulated at its "
                           "representative posterior sample")
    model = problem.chain(problem.output_type.simulated(sim)[0])
    jac = sensitivities(problem, theta, sd)
    return BaselineState(problem, theta, sd, samples, sim.rel_disp[0], sim.rel_vel[0],
                         problem.chain(sim.rel_acc[0]), problem.measured_chain - model, jac,
                         model, note)
