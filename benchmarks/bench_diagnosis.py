"""One default diagnosis of a 40 s recording, timed end to end (issue 21's goal: under 2 min).

The record is the literature generator's (``harvester.synthetic.literature``) LuGre scenario
of the ``literature`` grid (config/config.yaml: 40 s at 256 Hz, the effect at half the noise
RMS, seed ``--seed`` with the grid's seed), diagnosed as the grid's rule does
(``grid.scoring.run_diagnosis``, tanh baseline, default settings, no low-pass). It prints
the verdict, the wall time, and per round the candidates sampled and ruled out. Run it twice
to see the time without the kernels' compilation (they are cached in ``HARVESTER_CACHE``).

    python benchmarks/bench_diagnosis.py [--effect lugre] [--seed 0] [--out DIR]
"""

from __future__ import annotations

import argparse
import logging
import tempfile
import time
from pathlib import Path

import yaml

from harvester.data.daq import read_recording
from harvester.grid.generators import make_scenario_files
from harvester.grid.scoring import run_diagnosis

CONFIG = Path(__file__).resolve().parents[1] / "config" / "config.yaml"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--effect", default="lugre")
    parser.add_argument("--seed", type=int, default=0, help="the grid's seed index")
    parser.add_argument("--out", default=None, help="folder for the record (default: a temp one)")
    args = parser.parse_args()
    logging.basicConfig(level=logging.INFO, format="%(relativeCreated)8.0f ms %(message)s")
    cfg = yaml.safe_load(CONFIG.read_text())
    det = cfg["detection"]
    grid = det["grids"]["literature"]
    out = Path(args.out or tempfile.mkdtemp())
    csv, truth_path = out / f"{args.effect}.csv", out / f"{args.effect}.json"
    truth = make_scenario_files("literature", args.effect, float(grid["ratios"][0]), args.seed,
                                {"duration_s": float(grid["duration_s"]),
                                 "lead_in_s": float(det["lead_in_s"]), "seed": int(det["seed"])},
                                cfg["rig"], cfg["preprocess"], csv, truth_path)
    rec = read_recording(csv)
    fs = 1.0 / float(rec["time"].iloc[1] - rec["time"].iloc[0])
    clock = time.perf_counter()
    result = run_diagnosis(rec, truth["baseline"], truth["known"], seed=args.seed, fast=False,
                           lead_in=int(round(float(det["lead_in_s"]) * fs)), lowpass_hz=None)
    seconds = time.perf_counter() - clock
    for i, rnd in enumerate(result["rounds"]):
        skipped = [s["effect"] for s in rnd["screened"] if s["skipped"]]
        print(f"round {i + 1}: p = {rnd['p_value']:.3g}, sampled {rnd['sampled']}, "
              f"ruled out {skipped}, accepted {rnd['accepted']}")
    print(f"{args.effect}: verdict {result['verdict']}, missing {result['missing']}, "
          f"{seconds:.0f} s wall time for the diagnosis ({len(rec) / fs:.0f} s record)")
    print(result["headline"])
    for e in (result.get("missing_force") or {}).get("named_effects", []):
        print(e["sentence"])


if __name__ == "__main__":
    main()
