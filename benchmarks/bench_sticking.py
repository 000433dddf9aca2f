"""Cost of the dry friction that sticks against the smooth laws, batched as the diagnosis
simulates (``residual_sums``, the likelihood's path: a population of particles in one call).

Record: the frame of Marino and Cicirello at 450 g (``data/public/marino-frame``), its
friction on the ground (``data.kinds.on_ground``: driven by the force K y, output the storey's
absolute displacement), 2501 samples at 250 Hz. Population: PARTICLES particles with M = m =
3.0799 kg and k = 1191 N/m (the authors' values), c_m log-uniform 0.1-3 N s/m and the
friction's level log-uniform 0.05-5 N, the same draws for every structure; a Stribeck or tanh
shape from its own prior on the frame's scale (``harvester.model.priors``: the record's RMS
velocity and displacement, a force scale of 1 N). Pairs timed:

- ``coulomb_friction`` (F tanh(w / 1 mm/s), the smooth law the issue names) against
  ``sticking_friction`` (the same level, holding);
- ``tanh_friction`` (F_c, beta free) against ``sticking_friction+sticking_stribeck``.

Each figure is the best of REPEATS interleaved calls after one warm-up call (the kernels
compile once, cached on disk), on the threads Numba is given; the ratio is printed from this
one run. Goal: the sticking law within 2 x the smooth law's cost per simulation.

Run: ``.venv/bin/python benchmarks/bench_sticking.py``.
"""

from __future__ import annotations

import time
import zlib
from pathlib import Path

import numpy as np

from harvester.data.public import FRAME_DEVICE, marino_frame
from harvester.model.priors import DeviceScale
from harvester.model.simulate import residual_sums
from harvester.model.structures import Layout

FRAME = Path(__file__).resolve().parents[1] / "data" / "public" / "marino-frame"
PARTICLES, REPEATS, LOAD_G, LEAD_IN_S = 256, 5, 450, 0.5
#: The force scale (N) the shapes' priors are read on: about the frame's friction level.
FORCE_SCALE = 1.0
PAIRS = ((("coulomb_friction",), ("sticking_friction",)),
         (("tanh_friction",), ("sticking_friction", "sticking_stribeck")))


def population(names: tuple[str, ...], rng: np.random.Generator, device: DeviceScale,
               common: dict[str, np.ndarray]) -> np.ndarray:
    """Particles of a structure: the common draws where a parameter is a level, the rest
    from its prior on the device."""
    level = {"F_coulomb", "F_c", "F_dry"}
    lay = Layout.of(names)
    cols = []
    for name in lay.parameter_names:
        if name in common:
            cols.append(common[name])
        elif name in level:
            cols.append(common["level"])
        else:
            spec = next(p for t in lay.terms for p in t.parameters if p.name == name)
            rs = np.random.default_rng(zlib.crc32(name.encode()))
            cols.append(spec.prior_on(device).distribution().rvs(PARTICLES, random_state=rs))
    return np.column_stack(cols)


def main() -> None:
    rec = marino_frame(FRAME, LOAD_G, friction_on="ground")
    df = rec.data
    u, y = df["force"].to_numpy(), df["rel_disp"].to_numpy()
    dt = float(np.mean(np.diff(df["time"].to_numpy())))
    window = (int(LEAD_IN_S / dt), u.size)
    v = np.gradient(y, dt)
    device = DeviceScale(force=FORCE_SCALE, v=float(np.std(v)), z=float(np.std(y)),
                         f_high=10.0, M=FRAME_DEVICE["M"], m=FRAME_DEVICE["M"],
                         k=FRAME_DEVICE["k"])
    rng = np.random.default_rng(1)
    mass = np.full(PARTICLES, FRAME_DEVICE["M"])
    common = {"M": mass, "m": mass,
              "k": np.full(PARTICLES, FRAME_DEVICE["k"]),
              "c_m": np.exp(rng.uniform(np.log(0.1), np.log(3.0), PARTICLES)),
              "level": np.exp(rng.uniform(np.log(0.05), np.log(5.0), PARTICLES))}
    print(f"frame {LOAD_G} g on the ground: {u.size} samples at {1 / dt:g} Hz, {PARTICLES} "
          f"particles, best of {REPEATS}")
    for smooth, sticking in PAIRS:
        best, subs = {}, {}
        pops = {s: population(s, rng, device, common) for s in (smooth, sticking)}
        obs = y[window[0]:window[1]]
        for s in (smooth, sticking):  # warm-up: compile or load the kernels
            residual_sums(Layout.of(s), pops[s], u, dt, obs, window, output_kind="rel_disp",
                          force_input=True)
        for _ in range(REPEATS):
            for s in (smooth, sticking):
                t0 = time.perf_counter()
                sse, ok = residual_sums(Layout.of(s), pops[s], u, dt, obs, window,
                                        output_kind="rel_disp", force_input=True)
                best[s] = min(best.get(s, np.inf), time.perf_counter() - t0)
                subs[s] = (float(np.mean(ok)), float(np.min(sse[ok])))
        for s in (smooth, sticking):
            print(f"  {'+'.join(s):40s} {1e3 * best[s] / PARTICLES:7.3f} ms per simulation, "
                  f"{100 * subs[s][0]:.0f} % ok, best RMS misfit "
                  f"{1e6 * np.sqrt(subs[s][1] / obs.size):.1f} um")
        print(f"  ratio sticking / smooth: {best[sticking] / best[smooth]:.2f} (goal <= 2)")


if __name__ == "__main__":
    main()
