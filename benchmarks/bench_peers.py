"""The diagnosis beside the tools a user would otherwise reach for, on one record set (issue
64): per tool, named right / wrong / missed / false alarms, the fit on the held-out tail and
seconds per record (``harvester.grid.peers``).

    python benchmarks/bench_peers.py --set DIR [--skip-diagnosis] [--no-narx] [--csv OUT]
    python benchmarks/bench_peers.py --make DIR [--effects duffing ...] [--free-seeds 0 1]
    python benchmarks/bench_peers.py --make DIR --real [--fast] [--jobs 2] --set DIR
    python benchmarks/bench_peers.py --make DIR --kinds "base_disp->rel_disp" --duration 20

``--set DIR``: any folder of acceleration recordings (``<name>.csv`` with its sidecar
``<name>.yaml``) each with a truth ``<name>.json`` (``correct_names``, ``ratio``; as the
literature grid writes it). Tools: ``harvester diagnose`` (the library call the grid makes,
``grid.scoring.run_diagnosis``, default settings, the record's baseline; its diagnosis is kept
as ``<name>.diagnosis.json`` and reused), pysindy's STLSQ on the restoring force at three
thresholds, SysIdentPy's polynomial NARX free run. pysindy and sysidentpy: ``pip install
-e .[peers]``.

``--kept-only``: the diagnosis's rows only for records whose diagnosis is kept (none is run).
``--confusion``: the kept diagnoses only, per record (names, mass error named where none was
put in, the friction's form taken) and their confusion matrix (``grid.scoring``); the right
names listed as detectable but negligible under an adequate verdict; and per term how often a
flagging verdict names or ties it where it is not a right name (``grid.scoring.
wrong_name_rates``, issue 63's 5 % bar).

``--make DIR``: writes literature-grid records into DIR as the grid makes them
(config/config.yaml: 40 s at 256 Hz, ratio 0.5, the grid's seed offset): each of
``--effects`` at seed 0 and the effect-free record at each of ``--free-seeds``
(``--effects`` with no name: none), of each of ``--kinds`` (the generator's recording kinds,
``literature.KINDS``; default base_acc->rel_acc), ``--duration`` s each. ``--real``: the
shipped real recordings too (the frame at 250 g and 450 g, the Silverbox; ``grid.recorded``:
their truths and why), read from ``--data`` (default data/public); their diagnosis is ``diagnosis.diagnose_recording``, the
command line's call on the file, against the study's linear baseline.

``--fast``: the diagnosis's ``DiagnosisSettings.fast`` (15 s fitted by TMCMC, one round, two
candidates sampled; the grid's fast settings) on every record. ``--jobs N``: N diagnoses at
once, each integrating on cores / N threads. The command's wall time is printed last.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import pandas as pd
import yaml

ROOT = Path(__file__).resolve().parents[1]
CONFIG = ROOT / "config" / "config.yaml"
EFFECTS = ("duffing", "quadratic_damping", "stribeck_exponential", "end_stop_hertz")
DATA = ROOT / "data" / "public"


#: File-name tags of the literature generator's recording kinds (the default's: none).
KIND_TAGS = {"base_acc->rel_acc": "", "base_disp->rel_disp": "_dd", "base_disp->rel_acc": "_da",
             "force->rel_disp": "_fd"}


def make_set(out: Path, effects, free_seeds, kinds=("base_acc->rel_acc",),
             duration_s: float | None = None) -> None:
    """The grid's records (and truths, sidecars) of ``effects`` and effect-free seeds, of
    each recording kind of ``kinds`` (``<effect><tag>_s<seed>``, :data:`KIND_TAGS`), lasting
    ``duration_s`` (None: the grid's). A scenario a kind cannot express (friction on the
    ground with a force input) is skipped with a line saying why."""
    from harvester.grid.generators import make_scenario_files
    cfg = yaml.safe_load(CONFIG.read_text())
    det, grid = cfg["detection"], cfg["detection"]["grids"]["literature"]
    settings = {"duration_s": float(duration_s or grid["duration_s"]),
                "lead_in_s": float(det["lead_in_s"]), "seed": int(det["seed"])}
    out.mkdir(parents=True, exist_ok=True)
    jobs = [(e, float(grid["ratios"][0]), 0, k) for k in kinds for e in effects] + \
        [("none", 0.0, s, k) for k in kinds for s in free_seeds]
    for effect, ratio, seed, kind in jobs:
        csv = out / f"{effect}{KIND_TAGS[kind]}_s{seed}.csv"
        if csv.is_file():
            continue
        try:
            truth = make_scenario_files("literature", effect, ratio, seed,
                                        {**settings, "kind": kind}, cfg["rig"],
                                        cfg["preprocess"], csv, csv.with_suffix(".json"))
        except ValueError as err:
            print(f"skipped {csv.name}: {err}", flush=True)
            continue
        csv.with_suffix(".yaml").write_text("".join(f"{k}: {float(v)!r}\n"
                                                    for k, v in truth["known"].items()))
        print(f"made {csv.name}", flush=True)


def run_diagnosis_cached(rec, fast: bool = False) -> dict:
    """The record's diagnosis, kept beside it (``<name>.diagnosis.json``): a real
    recording's (truth ``diagnose: recording``) by ``diagnosis.diagnose_recording``, the
    command's call on the file; a grid record's by ``grid.scoring.run_diagnosis``, the
    grid's. ``fast``: ``DiagnosisSettings.fast`` with 15 s fitted (the grid's)."""
    kept = rec.path.with_suffix(".diagnosis.json")
    if kept.is_file():
        return json.loads(kept.read_text())
    d = _recorded_diagnosis(rec, fast) if rec.truth.get("diagnose") == "recording" \
        else _grid_diagnosis(rec, fast)
    kept.write_text(json.dumps(d, default=str))
    return d


def _grid_diagnosis(rec, fast: bool) -> dict:
    from harvester.data.sidecar import read_sidecar
    from harvester.grid.scoring import run_diagnosis
    t = rec.data["time"].to_numpy()
    fs = 1.0 / float(t[1] - t[0])
    lead_in = float((rec.truth.get("settings") or {}).get("lead_in_s", 1.0))
    return run_diagnosis(rec.data, rec.baseline, rec.known, seed=0, fast=fast,
                         lead_in=int(round(lead_in * fs)),
                         lowpass_hz=read_sidecar(rec.path).filtered_at_hz)


def _recorded_diagnosis(rec, fast: bool) -> dict:
    from harvester.diagnosis import DiagnosisSettings, diagnose_recording
    clock = time.perf_counter()
    settings = DiagnosisSettings.fast(fit_seconds=15.0, figures=False) if fast \
        else DiagnosisSettings(figures=False)
    d = diagnose_recording(rec.path, rec.baseline, settings=settings).to_dict()
    d["runtime_s"] = time.perf_counter() - clock
    d["implementation"] = "harvester.diagnosis.diagnose_recording" + (" (fast)" if fast else "")
    return d


def _diagnose_path(csv: str, fast: bool, threads: int) -> str:
    """A worker's job: the diagnosis of the record ``csv`` of its set, kept beside it."""
    from harvester.grid.peers import read_set
    from harvester.runlog import use_threads
    use_threads(threads)
    (rec,) = [r for r in read_set(Path(csv).parent) if str(r.path) == csv]
    run_diagnosis_cached(rec, fast)
    return csv


def diagnose_all(records, fast: bool, jobs: int) -> None:
    """The diagnoses not kept yet, ``jobs`` at once (each on cores / jobs threads)."""
    todo = [str(r.path) for r in records if not r.path.with_suffix(".diagnosis.json").is_file()]
    if jobs <= 1 or len(todo) <= 1:
        for csv in todo:
            _diagnose_path(csv, fast, os.cpu_count() or 1)
            print(f"diagnosed {Path(csv).stem}", flush=True)
        return
    threads = max(1, (os.cpu_count() or 1) // jobs)
    with ProcessPoolExecutor(jobs) as pool:
        for csv in pool.map(_diagnose_path, todo, [fast] * len(todo), [threads] * len(todo)):
            print(f"diagnosed {Path(csv).stem}", flush=True)


def _topology(d: dict) -> str:
    """The friction's form the diagnosis took where the sidecar was silent ("ground", "base",
    "base (untold)": the record could not tell; "" where none was compared), from its notes."""
    for note in d.get("notes") or []:
        if "does not say what the friction acts on" in note:
            return ("ground" if "taken: relative to the ground" in note else
                    "base" if "taken: relative to the base" in note else "base (untold)")
    return ""


def confusion(records) -> tuple[pd.DataFrame, pd.DataFrame]:
    """(per record, confusion matrix) of the kept diagnoses: ``grid.scoring.score``'s row
    beside the record, its recording kind, the names given, whether a mass error
    (inertia_error) was named where none was put in, the friction's form taken and whether
    the time budget cut the search for names; friction
    put on the ground is named right by ``ground_friction``, or by a friction law with the
    form "ground". The matrix is
    ``grid.scoring.confusion_matrix`` of the rows (true scenario x first name)."""
    from harvester.grid.scoring import accepted_names, confusion_matrix, score
    rows = []
    for rec in records:
        kept = rec.path.with_suffix(".diagnosis.json")
        if not kept.is_file():
            continue
        d = json.loads(kept.read_text())
        lit = rec.truth.get("literature") or {}
        ground = (lit.get("effect") or {}).get("kind") == "ground_friction"
        truth = {"effect": rec.path.stem, "seed": 0, **rec.truth}
        if ground:  # the library's term on the ground names it in any form
            truth["correct_names"] = sorted({*truth.get("correct_names", ()),
                                             "ground_friction"})
        row = score(truth, d)
        missing, form = list(d.get("missing") or []), _topology(d)
        named = missing[:1] or [e for t in d.get("ties") or [] for e in t.get("effects", [])]
        if ground and form != "ground" and "ground_friction" not in named \
                and row["outcome"] in ("named", "tied"):
            row["outcome"] = "wrong"
        said = missing + [e for t in d.get("ties") or [] for e in t.get("effects", [])]
        right = accepted_names(truth["effect"], None, truth) if not row["effect_free"] \
            else set()
        rows.append({**row, "record": rec.path.stem, "right": right,
                     # every name a flagging verdict gives (named or tied); the right name
                     # listed under an adequate verdict as detectable but negligible
                     "said": set(said) if row["flagged"] else set(),
                     "right_but_negligible": not row["flagged"] and not row["effect_free"]
                     and bool(set(missing + list(d.get("negligible") or [])) & right),
                     "kind": rec.truth.get("kind", "base_acc->rel_acc"),
                     "correct": " ".join(sorted(rec.correct)) or "-",
                     "names": " ".join(missing) or "-", "friction_form": form or "-",
                     "budget_cut": bool((d.get("budget") or {}).get("cut")),
                     # named as missing physics (a flagging verdict), or only listed under
                     # an adequate one as detectable but negligible
                     "mass_error_not_put_in": "inertia_error" in missing and row["flagged"]
                     and "inertia_error" not in rec.correct,
                     "mass_error_listed": "inertia_error" in missing
                     and "inertia_error" not in rec.correct})
    table = pd.DataFrame(rows)
    return table, confusion_matrix(table) if rows else pd.DataFrame()


def print_confusion(records) -> None:
    """The per-record table, the confusion matrix and the counts of :func:`confusion`."""
    from harvester.grid.scoring import wrong_name_rates
    table, matrix = confusion(records)
    if table.empty:
        print("no kept diagnosis")
        return
    cols = ["record", "correct", "verdict", "outcome", "names", "friction_form",
            "mass_error_not_put_in", "budget_cut", "runtime_s"]
    print(table[cols].to_string(index=False, float_format=lambda x: f"{x:.0f}"))
    print()
    print(matrix.to_string(index=False))
    lib = table[~table["effect_free"] & (table["correct"] != "-")]
    counts = lib["outcome"].value_counts().to_dict()
    free = table[table["effect_free"]]
    print(f"\nlibrary effects: {len(lib)} records, {counts}; outside the library: "
          f"{int((~table['effect_free'] & (table['correct'] == '-')).sum())}; effect-free: "
          f"{len(free)}, false alarms {int(free['flagged'].sum())}; mass error named where "
          f"none was put in: {int(table['mass_error_not_put_in'].sum())} (listed under an "
          f"adequate verdict: {int((table['mass_error_listed'] & ~table['flagged']).sum())})"
          f"; the right name listed as detectable but negligible under an adequate verdict: "
          f"{int(table['right_but_negligible'].sum())}; the time budget "
          f"cut the search on {int(table['budget_cut'].sum())} of {len(table)}")
    print("per term, in the names of a flagging verdict (named or tied) where it is not "
          "a right name (issue 63's bar: 5 %):")
    for name, (k, n) in wrong_name_rates(table).items():
        print(f"  {name}: {k} of {n} ({100 * k / n:.1f} %){'  > 5 %' if k > 0.05 * n else ''}")



def parser() -> argparse.ArgumentParser:
    """The command's options (module docstring)."""
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--set", type=Path, help="folder of recordings with truth files")
    p.add_argument("--make", type=Path, help="write literature-grid records into this folder")
    p.add_argument("--effects", nargs="*", default=list(EFFECTS))
    p.add_argument("--free-seeds", nargs="*", type=int, default=[0, 1])
    p.add_argument("--kinds", nargs="*", default=["base_acc->rel_acc"],
                   help="with --make: the literature generator's recording kinds")
    p.add_argument("--duration", type=float, help="with --make: seconds per record "
                   "(default: the grid's)")
    p.add_argument("--skip-diagnosis", action="store_true", help="the peers only")
    p.add_argument("--kept-only", action="store_true",
                   help="the diagnosis only where a <name>.diagnosis.json is kept (none run)")
    p.add_argument("--no-narx", action="store_true", help="without the NARX free run")
    p.add_argument("--diagnosis-only", action="store_true",
                   help="the diagnosis's rows alone (no pysindy, no NARX)")
    p.add_argument("--real", action="store_true",
                   help="with --make: the shipped real recordings too (grid.recorded)")
    p.add_argument("--data", type=Path, default=DATA, help="folder of the real recordings")
    p.add_argument("--fast", action="store_true", help="the diagnosis's fast settings")
    p.add_argument("--jobs", type=int, default=1, help="diagnoses run at once")
    p.add_argument("--csv", type=Path, help="write the per-record rows here")
    p.add_argument("--confusion", action="store_true", help="the kept diagnoses' names per "
                   "record and their confusion matrix (grid.scoring), nothing run")
    return p


def table_rows(records, args) -> list[dict]:
    """Each record's rows, the diagnosis's and the peers', printed as they come."""
    from harvester.grid.peers import diagnosis_row, peer_rows
    rows = []
    for rec in records:
        kept = rec.path.with_suffix(".diagnosis.json").is_file()
        run = not args.skip_diagnosis and (kept or not args.kept_only)
        found = [diagnosis_row(rec, lambda r: run_diagnosis_cached(r, args.fast))] if run \
            else []
        peers = [] if args.diagnosis_only else peer_rows(rec, narx=not args.no_narx)
        for r in found + peers:
            rows.append({"record": rec.path.stem, "correct": " ".join(sorted(rec.correct)),
                         **r, "names": " ".join(r["names"])})
            print(f"{rec.path.stem:28s} {r['tool']:22s} {rows[-1]['outcome']:12s} "
                  f"{' '.join(r['names'][:3]):40s} {r['heldout_nrmse'] or float('nan'):7.3f} "
                  f"{r['seconds']:8.2f} s", flush=True)
    return rows


def main(argv: list[str] | None = None) -> int:
    args = parser().parse_args(argv)
    clock = time.perf_counter()
    if args.make:
        make_set(args.make, args.effects, args.free_seeds, args.kinds, args.duration)
        if args.real:
            from harvester.grid.recorded import write_recorded_set
            for csv in write_recorded_set(args.data, args.make):
                print(f"made {csv.name}", flush=True)
    if not args.set:
        return 0
    from harvester.grid.peers import read_set, summary
    records = read_set(args.set)
    if args.confusion:
        print_confusion(records)
        return 0
    if not (args.skip_diagnosis or args.kept_only):
        diagnose_all(records, args.fast, args.jobs)
    table = pd.DataFrame(table_rows(records, args))
    if args.csv:
        table.to_csv(args.csv, index=False)
    print()
    print(summary(table).to_string(index=False, float_format=lambda x: f"{x:.3g}"))
    print(f"\n{len(records)} records, wall time {time.perf_counter() - clock:.0f} s "
          f"({'fast' if args.fast else 'default'} diagnosis settings, {args.jobs} at once)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
