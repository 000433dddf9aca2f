"""The missing force against the states: binned means with bands (the restoring-force views
of Masri and Caughey 1979, with the latent force's uncertainty), and the named effect's
force beside it.

``binned``: the window's samples in bins of equal count along z, z', the time or the input;
per bin the mean of f over each joint draw of the force (``LatentForce.draws``), so that the
band (+-2 sd of the bin means across draws) holds the correlation of f between samples.

``effect_force``: for a named effect (a term the improved model adds), the force by which the
improved model differs from the baseline along the latent force's smoothed states,

    dF = [c_m' z' + k' z + sum_T' X_T'] - [c_m z' + k z + sum_T X_T] + (M' - M) z'' + (m' - m) y''

(``term_forces``; primes: the improved model's values), through the force's band, beside the
latent force: if the term took the shape of what was missing, dF follows f within its band.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from harvester.data.units import SI, Units
from harvester.diagnosis.size.latent import LatentForce
from harvester.model.term_forces import model_force, term_force
from harvester.model.structures import Layout, ModelStructure, structure
from harvester.model.terms import term

#: What the force is viewed against: (LatentForce attribute, label, quantity of
#: ``data.units``, shown small: in mm where the displacement is in m).
AGAINST = {"z": ("rel_disp", "z", "displacement", True), "z'": ("rel_vel", "z'", "velocity", False),
           "time": ("time", "time", "s", False), "input": ("input", "input", None, False)}
#: The input's label and quantity, by its kind.
INPUT_UNITS = {"base_acc": ("y''", "acceleration"), "force": ("F", "force")}


@dataclass
class Binned:
    """Binned means of the missing force (the recording's force unit) against one quantity,
    with +-2 sd bands."""

    against: str
    label: str
    unit: str
    centre: np.ndarray
    mean: np.ndarray
    lower: np.ndarray
    upper: np.ndarray

    def to_dict(self) -> dict:
        return {"against": self.against, "unit": self.unit, "centre": self.centre.tolist(),
                "mean_N": self.mean.tolist(), "lower_N": self.lower.tolist(),
                "upper_N": self.upper.tolist()}


def binned(lf: LatentForce, against: str, bins: int = 24) -> Binned:
    """f's binned means against ``against`` (a key of AGAINST), bins of equal count."""
    attr, label, quantity, small = AGAINST[against]
    if against == "input":
        label, quantity = INPUT_UNITS.get(lf.input_kind, ("input", ""))
    scale, unit = lf.units.small(quantity) if small else (1.0, lf.units.label(quantity))
    x = np.asarray(getattr(lf, attr), dtype=float) * scale
    edges = np.unique(np.quantile(x, np.linspace(0.0, 1.0, bins + 1)))
    idx = np.clip(np.searchsorted(edges, x, side="right") - 1, 0, len(edges) - 2)
    count = np.bincount(idx, minlength=len(edges) - 1).astype(float)
    keep = count > 0
    centre = np.bincount(idx, x, len(edges) - 1)[keep] / count[keep]
    mean = np.bincount(idx, lf.force, len(edges) - 1)[keep] / count[keep]
    draws = lf.draws if lf.draws.size else lf.force[None, :]
    per_draw = np.array([np.bincount(idx, d, len(edges) - 1)[keep] / count[keep]
                         for d in draws])
    sd = per_draw.std(axis=0)
    return Binned(against, label, unit, centre, mean, mean - 2.0 * sd, mean + 2.0 * sd)


def views(lf: LatentForce, bins: int = 24) -> dict[str, Binned]:
    """The binned views against z, z', the time and the input."""
    return {a: binned(lf, a, bins) for a in AGAINST}


@dataclass
class EffectForce:
    """A named effect's force beside the latent force (module docstring), in the recording's
    force unit (``units``)."""

    term: str
    time: np.ndarray
    latent: np.ndarray
    latent_sd: np.ndarray
    change: np.ndarray  # dF: the improved model's force beyond the baseline's
    term_force: np.ndarray  # X_T of the named term alone
    share: float  # 1 - sum (f - dF)^2 / sum f^2
    coverage: float  # share of samples where |f - dF| < 2 sd
    rms_N: float  # RMS of dF
    rel_disp: np.ndarray = field(repr=False, default_factory=lambda: np.empty(0))
    rel_vel: np.ndarray = field(repr=False, default_factory=lambda: np.empty(0))
    units: Units = SI

    def to_dict(self) -> dict:
        return {"term": self.term, "share_of_latent_explained": self.share,
                "within_latent_band": self.coverage, "force_rms_N": self.rms_N,
                "term_force_rms_N": float(np.sqrt(np.mean(self.term_force**2))),
                "latent_rms_N": float(np.sqrt(np.mean(self.latent**2)))}


def parameter_values(structure: ModelStructure, theta: np.ndarray,
                     known: Mapping[str, float]) -> dict:
    """Every parameter's value: ``known`` with ``structure``'s free parameters at ``theta``."""
    values = dict(known)
    values.update(zip(structure.free_parameters, np.asarray(theta, dtype=float)))
    return values


def effect_force(lf: LatentForce, improved: ModelStructure, theta: np.ndarray,
                 known: Mapping[str, float], term_name: str) -> EffectForce:
    """The improved model (``improved`` at ``theta``: its free parameters, sigma last
    optional; ``known``: the rest) against the baseline along the latent force's joint draws
    of the states, averaged over them as f is, and the named term's own force (module
    docstring)."""
    new = parameter_values(improved, np.asarray(theta)[:len(improved.free_parameters)], known)
    old = lf.values
    z, v, a, u, lead = _states_from_start(lf)
    yb = u if lf.input_kind == "base_acc" else np.zeros_like(u)
    states = (z, v, a, yb, float(lf.time[1] - lf.time[0]))
    change = (model_force(improved.layout, new, *states)
              - model_force(_layout_of(lf), old, *states)
              + (new["M"] - old["M"]) * a + (new["m"] - old["m"]) * yb[None, :])
    change = lf.band(change)[:, lead:].mean(axis=0)
    own = lf.band(term_force(term(term_name), new, *states))[:, lead:].mean(axis=0)
    f = lf.force
    share = 1.0 - float(np.sum((f - change) ** 2) / max(np.sum(f**2), 1e-300))
    coverage = float(np.mean(np.abs(f - change) < 2.0 * lf.sd))
    return EffectForce(term_name, lf.time, f, lf.sd, change, own, share, coverage,
                       float(np.sqrt(np.mean(change**2))), lf.rel_disp, lf.rel_vel, lf.units)


def _states_from_start(lf: LatentForce):
    """(z, z', z'' (draws, samples), the input, the samples before the window) from the
    record's start, so that a term's own states settle before the window (``lead_draws``);
    the smoothed means alone where no draws were kept."""
    if not lf.state_draws.size:
        z, v, a = (x[None, :] for x in (lf.rel_disp, lf.rel_vel, lf.rel_acc))
        return z, v, a, lf.input, 0
    lead = lf.lead_draws.shape[-1]
    if lead == 0:
        return (*lf.state_draws, lf.input, 0)
    z, v, a = np.concatenate([lf.lead_draws, lf.state_draws], axis=-1)
    return z, v, a, np.concatenate([lf.lead_input, lf.input]), lead


def _layout_of(lf: LatentForce) -> Layout:
    """The baseline's layout, from its name (``base+term...``)."""
    return structure(lf.baseline).layout
