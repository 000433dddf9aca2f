"""The simulator against the bound this machine allows for the same equations.

The bound is a reference written here, outside the library: the tanh model of eq. (1)
(M z'' + c_m z' + k z + F_c tanh(beta z') = -m y''), classical RK4 with 4 sub-steps per
sample and the input linearly interpolated, a loop with the particles innermost (struct of
arrays, one structure, nothing dispatched inside the loop) so that the compiler vectorises
it, the particles split between the threads. It is timed twice: with the C library's tanh
(scalar calls, what a plain Numba loop gets) and with the vectorisable tanh of
``harvester.model.fastmath`` (the same arithmetic as the library's kernels: the bound).

The library is timed through ``harvester.model.simulate.simulate`` (every trajectory
returned: z, z', z'') and ``residual_sums`` (the likelihood's path: the sum of squared
residuals only). Same inputs (2256 samples at 256 Hz, 512 particles with c_m and beta
spread), same threads; the figures are the best of REPEATS interleaved runs, printed as
ratios measured in this one process. Goal: the library within 1.3 x the bound.

Then every structure a diagnosis meets (the tanh baseline with one library term, and with
hysteresis and one more): the structure's compiled kernel on one thread, a block of LANES x 16
particles in one call against the same particles one call each, whose ratio is the speed-up
the vector units give. A kernel that LLVM leaves scalar (a term's law not inlined into the
particle loop: 8 of these 21 until dd883f3 inlined the laws, the right-hand side and the
elementary functions in Numba's IR) shows a ratio near 1. Goal: at least 2 for every one.

Run: ``python benchmarks/bench_simulator.py`` (``make benchmark``).
"""

from __future__ import annotations

import time

import numba as nb
import numpy as np
from scipy.signal import butter, sosfilt

from harvester.model import codegen
from harvester.model import fastmath as fm
from harvester.model.simulate import LANES, residual_sums, simulate
from harvester.model.structures import Layout
from harvester.model.terms import TERMS, term

FS, N_SAMPLES, PARTICLES, SUBSTEPS, REPEATS = 256.0, 2256, 512, 4, 7
#: The paper's device: M, m (kg), k (N/m), c_m (N s/m).
DEVICE = [12.8, 8.0, 250.0, 109.5]


def _reference(tanh):
    """The reference loop for one tanh implementation (compiled per implementation)."""

    @nb.njit(error_model="numpy", nogil=True)
    def rhs(u, z, v, M, m, k, c, F, b):
        return (-m * u - c * v - k * z - F * tanh(b * v)) / M

    @nb.njit(error_model="numpy", nogil=True)
    def block(yb, dt, nsub, M, m, k, c, F, b, acc):
        P = M.shape[0]
        z = np.zeros(P)
        v = np.zeros(P)
        scratch = np.empty(P)
        h = dt / nsub
        for i in range(yb.shape[0] - 1):
            y0 = yb[i]
            dy = (yb[i + 1] - y0) / nsub
            for s in range(nsub):
                u0 = y0 + dy * s
                um = u0 + 0.5 * dy
                u1 = u0 + dy
                row = acc[i] if s == 0 else scratch
                for p in range(P):
                    zz, vv = z[p], v[p]
                    a1 = rhs(u0, zz, vv, M[p], m[p], k[p], c[p], F[p], b[p])
                    row[p] = a1
                    z2, v2 = zz + 0.5 * h * vv, vv + 0.5 * h * a1
                    a2 = rhs(um, z2, v2, M[p], m[p], k[p], c[p], F[p], b[p])
                    z3, v3 = zz + 0.5 * h * v2, vv + 0.5 * h * a2
                    a3 = rhs(um, z3, v3, M[p], m[p], k[p], c[p], F[p], b[p])
                    z4, v4 = zz + h * v3, vv + h * a3
                    a4 = rhs(u1, z4, v4, M[p], m[p], k[p], c[p], F[p], b[p])
                    z[p] = zz + h / 6.0 * (vv + 2.0 * v2 + 2.0 * v3 + v4)
                    v[p] = vv + h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4)
        n = yb.shape[0] - 1
        for p in range(P):
            acc[n, p] = rhs(yb[n], z[p], v[p], M[p], m[p], k[p], c[p], F[p], b[p])

    @nb.njit(parallel=True, error_model="numpy")
    def run(yb, dt, nsub, prm, acc, nthreads):
        for t in nb.prange(nthreads):
            block(yb, dt, nsub, prm[t, 0], prm[t, 1], prm[t, 2], prm[t, 3], prm[t, 4],
                  prm[t, 5], acc[t])

    return run


@nb.njit(inline="always", error_model="numpy")
def _libm_tanh(x):
    return np.tanh(x)


def _inputs():
    rng = np.random.default_rng(0)
    y = sosfilt(butter(4, 15.0, fs=FS, output="sos"), rng.standard_normal(N_SAMPLES))
    y *= 4.0 / np.abs(y).max()
    p = np.tile(DEVICE + [11.86, 88.35], (PARTICLES, 1))
    p[:, 3] *= rng.uniform(0.8, 1.2, PARTICLES)
    p[:, 5] *= rng.uniform(0.5, 2.0, PARTICLES)
    return y, p


def main() -> None:
    y, p = _inputs()
    dt, threads = 1.0 / FS, nb.get_num_threads()
    layout = Layout.of(["tanh_friction"])
    refs = {"reference, C library tanh": _reference(_libm_tanh),
            "reference, vectorisable tanh (the bound)": _reference(fm.tanh)}
    # per thread: contiguous parameters (thread, parameter, particle) and outputs
    prm = np.ascontiguousarray(p.T.reshape(6, threads, -1).transpose(1, 0, 2))
    acc = np.empty((threads, N_SAMPLES, PARTICLES // threads))
    observed = np.zeros(N_SAMPLES - 256)
    runs = {name: (lambda f=f: f(y, dt, SUBSTEPS, prm, acc, threads)) for name, f in refs.items()}
    runs["harvester simulate (z, z', z'' returned)"] = \
        lambda: simulate(layout, p, y, dt, n_substeps=SUBSTEPS)
    runs["harvester residual_sums (likelihood path)"] = \
        lambda: residual_sums(layout, p, y, dt, observed, (256, N_SAMPLES))
    for f in runs.values():  # compile
        f()
    ours = simulate(layout, p, y, dt, n_substeps=SUBSTEPS).rel_acc
    refs["reference, vectorisable tanh (the bound)"](y, dt, SUBSTEPS, prm, acc, threads)
    best = {name: np.inf for name in runs}
    for _ in range(REPEATS):
        for name, f in runs.items():
            start = time.perf_counter()
            f()
            best[name] = min(best[name], time.perf_counter() - start)
    bound = best["reference, vectorisable tanh (the bound)"]
    print(f"tanh model, {N_SAMPLES} samples, {SUBSTEPS} RK4 sub-steps, {PARTICLES} particles, "
          f"{threads} threads; best of {REPEATS}")
    print(f"{'':45s} {'ms/particle':>12s} {'x the bound':>12s}")
    for name, seconds in best.items():
        print(f"{name:45s} {1e3 * seconds / PARTICLES:12.4f} {seconds / bound:12.2f}")
    ref = acc.transpose(0, 2, 1).reshape(PARTICLES, N_SAMPLES)
    print(f"max |z''(harvester) - z''(reference)| = {np.max(np.abs(ours - ref)):.2e} m/s^2")


def _typical(names: tuple[str, ...]) -> np.ndarray:
    """The paper's device with each term's parameters at the centre of its reference prior."""
    values = list(DEVICE)
    for name in names:
        for par in term(name).parameters:
            spec = par.prior.spec(par.name, par.unit)
            values.append(float(spec.from_coordinate(spec.center)))
    return np.array(values)


def _kernel_seconds(integrate, y: np.ndarray, p: np.ndarray, one_by_one: bool) -> float:
    """Best of REPEATS: the kernel over the particles of ``p`` (particles, parameters) in
    one call, or one call per particle (inputs and outputs made before the clock starts)."""
    h = 1.0 / (FS * SUBSTEPS)
    groups = [p[i:i + 1] for i in range(len(p))] if one_by_one else [p]
    calls = [(np.ascontiguousarray(g.T), np.empty((y.size, len(g))), np.empty((0, len(g))),
              np.ones(len(g), dtype=np.bool_)) for g in groups]
    best = np.inf
    for _ in range(REPEATS):
        start = time.perf_counter()
        for P, acc, none, ok in calls:
            integrate(y, SUBSTEPS, h, P, acc, none, none, ok)
        best = min(best, time.perf_counter() - start)
    return best


def vector_speedups() -> None:
    """The speed-up of each diagnosis structure's kernel from its vector lanes (docstring)."""
    y, _ = _inputs()
    others = sorted(t for t in TERMS if t != "tanh_friction")
    structures = [("tanh_friction", t) for t in others] + \
        [("tanh_friction", "hysteresis", t) for t in others if t != "hysteresis"]
    print(f"\nkernels on one thread, {N_SAMPLES} samples, {SUBSTEPS} sub-steps: a block of "
          f"{LANES * 16} particles in one call against one call each")
    print(f"{'structure':55s} {'ms/particle':>12s} {'speed-up':>9s}")
    for names in structures:
        integrate = codegen.kernel(names).integrate
        p = np.tile(_typical(names), (LANES * 16, 1))
        _kernel_seconds(integrate, y[:8], p[:2], True)  # compile
        block = _kernel_seconds(integrate, y, p, False)
        alone = _kernel_seconds(integrate, y, p, True)
        print(f"{'+'.join(names):55s} {1e3 * block / len(p):12.4f} {alone / block:9.2f}")


if __name__ == "__main__":
    main()
    vector_speedups()
