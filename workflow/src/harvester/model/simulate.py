"""Forward model: the relative response predicted from the measured input, for a population.

Eq. (1) of Green et al. (2015), M z'' + c_m z' + k z + f(z') = -m y'', plus any terms of the
physics library (``harvester.model.terms``), integrated from rest for many parameter vectors
(particles) in one call by the structure's compiled kernel (``harvester.model.codegen``).

Method: classical fixed-step Runge-Kutta 4 with the input linearly interpolated between
samples. Each particle gets its own number of sub-steps per sample, chosen from a bound on the
fastest rate of its equations (``terms.step_rates``) so that rate x h <= ``RATE_H``, which keeps
RK4 stable (limit 2.78) and accurate over the whole prior range; the count is rounded up to a
ladder of values (``SUBSTEP_LADDER``, at most 25 % more steps) so that particles share counts
and are integrated together, the particles innermost, in blocks of ``BLOCK`` run by parallel
threads (stiffest blocks first). A particle whose state leaves the finite range is flagged
failed and its output set to NaN; the likelihood maps it to -inf.

``oversample`` q > 1 samples the response as a data acquisition with an anti-alias filter
does: the input is interpolated band-limited (``scipy.signal.resample_poly``) to q x the rate,
the model integrated there with the same sub-steps per input sample overall, and z'' taken at
the input's samples after the anti-alias low-pass of ``harvester.data.signals``
(``ANTIALIAS_*``). Point samples of z'' alias the friction harmonics above the Nyquist
frequency into the band: on a tanh device recorded through an anti-alias filter, 0.09 x the
noise RMS of mismatch at the true parameters, 0.02 x with ``oversample=4`` (measured).

:func:`simulate` returns the trajectories; :func:`residual_sums` returns only each particle's
sum of squared residuals against an observed window (through the output's filter), computed
block by block without building the trajectories: what the likelihood of eq. (10) needs.
"""

from __future__ import annotations

import functools
import threading
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field

import numba as nb
import numpy as np
from scipy import signal

from harvester.data.signals import (ANTIALIAS_FRACTION, ANTIALIAS_ORDER, apply_gain,
                                    butterworth_sos)
from harvester.model import acquisition, codegen
from harvester.model.structures import Layout
from harvester.model.terms import step_rates

#: Largest (fastest rate x sub-step); RK4 is stable up to 2.78 on a real negative eigenvalue.
RATE_H = 0.5
#: Fewest sub-steps per sample (accuracy near velocity reversals), and most (cost cap).
MIN_SUBSTEPS = 4
MAX_SUBSTEPS = 4096
#: States beyond this magnitude count as a failed (unstable) simulation.
BLOW_UP = codegen.BLOW_UP
#: Sub-step counts particles are rounded up to (ratio <= 1.25 between neighbours above 4).
SUBSTEP_LADDER = np.unique(np.concatenate([
    np.arange(1, 9), np.round(8 * 1.25 ** np.arange(1, 40)).astype(np.int64)]))
SUBSTEP_LADDER = SUBSTEP_LADDER[SUBSTEP_LADDER <= MAX_SUBSTEPS]
#: Most particles integrated together (a block of the struct-of-arrays loop).
BLOCK = 64
#: Doubles per vector instruction (AVX2): block sizes are multiples of it.
LANES = 4
OUTPUT_KINDS = {"rel_acc": 0, "rel_disp": 1}


@dataclass
class Simulation:
    """Batched simulation result: arrays of shape (particles, samples)."""

    rel_acc: np.ndarray  # z'' (m/s^2)
    rel_disp: np.ndarray  # z (m)
    rel_vel: np.ndarray  # z' (m/s)
    ok: np.ndarray  # (particles,) False where the integration failed
    substeps: np.ndarray  # (particles,) sub-steps per input sample used
    force: np.ndarray | None = field(default=None)  # servo driver: force applied (N)


def substeps(layout: Layout, params: np.ndarray, dt: float, v_bound: float | None = None,
             min_substeps: int = MIN_SUBSTEPS) -> np.ndarray:
    """Sub-steps per sample for each particle so that fastest rate x h <= RATE_H
    (``v_bound``: largest velocity in m/s, ``terms.step_rates``; None: its default)."""
    p = np.atleast_2d(np.asarray(params, dtype=float))
    values = {name: p[:, j] for j, name in enumerate(layout.parameter_names)}
    rate = step_rates(layout.terms, values, v_bound)
    n = np.ceil(rate * dt / RATE_H)
    n = np.where(np.isfinite(n), n, MAX_SUBSTEPS)
    return np.clip(n, min_substeps, MAX_SUBSTEPS).astype(np.int64)


def on_ladder(n_sub: np.ndarray) -> np.ndarray:
    """Each count rounded up to the next value of SUBSTEP_LADDER."""
    idx = np.searchsorted(SUBSTEP_LADDER, np.asarray(n_sub, dtype=np.int64))
    return SUBSTEP_LADDER[np.minimum(idx, SUBSTEP_LADDER.size - 1)]


@dataclass(frozen=True)
class Blocks:
    """Particles sorted by sub-step count and cut into blocks that share one."""

    order: np.ndarray  # particle index at each sorted position
    starts: np.ndarray
    stops: np.ndarray
    n_sub: np.ndarray  # per block

    @classmethod
    def of(cls, n_sub: np.ndarray, block: int = BLOCK, parts: int | None = None) -> "Blocks":
        """Blocks of at most ``block`` particles, each group of one sub-step count cut into a
        multiple of ``parts`` (the threads) blocks of near-equal size, so that every thread
        gets an equal share (150 particles on 2 threads: 4 blocks of 40 or 30, not 64, 64
        and 22)."""
        parts = threads() if parts is None else max(1, int(parts))
        order = np.argsort(n_sub, kind="stable")
        sorted_sub = n_sub[order]
        edges = np.flatnonzero(np.diff(sorted_sub)) + 1
        starts, stops = [], []
        for a, b in zip(np.r_[0, edges], np.r_[edges, len(order)]):
            count = parts * -(-(b - a) // (parts * block))
            size = LANES * -(-(b - a) // (count * LANES))
            for s in range(a, b, size):
                starts.append(s)
                stops.append(min(s + size, b))
        starts, stops = np.array(starts, dtype=np.int64), np.array(stops, dtype=np.int64)
        subs = sorted_sub[starts]
        heavy = np.argsort(-(subs * (stops - starts)), kind="stable")  # stiffest first
        return cls(order.astype(np.int64), starts[heavy], stops[heavy], subs[heavy])


_pool: ThreadPoolExecutor | None = None
_pool_lock = threading.Lock()
_warm: set = set()  # kernels (their integrate) that have run once in this process


def threads() -> int:
    """Threads that integrate blocks at once: Numba's setting (``NUMBA_NUM_THREADS``,
    ``numba.set_num_threads``; the cores by default)."""
    return int(nb.get_num_threads())


def _in_threads(block, blocks: Blocks, dt: float, head: tuple, tail: tuple) -> None:
    """``block(*head, a, b, n_sub, dt / n_sub, *tail)`` for every block [a, b), by a pool of
    ``threads()`` threads (the kernels release the GIL), the stiffest blocks first."""
    global _pool
    jobs = [(int(a), int(b), int(s), dt / s) for a, b, s in zip(blocks.starts, blocks.stops,
                                                                 blocks.n_sub)]
    if head[0] not in _warm:
        # the first call of a kernel runs one block alone: it compiles what the others need
        # (Numba's dispatchers are not safe to compile from two threads at once: seen to crash)
        codegen.bound_labels()
        block(*head, *jobs[-1], *tail)
        jobs = jobs[:-1]
        _warm.add(head[0])
    n_threads = min(threads(), len(jobs))
    if n_threads <= 1:
        for job in jobs:
            block(*head, *job, *tail)
        return
    with _pool_lock:
        if _pool is None or _pool._max_workers < n_threads:
            _pool = ThreadPoolExecutor(max_workers=threads(), thread_name_prefix="harvester")
        pool = _pool
    for f in [pool.submit(block, *head, *job, *tail) for job in jobs]:
        f.result()


def _checked_params(layout: Layout, params: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(params (N, n_par) float64 with invalid rows replaced by a valid one, valid (N,))."""
    p = np.array(np.atleast_2d(params), dtype=np.float64)
    if p.shape[1] != len(layout.parameter_names):
        raise ValueError(f"params has {p.shape[1]} columns, layout needs "
                         f"{len(layout.parameter_names)}: {layout.parameter_names}")
    valid = np.all(np.isfinite(p), axis=1)
    p[~valid] = 0.0
    return p, valid


@functools.lru_cache(maxsize=64)
def _filter(spec: tuple[float, int] | None, fs: float) -> tuple[np.ndarray, int]:
    """Rows of a zero-phase Butterworth low-pass (cut-off Hz, order) at fs, or no filter;
    designed once per (spec, fs): the design cost 3.4 ms of a one-particle likelihood call's
    8.6 ms, which is how ``pm.sample_smc`` calls it. The rows are shared: read them only."""
    if spec is None:
        return acquisition.NO_FILTER, 0
    return acquisition.filter_rows(butterworth_sos(fs, spec[0], int(spec[1])))


@dataclass(frozen=True)
class Acquisition:
    """How the simulated output is sampled and filtered before it is compared.

    oversample: q (1: point samples); output_filter: (cut-off Hz, order) of a zero-phase
    Butterworth low-pass applied to the output at the record's rate, or None.
    """

    oversample: int = 1
    output_filter: tuple[float, int] | None = None


def base_velocity(base_acc: np.ndarray, dt: float) -> np.ndarray:
    """y' (m/s) from the base acceleration y'' (m/s^2) sampled every ``dt`` s: its
    trapezoidal integral less its linear trend (the unknown initial velocity, and a bias of
    y''). A high-pass against further drift (0.05 Hz, zero phase) cost the frame's 1 Hz
    velocity its shape at the record's ends (correlation 0.85 with y' from the displacement,
    0.99996 without). Where the base acceleration was derived from a recorded displacement,
    this is the displacement's derivative less its mean."""
    a = np.asarray(base_acc, dtype=float)
    v = np.concatenate([[0.0], np.cumsum(0.5 * (a[1:] + a[:-1]) * dt)])
    return signal.detrend(v)


def _prepare(layout: Layout, params: np.ndarray, u: np.ndarray, dt: float,
             n_substeps, v_bound, q: int, min_substeps: int = MIN_SUBSTEPS,
             force_input: bool = False):
    """(params, valid, fine input, fine dt, sub-steps per fine sample, blocks). A base
    input of a structure with a ``ground`` term becomes y'' + 1j y' (``base_velocity``)."""
    if int(q) != q or q < 1:
        raise ValueError(f"oversample must be a positive integer, got {q}")
    p, valid = _checked_params(layout, params)
    u = np.ascontiguousarray(u, dtype=np.float64)
    if not force_input and codegen.has_ground(layout.terms):
        u = np.ascontiguousarray(u + 1j * base_velocity(u, dt))
    if n_substeps is None:
        coarse = substeps(layout, p, dt, v_bound, min_substeps)
        fine = on_ladder(np.maximum(1, -(-coarse // q)))
    else:
        coarse = np.broadcast_to(np.asarray(n_substeps, dtype=np.int64), (p.shape[0],))
        fine = np.maximum(1, -(-coarse // q)) if q > 1 else coarse.copy()
    if q > 1:
        u = np.ascontiguousarray(signal.resample_poly(u, q, 1)[: u.size * q])
    return p, valid, u, dt / q, fine.astype(np.int64), Blocks.of(fine)


def acquired(x: np.ndarray, dt: float, oversample: int) -> np.ndarray:
    """A record sampled every ``dt`` s through the filter the acquisition (``oversample`` q,
    module docstring) puts on the simulated output's in-band content: the anti-alias
    low-pass's zero-phase gain at q x the rate, below the record's Nyquist frequency.

    A recorded output went through its own DAQ only. Passed through this it meets the
    simulated one on equal terms: the linear response of a device to the recorded input then
    carries the same filter on both sides (measured on a linear device at 256 Hz: without
    it the simulated z'' is 0.985 of the recorded at 80 Hz and 0.60 at 100 Hz). Below 0.6 x
    the anti-alias edge it changes a record by less than 1e-3.
    """
    x = np.asarray(x, dtype=float)
    q = int(oversample)
    if q == 1:
        return x.copy()
    # the zero-phase anti-alias gain |H(f)|^2 at q x the rate, applied in the frequency
    # domain: the band-limited interpolation itself is the identity on a band-limited record
    # (its FIR's ripple, 1e-3, would otherwise move every record by that much)
    fs_fine = q / dt
    sos = butterworth_sos(fs_fine, ANTIALIAS_FRACTION * fs_fine / (2.0 * q), ANTIALIAS_ORDER)
    return apply_gain(x, 1.0 / dt, lambda f: np.abs(signal.sosfreqz(sos, worN=f, fs=fs_fine)[1])
                      ** 2, ANTIALIAS_PAD)


#: Samples mirrored at each end of a record before :func:`acquired`'s DFT.
ANTIALIAS_PAD = 256


def _base_block(integrate, u, P, order, a, b, n_sub, h, q, aa, aa_pad, out_filt, out_pad,
                kind, stride, window, observed, out_z, out_v, out_acc, sse, ok):
    """One block [a, b) of the sorted particles: integrate, then acquire."""
    n, C = u.size, b - a
    Pb = acquisition.columns(P, a, b)
    ba = np.empty((n if (kind == 0 or out_acc.shape[0]) else 0, C))
    bz = np.empty((n if (kind == 1 or out_z.shape[0]) else 0, C))
    bv = np.empty((n if out_v.shape[0] else 0, C))
    okc = np.ones(C, dtype=np.bool_)
    integrate(u, n_sub, h, Pb, ba, bz, bv, okc)
    acquisition.acquire(ba, bz, bv, order[a:b], q, aa, aa_pad, out_filt, out_pad, kind, stride,
                        window, observed, out_z, out_v, out_acc, sse, ok, okc)


def _servo_block(integrate, qg, dist, dt, q0, gtau, kp, kv, P, order, a, b, n_sub, h, stride,
                 window, observed, out_z, out_v, out_acc, out_f, sse, ok):
    """One block [a, b) of the sorted particles inside the position loop."""
    n, C = qg.size, b - a
    Pb = acquisition.columns(P, a, b)
    bz = np.empty((n, C))
    bv, ba, bf = (np.empty((n if o.shape[0] else 0, C)) for o in (out_v, out_acc, out_f))
    okc = np.ones(C, dtype=np.bool_)
    integrate(qg, dist, dt, q0, gtau, kp, kv, n_sub, h, Pb, ba, bz, bv, bf, okc)
    rows = order[a:b]
    acquisition.finish_block(bz, rows, window, stride, observed, sse, ok, okc, out_z, bz, out_v,
                             bv, out_acc, ba)
    acquisition.write_rows(out_f, bf, rows)


def _run_base(layout, p, valid, u, dt_fine, fine, blocks, q, force_input, filt, kind,
              window, stride, observed, want):
    """Call the structure's kernel; returns (sse, ok, outputs)."""
    module = codegen.kernel(layout.names, "force" if force_input else "base")
    N, n = p.shape[0], u.size // q
    aa, aa_pad = _filter((ANTIALIAS_FRACTION / (2.0 * q * dt_fine), ANTIALIAS_ORDER)
                         if q > 1 else None, 1.0 / dt_fine)
    out_filt, out_pad = filt
    outs = {k: np.empty((N, n) if k in want else (0, n)) for k in ("z", "v", "acc")}
    sse, ok = np.full(N, np.inf), np.zeros(N, dtype=np.bool_)
    P = np.ascontiguousarray(p[blocks.order].T)
    _in_threads(_base_block, blocks, dt_fine, (module.integrate, u, P, blocks.order),
                (int(q), aa, aa_pad, out_filt, out_pad, OUTPUT_KINDS[kind], int(stride),
                 np.asarray(window, dtype=np.int64), observed, outs["z"], outs["v"],
                 outs["acc"], sse, ok))
    ok &= valid
    return sse, ok, outs


def simulate(layout: Layout, params: np.ndarray, base_acc: np.ndarray, dt: float,
             n_substeps: int | np.ndarray | None = None, force_input: bool = False,
             v_bound: float | None = None, oversample: int = 1) -> Simulation:
    """Relative response to the base acceleration ``base_acc`` (m/s^2) sampled every ``dt`` s.

    With ``force_input`` the input is a force on the mass (N) instead, the base fixed; the
    response is then relative to ground. ``params`` is (particles, len(layout.parameter_names))
    in the layout's order, or one vector. ``n_substeps`` (per input sample) overrides the
    automatic choice (used to verify convergence); ``v_bound`` (m/s) tightens it where the
    largest velocity is known (see ``substeps``); ``oversample``: module docstring.
    """
    q = int(oversample)
    p, valid, u, dt_f, fine, blocks = _prepare(layout, params, base_acc, dt, n_substeps,
                                               v_bound, q, force_input=force_input)
    _, ok, outs = _run_base(layout, p, valid, u, dt_f, fine, blocks, q, force_input,
                            (acquisition.NO_FILTER, 0), "rel_acc", (0, 0), 1, np.empty(0),
                            ("z", "v", "acc"))
    for a in outs.values():
        a[~ok] = np.nan
    return Simulation(outs["acc"], outs["z"], outs["v"], ok, fine * q)


def residual_sums(layout: Layout, params: np.ndarray, input: np.ndarray, dt: float,
                  observed: np.ndarray, window: tuple[int, int], stride: int = 1,
                  output_kind: str = "rel_acc", acquisition_: Acquisition = Acquisition(),
                  force_input: bool = False, v_bound: float | None = None
                  ) -> tuple[np.ndarray, np.ndarray]:
    """(sum of squared residuals, ok) per particle: ``observed`` (the measured output at
    samples window[0]:window[1]:stride) minus the simulated output of ``output_kind``
    ('rel_acc' or 'rel_disp') through the acquisition; inf where the simulation failed."""
    q = int(acquisition_.oversample)
    p, valid, u, dt_f, fine, blocks = _prepare(layout, params, input, dt, None, v_bound, q,
                                               force_input=force_input)
    filt = _filter(acquisition_.output_filter, 1.0 / dt)
    obs = np.ascontiguousarray(observed, dtype=np.float64)
    if not 0 <= window[0] < window[1] <= np.asarray(input).shape[0]:
        raise ValueError(f"window {window} outside the record of {np.asarray(input).shape[0]} "
                         "samples")
    expected = len(range(window[0], window[1], stride))
    if obs.size != expected:
        raise ValueError(f"observed has {obs.size} samples, the window {window} with stride "
                         f"{stride} holds {expected}")
    sse, ok, _ = _run_base(layout, p, valid, u, dt_f, fine, blocks, q, force_input, filt,
                           output_kind, window, stride, obs, ())
    sse[~ok] = np.inf
    return sse, ok


@dataclass(frozen=True)
class ServoGains:
    """A digital position loop: vir_k = kv (kp (qg_k - q_k) - (q_k - q_{k-2}) / (2 dt)) + d_k
    (V), force gtau vir_k (N) held over the sample. gtau in N/V, kp in 1/s, kv in V s/m."""

    gtau: float
    kp: float
    kv: float


def run_servo(layout: Layout, params: np.ndarray, reference: np.ndarray,
              disturbance: np.ndarray, gains: ServoGains, dt: float, q0: float = 0.0,
              n_substeps: int | np.ndarray | None = None, min_substeps: int = 1,
              observed: np.ndarray | None = None, window: tuple[int, int] = (0, 0),
              stride: int = 1, outputs: bool = True) -> tuple[np.ndarray, Simulation]:
    """The model (force input, base fixed) inside a digital position loop (``ServoGains``),
    from rest at q0 (m); ``reference`` qg (m) and ``disturbance`` d (V) every ``dt`` s.

    Returns (sum of squared residuals of the position against ``observed`` at samples
    window[0]:window[1]:stride, or infs without ``observed``; the simulation, whose arrays are
    empty unless ``outputs``). Sub-steps: as :func:`substeps` with at least ``min_substeps``
    per sample, or ``n_substeps``.
    """
    p, valid = _checked_params(layout, params)
    valid &= p[:, layout.index("M")] > 0
    p[~valid] = 1.0
    qg = np.ascontiguousarray(reference, dtype=np.float64)
    dist = np.ascontiguousarray(disturbance, dtype=np.float64)
    if dist.shape != qg.shape:
        raise ValueError("reference and disturbance differ in length")
    N, n = p.shape[0], qg.size
    n_sub = (on_ladder(substeps(layout, p, dt, None, min_substeps)) if n_substeps is None else
             np.broadcast_to(np.asarray(n_substeps, dtype=np.int64), (N,)).copy())
    blocks = Blocks.of(n_sub)
    obs = np.empty(0) if observed is None else np.ascontiguousarray(observed, dtype=np.float64)
    shape = (N, n) if outputs else (0, n)
    outs = {k: np.empty(shape) for k in ("z", "v", "acc", "f")}
    sse, ok = np.full(N, np.inf), np.zeros(N, dtype=np.bool_)
    module = codegen.kernel(layout.names, "servo")
    _in_threads(_servo_block, blocks, dt,
                (module.integrate, qg, dist, float(dt), float(q0), gains.gtau, gains.kp, gains.kv,
                 np.ascontiguousarray(p[blocks.order].T), blocks.order),
                (int(stride), np.asarray(window, dtype=np.int64), obs, outs["z"], outs["v"],
                 outs["acc"], outs["f"], sse, ok))
    ok &= valid
    sse[~ok] = np.inf
    if outputs:
        for a in outs.values():
            a[~ok] = np.nan
    return sse, Simulation(outs["acc"], outs["z"], outs["v"], ok, n_sub, force=outs["f"])
