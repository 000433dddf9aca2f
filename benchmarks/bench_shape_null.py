"""How often the missing force's description reads a shape where there is none (issue 43):
the rate of effect-free records whose best shape stands beyond ``shapes.SHAPE_SD``, with its
Wilson interval, against a nominal rate.

Effect-free records of the literature generator (scenario ``none``: the baseline device
alone, its own smooth friction law), made as the ``literature`` grid makes them (40 s at
256 Hz, the grid's seed offset; ``bench_outside_library.make_record``), each described from
the diagnosis's baseline posterior (``bench_outside_library.describe_only``, 12-106 s a
record; a record the reader refuses is said so and left out). One row per record: seed, the
best shape, its standing (sd, referred to its coefficients, ``shapes.standing``), the
largest standing of any shape, and whether the force was read; then the rate of reads with
its 95 % Wilson interval, the standings' quantiles, and the threshold at which the records
would read at the nominal rate; beside it, the periodic shape fitted as a term of the model
(``diagnosis.size.shape_terms``): its gain, its period, and the rate at which it stands. A record
already in ``--out`` is reused (its description is recomputed).

    python benchmarks/bench_shape_null.py [--seeds 0 1 ... | --first 0 --count 60]
        [--nominal 0.05] [--out DIR]
"""

from __future__ import annotations

import argparse
import json
import tempfile
from pathlib import Path

import numpy as np

from bench_outside_library import describe_only, make_record
from harvester.data.errors import DataError
from harvester.diagnosis.size.shape_terms import STAND_NATS
from harvester.diagnosis.size.shapes import SHAPE_SD
from harvester.grid.scoring import wilson_interval


def standings(diag: dict) -> tuple[str, float, float, bool]:
    """(the best shape, its standing, the largest standing of any shape, read or not)."""
    shape = (diag.get("missing_force") or {}).get("shape") or {}
    shapes = shape.get("shapes") or [{"shape": "-", "standing_sd": float("nan")}]
    most = max((float(s.get("standing_sd", float("nan"))) for s in shapes), default=np.nan)
    return (shapes[0]["shape"], float(shapes[0].get("standing_sd", np.nan)), most,
            bool(shape.get("readable", False)))


def fitted(diag: dict) -> tuple[float, float, bool]:
    """The periodic shape fitted as a term (``diagnosis.size.shape_terms``): (its Laplace gain
    over the baseline, nats; its period, m; whether it stands)."""
    fs = (diag.get("missing_force") or {}).get("fitted_shape") or {}
    return (float(fs.get("gain_nats", np.nan)),
            float((fs.get("parameters") or {}).get("period_m", np.nan)), bool(fs.get("stands")))


def fitted_summary(gains: np.ndarray, stands: np.ndarray, nominal: float) -> list[str]:
    """The fitted shape's stand rate with its Wilson interval and its gains' quantiles."""
    k, n = int(stands.sum()), int(stands.size)
    lo, hi = wilson_interval(k, n)
    q = np.nanquantile(gains, [0.5, 0.95, 1.0])
    return [f"# the periodic shape fitted as a term stands (>= {STAND_NATS:g} nats): {k} of "
            f"{n} ({k / n:.1%}, 95 % Wilson {float(lo):.1%}-{float(hi):.1%}; nominal "
            f"{nominal:.0%}); its gain: median {q[0]:.1f}, 95 % {q[1]:.1f}, max {q[2]:.1f} nats"]


def summary(best: np.ndarray, read: np.ndarray, nominal: float) -> list[str]:
    """The read rate with its Wilson interval, the standings' quantiles and the threshold at
    the nominal rate (the best standings' 1 - nominal quantile)."""
    k, n = int(read.sum()), int(read.size)
    lo, hi = wilson_interval(k, n)
    q = np.nanquantile(best, [0.5, 0.9, 0.95, 1.0])
    return [f"# read at SHAPE_SD = {SHAPE_SD:g} sd: {k} of {n} effect-free records "
            f"({k / n:.1%}, 95 % Wilson {float(lo):.1%}-{float(hi):.1%}; nominal {nominal:.0%})",
            f"# best shape's standing: median {q[0]:.2f}, 90 % {q[1]:.2f}, 95 % {q[2]:.2f}, "
            f"max {q[3]:.2f} sd",
            f"# threshold read at the nominal {nominal:.0%}: "
            f"{np.nanquantile(best, 1.0 - nominal):.2f} sd"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", nargs="+", type=int, default=None,
                        help="the grid's seed indices (default: --first .. --first + --count)")
    parser.add_argument("--first", type=int, default=0)
    parser.add_argument("--count", type=int, default=60)
    parser.add_argument("--nominal", type=float, default=0.05)
    parser.add_argument("--out", type=Path, default=None, help="records (default: temp)")
    args = parser.parse_args()
    seeds = args.seeds or list(range(args.first, args.first + args.count))
    out = args.out or Path(tempfile.mkdtemp(prefix="shape_null_"))
    out.mkdir(parents=True, exist_ok=True)
    print(f"# records in {out}\n# seed best_shape standing_sd largest_sd read "
          "fitted_gain_nats fitted_period_mm stands seconds")
    best, read, gains, stands = [], [], [], []
    for seed in seeds:
        csv = out / f"none_r0_s{seed}.csv"
        if csv.with_suffix(".json").is_file():
            truth = json.loads(csv.with_suffix(".json").read_text())
        else:
            csv, truth = make_record("none", seed, 0.0, out)
        try:
            diag, seconds = describe_only(csv, truth)
        except DataError as err:  # an effect-free record refused is a finding of its own
            print(f"{seed:5d} refused: {err}", flush=True)
            continue
        name, sd, most, is_read = standings(diag)
        gain, period, stand = fitted(diag)
        best.append(sd)
        read.append(is_read)
        gains.append(gain)
        stands.append(stand)
        print(f"{seed:5d} {name:28s} {sd:8.2f} {most:8.2f} {'yes' if is_read else 'no':4s} "
              f"{gain:8.1f} {1e3 * period:9.4g} {'yes' if stand else 'no':4s} {seconds:6.0f}",
              flush=True)
    print("\n".join(summary(np.array(best), np.array(read), args.nominal)
                    + fitted_summary(np.array(gains), np.array(stands), args.nominal)))


if __name__ == "__main__":
    main()
