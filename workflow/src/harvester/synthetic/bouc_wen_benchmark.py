"""The Bouc-Wen hysteretic benchmark system of Noel and Schoukens (2016), simulated as the
benchmark's own example generates its data, written as a force -> rel_disp recording.

System (Noel and Schoukens 2016, eqs. 1-3; a single degree of freedom with a hysteretic
restoring force):

    m_L y'' + c_L y' + k_L y + z(y, y') = u(t),
    z' = alpha y' - beta (gamma |y'| |z|^(nu-1) z + delta y' |z|^nu),

m_L = 2 kg, c_L = 10 N s/m, k_L = 5e4 N/m, alpha = 5e4 N/m, beta = 1e3 m^-1, gamma = 0.8,
delta = -1.1, nu = 1 (:data:`PARAMETERS`). Small-amplitude linear stiffness k_L + alpha =
1e5 N/m: 35.59 Hz, 1.12 % damping, the linear modal parameters the benchmark states.

Acquisition, as the benchmark's example script ``BoucWen_ExampleIntegration.m`` (in the
benchmark's files, ``BoucWenFiles.zip``, doi:10.4121/12967592) makes its data: a random-phase
multisine, lines of 750 / 8192 Hz from 5 to 150 Hz on a period of 8192 output samples, its
RMS ``rms_N`` (the example's 50 N), defined at the integration rate 20 x 750 Hz = 15 kHz;
the system integrated from rest at 15 kHz by a Newmark scheme (the example's integrator is
an encrypted MATLAB file, ``BoucWen_NewmarkIntegration.p``: here Newmark's average
acceleration with the trapezoidal rule for z, both implicit, solved by Newton's method each
step, :func:`newmark`); y decimated to 750 Hz by FIR low-pass filters of order 30 in the
prime factors 2, 2, 5 of 20 (the example's ``decimate(y, r, 'fir')``; here
``scipy.signal.decimate`` with the same order, linear phase compensated), u down-sampled;
one period more simulated than kept, so that the filter's end effect is cut away. Output
noise: white Gaussian, standard deviation 8e-3 mm (:data:`NOISE_SD_M`, the benchmark's
level as its ports use it: deepSI's ``Bouc_wen`` system, github.com/GerbenBeintema/deepSI,
``deepSI/systems/boucwen.py``, 8e-6 m, which it also low-passes; white here, band-limited
by the 750 Hz sampling alone). The benchmark's parameters and signal design were
read in those public copies (the example script, deepSI); the nonlinear-benchmark Python
package (github.com/GerbenBeintema/nonlinear_benchmarks) loads only the benchmark's test
signals and has no simulator.

The recording (:func:`generate`): ``time, force, rel_disp`` (N, m); its sidecar the masses a
user of the benchmark knows, M = m = m_L, and the small-amplitude stiffness k = k_L + alpha
(:func:`sidecar`: the stiffness a static or small-amplitude test measures, and the one the
benchmark's stated linear modal parameters imply; with k_L alone the linear model would
misplace the resonance by 10 Hz); ``filtered_at_hz: 0``, the decimation filter lying at the
Nyquist frequency, none within the band. The truth: ``correct_names`` the hysteresis family,
["hysteresis", "hysteretic_spring"] (the library's loop in the friction and in the spring), and
the nonlinearity's contribution to y (against the linear system k_L + alpha, same input) over
the noise (``ratio``), as the project's record sets read it (``harvester.grid.peers``).

This module imports nothing from ``harvester``: it is a second, independent statement of
the physics.

References
----------
Noel, J.P., Schoukens, M. (2016) Hysteretic benchmark with a dynamic nonlinearity. Workshop
on Nonlinear System Identification Benchmarks, Brussels; 4TU.ResearchData, doi:10.4121/12967592.
Schoukens, M., Noel, J.P. (2017) Three benchmarks addressing open challenges in nonlinear
system identification. IFAC-PapersOnLine 50(1):446-451.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numba as nb
import numpy as np
import pandas as pd
from scipy import signal

__all__ = ["PARAMETERS", "BenchmarkRecording", "Multisine", "generate", "newmark",
           "reference_solution", "sidecar"]

#: The benchmark's system (SI units).
PARAMETERS: dict[str, float] = {"m_L": 2.0, "c_L": 10.0, "k_L": 5.0e4, "alpha": 5.0e4,
                                "beta": 1.0e3, "gamma": 0.8, "delta": -1.1, "nu": 1.0}
#: Output rate (Hz), integration rate / output rate, samples per multisine period.
FS, UPSAMPLE, PERIOD = 750.0, 20, 8192
#: The multisine's band (Hz) and the example's RMS (N).
F_MIN, F_MAX, RMS_N = 5.0, 150.0, 50.0
#: Output noise standard deviation (m).
NOISE_SD_M = 8.0e-6
#: Order of each FIR decimation stage (MATLAB's ``decimate(..., 'fir')``), and the stages.
FIR_ORDER, STAGES = 30, (2, 2, 5)
#: Newton's iterations per step: at most, and the tolerance on the step's a (m/s^2) and z (N).
NEWTON_MAX, NEWTON_TOL = 30, 1e-12


@dataclass(frozen=True)
class Multisine:
    """u(t) = scale sum_k cos(2 pi k t / T + phase_k) (N), T = PERIOD / FS, lines k
    (:func:`draw_multisine`)."""

    lines: np.ndarray = field(repr=False)
    phases: np.ndarray = field(repr=False)
    scale: float

    @property
    def period(self) -> float:
        return PERIOD / FS

    def at(self, t: np.ndarray | float) -> np.ndarray:
        """u (N) at times t (s), by the sum of cosines (for reference solutions)."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        arg = 2.0 * np.pi * np.outer(t, self.lines / self.period) + self.phases
        return self.scale * np.cos(arg).sum(axis=1)

    def on_grid(self, n: int) -> np.ndarray:
        """u (N) at the integration rate FS x UPSAMPLE, n samples from t = 0 (inverse FFT,
        repeated period after period)."""
        n_int = PERIOD * UPSAMPLE
        spec = np.zeros(n_int // 2 + 1, dtype=complex)
        spec[self.lines] = 0.5 * n_int * np.exp(1j * self.phases)
        one = self.scale * np.fft.irfft(spec, n_int)
        return np.tile(one, -(-n // n_int))[:n]


def draw_multisine(rng: np.random.Generator, rms_N: float = RMS_N) -> Multisine:
    """The example's multisine: lines k f_res, f_res = FS / PERIOD, from floor(F_MIN / f_res)
    to ceil(F_MAX / f_res), phases uniform in [0, 2 pi), scaled to RMS ``rms_N``."""
    f_res = FS / PERIOD
    lines = np.arange(int(np.floor(F_MIN / f_res)), int(np.ceil(F_MAX / f_res)) + 1)
    phases = rng.uniform(0.0, 2.0 * np.pi, lines.size)
    # a sum of n unit cosines at distinct lines has RMS sqrt(n / 2)
    return Multisine(lines, phases, rms_N / np.sqrt(0.5 * lines.size))


@nb.njit(cache=True)
def _rate(v, z, alpha, beta, gamma, delta, nu):
    """z' (N/s) and its derivatives with respect to y' and z."""
    az = abs(z)
    pw = az ** (nu - 1.0) if az > 0.0 else (1.0 if nu == 1.0 else 0.0)
    g = alpha * v - beta * (gamma * abs(v) * pw * z + delta * v * pw * az)
    dv = alpha - beta * (gamma * np.sign(v) * pw * z + delta * pw * az)
    dz = -beta * nu * pw * (gamma * abs(v) + delta * v * np.sign(z))
    return g, dv, dz


@nb.njit(cache=True)
def _newmark(u, h, m, c, k, alpha, beta, gamma, delta, nu):
    """y (m), y' (m/s), z (N) at the samples of u (N), from rest (:func:`newmark`)."""
    n = u.size
    y, v, z = np.zeros(n), np.zeros(n), np.zeros(n)
    a = u[0] / m
    for i in range(1, n):
        y0, v0, z0 = y[i - 1], v[i - 1], z[i - 1]
        g0 = _rate(v0, z0, alpha, beta, gamma, delta, nu)[0]
        a1, z1 = a, z0 + h * g0
        for _ in range(NEWTON_MAX):
            v1 = v0 + 0.5 * h * (a + a1)
            y1 = y0 + h * v0 + 0.25 * h * h * (a + a1)
            g1, dv, dz = _rate(v1, z1, alpha, beta, gamma, delta, nu)
            r1 = m * a1 + c * v1 + k * y1 + z1 - u[i]
            r2 = z1 - z0 - 0.5 * h * (g0 + g1)
            j11, j12 = m + 0.5 * h * c + 0.25 * h * h * k, 1.0
            j21, j22 = -0.25 * h * h * dv, 1.0 - 0.5 * h * dz
            det = j11 * j22 - j12 * j21
            da = (r1 * j22 - j12 * r2) / det
            dzz = (j11 * r2 - j21 * r1) / det
            a1, z1 = a1 - da, z1 - dzz
            if abs(da) < NEWTON_TOL * (1.0 + abs(a1)) and abs(dzz) < NEWTON_TOL * (1.0 + abs(z1)):
                break
        v[i] = v0 + 0.5 * h * (a + a1)
        y[i] = y0 + h * v0 + 0.25 * h * h * (a + a1)
        z[i], a = z1, a1
    return y, v, z


def newmark(u: np.ndarray, h: float, params: dict[str, float] | None = None
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """y (m), y' (m/s), z (N) of the system at the samples of the force u (N, every h s),
    from rest: Newmark's average acceleration (gamma_N 1/2, beta_N 1/4) for y, the
    trapezoidal rule for z, the step's equations solved together by Newton's method."""
    p = {**PARAMETERS, **(params or {})}
    return _newmark(np.ascontiguousarray(u, dtype=float), float(h), p["m_L"], p["c_L"],
                    p["k_L"], p["alpha"], p["beta"], p["gamma"], p["delta"], p["nu"])


def reference_solution(excitation: Multisine, t_end: float, t_eval: np.ndarray,
                       params: dict[str, float] | None = None, rtol: float = 1e-10,
                       atol: float = 1e-13) -> np.ndarray:
    """y (m) at ``t_eval`` by scipy's DOP853 at tight tolerance, u from the sum of cosines
    (the check of :func:`newmark`)."""
    from scipy.integrate import solve_ivp
    p = {**PARAMETERS, **(params or {})}

    def rhs(t, x):
        y, v, z = x
        u = excitation.at(t)[0]
        g = _rate(v, z, p["alpha"], p["beta"], p["gamma"], p["delta"], p["nu"])[0]
        return [v, (u - p["c_L"] * v - p["k_L"] * y - z) / p["m_L"], g]

    sol = solve_ivp(rhs, (0.0, t_end), [0.0, 0.0, 0.0], method="DOP853", t_eval=t_eval,
                    rtol=rtol, atol=atol, max_step=1.0 / (FS * UPSAMPLE))
    return sol.y[0]


def _decimate(y: np.ndarray) -> np.ndarray:
    for q in STAGES:
        y = signal.decimate(y, q, n=FIR_ORDER, ftype="fir", zero_phase=True)
    return y


def sidecar() -> dict[str, float]:
    """What a user of the benchmark knows: M = m = m_L, k = k_L + alpha (module docstring),
    no low-pass within the band."""
    p = PARAMETERS
    return {"M": p["m_L"], "m": p["m_L"], "k": p["k_L"] + p["alpha"], "filtered_at_hz": 0}


@dataclass
class BenchmarkRecording:
    """The recording (time, force, rel_disp), its sidecar and its truth."""

    recording: pd.DataFrame
    sidecar: dict[str, float]
    truth: dict[str, Any]
    clean: np.ndarray = field(repr=False)   # noise-free y (m), output rate
    linear: np.ndarray = field(repr=False)  # y of the linear system k_L + alpha (m)

    def write(self, out_dir: str | Path, name: str = "bouc_wen_benchmark") -> dict[str, Path]:
        """``<name>.csv``, its sidecar ``<name>.yaml`` and truth ``<name>.json``: a record
        set's member (``harvester.grid.peers.read_set``)."""
        out = Path(out_dir)
        out.mkdir(parents=True, exist_ok=True)
        paths = {"recording": out / f"{name}.csv", "sidecar": out / f"{name}.yaml",
                 "truth": out / f"{name}.json"}
        self.recording.to_csv(paths["recording"], index=False, float_format="%.10g")
        paths["sidecar"].write_text("".join(f"{k}: {v!r}\n" for k, v in self.sidecar.items()))
        paths["truth"].write_text(json.dumps(self.truth, indent=2) + "\n")
        return paths


def _outputs(u: np.ndarray, n_out: int, params: dict[str, float] | None = None
             ) -> np.ndarray:
    """y (m) at the output rate, n_out samples, noise-free."""
    y = newmark(u, 1.0 / (FS * UPSAMPLE), params)[0]
    return _decimate(y)[:n_out]


def generate(seed: int = 0, duration_s: float = 40.0, rms_N: float = RMS_N,
             noise_sd_m: float = NOISE_SD_M) -> BenchmarkRecording:
    """A record of ``duration_s`` seconds (module docstring), the multisine's phases and the
    noise drawn from ``seed``."""
    if duration_s <= 2.0 or rms_N <= 0.0 or noise_sd_m < 0.0:
        raise ValueError("need duration_s > 2 s, rms_N > 0 and noise_sd_m >= 0")
    rng_phase, rng_noise = (np.random.default_rng(s)
                            for s in np.random.SeedSequence([int(seed), 0xB0C]).spawn(2))
    exc = draw_multisine(rng_phase, rms_N)
    n_out = int(round(duration_s * FS))
    periods = -(-n_out // PERIOD) + 1  # one more than kept: the filter's end effect
    u = exc.on_grid(periods * PERIOD * UPSAMPLE)
    clean = _outputs(u, n_out)
    p = PARAMETERS
    linear = _outputs(u, n_out, {"k_L": p["k_L"] + p["alpha"], "alpha": 0.0, "beta": 0.0})
    noise = noise_sd_m * rng_noise.standard_normal(n_out)
    rec = pd.DataFrame({"time": np.arange(n_out) / FS, "force": u[::UPSAMPLE][:n_out],
                        "rel_disp": clean + noise})
    return BenchmarkRecording(rec, sidecar(), _truth(seed, exc, clean, linear, noise_sd_m,
                                                     duration_s), clean, linear)


def _truth(seed: int, exc: Multisine, clean: np.ndarray, linear: np.ndarray,
           noise_sd_m: float, duration_s: float) -> dict[str, Any]:
    lead = int(FS)  # after the diagnosis's 1 s lead-in
    contribution = float(np.sqrt(np.mean((clean - linear)[lead:] ** 2)))
    known = {k: v for k, v in sidecar().items() if k in ("M", "m", "k")}
    return {
        "scenario": "bouc_wen_benchmark", "generator": "harvester.synthetic.bouc_wen_benchmark",
        "simulated": True, "seed": int(seed),
        "correct_names": ["hysteresis", "hysteretic_spring"],
        "related_names": ["cubic_stiffness", "coulomb_friction"],
        "form": "m_L y'' + c_L y' + k_L y + z = u, z' = alpha y' - beta (gamma |y'| "
                "|z|^(nu-1) z + delta y' |z|^nu)",
        "citation": "Noel, J.P., Schoukens, M. (2016) Hysteretic benchmark with a dynamic "
                    "nonlinearity. Workshop on Nonlinear System Identification Benchmarks; "
                    "doi:10.4121/12967592",
        "parameters": dict(PARAMETERS), "known": known, "baseline": "linear",
        "ratio": contribution / noise_sd_m if noise_sd_m > 0 else None,
        "nonlinear_contribution_rms_m": contribution,
        "rel_disp_rms_m": float(np.sqrt(np.mean(clean[lead:] ** 2))),
        "noise_sd_m": noise_sd_m, "fs_hz": FS, "duration_s": duration_s,
        "excitation": {"kind": "random-phase multisine", "band_hz": [F_MIN, F_MAX],
                       "lines": int(exc.lines.size), "rms_N": float(exc.scale * np.sqrt(
                           0.5 * exc.lines.size)), "period_samples": PERIOD},
        "integration": {"method": "Newmark average acceleration, trapezoidal z, Newton",
                        "rate_hz": FS * UPSAMPLE, "decimation": f"FIR order {FIR_ORDER}, "
                        f"stages {list(STAGES)}"},
        "settings": {"lead_in_s": 1.0},
    }
