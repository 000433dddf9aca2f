"""The frame of Marino and Cicirello fitted by least squares with the sticking laws against the
smooth ones: the sliding level, the stuck share and the misfit each gives.

Records: ``data/public/marino-frame`` at 250 and 450 g, as the lasers recorded them (no
low-pass), rewritten with the friction on the ground (``data.kinds.on_ground``: driven by
K y, output the storey's absolute displacement; M = m = 3.0799 kg, K = 1191 N/m, the
authors' values). Each structure's c_m and friction parameters are fitted by
``scipy.optimize.least_squares`` on 1.0-7.4 s (the span the diagnosis analyses in a 10 s
record), the output's mean free; the misfit is the RMS residual (m). A point estimate from
one start, not a posterior: a local optimum is possible.

Then the log-likelihood of the 450 g record about the Stribeck form's MAP that ``harvester
diagnose`` found for it (``MAP_450``, sigma ``SIGMA_450``), along F_dry, F_break and v_break
on grids of 41, 81 and 161 points: the largest step between neighbours halves with the
spacing where the likelihood is continuous.

Run: ``.venv/bin/python benchmarks/bench_sticking_frame.py`` (about a minute).
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.io import loadmat
from scipy.optimize import least_squares

from harvester.data.kinds import on_ground
from harvester.data.public import FRAME_DEVICE
from harvester.model.simulate import residual_sums, simulate
from harvester.model.structures import Layout

FRAME = Path(__file__).resolve().parents[1] / "data" / "public" / "marino-frame"
WINDOW_S = (1.0, 7.4)
#: (terms, start, lower, upper) of c_m and the terms' parameters.
FITS = (((), [1.0], [0.0], [200.0]),
        (("coulomb_friction",), [1.0, 0.5], [0.0, 0.0], [200.0, 10.0]),
        (("sticking_friction",), [1.0, 0.5], [0.0, 0.0], [200.0, 10.0]),
        (("sticking_friction", "sticking_stribeck"), [1.0, 0.5, 0.2, 0.005, 1.5],
         [0.0, 0.0, 0.0, 1e-5, 1.0], [200.0, 10.0, 10.0, 1.0, 3.0]))


def recording(load_g: int) -> tuple[np.ndarray, np.ndarray, float]:
    """(force K y (N), absolute displacement (m), dt (s)) of the frame at a load, unfiltered."""
    x, y = (loadmat(FRAME / f"s_b_{load_g}g_{c}.mat") for c in ("x", "y"))
    t = x["t"].ravel() - x["t"].ravel()[0]
    base, rel = y["y"].ravel() / 1e3, (x["x"].ravel() - y["y"].ravel()) / 1e3
    df = pd.DataFrame({"time": t, "base_disp": base - base.mean(),
                       "rel_disp": rel - rel.mean()})
    g, _, _ = on_ground(df, FRAME_DEVICE, f"frame {load_g} g")
    return g["force"].to_numpy(), g["rel_disp"].to_numpy(), float(np.mean(np.diff(t)))


def fit(terms, start, lower, upper, u, x, dt) -> None:
    lay = Layout.of(terms)
    w = slice(int(WINDOW_S[0] / dt), int(WINDOW_S[1] / dt))
    masses = [FRAME_DEVICE["M"], FRAME_DEVICE["M"], FRAME_DEVICE["k"]]

    def run(q):
        return simulate(lay, np.r_[masses, q], u, dt, force_input=True)

    def residual(q):
        r = run(q).rel_disp[0][w] - x[w]
        return r - r.mean()
    t0 = time.perf_counter()
    sol = least_squares(residual, start, bounds=(lower, upper), x_scale=np.array(start),
                        diff_step=1e-3)
    v = run(sol.x).rel_vel[0][w]
    names = lay.parameter_names[3:]
    values = ", ".join(f"{n} {q:.4g}" for n, q in zip(names, sol.x))
    print(f"  {'+'.join(terms) or 'linear':36s} RMS {1e6 * np.sqrt(np.mean(sol.fun**2)):6.1f} "
          f"um, stuck {np.mean(v == 0):.3f}; {values} ({time.perf_counter() - t0:.0f} s)")


#: linear+sticking_friction+sticking_stribeck's MAP on the 450 g record (the diagnosis's log:
#: c_m, F_dry, F_break, v_break, delta_break) and its sigma (m).
MAP_450 = {"c_m": 77.93, "F_dry": 0.09255, "F_break": 0.9731, "v_break": 0.008853,
           "delta_break": 2.703}
SIGMA_450 = 1.019e-4
#: Half-widths of the grids about the MAP.
HALF = {"F_dry": 0.022, "F_break": 0.022, "v_break": 0.001}


def continuity(u, x, dt) -> None:
    lay = Layout.of(["sticking_friction", "sticking_stribeck"])
    w = (int(WINDOW_S[0] / dt), int(WINDOW_S[1] / dt))
    row = np.r_[FRAME_DEVICE["M"], FRAME_DEVICE["M"], FRAME_DEVICE["k"], list(MAP_450.values())]
    for name, half in HALF.items():
        steps = []
        for num in (41, 81, 161):
            P = np.tile(row, (num, 1))
            j = lay.index(name)
            P[:, j] = np.linspace(row[j] - half, row[j] + half, num)
            sse, _ = residual_sums(lay, P, u, dt, x[w[0]:w[1]], w, output_kind="rel_disp",
                                   force_input=True)
            steps.append(np.max(np.abs(np.diff(sse))) / (2 * SIGMA_450**2))
        print(f"  {name} +- {half:g}: largest step " + ", ".join(f"{s:.3g}" for s in steps)
              + " nats (41, 81, 161 points)")


def main() -> None:
    for load in (250, 450):
        u, x, dt = recording(load)
        print(f"frame {load} g on the ground, unfiltered, {WINDOW_S[0]}-{WINDOW_S[1]} s:")
        for terms, start, lower, upper in FITS:
            fit(terms, start, lower, upper, u, x, dt)
    print("log-likelihood about the Stribeck form's MAP at 450 g:")
    continuity(u, x, dt)


if __name__ == "__main__":
    main()
