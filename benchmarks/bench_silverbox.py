"""The Silverbox through the command line at its defaults, and its simulation error on
held-out samples beside what is published for the benchmark (issue 41).

    .venv/bin/python benchmarks/bench_silverbox.py [--out DIR] [--fit-samples N]
                                                   [--held-samples N] [--skip-diagnose]

Reads data/public/silverbox/Schroeder80mV.mat (the bundled copy; skips with a message when it is absent),
writes the first ``--fit-samples`` of its multisine (8 s by default, in volts; no sidecar)
and runs, each timed by the wall clock:

* ``harvester diagnose REC --baseline linear``: the verdict and the term it names;
* ``harvester compare REC --models linear linear+cubic_stiffness``: each model's log
  evidence and TMCMC wall time (``wall_time_s`` of its posterior);

then simulates each model's posterior (``SAMPLES`` thinned rows, their predictive mean) from
rest for the input alone over the fitted samples and the ``--held-samples`` after them, and
prints the RMS error in mV on those held-out samples
(``harvester.inference.unseen.heldout_error``).

With ``--benchmark`` the same is done on the benchmark's own record, SNLS80mV.mat, as the
benchmark cuts it (``harvester.data.public.silverbox_benchmark``): fitted on the first
``--fit-samples`` of its training multisine, each model simulated for each test's input
alone, its RMS error (mV) after the first ``SILVERBOX_INIT`` samples (the test input
band-limited between samples, then held and linear: ``study.benchmark.reconstruction_errors``)
printed beside the published errors on the same tests that were read in their sources
(``harvester.data.published``; none is quoted from memory).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SILVERBOX = ROOT / "data" / "public" / "silverbox" / "Schroeder80mV.mat"
BENCHMARK = SILVERBOX.with_name("SNLS80mV.mat")
MODELS = ("linear", "linear+cubic_stiffness")
#: Posterior rows simulated for the held-out predictive mean.
SAMPLES = 100


def _run(args: list[str], cwd: Path) -> float:
    """Wall-clock seconds of one ``harvester`` command (raises if it fails)."""
    exe = Path(sys.executable).with_name("harvester")
    t0 = time.perf_counter()
    subprocess.run([str(exe), *args], cwd=cwd, check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - t0


def diagnose(rec: Path, out: Path) -> dict:
    """Verdict, named terms and seconds of ``harvester diagnose REC --baseline linear``."""
    seconds = _run(["diagnose", rec.name, "--baseline", "linear", "--out", out.name,
                    "--log", f"{out.name}.log", "--no-figures"], rec.parent)
    d = json.loads((out / "diagnosis.json").read_text())
    return {"seconds": seconds, "verdict": d.get("verdict"), "missing": d.get("missing"),
            "headline": d.get("headline")}


def compare(rec: Path, out: Path) -> dict:
    """Seconds of ``harvester compare`` and, per model, log evidence and TMCMC seconds."""
    import pandas as pd

    from harvester.inference.posterior import read_posterior
    seconds = _run(["compare", rec.name, "--models", *MODELS, "--out", out.name, "--log",
                    f"{out.name}.log", "--no-figures"], rec.parent)
    table = pd.read_csv(out / "evidence.csv").set_index("model")
    models = {}
    for m in MODELS:
        idata = read_posterior(out / "models" / m / "posterior.nc")
        models[m] = {"log_evidence": float(table.loc[m, "log_evidence"]),
                     "tmcmc_s": float(idata.sample_stats.attrs["wall_time_s"]), "idata": idata}
    return {"seconds": seconds, "models": models}


def heldout_mv(idata, held) -> dict:
    """The posterior's predictive mean on the held-out samples: RMS error and RMS output, mV."""
    from harvester.inference.posterior import posterior_theta
    from harvester.inference.predictive import thin
    from harvester.inference.unseen import heldout_error, unseen_problem
    df = held.whole.data
    problem = unseen_problem(idata, df, "posterior", "Silverbox")
    err = heldout_error(problem, thin(posterior_theta(idata), SAMPLES, 0),
                        df["force"].to_numpy(), df["rel_disp"].to_numpy(), held.section)
    return {**err, "rms_error_mV": 1e3 * err["rms_error"], "rms_output_mV": 1e3 * err["rms_output"]}


def _print_heldout(held, errors: dict) -> None:
    from harvester.data.public import SILVERBOX_FS
    a, b = held.section
    print(f"Silverbox Schroeder80mV: fitted on {len(held.fit.data) / SILVERBOX_FS:.2f} s; held "
          f"out {(b - a) / SILVERBOX_FS:.2f} s after it (samples {a}-{b} from the multisine's "
          "start)")
    for m, e in errors.items():
        print(f"  {m:24s} held-out RMS error {e['rms_error_mV']:.3f} mV (output RMS "
              f"{e['rms_output_mV']:.1f} mV, NRMSE {e['nrmse']:.4f})")


def _print_benchmark(split, cmp: dict) -> None:
    from harvester.data.public import SILVERBOX_FS, SILVERBOX_INIT, SILVERBOX_TESTS
    from harvester.study.benchmark import benchmark_table, best_lines
    table = benchmark_table({m: r["idata"] for m, r in cmp["models"].items()}, split, SAMPLES)
    n = len(split.fit.data)
    print(f"Silverbox benchmark (SNLS80mV.mat): fitted on the training multisine's first {n} "
          f"samples ({n / SILVERBOX_FS:.2f} s); RMS error (mV) on each test after its first "
          f"{SILVERBOX_INIT} samples, simulated for its input alone:")
    shown = table[["model", *SILVERBOX_TESTS, "input between samples"]].copy()
    shown["input between samples"] = shown["input between samples"].str.split(" ").str[0]
    print(shown.to_string(index=False, float_format=lambda x: f"{x:.3f}"))
    for _, r in table[table["source"] != "this study"].iterrows():
        print(f"  {r['model']}: {r['source']}")
    for line in best_lines(table):
        print(line)


def _print(diag: dict | None, cmp: dict) -> None:
    if diag is not None:
        print(f"diagnose --baseline linear: {diag['verdict']}, named {diag['missing']}, "
              f"{diag['seconds']:.0f} s")
    print(f"compare {' '.join(MODELS)}: {cmp['seconds']:.0f} s")
    for m, r in cmp["models"].items():
        print(f"  {m:24s} log evidence {r['log_evidence']:10.2f}  TMCMC {r['tmcmc_s']:5.0f} s")


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--out", type=Path, help="working directory (default: a temporary one)")
    p.add_argument("--fit-samples", type=int, default=4883, help="samples fitted (4883: 8 s)")
    p.add_argument("--held-samples", type=int, default=4883, help="held-out samples (4883)")
    p.add_argument("--skip-diagnose", action="store_true", help="time the compare only")
    p.add_argument("--benchmark", action="store_true",
                   help="fit and test on SNLS80mV.mat as the benchmark cuts it")
    args = p.parse_args(argv)
    source = BENCHMARK if args.benchmark else SILVERBOX
    if not source.is_file():
        print(f"skipped: {source} is absent (see data/public/silverbox/SOURCE.md)")
        return 0
    from harvester.data import public
    if args.benchmark:
        split = public.silverbox_benchmark(source, args.fit_samples)
        fit = split.fit
    else:
        held = public.silverbox_heldout(source, args.fit_samples, args.held_samples)
        fit = held.fit
    with tempfile.TemporaryDirectory() as tmp:
        work = args.out or Path(tmp)
        work.mkdir(parents=True, exist_ok=True)
        rec = fit.write(work / "silverbox.csv")
        diag = None if args.skip_diagnose else diagnose(rec, work / "diagnosis")
        cmp = compare(rec, work / "compare")
        _print(diag, cmp)
        if args.benchmark:
            _print_benchmark(split, cmp)
        else:
            _print_heldout(held, {m: heldout_mv(r["idata"], held)
                                  for m, r in cmp["models"].items()})
    return 0


if __name__ == "__main__":
    sys.exit(main())
