"""Power the harvester would deliver to its load, predicted from the electrical posteriors.

Draws of the parameters come from each structure's posterior in proportion to its weight of
Bayesian model averaging (``electrical.identify.model_weights``): the predictive of the
mixture, p(P | D) = sum_s p(s | D) p(P | D, s). Each draw and each load R_L (ohm) is one
particle of one call of the compiled simulator (eq. 1, tanh friction, the generator's c_e and
-c_e tau at that load); the load power is ``generator.load_power`` and its mean is taken after
a lead-in (the model starts at rest).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from harvester.electrical import generator as gen
from harvester.electrical.problem import LAYOUT_TERMS, simulate_loaded
from harvester.model.structures import Layout

#: Columns of a table of draws (``structure`` besides).
PARAMETERS = ("c_m", "F_c", "beta", "K_e", "R_s", "L_s", "sigma_acc", "sigma_V")


def bma_draws(posteriors: Mapping[str, pd.DataFrame], weights: Mapping[str, float], n: int,
              rng: np.random.Generator) -> pd.DataFrame:
    """n draws of the BMA mixture: counts per structure multinomial in the weights, rows of
    each posterior drawn with replacement; column ``structure`` says whose."""
    names = list(posteriors)
    p = np.array([weights[s] for s in names], dtype=float)
    counts = rng.multinomial(n, p / p.sum())
    parts = []
    for s, c in zip(names, counts):
        if c:
            rows = rng.integers(0, len(posteriors[s]), size=c)
            parts.append(posteriors[s].iloc[rows][list(PARAMETERS)].assign(structure=s))
    return pd.concat(parts, ignore_index=True)


def with_change(draws: pd.DataFrame, change: Mapping[str, float]) -> pd.DataFrame:
    """Draws with parameters scaled: {"F_c": 0.5} halves the friction of every draw."""
    out = draws.copy()
    for name, factor in change.items():
        out[name] = out[name] * float(factor)
    return out


@dataclass(frozen=True)
class PowerPrediction:
    """Mean load power (W) per draw, load and window (draws x loads x windows) of an
    excitation after its lead-in, the loads (ohm), the window length (s), failed simulations.

    A window is one record of ``window_s`` seconds: over the windows of a long stationary
    excitation (a sea state), the power varies from record to record as well as with the
    parameters."""

    windows: np.ndarray
    loads: np.ndarray
    window_s: float
    failed: int

    @property
    def power(self) -> np.ndarray:
        """Mean power over all windows (W), draws x loads: the parameters' uncertainty."""
        return self.windows.mean(axis=2)

    @property
    def seconds(self) -> float:
        return self.window_s * self.windows.shape[2]

    @property
    def energy(self) -> np.ndarray:
        """Energy delivered to the load over all windows (J), draws x loads."""
        return self.power * self.seconds

    @property
    def per_record(self) -> np.ndarray:
        """Mean power of one record (W), (draws x windows) x loads: parameters and the
        record-to-record spread together."""
        return self.windows.transpose(0, 2, 1).reshape(-1, self.loads.size)

    @property
    def record_energy(self) -> np.ndarray:
        """Energy over one record of window_s (J), (draws x windows) x loads."""
        return self.per_record * self.window_s


def particles(draws: pd.DataFrame, loads: Sequence[float]) -> dict[str, np.ndarray]:
    """Every draw at every load: arrays of len(draws) x len(loads), draws outermost."""
    n_l = len(loads)
    p = {k: np.repeat(draws[k].to_numpy(dtype=float), n_l) for k in PARAMETERS}
    p["g"] = np.tile([gen.conductance(r) for r in loads], len(draws))
    return p


def predict_power(draws: pd.DataFrame, loads: Sequence[float], base_acc: np.ndarray,
                  dt: float, known: Mapping[str, float], G: float, lead_in_s: float,
                  window_s: float | None = None) -> PowerPrediction:
    """Mean load power of every draw at every load for the base acceleration y'' (m/s^2),
    over consecutive windows of ``window_s`` s after the lead-in (None: one window, the
    whole rest of the record)."""
    p = particles(draws, loads)
    start = int(round(lead_in_s / dt))
    n = np.size(base_acc) - start
    width = n if window_s is None else int(round(window_s / dt))
    if n < 2 or width > n:
        raise ValueError(f"the excitation ({np.size(base_acc) * dt:g} s) is shorter than the "
                         f"lead-in ({lead_in_s:g} s) and one window ({width * dt:g} s)")
    v, a, ok = simulate_loaded(Layout.of(LAYOUT_TERMS), p, known, p["g"], G, base_acc, dt)
    count = n // width
    stop = start + count * width
    inst = gen.load_power(v[:, start:stop], a[:, start:stop], p["K_e"], p["R_s"], p["L_s"],
                          p["g"], G)
    per_window = inst.reshape(inst.shape[0], count, width).mean(axis=2)
    per_window[~ok] = np.nan
    shape = (len(draws), len(loads), count)
    return PowerPrediction(per_window.reshape(shape), np.asarray(loads, dtype=float),
                           width * dt, int((~ok).sum()))
