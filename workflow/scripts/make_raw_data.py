"""Regenerate the SIMULATED raw recordings (data/raw) from the virtual rig, with SHA256SUMS.

Snakemake: rule ``regenerate_raw_data`` (config from ``snakemake.config``, output directory
``snakemake.output[0]``, log ``snakemake.log[0]``).
Command line: ``python workflow/scripts/make_raw_data.py config/config.yaml data/raw``.
The output is bit-for-bit identical for the same config.
"""

# No `from __future__ import annotations`: Snakemake prepends its preamble to this file.
import logging
import sys
import time
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import pandas as pd
import yaml

from harvester import daq, rig
from harvester.runlog import rule_log, setup

log = logging.getLogger("harvester.make_raw_data")


def make_raw_data(config: Mapping[str, Any], out_dir: str | Path) -> list[Path]:
    """Write every record of ``config['rig']['records']``, the static test and SHA256SUMS."""
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
    sums = daq.write_checksums(out, names)
    log.info("wrote %d files and %s", len(names), sums)
    return [out / n for n in names] + [sums]


def main(argv: list[str]) -> int:
    """Command line: CONFIG.yaml OUT_DIR."""
    if len(argv) != 2:
        print("usage: make_raw_data.py CONFIG.yaml OUT_DIR", file=sys.stderr)
        return 2
    setup()
    with open(argv[0], encoding="utf-8") as fh:
        make_raw_data(yaml.safe_load(fh), argv[1])
    return 0


if __name__ == "__main__":
    if "snakemake" in globals():
        with rule_log(snakemake):  # noqa: F821
            make_raw_data(snakemake.config, snakemake.output[0])  # noqa: F821
    else:
        sys.exit(main(sys.argv[1:]))
