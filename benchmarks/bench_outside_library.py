"""The diagnosis on forms outside the library (issue 43, first done-when item): no library
name, and the missing force's description with the right shape and its period, frequency or
trend within 10 %.

Records of the literature generator's scenarios whose correct names are empty
(``harvester.synthetic.literature``: ``cogging``, ``quadratic_spring``, ``friction_drift``,
``mains_hum``), made as the ``literature`` grid makes them (``grid.generators.
make_scenario_files``, config/config.yaml: 40 s at 256 Hz, the grid's seed offset, no
low-pass), each with its sidecar (the "known" M, m, k), then ``harvester diagnose REC.csv
--baseline tanh --no-figures`` at the default settings. One row per record: scenario, seed,
verdict, names given, the described shape, its parameter, the truth's, their ratio, and the
diagnosis's wall time. For the mains hum, a line the missing force leaves in the recording
(``diagnosis.size.lines``) stands in for the force's line when that is not read.

    python benchmarks/bench_outside_library.py [--ratio 1] [--fast] [--seeds 0 1]
        [--scenarios cogging ...] [--out DIR]

``--fast``: seed 0 only. Every scenario's seed 0 runs before any seed 1. A full diagnosis
takes minutes to an hour on 2 shared cores (cogging seed 0: 51 min, two rounds sampled);
``--describe-only`` gives the description alone (the diagnosis's baseline posterior and its
missing force, about a minute per record; verdict "(not run)", no names) and keeps each
latent force as ``<record>.latent.pkl`` to refit the shapes offline. A record, or a
diagnosis.json, already in ``--out`` is reused.
"""

from __future__ import annotations

import argparse
import json
import pickle
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import yaml

from harvester.grid.generators import make_scenario_files

ROOT = Path(__file__).resolve().parents[1]
CONFIG = ROOT / "config" / "config.yaml"
SCENARIOS = ("cogging", "quadratic_spring", "friction_drift", "mains_hum")
#: scenario -> (the shape that describes it, the shape's parameter, its unit's scale and name)
EXPECTED = {"cogging": ("periodic in z", "period_m", 1e3, "mm"),
            "quadratic_spring": ("even in z", "k2_N_per_m2", 1.0, "N/m^2"),
            "friction_drift": ("drifting friction", "slope_N_per_s", 1.0, "N/s"),
            "mains_hum": ("line", "frequency_hz", 1.0, "Hz")}


def true_value(name: str, lit: dict) -> float:
    """The generator's value of the described parameter (SI)."""
    par = lit["effect"]["parameters"]
    if name == "cogging":
        return par["period_m"]
    if name == "quadratic_spring":
        return par["k2_N_per_m2"]
    if name == "friction_drift":
        return par["change_over_record"] * lit["device"]["F_c"] / par["record_s"]
    return par["frequency_hz"]


def make_record(name: str, seed: int, ratio: float, out: Path) -> tuple[Path, dict]:
    """The grid's record and truth, and the sidecar beside the record."""
    cfg = yaml.safe_load(CONFIG.read_text())
    det, grid = cfg["detection"], cfg["detection"]["grids"]["literature"]
    csv = out / f"{name}_r{ratio:g}_s{seed}.csv"
    truth = make_scenario_files("literature", name, ratio, seed,
                                {"duration_s": float(grid["duration_s"]),
                                 "lead_in_s": float(det["lead_in_s"]), "seed": int(det["seed"])},
                                cfg["rig"], cfg["preprocess"], csv, csv.with_suffix(".json"))
    csv.with_suffix(".yaml").write_text("".join(f"{k}: {float(v)!r}\n"
                                                for k, v in truth["known"].items()))
    return csv, truth


def diagnose(csv: Path) -> tuple[dict, float]:
    """``harvester diagnose`` at the default settings; (diagnosis.json, wall seconds). A
    diagnosis.json already in the record's folder is read instead (its own runtime)."""
    out = csv.with_suffix("")
    if (out / "diagnosis.json").is_file():
        diag = json.loads((out / "diagnosis.json").read_text())
        return diag, float(diag.get("runtime_s", float("nan")))
    clock = time.perf_counter()
    subprocess.run([str(Path(sys.executable).with_name("harvester")), "diagnose", str(csv),
                    "--baseline", "tanh", "--out", str(out), "--no-figures"], check=True,
                   stdout=subprocess.DEVNULL)
    return json.loads((out / "diagnosis.json").read_text()), time.perf_counter() - clock


def describe_only(csv: Path, truth: dict) -> tuple[dict, float]:
    """The missing force's description as the diagnosis makes it (its baseline's posterior
    under its likelihood, the analysed window), without the rounds that name library terms:
    a diagnosis.json-like dict with verdict "(not run)" (``--describe-only``)."""
    from harvester.data.daq import read_recording
    from harvester.diagnosis.prepare.analysis import prepare, start_baseline
    from harvester.inference.map_fit import baseline_state
    from harvester.diagnosis.size.missing_force import missing_force
    from harvester.diagnosis.run import fitted_shape
    from harvester.diagnosis.prepare.settings import DiagnosisSettings
    from harvester.initial.recording import diagnosis_priors

    clock = time.perf_counter()
    rec, settings = read_recording(csv), DiagnosisSettings(figures=False)
    priors, _ = diagnosis_priors(rec, "tanh", truth["known"])
    a = prepare(rec, None, "tanh", truth["known"], settings, str(csv))
    start = start_baseline(a, priors, None, settings)
    problem = a.chain(start.detection_problem, start.temper, structure=a.structure)
    state = baseline_state(problem, start.samples)
    mf = missing_force(state, (a.lead, a.hold))
    mf.fitted_shape = fitted_shape(a, state, start, None, settings)
    with open(csv.with_suffix(".latent.pkl"), "wb") as fh:  # to refit the shapes offline
        pickle.dump(mf.latent, fh)
    return ({"verdict": "(not run)", "missing": [], "missing_force": mf.to_dict(),
             "headline": mf.sentence()}, time.perf_counter() - clock)


def row(name: str, seed: int, truth: dict, diag: dict, seconds: float) -> str:
    """One line: scenario, seed, verdict, names, described shape, parameter, truth, ratio."""
    want, key, scale, unit = EXPECTED[name]
    shape = ((diag.get("missing_force") or {}).get("shape") or {})
    shapes = shape.get("shapes") or []
    best = shapes[0] if shapes else {"shape": "-", "parameters": {}}
    stands_out = not shape.get("sentence", "").startswith("no missing force")
    described = next((s for s in shapes if s["shape"] == want), None)
    value = described["parameters"].get(key, float("nan")) if described else float("nan")
    fitted = (diag.get("missing_force") or {}).get("fitted_shape") or {}
    if fitted.get("stands") and not stands_out:  # the description the diagnosis gives then
        best, stands_out = {"shape": f"{fitted['shape']} (as a term)"}, True
        value = fitted["parameters"].get(key, float("nan")) if fitted["shape"] == want \
            else float("nan")
    line = (diag.get("missing_force") or {}).get("residual_line")
    if name == "mains_hum" and line and not (stands_out and best["shape"] == want):
        best, value, stands_out = {"shape": "line in the residual"}, line["frequency_hz"], True
    truth_value = true_value(name, truth["literature"])
    names = ",".join(diag.get("missing") or []) or "-"
    return (f"{name:17s} {seed:4d}  {diag['verdict']:16s} {names:24s} "
            f"{best['shape'] + ('' if stands_out else ' (within its sd)'):28s} "
            f"{scale * value:10.4g} {scale * truth_value:10.4g} {unit:6s} "
            f"{value / truth_value:6.3f} {seconds:7.0f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--ratio", type=float, default=1.0,
                        help="contribution RMS / noise RMS (a ratio of the grids: 1)")
    parser.add_argument("--fast", action="store_true", help="seed 0 only")
    parser.add_argument("--scenarios", nargs="+", default=list(SCENARIOS))
    parser.add_argument("--seeds", nargs="+", type=int, default=[0, 1],
                        help="the grid's seed indices (0 1)")
    parser.add_argument("--out", default=None, help="folder for the records (default: temp)")
    parser.add_argument("--describe-only", action="store_true",
                        help="the missing force's description from the diagnosis's baseline "
                             "only (minutes less per record; no names)")
    args = parser.parse_args()
    out = Path(args.out or tempfile.mkdtemp())
    out.mkdir(parents=True, exist_ok=True)
    print(f"{'scenario':17s} {'seed':>4s}  {'verdict':16s} {'names given':24s} "
          f"{'described shape (best)':28s} {'described':>10s} {'truth':>10s} {'unit':6s} "
          f"{'ratio':>6s} {'seconds':>7s}", flush=True)
    for seed in (0,) if args.fast else args.seeds:
        for name in args.scenarios:
            csv = out / f"{name}_r{args.ratio:g}_s{seed}.csv"
            if csv.with_suffix(".json").is_file():
                truth = json.loads(csv.with_suffix(".json").read_text())
            else:
                csv, truth = make_record(name, seed, args.ratio, out)
            diag, seconds = describe_only(csv, truth) if args.describe_only else diagnose(csv)
            print(row(name, seed, truth, diag, seconds), flush=True)
            print(f"    {diag['headline']}", flush=True)


if __name__ == "__main__":
    main()
