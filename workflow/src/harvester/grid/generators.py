"""The grid's two truth generators behind one call: a scenario's recording and its truth in
the form the scoring reads.

``library``: :mod:`harvester.synthetic.scenarios`, the virtual rig with one of the library's
own effects (its shapes and priors). ``literature``: :mod:`harvester.synthetic.literature`,
written from the published forms without reading the library (LuGre, Bouc-Wen, Hertz and
Hunt-Crossley contact, Karnopp, a flexible mount, ...), a new device per seed, a multisine
excitation and an anti-aliased DAQ. Only the second says whether the diagnosis generalises.

Truth keys the scoring reads (:func:`harvester.grid.scoring.score`): ``effect`` (scenario
name), ``ratio``, ``seed``, ``baseline``, ``known`` (M, m, k), ``settings.lead_in_s``,
``contribution_ratio``, ``unabsorbed_to_noise``, ``peak_to_noise``, and for the literature
generator ``correct_names`` (the library terms that name its mechanism). ``settings.kind``:
the literature generator's recording kind (``literature.KINDS``; its records of a kind other
than base_acc -> rel_acc are diagnosed as the command line reads the file, ``diagnose:
recording``, so that the sidecar's silence about friction_on is read as a user's).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

#: The generators a grid may name (config ``detection.grids.<grid>.generator``).
GENERATORS = ("library", "literature")
#: The literature generator's effect-free scenario.
LITERATURE_NONE = "none"


def make_scenario_files(generator: str, effect: str, ratio: float, seed: int,
                        settings: Mapping[str, Any], rig_cfg: Mapping[str, Any],
                        preprocess: Mapping[str, Any], csv_path, truth_path) -> dict:
    """Write one scenario's recording (converted CSV) and truth (JSON); return the truth."""
    if generator == "library":
        return _library(effect, ratio, seed, settings, rig_cfg, preprocess, csv_path,
                        truth_path)
    if generator == "literature":
        return _literature(effect, ratio, seed, settings, csv_path, truth_path)
    raise ValueError(f"detection generator {generator!r}: expected one of {GENERATORS}")


def _library(effect, ratio, seed, settings, rig_cfg, preprocess, csv_path, truth_path):
    from harvester.synthetic.scenarios import ScenarioSettings, make_scenario, write_scenario

    chosen = ScenarioSettings.from_config({"rig": rig_cfg, "preprocess": preprocess},
                                          **settings)
    scenario = make_scenario(effect, ratio, seed, chosen, rig_cfg=rig_cfg)
    write_scenario(scenario, csv_path, truth_path)
    return scenario.truth


def literature_refit(made) -> float:
    """``information.refit_unabsorbed`` of a literature record (``GeneratedRecording``) over
    the default diagnosis's TMCMC window, with the tanh baseline."""
    from harvester.diagnosis.prepare.analysis import analysis_window
    from harvester.diagnosis.prepare.settings import DiagnosisSettings
    from harvester.grid.information import refit_unabsorbed
    from harvester.synthetic.literature import LEAD_IN_S

    rec = made.recording
    fs = 1.0 / float(rec["time"].iloc[1] - rec["time"].iloc[0])
    lead, hold, _ = analysis_window(len(rec), fs, LEAD_IN_S,
                                    DiagnosisSettings().holdout_fraction)
    dev = made.truth["device"]  # the device's own tanh parameters: a start for the refits
    start = np.array([dev["c"], dev["F_c"], 1.0 / dev["v_t"]])
    return refit_unabsorbed(rec, made.input_contribution, made.sidecar,
                            float(made.truth["noise_rms_rel_acc"]), window=(lead, hold),
                            start=start)


def _literature(effect, ratio, seed, settings, csv_path, truth_path):
    from harvester.data.daq import write_recording
    from harvester.data.fileio import write_json
    from harvester.synthetic.literature import KINDS, LEAD_IN_S, generate

    effect_free = effect == LITERATURE_NONE
    kind = settings.get("kind", KINDS[0])
    made = generate(effect, seed + int(settings.get("seed", 0)),
                    ratio=0.0 if effect_free else ratio,
                    duration_s=float(settings["duration_s"]), kind=kind)
    lit = made.truth
    truth = {
        "effect": effect, "ratio": 0.0 if effect_free else float(ratio), "seed": int(seed),
        "baseline": "tanh", "known": dict(made.sidecar), "generator": "literature",
        "settings": {"lead_in_s": LEAD_IN_S, "duration_s": float(settings["duration_s"])},
        "contribution_ratio": float(lit.get("ratio_achieved", 0.0)),
        "unabsorbed_to_noise": float(lit.get("unabsorbed_to_noise", 0.0)),
        "peak_to_noise": float(lit.get("peak_to_noise", 0.0)),
        "noise_rms": float(lit.get("noise_rms_rel_acc", lit.get("noise_rms_output"))),
        "invisible": False,
        "correct_names": list(lit.get("correct_names") or []),
        "related_names": list(lit.get("related_names") or []),
        "literature": lit,
    }
    if kind == KINDS[0]:  # the refit is of base_acc -> rel_acc records
        truth["refit_unabsorbed_to_noise"] = 0.0 if effect_free else literature_refit(made)
    else:  # the command line's call on the file (its sidecar silent about friction_on)
        truth.update(kind=kind, diagnose="recording")
    write_recording(made.recording, csv_path)
    write_json(truth, truth_path)
    return truth
