"""The power study's steps as the workflow and the command line call them: posteriors in,
tables, design numbers and figure data out (one place for both fronts)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from harvester.data.fileio import read_json
from harvester.electrical.records import load_record, read_meta
from harvester.power import design
from harvester.power.calibration import coverage_table, held_out_windows
from harvester.power.excitations import Excitation
from harvester.power.predict import bma_draws, predict_power, with_change


def load_posteriors(samples: Sequence[str | Path], weights: str | Path):
    """({structure: posterior samples}, {structure: BMA weight}, device) from the files of
    rules electrical_identify (samples_<structure>.csv) and electrical_evidence."""
    info = read_json(weights)
    posteriors = {Path(p).stem.removeprefix("samples_"): pd.read_csv(p) for p in samples}
    missing = set(info["weights"]) - set(posteriors)
    if missing:
        raise ValueError(f"no posterior samples for structures {sorted(missing)}")
    return posteriors, info["weights"], info["device"]


def power_study(posteriors: Mapping[str, pd.DataFrame], weights: Mapping[str, float],
                device: Mapping, exc: Excitation, cfg: Mapping) -> dict:
    """Curve, energy table, design numbers (optima, gain of the change) on one excitation;
    cfg: config ``power`` (draws, seed, loads, lead_in_s, record_s, interval, low_quantile,
    change). ``record_s`` (None: the whole excitation is one record) cuts the excitation into
    records whose spread joins the parameters' in the ``record_`` columns."""
    rng = np.random.default_rng(int(cfg["seed"]))
    draws = bma_draws(posteriors, weights, int(cfg["draws"]), rng)
    loads = design.load_grid(cfg["loads"])
    args = (exc.base_acc, exc.dt, device["known"], float(device["G"]),
            float(cfg["lead_in_s"]), cfg.get("record_s"))
    base = predict_power(draws, loads, *args)
    mod = predict_power(with_change(draws, cfg["change"]), loads, *args)
    interval, low_q = float(cfg["interval"]), float(cfg["low_quantile"])
    records = base.windows.shape[2] > 1
    curve = design.curve(loads, base.power, interval, low_q,
                         base.per_record if records else None)
    changed_curve = design.curve(loads, mod.power, interval, low_q,
                                 mod.per_record if records else None)
    optimum = design.optimal_loads(curve, low_q)
    best = optimum["expected"]["load_ohm"]
    energy = design.at_load(loads, base.record_energy, best)
    result = {
        "excitation": exc.name, "description": exc.description, "seconds": base.seconds,
        "record_s": base.window_s, "records": base.windows.shape[2], "draws": len(draws),
        "draws_per_structure": draws["structure"].value_counts().to_dict(),
        "failed_simulations": base.failed + mod.failed, "optimum": optimum,
        "changed_optimum": design.optimal_loads(changed_curve, low_q),
        "change": dict(cfg["change"]),
        "gain_at_best_load": design.paired_gain(base.power, mod.power, loads, best, interval)
        | _prefixed(design.paired_gain(base.per_record, mod.per_record, loads, best,
                                       interval), "record_"),
        "energy_per_record_at_best_J": _quantiles(energy, interval) | {"load_ohm": best}}
    return {"curve": curve.assign(**{f"changed_{c}": changed_curve[c] for c in
                                     changed_curve.columns if c != "load_ohm"}),
            "changed_curve": changed_curve, "design": result,
            "energy": design.energy_table(loads, base.record_energy),
            "energy_at_best": energy,
            "changed_energy_at_best": design.at_load(loads, mod.record_energy, best)}


def _prefixed(gain: Mapping[str, float], prefix: str) -> dict[str, float]:
    """The spread entries of a gain (interval ends, probability) under a prefix."""
    keys = ("ratio_low", "ratio_high", "gain_W_low", "gain_W_high", "probability_of_gain")
    return {prefix + k: gain[k] for k in keys}


def _quantiles(x: np.ndarray, interval: float) -> dict[str, float]:
    lo, hi = np.nanquantile(x, [(1 - interval) / 2, (1 + interval) / 2])
    return {"mean": float(np.nanmean(x)), "low": float(lo), "high": float(hi)}


def held_out_study(posteriors: Mapping[str, pd.DataFrame], weights: Mapping[str, float],
                   device: Mapping, records: Sequence[str], metas: Sequence[str],
                   cfg: Mapping, preprocess: Mapping) -> tuple[pd.DataFrame, pd.DataFrame]:
    """(windows, coverage) of the held-out loaded records; cfg: config ``power``."""
    cal = cfg["calibration"]
    rng = np.random.default_rng(int(cfg["seed"]) + int(cal["seed_offset"]))
    draws = bma_draws(posteriors, weights, int(cal["draws"]), rng)
    levels = [float(x) for x in cal["levels"]]
    frames = []
    for csv, meta in zip(records, metas):
        rec = load_record(csv, read_meta(meta), float(preprocess["lowpass_hz"]),
                          int(preprocess["filter_order"]), float(cal["lead_in_s"]), None)
        frames.append(held_out_windows(rec, draws, device["known"], float(cal["window_s"]),
                                       levels))
    windows = pd.concat(frames, ignore_index=True)
    return windows, coverage_table(windows, levels)


def write_power_study(study: dict, directory: str | Path, cfg: Mapping,
                      figures: bool = True) -> list[str]:
    """Write curve.csv, energy.csv, design.json (and power_vs_load.png, energy.png) into
    ``directory``; the names written."""
    from harvester.data.fileio import write_json
    from harvester.power import figures as fig

    out = Path(directory)
    study["curve"].to_csv(out / "curve.csv", index=False, float_format="%.6g")
    study["energy"].to_csv(out / "energy.csv", index=False, float_format="%.6g")
    write_json(study["design"], out / "design.json")
    names = ["curve.csv", "energy.csv", "design.json"]
    if figures:
        d = study["design"]
        fig.power_vs_load(study["curve"], study["changed_curve"], d["optimum"],
                          float(cfg["interval"]), float(cfg["low_quantile"]), d["description"],
                          out / "power_vs_load.png")
        fig.energy_distribution(study["energy_at_best"], study["changed_energy_at_best"],
                                d["optimum"]["expected"]["load_ohm"], d["record_s"],
                                d["description"], out / "energy.png")
        names += ["power_vs_load.png", "energy.png"]
    return names
