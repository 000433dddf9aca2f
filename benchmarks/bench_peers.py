"""The diagnosis beside the tools a user would otherwise reach for, on one record set (issue
64): per tool, named right / wrong / missed / false alarms, the fit on the held-out tail and
seconds per record (``harvester.grid.peers``).

    python benchmarks/bench_peers.py --set DIR [--skip-diagnosis] [--no-narx] [--csv OUT]
    python benchmarks/bench_peers.py --make DIR [--effects duffing ...] [--free-seeds 0 1]

``--set DIR``: any folder of acceleration recordings (``<name>.csv`` with its sidecar
``<name>.yaml``) each with a truth ``<name>.json`` (``correct_names``, ``ratio``; as the
literature grid writes it). Tools: ``harvester diagnose`` (the library call the grid makes,
``grid.scoring.run_diagnosis``, default settings, the record's baseline; its diagnosis is kept
as ``<name>.diagnosis.json`` and reused), pysindy's STLSQ on the restoring force at three
thresholds, SysIdentPy's polynomial NARX free run. pysindy and sysidentpy: ``pip install
-e .[peers]``.

``--kept-only``: the diagnosis's rows only for records whose diagnosis is kept (none is run).

``--make DIR``: writes literature-grid records into DIR as the grid makes them
(config/config.yaml: 40 s at 256 Hz, ratio 0.5, the grid's seed offset): each of
``--effects`` at seed 0 and the effect-free record at each of ``--free-seeds``.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import pandas as pd
import yaml

ROOT = Path(__file__).resolve().parents[1]
CONFIG = ROOT / "config" / "config.yaml"
EFFECTS = ("duffing", "quadratic_damping", "stribeck_exponential", "end_stop_hertz")


def make_set(out: Path, effects, free_seeds) -> None:
    """The grid's records (and truths, sidecars) of ``effects`` and effect-free seeds."""
    from harvester.grid.generators import make_scenario_files
    cfg = yaml.safe_load(CONFIG.read_text())
    det, grid = cfg["detection"], cfg["detection"]["grids"]["literature"]
    settings = {"duration_s": float(grid["duration_s"]), "lead_in_s": float(det["lead_in_s"]),
                "seed": int(det["seed"])}
    out.mkdir(parents=True, exist_ok=True)
    jobs = [(e, float(grid["ratios"][0]), 0) for e in effects] + \
        [("none", 0.0, s) for s in free_seeds]
    for effect, ratio, seed in jobs:
        csv = out / f"{effect}_s{seed}.csv"
        if csv.is_file():
            continue
        truth = make_scenario_files("literature", effect, ratio, seed, settings, cfg["rig"],
                                    cfg["preprocess"], csv, csv.with_suffix(".json"))
        csv.with_suffix(".yaml").write_text("".join(f"{k}: {float(v)!r}\n"
                                                    for k, v in truth["known"].items()))
        print(f"made {csv.name}", flush=True)


def run_diagnosis_cached(rec) -> dict:
    """The record's diagnosis (``grid.scoring.run_diagnosis``), kept beside it."""
    from harvester.data.sidecar import read_sidecar
    from harvester.grid.scoring import run_diagnosis
    kept = rec.path.with_suffix(".diagnosis.json")
    if kept.is_file():
        return json.loads(kept.read_text())
    t = rec.data["time"].to_numpy()
    fs = 1.0 / float(t[1] - t[0])
    lead_in = float((rec.truth.get("settings") or {}).get("lead_in_s", 1.0))
    d = run_diagnosis(rec.data, rec.truth.get("baseline", "tanh"), rec.known, seed=0,
                      lead_in=int(round(lead_in * fs)),
                      lowpass_hz=read_sidecar(rec.path).filtered_at_hz)
    kept.write_text(json.dumps(d, default=str))
    return d


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--set", type=Path, help="folder of recordings with truth files")
    p.add_argument("--make", type=Path, help="write literature-grid records into this folder")
    p.add_argument("--effects", nargs="*", default=list(EFFECTS))
    p.add_argument("--free-seeds", nargs="*", type=int, default=[0, 1])
    p.add_argument("--skip-diagnosis", action="store_true", help="the peers only")
    p.add_argument("--kept-only", action="store_true",
                   help="the diagnosis only where a <name>.diagnosis.json is kept (none run)")
    p.add_argument("--no-narx", action="store_true", help="without the NARX free run")
    p.add_argument("--csv", type=Path, help="write the per-record rows here")
    args = p.parse_args(argv)
    if args.make:
        make_set(args.make, args.effects, args.free_seeds)
    if not args.set:
        return 0
    from harvester.grid.peers import diagnosis_row, peer_rows, read_set, summary
    rows = []
    for rec in read_set(args.set):
        kept = rec.path.with_suffix(".diagnosis.json").is_file()
        run = not args.skip_diagnosis and (kept or not args.kept_only)
        found = [diagnosis_row(rec, run_diagnosis_cached)] if run else []
        for r in found + peer_rows(rec, narx=not args.no_narx):
            rows.append({"record": rec.path.stem, "correct": " ".join(sorted(rec.correct)),
                         **r, "names": " ".join(r["names"])})
            print(f"{rec.path.stem:28s} {r['tool']:22s} {rows[-1]['outcome']:12s} "
                  f"{' '.join(r['names'][:3]):40s} {r['heldout_nrmse'] or float('nan'):7.3f} "
                  f"{r['seconds']:8.2f} s", flush=True)
    table = pd.DataFrame(rows)
    if args.csv:
        table.to_csv(args.csv, index=False)
    print()
    print(summary(table).to_string(index=False, float_format=lambda x: f"{x:.3g}"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
