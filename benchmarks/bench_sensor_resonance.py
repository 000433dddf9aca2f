"""A resonance of the output's sensor against a mode of the device on literature records
(issue 63, ``diagnosis.name.sensor``).

For each record ``NAME:SEED[:F_HZ:ZETA[:NOISE]]`` of the literature generator
(``generate(NAME, SEED, ratio=1, noise_rel_acc=NOISE, sensor_resonance=(F_HZ, ZETA))``, no
sensor resonance where F_HZ is left out; NOISE 0.09 m/s^2 by default), the tanh baseline's
state is taken by ``quick_detect`` (MAP and Laplace draws, fast settings), tanh +
unmodelled_mode is fitted by MAP on the same likelihood, and the mode at the mean of 40 of
its Laplace draws (as a posterior's mean would be taken) is held against the best sensor
reading of the baseline (``read_resonance``). One line per record:
the detection's p-value, the mode's MAP, the conclusion, the sensor's fitted resonance and
both gains (tempered nats over the baseline). With ``--right`` the record's own effect
(its scenario's first correct name, else the mode) is fitted and held against the sensor
instead: on a record of a device effect the sensor must not win.

    python benchmarks/bench_sensor_resonance.py none:1:45:0.05:0.03 none:6:45:0.05 \\
        none:6 secondary_mode:0 flexible_mount:0 none:0
    python benchmarks/bench_sensor_resonance.py --right lugre:0 dahl:0 bouc_wen:0 duffing:0

About 30-80 s per record on 2 shared cores.
"""

from __future__ import annotations

import argparse
import time

from harvester.diagnosis.detect.quick import quick_detect
from harvester.diagnosis.detect.scores import band_top
from harvester.diagnosis.name.results import ConfirmSettings
from harvester.diagnosis.name.sensor import MODE, read_resonance
from harvester.diagnosis.prepare.settings import DiagnosisSettings
from harvester.inference.map_fit import fit_map
from harvester.synthetic.literature import SCENARIOS, generate


def held(name: str, seed: int, sensor: tuple[float, float] | None, noise: float,
         right: bool = False) -> str:
    """One record's line."""
    clock = time.perf_counter()
    g = generate(name, seed, ratio=1.0, noise_rel_acc=noise, sensor_resonance=sensor)
    det, state = quick_detect(g.recording, "tanh", g.sidecar, settings=DiagnosisSettings.fast())
    p = state.problem
    term = (SCENARIOS[name].correct_names or (MODE,))[0] if right else MODE
    mode = p.replace(structure=p.structure.with_term(term))
    mp = fit_map(mode, {}, seed=0)
    r = read_resonance(state, term, mode, mp.samples(40, 0).mean(axis=0),
                       band_top(1.0 / p.dt, None), ConfirmSettings())
    fit = dict(zip(mode.parameter_names, mp.theta))
    shown = (f"mode MAP {fit['f_mode']:.3g} Hz zeta {fit['zeta_mode']:.2g} mass "
             f"{fit['mass_mode']:.3g} kg" if term == MODE else f"{term} by MAP")
    truth = g.truth.get("sensor_resonance")
    said = "none" if truth is None else \
        f"{truth['f_hz']:g} Hz zeta {truth['zeta']:g}, {truth['change_to_noise']:.2f} x noise"
    return (f"{name} seed {seed} (sensor: {said}; noise {noise:g}): p {det.p_value:.3g}; "
            f"{shown}; {r.conclusion}: sensor read at {r.f_hz:.3g} Hz zeta "
            f"{r.zeta:.2g} ({r.sensor}) {r.sensor_gain:+.1f} nats, {term} {r.device_gain:+.1f} "
            f"({time.perf_counter() - clock:.0f} s)")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("records", nargs="+", help="NAME:SEED[:F_HZ:ZETA[:NOISE]]")
    ap.add_argument("--right", action="store_true",
                    help="hold the record's own effect against the sensor, not the mode")
    args = ap.parse_args()
    for spec in args.records:
        parts = spec.split(":")
        sensor = (float(parts[2]), float(parts[3])) if len(parts) > 3 else None
        noise = float(parts[4]) if len(parts) > 4 else 0.09
        print(held(parts[0], int(parts[1]), sensor, noise, args.right), flush=True)


if __name__ == "__main__":
    main()
