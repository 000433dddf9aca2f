"""How big a named effect is and whether it matters: its force in newtons and as a share of
the device's forces, the share of the missing force it explains, the change it makes to the
predicted response on unseen data, and a floor of relevance below which it is "detectable but
negligible" rather than missing physics.

Sizes, along the latent force's smoothed states (``latent_views.effect_force``):

    force_rms        RMS of dF, the improved model's force beyond the baseline's (N, or the
                     recording's force unit: ``units``, ``data.units``)
    share_of_drive   force_rms / RMS of the drive (m y'' or F): the force that moves the device
    share_of_latent  1 - sum (f - dF)^2 / sum f^2, f the latent (missing) force
    response change  RMS of the improved minus the baseline's predicted output on unseen data,
                     through the measurement chain, and as a share of the output's RMS

Floor (``RelevanceFloor``, on by default): an effect is negligible when both its force and its
response change lie below the floor's shares (1 %). The false alarm of the literature grid's
damper device, an inertia error of 0.055 % of M, moves the force by about that share of the
inertial force: far below it.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from harvester.data.units import SI, Units
from harvester.diagnosis.latent import LatentForce
from harvester.diagnosis.latent_views import EffectForce
from harvester.model.structures import ModelStructure


@dataclass(frozen=True)
class RelevanceFloor:
    """Below both shares an effect is "detectable but negligible" (``enabled``: the
    setting; the summary states it)."""

    force_share: float = 0.01
    response_share: float = 0.01
    enabled: bool = True

    def to_dict(self) -> dict:
        return dataclasses.asdict(self)


@dataclass
class EffectSize:
    """A named effect's physical size and relevance (module docstring)."""

    term: str
    force_rms_N: float
    share_of_drive: float
    share_of_latent: float
    response_change_rms: float | None  # unit of the output
    response_change_share: float | None
    negligible: bool
    floor: RelevanceFloor
    units: Units = SI  # the recording's (force_rms_N is in its force unit)

    @property
    def label(self) -> str:
        return "detectable but negligible" if self.negligible else "relevant"

    def sentence(self) -> str:
        text = (f"{self.term}: {self.force_rms_N:.3g} {self.units.label('force')} RMS "
                f"({100 * self.share_of_drive:.2g} % of the drive), explains "
                f"{100 * max(self.share_of_latent, 0):.0f} % of the missing force")
        if self.response_change_share is not None:
            text += (f", changes the predicted response by {100 * self.response_change_share:.2g}"
                     " % RMS on unseen data")
        return f"{text}: {self.label}"

    def to_dict(self) -> dict:
        return {"term": self.term, "force_rms_N": self.force_rms_N,
                "force_unit": self.units.label("force"),
                "share_of_drive": self.share_of_drive, "share_of_latent": self.share_of_latent,
                "response_change_rms": self.response_change_rms,
                "response_change_share": self.response_change_share,
                "relevance": self.label, "floor": self.floor.to_dict(),
                "sentence": self.sentence()}


def drive_rms(lf: LatentForce) -> float:
    """RMS of the force that drives the device (N): m y'' for a base input, F for a force."""
    gain = lf.values.get("m", 0.0) if lf.input_kind == "base_acc" else 1.0
    return float(max(np.sqrt(np.mean((gain * lf.input) ** 2)), 1e-12))


def response_change(problem, theta: np.ndarray, improved: ModelStructure,
                    improved_theta: np.ndarray, input: np.ndarray, window: slice
                    ) -> tuple[float, float]:
    """(RMS change, as a share of the output's RMS) of the predicted output over ``window``
    when the baseline (``problem``'s structure at ``theta``) becomes ``improved`` at
    ``improved_theta``, both driven by ``input`` (unseen data) and through the chain."""
    other = dataclasses.replace(problem, structure=improved)
    kind = problem.output_kind
    out = []
    for p, th in ((problem, theta), (other, improved_theta)):
        sim = p.simulate(np.atleast_2d(th), input)
        if not sim.ok[0]:
            raise RuntimeError(f"{p.structure.name} cannot be simulated on the unseen input")
        y = sim.rel_disp[0] if kind == "rel_disp" else sim.rel_acc[0]
        out.append(problem.chain(y)[window] if hasattr(problem, "chain") else y[window])
    change = float(np.sqrt(np.mean((out[1] - out[0]) ** 2)))
    return change, change / float(max(np.sqrt(np.mean(out[0] ** 2)), 1e-300))


def effect_size(lf: LatentForce, ef: EffectForce, floor: RelevanceFloor = RelevanceFloor(),
                response: tuple[float, float] | None = None) -> EffectSize:
    """The named effect's size from its force beside the latent force (``ef``) and, if
    given, its ``response`` change on unseen data (:func:`response_change`); labelled in
    ``lf.units``."""
    share = ef.rms_N / drive_rms(lf)
    small_response = response is None or response[1] < floor.response_share
    negligible = floor.enabled and share < floor.force_share and small_response
    return EffectSize(ef.term, ef.rms_N, share, ef.share,
                      None if response is None else response[0],
                      None if response is None else response[1], negligible, floor, lf.units)
