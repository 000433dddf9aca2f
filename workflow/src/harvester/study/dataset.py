"""The study's raw data set: every record of the virtual rig, the static test, the loaded
records with the generator's voltage, and SHA256SUMS."""

from __future__ import annotations

import logging
import time
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import pandas as pd

from harvester.data import daq

from harvester.synthetic import electrical, rig

log = logging.getLogger("harvester.study.dataset")


def write_loaded_records(rig_cfg: Mapping[str, Any], out: Path) -> list[str]:
    """Write every record of ``rig_cfg['loaded_records']`` (none if absent); their file names.

    Each holds ai0, ai1 and the line-voltage channels ai2 (v_ab) and ai3 (v_bc)
    (``harvester.synthetic.electrical``).
    """
    names: list[str] = []
    for record in rig_cfg.get("loaded_records", {}):
        start = time.perf_counter()
        sim = electrical.simulate_loaded_record(rig_cfg, record)
        frame = pd.DataFrame({"time": sim.time, "ai0": sim.ai0, "ai1": sim.ai1, "ai2": sim.ai2,
                              "ai3": sim.ai3})
        meta = daq.loaded_record_metadata(rig_cfg, record, len(frame), sim.seed, sim.load_ohm)
        daq.write_raw_record(frame, out / f"{record}.csv", out / f"{record}.json", meta)
        names += [f"{record}.csv", f"{record}.json"]
        log.info("%s: load %s ohm, %d samples, seed %d, %d sub-steps, %.2f s", record,
                 sim.load_ohm, len(frame), sim.seed, sim.truth["substeps"],
                 time.perf_counter() - start)
    return names


def make_raw_data(config: Mapping[str, Any], out_dir: str | Path) -> list[Path]:
    """Write every record of ``config['rig']['records']``, the static test, the loaded records
    (``config['rig']['loaded_records']``) and SHA256SUMS.

    The output is bit-for-bit identical for the same config (all streams seeded from it).
    """
    rig_cfg = config["rig"]
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    names: list[str] = []
    for record in rig_cfg["records"]:
        start = time.perf_counter()
        sim = rig.simulate_record(rig_cfg, record)
        frame = pd.DataFrame({"time": sim.time, "ai0": sim.ai0, "ai1": sim.ai1})
        meta = daq.record_metadata(rig_cfg, record, len(frame), sim.seed)
        daq.write_raw_record(frame, out / f"{record}.csv", out / f"{record}.json", meta)
        names += [f"{record}.csv", f"{record}.json"]
        log.info("%s: %d samples, seed %d, stuck %.1f %%, %.2f s", record, len(frame), sim.seed,
                 100.0 * sim.truth["stuck"].mean(), time.perf_counter() - start)
    static = rig.static_friction_test(rig_cfg)
    daq.write_static_test(static, out / "static_friction.csv", out / "static_friction.json",
                          daq.static_test_metadata(rig_cfg))
    names += ["static_friction.csv", "static_friction.json"]
    names += write_loaded_records(rig_cfg, out)
    sums = daq.write_checksums(out, names)
    log.info("wrote %d files and %s", len(names), sums)
    return [out / n for n in names] + [sums]
