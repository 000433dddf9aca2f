"""Records with a known added force for the latent-force tests, written outside the library:
a linear device (Table 1's M, m, k; c_m = 60 N s/m) shaken by the study's excitation, plus a
force f(z, z', t) of any shape, integrated by RK4 (8 sub-steps per sample, the input linear
in a sample); each channel gets white sensor noise and the 20 Hz zero-phase low-pass."""

from __future__ import annotations

import numpy as np
import pandas as pd

from harvester.data.signals import lowpass
from harvester.inference.map_fit import BaselineState, ChainProblem, baseline_state
from harvester.inference.likelihood import DAQ_OVERSAMPLE
from harvester.synthetic.measured import TABLE1_KNOWN, base_excitation

FS = 256.0
C_M = 60.0
LOWPASS_HZ = 20.0


def rk4_record(extra, seconds: float = 20.0, seed: int = 0, peak: float = 4.0,
               n_sub: int = 8) -> dict[str, np.ndarray]:
    """Noise-free z, z', z'', the added force f (N) and the input y'' of the linear device plus
    ``extra(z, v, t)`` (N, opposing like a term's force)."""
    M, m, k = (TABLE1_KNOWN[p] for p in ("M", "m", "k"))
    n = int(round(seconds * FS))
    y = base_excitation(n, FS, np.random.default_rng(seed), peak=peak)
    h = 1.0 / (FS * n_sub)

    def acc(z, v, t, u):
        return (-m * u - C_M * v - k * z - extra(z, v, t)) / M

    z = v = 0.0
    out = np.zeros((4, n))
    for i in range(n):
        t0 = i / FS
        out[:, i] = z, v, acc(z, v, t0, y[i]), extra(z, v, t0)
        if i == n - 1:
            break
        for s in range(n_sub):
            t = t0 + s * h
            u0 = y[i] + (y[i + 1] - y[i]) * s / n_sub
            u1 = y[i] + (y[i + 1] - y[i]) * (s + 0.5) / n_sub
            u2 = y[i] + (y[i + 1] - y[i]) * (s + 1) / n_sub
            k1 = (v, acc(z, v, t, u0))
            k2 = (v + 0.5 * h * k1[1], acc(z + 0.5 * h * k1[0], v + 0.5 * h * k1[1], t + h / 2, u1))
            k3 = (v + 0.5 * h * k2[1], acc(z + 0.5 * h * k2[0], v + 0.5 * h * k2[1], t + h / 2, u1))
            k4 = (v + h * k3[1], acc(z + h * k3[0], v + h * k3[1], t + h, u2))
            z += h / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
            v += h / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
    return {"z": out[0], "v": out[1], "a": out[2], "f": out[3], "y": y}


def recording(truth: dict[str, np.ndarray], output: str = "rel_acc", noise: float = 0.02,
              seed: int = 1) -> pd.DataFrame:
    """The recording (time, base_acc, ``output``) of a :func:`rk4_record`: white sensor noise
    (``noise`` m/s^2 on the output's accelerometer, or 10 um on a displacement; none on the
    base), both channels low-passed at 20 Hz."""
    rng = np.random.default_rng(seed)
    n = truth["y"].size
    clean = truth["a"] if output == "rel_acc" else truth["z"]
    sd = noise if output == "rel_acc" else 1e-5
    out = clean + sd * rng.standard_normal(n)
    return pd.DataFrame({"time": np.arange(n) / FS,
                         "base_acc": lowpass(truth["y"], FS, LOWPASS_HZ, 8),
                         output: lowpass(out, FS, LOWPASS_HZ, 8)})


def linear_state(df: pd.DataFrame, c_m: float = C_M, lead_s: float = 1.0) -> BaselineState:
    """The linear baseline at c_m (Table 1's M, m, k) on ``df`` through the measurement
    chain, its sigma the RMS residual over the window (lead-in ``lead_s`` s, 0.5 s kept for
    the filters' end)."""
    output = "rel_disp" if "rel_disp" in df else "rel_acc"
    n = len(df)
    window = (int(lead_s * FS), n - int(0.5 * FS))
    from harvester.model.structures import structure
    problem = ChainProblem(structure("linear"), df["base_acc"].to_numpy(), df[output].to_numpy(),
                           1.0 / FS, dict(TABLE1_KNOWN), window, output_kind=output,
                           lowpass_hz=LOWPASS_HZ, oversample=DAQ_OVERSAMPLE)
    theta = np.array([[c_m, 1.0]])
    if output == "rel_acc":
        state = baseline_state(problem, theta)
    else:  # the diagnosis's BaselineState is written for z''; the smoother needs theta alone
        sim = problem.simulate(theta[0])
        state = BaselineState(problem, theta[0], np.zeros(2), theta, sim.rel_disp[0],
                              sim.rel_vel[0], sim.rel_acc[0], np.zeros(n), np.zeros((n, 1)))
    out = state.problem.simulate(theta[0])
    model = out.rel_disp[0] if output == "rel_disp" else out.rel_acc[0]
    resid = problem.measured_chain - problem.chain(model)
    state.theta = np.array([c_m, float(np.std(resid[window[0]:window[1]]))])
    return state
