"""The identification problem: data, a model structure and the Gaussian likelihood of eqs. (8)-(10).

Each used sample of the measured output is modelled as N(y_hat_i(theta), sigma^2), independent
(eq. 9), so log L = -N/2 log(2 pi sigma^2) - sum_i r_i^2 / (2 sigma^2), eq. (10), with sigma
identified alongside the physical parameters. The model is simulated from the start of the
record (from rest) and the likelihood uses every ``stride``-th sample in ``window``.

Input and output kinds (``harvester.data.recording``): the model is driven by the base acceleration
(``base_acc``, m/s^2, the paper's case) or by a force on the mass (``force``, N, base fixed,
so m does not enter eq. 1), and predicts the relative acceleration (``rel_acc``, m/s^2, the
paper's eq. 8) or the relative displacement (``rel_disp``, m). The model starts at rest at
z = 0: a measured displacement is zero at the rest position the record starts from (the
recording format says so, ``harvester.data.recording``).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np
from scipy.signal import sosfiltfilt
from scipy.special import logsumexp

from harvester.data.recording import OUTPUT_KINDS
from harvester.data.signals import butterworth_sos
from harvester.model.simulate import (Acquisition, Simulation, acquired, residual_sums,
                                      simulate)
from harvester.model.structures import ModelStructure


#: The acquisition's view of the model: z'' simulated at this x the record's rate, low-passed
#: and taken at every 4th sample (``simulate``'s ``oversample``), as a data acquisition with an
#: anti-alias filter samples it. Point samples fold friction harmonics above the Nyquist
#: frequency into the band: about 0.1 x the noise RMS on the study's tanh device.
DAQ_OVERSAMPLE = 4


def gaussian_loglike(sse: np.ndarray, n: int, sigma: np.ndarray) -> np.ndarray:
    """-n/2 ln(2 pi sigma^2) - sse / (2 sigma^2), eq. (10): n independent Gaussian
    residuals of sd sigma whose squares sum to sse."""
    return -0.5 * n * np.log(2.0 * np.pi * sigma ** 2) - 0.5 * sse / sigma ** 2


#: Half-width of the sigma quadrature in sds of sigma's peak, and its number of nodes.
SIGMA_SPAN, SIGMA_NODES = 12.0, 241


def sigma_marginal_loglike(sse: np.ndarray, n: int, temper: float, log_prior) -> np.ndarray:
    """log int L(sigma)^temper pi(sigma) d sigma, eq. (10) tempered, per sum of squares (nats).

    The integrand peaks at sigma_hat = sqrt(sse / n) with relative sd 1 / sqrt(2 temper n);
    the trapezoid rule over +-SIGMA_SPAN of those sds (``log_prior``: sigma -> log pi). NaN or
    non-positive sums give -inf."""
    sse = np.atleast_1d(np.asarray(sse, dtype=float))
    ok = np.isfinite(sse) & (sse > 0)
    out = np.full(sse.shape, -np.inf)
    if not ok.any():
        return out
    hat = np.sqrt(sse[ok] / n)
    rel = np.linspace(-SIGMA_SPAN, SIGMA_SPAN, SIGMA_NODES) / np.sqrt(2.0 * temper * n)
    sigma = hat[:, None] * np.maximum(1.0 + rel[None, :], 1e-3)
    with np.errstate(divide="ignore"):
        f = temper * gaussian_loglike(sse[ok][:, None], n, sigma) + log_prior(sigma)
    step = np.diff(sigma, axis=1)
    pair = np.logaddexp(f[:, 1:], f[:, :-1]) + np.log(0.5 * step)
    out[ok] = logsumexp(pair, axis=1)
    return out


@dataclass
class Problem:
    """What the sampler needs: theta = (free parameters..., sigma) -> log-likelihood.

    ``input`` is the whole record of the input of kind ``input_kind`` ('base_acc' in m/s^2 or
    'force' in N), ``output`` the measured output of kind ``output_kind`` ('rel_acc' in
    m/s^2 or 'rel_disp' in m). ``base_acc`` and ``rel_acc`` are the paper-case names of the
    same arrays (kept for the study's scripts).
    """

    structure: ModelStructure
    input: np.ndarray  # whole record, unit of input_kind
    output: np.ndarray  # measured, whole record, unit of output_kind
    dt: float  # s
    known: dict[str, float]  # values of the layout parameters that are not identified
    window: tuple[int, int] | None = None  # samples [start, stop) used by the likelihood
    output_filter: tuple[float, int] | None = None  # (cut-off Hz, order) applied to simulated z''
    input_kind: str = "base_acc"
    output_kind: str = "rel_acc"
    stride: int = 1  # the likelihood uses every stride-th sample of the window
    temper: float = 1.0  # power of the likelihood: eq. (10) x temper (1 / tau for correlated noise)
    v_bound: float | None = None  # largest velocity (m/s) for the sub-step choice (simulate)
    oversample: int = 1  # simulate at this x the rate and anti-alias z'' (simulate, a DAQ's view)
    n_evaluations: int = field(default=0, init=False)
    _acquired: np.ndarray | None = field(default=None, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        self.input = np.asarray(self.input, dtype=float)
        self.output = np.asarray(self.output, dtype=float)
        self._check_kinds()
        if self.input.shape != self.output.shape:
            raise ValueError(f"{self.input_kind} and {self.output_kind} differ in length")
        layout = self.structure.layout
        missing = [n for n in layout.parameter_names
                   if n not in self.structure.free_parameters and n not in self.known]
        if missing:
            raise ValueError(f"no value for known parameters {missing} of {self.structure.name}")
        start, stop = self.window or (0, len(self.output))
        self.window = (int(start), int(stop))
        if not 0 <= start < stop <= len(self.output):
            raise ValueError(f"window {self.window} outside the record of {len(self.output)} "
                             "samples")
        self.stride = int(self.stride)
        if self.stride < 1:
            raise ValueError(f"stride must be a positive integer, got {self.stride}")
        if not 0.0 < self.temper <= 1.0:
            raise ValueError(f"temper must be in (0, 1], got {self.temper}")
        self._free_idx = np.array([layout.index(n) for n in self.structure.free_parameters])
        self._template = np.array([self.known.get(n, np.nan) for n in layout.parameter_names])

    def _check_kinds(self) -> None:
        from harvester.data.kinds import INPUTS
        driven = [k for k, kind in INPUTS.items() if kind.model == k]
        if self.input_kind not in driven:
            hint = (f" (convert it first: harvester.data.kinds.model_recording gives "
                    f"{INPUTS[self.input_kind].model})" if self.input_kind in INPUTS else "")
            raise ValueError(f"input_kind must be one of {driven}, got {self.input_kind!r}"
                             + hint)
        if self.output_kind not in OUTPUT_KINDS:
            raise ValueError(f"output_kind must be one of {list(OUTPUT_KINDS)}, "
                             f"got {self.output_kind!r}")

    # ---- paper-case names -------------------------------------------------------------------

    @property
    def base_acc(self) -> np.ndarray:
        """The input record (the base acceleration in the paper's case)."""
        return self.input

    @property
    def rel_acc(self) -> np.ndarray:
        """The measured output record (the relative acceleration in the paper's case)."""
        return self.output

    # ---- data ---------------------------------------------------------------------------------

    @property
    def parameter_names(self) -> tuple[str, ...]:
        """Names of theta's columns: the free physical parameters, then sigma."""
        return self.structure.free_parameters + ("sigma",)

    @property
    def samples(self) -> slice:
        """The samples of the record the likelihood uses."""
        return slice(self.window[0], self.window[1], self.stride)

    @property
    def n_data(self) -> int:
        return len(range(*self.samples.indices(len(self.output))))

    @property
    def acquired_output(self) -> np.ndarray:
        """The measured output record through the acquisition's filter (``oversample``;
        :func:`harvester.model.simulate.acquired`), as the simulated output is sampled."""
        if self._acquired is None:
            self._acquired = acquired(self.output, self.dt, self.oversample)
        return self._acquired

    @property
    def observed(self) -> np.ndarray:
        """What the likelihood compares the simulated output with: the samples it uses of
        :attr:`acquired_output`."""
        return self.acquired_output[self.samples]

    # ---- model --------------------------------------------------------------------------------

    def layout_params(self, theta: np.ndarray) -> np.ndarray:
        """Full layout parameter matrix (particles, layout params) from theta (particles, P)."""
        theta = np.atleast_2d(theta)
        full = np.tile(self._template, (theta.shape[0], 1))
        full[:, self._free_idx] = theta[:, : len(self._free_idx)]
        return full

    def simulate(self, theta: np.ndarray, input: np.ndarray | None = None, *,
                 base_acc: np.ndarray | None = None) -> Simulation:
        """Simulated response for each row of theta, to the training or another input.

        ``base_acc`` is the paper-case name of ``input`` (either may be given).
        """
        u = self.input if input is None and base_acc is None else (
            input if input is not None else base_acc)
        return simulate(self.structure.layout, self.layout_params(theta), u, self.dt,
                        force_input=self.input_kind == "force", v_bound=self.v_bound,
                        oversample=self.oversample)

    @property
    def output_type(self):
        """The output's kind object (``harvester.data.kinds.OutputKind``)."""
        from harvester.data.kinds import output_kind
        return output_kind(self.output_kind)

    @property
    def input_type(self):
        """The input's kind object (``harvester.data.kinds.InputKind``)."""
        from harvester.data.kinds import input_kind
        return input_kind(self.input_kind)

    def output_of(self, sim: Simulation) -> np.ndarray:
        """The simulated output of this problem's kind (particles, samples), NaN where failed."""
        out = self.output_type.simulated(sim).copy()
        out[~sim.ok] = np.nan
        if self.output_filter is not None and sim.ok.any():
            cutoff, order = self.output_filter
            sos = butterworth_sos(1.0 / self.dt, cutoff, order)
            out[sim.ok] = sosfiltfilt(sos, out[sim.ok], axis=-1)
        return out

    def predict(self, theta: np.ndarray, input: np.ndarray | None = None) -> np.ndarray:
        """Predicted output (particles, samples) for each row of theta (NaN where failed),
        for the training input or another one."""
        return self.output_of(self.simulate(theta, input))

    def replace(self, **changes) -> "Problem":
        """A copy with some fields changed (same class, kinds, stride; e.g. ``temper=0.1``)."""
        return dataclasses.replace(self, **changes)

    @property
    def acquisition(self) -> Acquisition:
        """How the simulated output is sampled and filtered before it meets ``observed``."""
        return Acquisition(self.oversample, self.output_filter)

    # What a MAP fit reads of a problem (``harvester.inference.map_fit.fit_map``; its
    # ChainProblem puts both sides through its own low-pass).
    @property
    def measured_chain(self) -> np.ndarray:
        """The measured output over the record as the residual takes it."""
        return self.acquired_output

    def predicted(self, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(the simulated output over the record (N, n), NaN where failed; ok (N,))."""
        sim = self.simulate(np.atleast_2d(theta))
        return self.output_of(sim), sim.ok

    def residuals(self, theta: np.ndarray) -> np.ndarray:
        """Measured minus simulated output on the likelihood's samples (N, n_data): the
        residuals whose sum of squares is :meth:`residual_sums`'s."""
        return self.observed[None, :] - self.predicted(theta)[0][:, self.samples]

    def residual_sums(self, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(sum of squared residuals over the likelihood's samples, ok) per row of theta,
        computed block by block by the compiled simulator (no trajectories are kept)."""
        return residual_sums(self.structure.layout, self.layout_params(theta), self.input,
                             self.dt, self.observed, self.window, self.stride, self.output_kind,
                             self.acquisition, force_input=self.input_kind == "force",
                             v_bound=self.v_bound)

    def profiled_loglike(self, sse: np.ndarray) -> np.ndarray:
        """:meth:`loglike` with sigma at its maximum, sqrt(sse / n), from the sums of squared
        residuals."""
        sse, n = np.asarray(sse, dtype=float), self.n_data
        with np.errstate(divide="ignore", invalid="ignore"):
            return self.temper * gaussian_loglike(sse, n, np.sqrt(sse / n))

    def loglike(self, theta: np.ndarray) -> np.ndarray:
        """Log-likelihood, eq. (10) x ``temper``, per row of theta; -inf where simulation failed.

        ``temper`` < 1 is the power likelihood L ** temper: with residuals correlated over
        tau samples, temper = 1 / tau counts each independent piece of information once.
        """
        theta = np.atleast_2d(np.asarray(theta, dtype=float))
        self.n_evaluations += theta.shape[0]
        sigma = theta[:, -1]
        sse, ok = self.residual_sums(theta)
        n = self.n_data
        with np.errstate(invalid="ignore", divide="ignore"):
            ll = gaussian_loglike(sse, n, sigma)
        ll[~(sigma > 0) | ~ok | ~np.isfinite(ll)] = -np.inf
        return self.temper * ll if self.temper != 1.0 else ll
