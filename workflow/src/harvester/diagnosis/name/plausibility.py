"""Whether a candidate's posterior implies a device the sidecar contradicts.

The masses and the stiffness the user gives (the sidecar's M, m, k) are measurements with an
uncertainty: the sidecar's ``M_sd`` (``m_sd``, ``k_sd``), else ``DEFAULT_RELATIVE_SD`` of the
value (``harvester.data.sidecar``). A term may declare the device quantities its parameters
change (``Term.device``: an inertia error's M + dM, m + m_share dM). For each, over the
candidate's posterior draws, the implied value X against the stated Y +- s:

    z = |median(X) - Y| / sqrt(sd(X)^2 + s^2),     agrees  <=>  z <= AGREEMENT_SDS (3)

A candidate whose implied device disagrees is not named as that physics
(``confirm.judge``): the record's mismatch acts like it (a mass) but is not one. Terms that
declare no device quantity, and quantities the sidecar does not state, are not checked.

The bar: with the default 15 % and a sharp posterior, a mass error is admitted up to 45 % of
the stated M (or m): the literature generator's mass-error records at up to 2 x the noise RMS
hold true errors up to 26 % of M and 35 % of m (``data.sidecar.DEFAULT_RELATIVE_SD``), and
issue 63's +57 kg on a 20 kg device (19 sd) and +4.1 kg on a 3.1 kg frame (8.8 sd) are
refused.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass

import numpy as np

from harvester.data.sidecar import DEFAULT_RELATIVE_SD, DEVICE_PARAMETERS
from harvester.model.structures import ModelStructure
from harvester.model.terms import term

#: Combined standard deviations beyond which an implied quantity contradicts the stated one.
AGREEMENT_SDS = 3.0
#: Each quantity in words: what it is, and what a term that moves it acts like.
QUANTITY_WORDS: dict[str, tuple[str, str]] = {
    "M": ("the effective mass", "a mass"), "m": ("the oscillating mass", "a mass"),
    "k": ("the stiffness", "a spring")}


@dataclass(frozen=True)
class Measured:
    """A device quantity as stated: value and standard uncertainty (its unit: ``unit``)."""

    name: str
    value: float
    sd: float
    stated_sd: bool = False  # the sidecar's own <name>_sd, not the default

    @property
    def unit(self) -> str:
        return DEVICE_PARAMETERS[self.name]


def measured_device(known: Mapping[str, float], sds: Iterable[tuple[str, float]] = (),
                    relative_sd: float = DEFAULT_RELATIVE_SD) -> dict[str, Measured]:
    """The stated device quantities among ``known`` (M, m, k) with their uncertainty: ``sds``
    (name, sd) where given, else ``relative_sd`` of the value."""
    given = dict(sds)
    return {n: Measured(n, float(known[n]), float(given.get(n, relative_sd * abs(known[n]))),
                        n in given)
            for n in DEVICE_PARAMETERS if n in known}


@dataclass(frozen=True)
class Implied:
    """A device quantity a candidate's posterior implies, against the stated one."""

    term: str
    measured: Measured
    median: float
    interval: tuple[float, float]  # 95 %
    sd: float

    @property
    def z(self) -> float:
        """|median - stated| in combined standard deviations (module docstring)."""
        return abs(self.median - self.measured.value) / float(
            max(np.hypot(self.sd, self.measured.sd), 1e-300))

    @property
    def agrees(self) -> bool:
        return bool(self.z <= AGREEMENT_SDS)

    def sentence(self) -> str:
        """The contradiction (or agreement) in words."""
        what, like = QUANTITY_WORDS[self.measured.name]
        m, u = self.measured, self.measured.unit
        stated = f"the sidecar's {m.value:.3g} +- {m.sd:.2g} {u}" + (
            "" if m.stated_sd else f" ({100 * DEFAULT_RELATIVE_SD:.0f} % assumed)")
        implied = (f"{self.median:.3g} {u} (95 % {self.interval[0]:.3g}-"
                   f"{self.interval[1]:.3g})")
        if self.agrees:
            return (f"{self.term} implies {what} {implied}, within {AGREEMENT_SDS:g} sd of "
                    f"{stated}")
        return (f"{self.term}: the record's mismatch pulls {what} to {implied}, which "
                f"contradicts {stated} ({self.z:.1f} sd): the missing physics acts like "
                f"{like} but is not one")

    def to_dict(self) -> dict:
        return {"term": self.term, "quantity": self.measured.name, "unit": self.measured.unit,
                "implied_median": self.median, "implied_interval": list(self.interval),
                "implied_sd": self.sd, "stated": self.measured.value,
                "stated_sd": self.measured.sd, "stated_sd_given": self.measured.stated_sd,
                "z": self.z, "bar_sd": AGREEMENT_SDS, "agrees": self.agrees,
                "sentence": self.sentence()}


def draw_values(structure: ModelStructure, samples: np.ndarray,
                known: Mapping[str, float]) -> dict[str, np.ndarray | float]:
    """Every parameter's value over the posterior ``samples`` (rows: free parameters, sigma
    last optional): arrays for the free ones, ``known``'s for the rest."""
    rows = np.atleast_2d(np.asarray(samples, dtype=float))
    values: dict[str, np.ndarray | float] = dict(known)
    values.update({n: rows[:, i] for i, n in enumerate(structure.free_parameters)})
    return values


def implied_device(effect: str, structure: ModelStructure, samples: np.ndarray,
                   known: Mapping[str, float], measured: Mapping[str, Measured]
                   ) -> list[Implied]:
    """The stated quantities ``effect``'s term implies over the posterior ``samples`` of
    ``structure`` (which holds it), each against ``measured`` (:func:`measured_device`);
    empty where the term declares none (``Term.device``) or the sidecar states none of them."""
    t = term(effect)
    if t.device is None or not measured or len(np.atleast_2d(samples)) == 0:
        return []
    implied = t.device(draw_values(structure, samples, known))
    out = []
    for name, x in implied.items():
        if name not in measured:
            continue
        x = np.broadcast_to(np.asarray(x, dtype=float), (len(np.atleast_2d(samples)),))
        lo, mid, hi = np.percentile(x, [2.5, 50.0, 97.5])
        out.append(Implied(effect, measured[name], float(mid), (float(lo), float(hi)),
                           float(np.std(x))))
    return out


def contradictions(device: Iterable[Implied]) -> list[Implied]:
    """The implied quantities that contradict the sidecar."""
    return [d for d in device if not d.agrees]
