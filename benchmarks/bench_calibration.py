"""The verdict's calibration, measured: false alarms on effect-free records of both generators,
and the detection's power against effect strength, with the rank p-value and the tail one.

Part 1 (``--false-alarms``): effect-free records of the library generator (tanh and linear
devices, ``synthetic.scenarios``) and of the literature generator (a new device per seed,
``synthetic.literature``), each diagnosed in full (``grid.scoring.run_diagnosis``, TMCMC
included; ``--fast``: ``DiagnosisSettings.fast``). A false alarm is a flagged verdict
("missing_physics" or "inadequate"); the rate is printed with its Wilson interval beside the
nominal rate it should stay under (the evidence's alpha plus ``unexplained_alpha``).

Part 2 (``--power``): the concealed-effect grid's library effects at several strengths
(contribution / noise RMS), detection only (``quick_detect``: MAP baseline, the default 400
replicates). For each record the library family's p-value by rank (what it was before the tail
was modelled, never below 1/401) and by the tail model (``inference.tail``); the share of
records below alpha = 0.05 and below unexplained_alpha = 0.001 under each.

    python benchmarks/bench_calibration.py [--seeds 10] [--duration 20] [--fast]
"""

from __future__ import annotations

import argparse
import logging
import tempfile
import time
from pathlib import Path

import numpy as np
import yaml

from harvester.data.daq import read_recording
from harvester.diagnosis import DiagnosisSettings, quick_detect
from harvester.grid.generators import make_scenario_files
from harvester.grid.scoring import FLAGGED, run_diagnosis, wilson_interval

CONFIG = Path(__file__).resolve().parents[1] / "config" / "config.yaml"
#: Effect-free scenarios: (generator, scenario).
EFFECT_FREE = (("library", "none_tanh"), ("library", "none_linear"), ("literature", "none"))
#: Effects and strengths of the power part.
POWER_EFFECTS = ("end_stop", "unmodelled_mode", "cubic_stiffness", "coulomb_friction")
POWER_RATIOS = (0.125, 0.25, 0.5)


def record(generator: str, effect: str, ratio: float, seed: int, duration: float, cfg, out):
    det = cfg["detection"]
    csv, truth_path = out / f"{generator}_{effect}_{ratio}_{seed}.csv", out / "truth.json"
    truth = make_scenario_files(generator, effect, ratio, seed,
                                {"duration_s": duration, "lead_in_s": float(det["lead_in_s"]),
                                 "seed": int(det["seed"])},
                                cfg["rig"], cfg["preprocess"], csv, truth_path)
    return read_recording(csv), truth


def false_alarms(args, cfg, out) -> None:
    settings = DiagnosisSettings.fast() if args.fast else DiagnosisSettings()
    nominal = settings.evidence_alpha + settings.unexplained_alpha
    rows = []
    for seed in range(args.seeds):
        for generator, effect in EFFECT_FREE:
            if generator == "library" and seed % 2 != (effect == "none_linear"):
                continue  # the library's two devices take turns
            rec, truth = record(generator, effect, 0.0, seed, args.duration, cfg, out)
            fs = 1.0 / float(rec["time"].iloc[1] - rec["time"].iloc[0])
            clock = time.perf_counter()
            res = run_diagnosis(rec, truth["baseline"], truth["known"], seed=seed,
                                fast=args.fast, lead_in=int(round(float(
                                    cfg["detection"]["lead_in_s"]) * fs)),
                                lowpass_hz=20.0 if generator == "library" else None)
            fam = res["detection"]["families"].get("library", {})
            tail = fam.get("p_value_from") or {}
            rows.append((generator, effect, seed, res["verdict"], tail.get("rank"),
                         fam.get("p_value"), res.get("explained_share"),
                         (res.get("fit_judgement") or {}).get("residual_over_floor")))
            print(f"{generator:10s} {effect:12s} seed {seed}: {res['verdict']:15s} "
                  f"p rank {_fmt(rows[-1][4])} tail {_fmt(rows[-1][5])} explained "
                  f"{_fmt(rows[-1][6])} residual/floor {_fmt(rows[-1][7])} "
                  f"({time.perf_counter() - clock:.0f} s)", flush=True)
    flagged = sum(r[3] in FLAGGED for r in rows)
    lo, hi = wilson_interval(flagged, len(rows))
    print(f"\nfalse alarms: {flagged} of {len(rows)} effect-free records = "
          f"{flagged / len(rows):.3f}, 95 % interval [{float(lo):.3f}, {float(hi):.3f}]; nominal "
          f"at most {nominal:.3f} (evidence alpha {settings.evidence_alpha} + unexplained "
          f"alpha {settings.unexplained_alpha})")


def power(args, cfg, out) -> None:
    settings = DiagnosisSettings()
    print(f"\n{'effect':18s} {'ratio':>6s} {'seed':>4s} {'p rank':>9s} {'p tail':>9s}")
    table: dict[float, list[tuple[float, float]]] = {r: [] for r in POWER_RATIOS}
    for ratio in POWER_RATIOS:
        for effect in POWER_EFFECTS:
            for seed in range(args.power_seeds):
                rec, truth = record("library", effect, ratio, seed, args.duration, cfg, out)
                det, _ = quick_detect(rec, truth["baseline"], truth["known"], None,
                                      DiagnosisSettings(seed=seed, lowpass_hz=20.0))
                tail = det.family_tail["library"]
                table[ratio].append((tail.rank, tail.p))
                print(f"{effect:18s} {ratio:6.3f} {seed:4d} {tail.rank:9.3g} {tail.p:9.3g}",
                      flush=True)
    print(f"\n{'ratio':>6s} {'n':>3s}  share p < {settings.alpha} (rank / tail)  "
          f"share p < {settings.unexplained_alpha} (rank / tail)")
    for ratio, ps in table.items():
        p = np.array(ps)
        print(f"{ratio:6.3f} {len(p):3d}  {np.mean(p[:, 0] < settings.alpha):.2f} / "
              f"{np.mean(p[:, 1] < settings.alpha):.2f}"
              f"{'':22s}{np.mean(p[:, 0] < settings.unexplained_alpha):.2f} / "
              f"{np.mean(p[:, 1] < settings.unexplained_alpha):.2f}")


def _fmt(x) -> str:
    return "-" if x is None else f"{x:.3g}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=10, help="seeds per generator (part 1)")
    parser.add_argument("--power-seeds", type=int, default=2)
    parser.add_argument("--duration", type=float, default=20.0, help="record length (s)")
    parser.add_argument("--fast", action="store_true", help="DiagnosisSettings.fast in part 1")
    parser.add_argument("--skip-false-alarms", action="store_true")
    parser.add_argument("--skip-power", action="store_true")
    args = parser.parse_args()
    logging.basicConfig(level=logging.WARNING)
    cfg = yaml.safe_load(CONFIG.read_text())
    out = Path(tempfile.mkdtemp())
    if not args.skip_false_alarms:
        false_alarms(args, cfg, out)
    if not args.skip_power:
        power(args, cfg, out)


if __name__ == "__main__":
    main()
