"""The shipped real recordings as a record set for the peers (``grid.peers``, issue 64): each
written as the project reads it (``data.public.public_recording``: CSV and sidecar) with a
truth file saying what is known of the device and which library names count as right.

What is known comes from each source (``data/public/*/SOURCE.md``), not from any tool's
answer; the strength of the missing force against the noise is not known (``ratio`` null),
and the baseline is the study's for these records (``config/config.yaml``, ``groups``:
linear).

* **The frame** (Marino and Cicirello 2023), loads 250 g and 450 g: a brass-on-steel contact
  fixed to the ground, which its authors identify as rate-dependent dry friction with stick
  phases. Against the linear baseline the whole contact is missing; every library term that
  is a dry-friction law (a force that opposes the contact's sliding velocity and saturates at
  a sliding level) names it: ``coulomb_friction``, ``tanh_friction`` (Coulomb with a finite
  slope at reversal: ``grid.scoring.ACCEPTED``), ``stribeck_friction`` (rate-dependent),
  ``sticking_friction`` and ``sticking_stribeck`` (with the stuck state the source reports),
  and ``hysteresis``: the library's term is Dahl's / LuGre's pre-sliding friction, whose
  force saturates at F_hyst while sliding (delta -> 0 is Coulomb's law), a dry-friction law
  with a finite stiffness when stuck; every real dry contact has a pre-sliding displacement.
  Not right: ``asymmetric_friction`` (the source reports no direction dependence; it is
  related), a spring, a damper, a stop, a mode, a mass error.
* **The Silverbox** (Wigren and Schoukens 2013): an electronic circuit built as a forced
  oscillator with a cubic spring (its SOURCE.md; the benchmark's own description), so
  ``cubic_stiffness`` is right; ``end_stop`` (a hardening force of another shape) is related.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

#: Library terms that are dry-friction laws (module docstring).
DRY_FRICTION = ("coulomb_friction", "tanh_friction", "stribeck_friction", "sticking_friction",
                "sticking_stribeck", "hysteresis")
#: Lead-in (s) of the analysis: the diagnosis's default (``grid.peers.split`` reads it).
LEAD_IN_S = 1.0


@dataclass(frozen=True)
class RecordedTruth:
    """What is known of one real recording: its file under the data folder, the effect in
    words, the names counted right and those only related, and why."""

    name: str
    file: str
    effect: str
    correct: tuple[str, ...]
    related: tuple[str, ...]
    why: str
    baseline: str = "linear"

    def truth(self) -> dict:
        """The truth file's content, as ``grid.peers.read_set`` reads it (``"diagnose":
        "recording"``: the diagnosis of the file, as the command line makes it)."""
        return {"effect": self.effect, "correct_names": list(self.correct),
                "related_names": list(self.related), "ratio": None, "seed": 0,
                "baseline": self.baseline, "recorded": True, "diagnose": "recording",
                "source": self.file, "why": self.why, "settings": {"lead_in_s": LEAD_IN_S}}


_FRAME_WHY = ("a brass-on-steel contact fixed to the ground, identified by its authors as "
              "rate-dependent dry friction with stick phases (SOURCE.md): every library "
              "dry-friction law names it against the linear baseline, hysteresis included "
              "(Dahl/LuGre pre-sliding friction, Coulomb's law while sliding)")
_SILVERBOX_WHY = ("an electronic forced oscillator with a cubic spring, m y'' + d y' + a y + "
                  "b y^3 = u (SOURCE.md, Wigren and Schoukens 2013)")

#: The shipped real recordings and their truths.
RECORDED: tuple[RecordedTruth, ...] = (
    RecordedTruth("frame_250g", "marino-frame/s_b_250g_x.mat", "dry_friction_on_ground",
                  DRY_FRICTION, ("asymmetric_friction",), _FRAME_WHY),
    RecordedTruth("frame_450g", "marino-frame/s_b_450g_x.mat", "dry_friction_on_ground",
                  DRY_FRICTION, ("asymmetric_friction",), _FRAME_WHY),
    RecordedTruth("silverbox", "silverbox/Schroeder80mV.mat", "cubic_spring",
                  ("cubic_stiffness",), ("end_stop",), _SILVERBOX_WHY),
)


def write_recorded_set(data_dir: str | Path, out: str | Path,
                       recorded: tuple[RecordedTruth, ...] = RECORDED) -> list[Path]:
    """Each of ``recorded`` read from ``data_dir`` (the folder holding ``marino-frame/`` and
    ``silverbox/``) into ``out`` as ``<name>.csv``, its sidecar and its truth ``<name>.json``;
    files already there are kept. The CSV paths."""
    from harvester.data.public import public_recording
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for r in recorded:
        csv = out / f"{r.name}.csv"
        if not csv.is_file():
            public_recording(Path(data_dir) / r.file).write(csv)
        csv.with_suffix(".json").write_text(json.dumps(r.truth(), indent=1) + "\n")
        paths.append(csv)
    return paths
