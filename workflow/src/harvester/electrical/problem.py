"""The joint likelihood of the loaded records: acceleration and voltage, one noise level each.

For a parameter vector theta = (ln c_m, ln F_c, ln beta, K_e, R_s[, L_s], sigma_acc, sigma_V)
and each record r (load conductance g_r), eq. (1) with the tanh friction and the generator
(``generator.mechanical_equivalent``: c_m + c_e, M - c_e tau) is integrated from rest by the
compiled simulator for all particles at once; then over the record's window

    log L = sum_r [ -n_r/2 ln(2 pi sigma_acc^2) - |z''_r - z''_hat|^2 / (2 sigma_acc^2)
                    -n_r/2 ln(2 pi sigma_V^2)   - |V_r - V_hat|^2 / (2 sigma_V^2) ],

z'' through the same zero-phase low-pass as the data (the paper's eq. 10 on each channel),
V the line-voltage magnitude (``generator.line_voltage_magnitude``). Residuals are taken as
independent Gaussian, as in eq. (9); the magnitude's noise is only near-Gaussian (Rician where
V is within a few noise levels of zero, a small share of the samples).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy.signal import sosfiltfilt

from harvester.data.signals import butterworth_sos, settling_samples
from harvester.electrical import generator as gen
from harvester.electrical.priors import MECHANICAL, MechanicalPrior
from harvester.electrical.records import LoadedRecord
from harvester.inference.likelihood import DAQ_OVERSAMPLE, gaussian_loglike
from harvester.model.simulate import simulate
from harvester.model.structures import Layout

#: Electrical model structures: whether the phase inductance (electrical lag) is modelled.
STRUCTURES: dict[str, bool] = {"resistive": False, "inductive": True}
#: The mechanical structure under the generator: eq. (1) with tanh friction (the paper's M2).
LAYOUT_TERMS = ("tanh_friction",)


def structure_parameters(structure: str) -> tuple[str, ...]:
    """Physical and noise parameters of a structure, in theta's order (after ln c_m, ln F_c,
    ln beta)."""
    inductive = STRUCTURES[structure]
    return ("K_e", "R_s") + (("L_s",) if inductive else ()) + ("sigma_acc", "sigma_V")


@dataclass
class ElectricalProblem:
    """The loaded records, one electrical structure, the known masses and spring, and how
    z'' is acquired (``oversample``) and filtered (``lowpass``: cut-off Hz, order)."""

    records: Sequence[LoadedRecord]
    structure: str
    mechanical: MechanicalPrior
    lowpass: tuple[float, int]
    oversample: int = 4
    n_evaluations: int = field(default=0, init=False)

    def __post_init__(self) -> None:
        if self.structure not in STRUCTURES:
            raise KeyError(f"unknown electrical structure {self.structure!r}; known: "
                           f"{sorted(STRUCTURES)}")
        self.layout = Layout.of(LAYOUT_TERMS)

    @property
    def parameter_names(self) -> tuple[str, ...]:
        """theta's columns: ln of the mechanical ones, then ``structure_parameters``."""
        return tuple(f"ln_{n}" for n in MECHANICAL) + structure_parameters(self.structure)

    def physical(self, theta: np.ndarray) -> dict[str, np.ndarray]:
        """Columns of theta by name in physical units (c_m, F_c, beta exponentiated; L_s = 0
        in the resistive structure)."""
        theta = np.atleast_2d(np.asarray(theta, dtype=float))
        out = {n: np.exp(theta[:, j]) for j, n in enumerate(MECHANICAL)}
        for j, n in enumerate(structure_parameters(self.structure), start=len(MECHANICAL)):
            out[n] = theta[:, j]
        out.setdefault("L_s", np.zeros(theta.shape[0]))
        return out

    def simulate_record(self, p: dict[str, np.ndarray], rec: LoadedRecord,
                        base_acc: np.ndarray | None = None, oversample: int | None = None):
        """(z', z'', ok) per particle (rows) for record ``rec`` (or another input)."""
        return simulate_loaded(self.layout, p, self.mechanical.known, rec.g, rec.G,
                               rec.base_acc if base_acc is None else base_acc, rec.dt,
                               self.oversample if oversample is None else oversample)

    def record_sums(self, p: dict[str, np.ndarray], rec: LoadedRecord):
        """(acceleration SSE, voltage SSE, ok) per particle over the record's window. The
        simulation stops where the zero-phase filter's end effect has decayed below 1e-12
        (``settling_samples``) after the window, not at the record's end."""
        sos = butterworth_sos(1.0 / rec.dt, self.lowpass[0], int(self.lowpass[1]))
        stop = min(rec.base_acc.size, rec.window[1] + settling_samples(sos))
        v, a, ok = self.simulate_record(p, rec, base_acc=rec.base_acc[:stop])
        s = rec.samples
        a_f = sosfiltfilt(sos, np.nan_to_num(a), axis=-1)
        sse_a = np.sum((a_f[:, s] - rec.rel_acc[s]) ** 2, axis=1)
        volts = gen.line_voltage_magnitude(v[:, s], a[:, s], p["K_e"], p["R_s"], p["L_s"],
                                           rec.g, rec.G)
        sse_v = np.sum((volts - rec.voltage[s]) ** 2, axis=1)
        return sse_a, sse_v, ok

    def loglike(self, theta: np.ndarray) -> np.ndarray:
        """Log-likelihood per row of theta (module docstring); -inf where a simulation failed
        or a noise level is not positive."""
        theta = np.atleast_2d(np.asarray(theta, dtype=float))
        self.n_evaluations += theta.shape[0]
        p = self.physical(theta)
        ll = np.zeros(theta.shape[0])
        good = (p["sigma_acc"] > 0) & (p["sigma_V"] > 0)
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            for rec in self.records:
                sse_a, sse_v, ok = self.record_sums(p, rec)
                ll += gaussian_loglike(sse_a, rec.n_data, p["sigma_acc"])
                ll += gaussian_loglike(sse_v, rec.n_data, p["sigma_V"])
                good &= ok
        ll[~good | ~np.isfinite(ll)] = -np.inf
        return ll


def simulate_loaded(layout: Layout, p: dict[str, np.ndarray], known: dict[str, float],
                    g, G: float, base_acc: np.ndarray, dt: float,
                    oversample: int = DAQ_OVERSAMPLE):
    """(z' (m/s), z'' (m/s^2), ok) per particle of eq. (1) + tanh friction + the generator at
    load conductance g (1/ohm, scalar or per particle); ``p``: c_m, F_c, beta, K_e, R_s, L_s
    arrays (one per particle); ``known``: M, m, k. ``oversample``: as the DAQ samples
    (``harvester.model.simulate``; point samples, 1, bias the mean z'^2 by about 1 % on the
    rig's records). Not ok: failed, or outside the first-order model's domain."""
    M_eff, c_eff = gen.mechanical_equivalent(known["M"], p["c_m"], p["K_e"], p["R_s"],
                                             p["L_s"], g, G)
    n = np.size(p["c_m"])
    P = np.column_stack([M_eff, np.full(n, known["m"]), np.full(n, known["k"]), c_eff,
                         p["F_c"], p["beta"]])
    sim = simulate(layout, P, base_acc, dt, oversample=oversample)
    return sim.rel_vel, sim.rel_acc, sim.ok
