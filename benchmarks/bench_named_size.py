"""A named effect's size against the generator's truth (issue 43, the sizes' done-when item),
with the base sensor's noise shared with the output or not.

Records of the literature generator as the ``literature`` grid makes them (40 s at 256 Hz, the
grid's seed offset, ratio 0.5 by default), each also made with ``shared_input_noise=False``:
the same device, excitation and effect, rel_acc's noise the same level but independent of the
recorded input (``harvester.synthetic.literature.generate``). Each is diagnosed by
``harvester diagnose REC.csv --baseline tanh --no-figures`` at the default settings. One row
per record: effect, seed, noise, verdict, the first named term, its parameters beside the
truth's (a mass error's dM and m_share; their distance in posterior sds), its own force's RMS
with its 95 % interval, the generator's missing force RMS, whether the interval holds it
(``grid.scoring.named_size``; for a tie, its first member's), which part both are of (the
whole force, or its varying part where the diagnosis says the record leaves the mean to the
term's form), and the wall time. A record or diagnosis.json already in
``--out`` is reused (the record is checked against a new one first).

    python benchmarks/bench_named_size.py [--effects payload_error rotor_inertia_error]
        [--seeds 0] [--noise shared own] [--ratio 0.5] [--out DIR]

A diagnosis takes 1-8 min on 2 cores (docs/measurements.md).
"""

from __future__ import annotations

import argparse
import json
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd
import yaml

from bench_outside_library import diagnose
from harvester.data.daq import write_recording
from harvester.grid.scoring import named_size
from harvester.synthetic.literature import generate

ROOT = Path(__file__).resolve().parents[1]
CONFIG = ROOT / "config" / "config.yaml"


def make_record(effect: str, seed: int, ratio: float, shared: bool, out: Path
                ) -> tuple[Path, dict]:
    """The grid's record of ``effect`` (its seed offset and duration), the input noise shared
    or not; its sidecar and truth beside it. An existing record must match the new one."""
    cfg = yaml.safe_load(CONFIG.read_text())
    det = cfg["detection"]
    duration = float(det["grids"]["literature"]["duration_s"])
    made = generate(effect, seed + int(det["seed"]), ratio=ratio, duration_s=duration,
                    shared_input_noise=shared)
    csv = out / f"{effect}_r{ratio:g}_s{seed}_{'shared' if shared else 'own'}.csv"
    if csv.is_file():
        old = pd.read_csv(csv).to_numpy()
        if old.shape != made.recording.shape or np.abs(old - made.recording.to_numpy()).max() > 1e-6:
            raise SystemExit(f"{csv} differs from the generator's record: remove it")
    else:
        write_recording(made.recording, csv)
    csv.with_suffix(".yaml").write_text("".join(f"{k}: {float(v)!r}\n"
                                                for k, v in made.sidecar.items()))
    truth = {"literature": made.truth, "known": dict(made.sidecar)}
    csv.with_suffix(".json").write_text(json.dumps(made.truth, default=float, indent=1))
    return csv, truth


def mass_truth(truth: dict) -> dict[str, float]:
    """A mass error's dM and m_share from the generator's true masses and the sidecar's."""
    true = truth["literature"].get("true_masses")
    if not true:
        return {}
    dm = true["M"] - truth["known"]["M"]
    return {"dM": dm, "m_share": (true["m"] - truth["known"]["m"]) / dm if dm else float("nan")}


def named_parameters(diag: dict) -> dict[str, tuple[float, float]]:
    """(mean, sd) of the added parameters of the named fit (diagnosis.json's ``fit``)."""
    added = (diag.get("fit") or {}).get("added_parameters") or {}
    return {k: (float(v["mean"]), float(v["sd"])) for k, v in added.items()}


def first_named(diag: dict) -> tuple[str, dict]:
    """The first named term ("a | b" for a tie, read as its first member) and a diagnosis
    that names it alone, for ``named_size``."""
    if diag.get("missing"):
        return ",".join(diag["missing"]), diag
    ties = diag.get("ties") or []
    if not ties:
        return "-", diag
    effects = list(ties[0].get("effects") or [])
    return "tie " + " | ".join(effects), {**diag, "missing": effects[:1]}


def row(effect: str, seed: int, shared: bool, truth: dict, diag: dict, seconds: float) -> str:
    names, alone = first_named(diag)
    size = named_size(truth, alone)
    est, true = named_parameters(diag), mass_truth(truth)
    params = " ".join(f"{k} {est[k][0]:.4g}+-{est[k][1]:.2g} ({true[k]:.4g}, "
                      f"{abs(est[k][0] - true[k]) / est[k][1]:.1f} sd)"
                      for k in ("dM", "m_share") if k in est and k in true)
    covered = {1.0: "yes", 0.0: "no"}.get(size["size_covered"], "-")
    return (f"{effect:20s} {seed:3d} {'shared' if shared else 'own':6s} "
            f"{diag['verdict']:16s} {names:28s} {params:60s} "
            f"{size['size_N']:9.4g} ({size['size_lo_N']:.4g}-{size['size_hi_N']:.4g}) "
            f"{size['size_true_N']:9.4g} {covered:4s} {size['size_part']:7s} {seconds:6.0f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--effects", nargs="+", default=["payload_error", "rotor_inertia_error"])
    parser.add_argument("--seeds", nargs="+", type=int, default=[0])
    parser.add_argument("--noise", nargs="+", choices=("shared", "own"),
                        default=["shared", "own"])
    parser.add_argument("--ratio", type=float, default=0.5)
    parser.add_argument("--out", type=Path, default=None,
                        help="records and diagnoses (default: a temporary folder)")
    args = parser.parse_args()
    out = args.out or Path(tempfile.mkdtemp(prefix="named_size_"))
    out.mkdir(parents=True, exist_ok=True)
    print(f"# records and diagnoses in {out}")
    print("# effect seed noise verdict names parameters (truth, distance) "
          "own force N (95 %) truth covered part wall_s")
    for seed in args.seeds:
        for effect in args.effects:
            for noise in args.noise:
                csv, truth = make_record(effect, seed, args.ratio, noise == "shared", out)
                diag, seconds = diagnose(csv)
                print(row(effect, seed, noise == "shared", truth, diag, seconds), flush=True)


if __name__ == "__main__":
    main()
