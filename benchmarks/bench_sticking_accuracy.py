"""Accuracy of the dry friction that sticks (``harvester.model.stick``), printed as tables.

1. Against the event-driven reference (``harvester.synthetic.event_driven``, DOP853 at rtol
   1e-11 between events located exactly): a forced oscillator (M 1 kg, c 0.5 N s/m, k 400
   N/m, two sines of 3 and 0.8 N, 6 s at 200 Hz) with Coulomb's law (2 N) and with a Stribeck
   excess (1.5 N sliding, +1 N static, delta 1 and 2) at Stribeck velocities 1e-2 to 1e-4
   m/s: the largest displacement error over the largest displacement, per sub-steps per
   sample, and the stuck shares of both.
2. The literature generator's Karnopp element (``synthetic.literature``, its own RK4 and
   stick band, share 1, breakaway 1.5 x sliding) as its band narrows, against
   sticking_friction + sticking_stribeck (v_break 1e-3 of the RMS velocity, delta 2).
3. Continuity: the log-likelihood of a record (the Coulomb case at 2 N, displacement noise
   1e-5 m) on grids of F_dry over 1.8-2.2 N: the largest step between neighbours, which halves
   with the spacing where the likelihood is continuous.

Run: ``.venv/bin/python benchmarks/bench_sticking_accuracy.py`` (about a minute).
"""

from __future__ import annotations

import numpy as np

from harvester.model.simulate import residual_sums, simulate
from harvester.model.structures import Layout
from harvester.synthetic import event_driven as ed
from harvester.synthetic import literature as lit

FS, M, C, K = 200.0, 1.0, 0.5, 400.0
SUBSTEPS = (4, 8, 16, 64)


def forcing(seconds: float, amplitude: float) -> np.ndarray:
    t = np.arange(int(seconds * FS) + 1) / FS
    return amplitude * np.sin(2 * np.pi * 1.5 * t) + 0.8 * np.sin(2 * np.pi * 4.1 * t + 0.3)


def against_reference() -> None:
    print("1. against the event-driven reference (max |z - z_ref| / max |z_ref|)")
    print(f"   {'law':34s} " + " ".join(f"{n:>8d}" for n in SUBSTEPS) + "   stuck (ref)")
    cases = [("Coulomb 2 N", ("sticking_friction",), [2.0], lambda s: 2.0 + 0 * s, 2.0, 2.2)]
    for vb in (1e-2, 1e-3, 1e-4):
        for de in (1.0, 2.0):
            cases.append((f"Stribeck v_b {vb:g} delta {de:g}",
                          ("sticking_friction", "sticking_stribeck"), [1.5, 1.0, vb, de],
                          lambda s, vb=vb, de=de: 1.5 + np.exp(-(s / vb) ** de), 2.5, 3.0))
    for name, terms, q, law, level, amp in cases:
        f = forcing(6.0, amp)
        ref = ed.simulate(ed.Oscillator(M, C, K, law, level), f, 1 / FS, 0.01)
        errs, stuck = [], 0.0
        for n in SUBSTEPS:
            sim = simulate(Layout.of(terms), [M, 1.0, K, C, *q], f, 1 / FS, n_substeps=n,
                           force_input=True)
            errs.append(np.max(np.abs(sim.rel_disp[0] - ref.x)) / np.max(np.abs(ref.x)))
            stuck = np.mean(sim.rel_vel[0] == 0.0)
        print(f"   {name:34s} " + " ".join(f"{e:8.1e}" for e in errs)
              + f"   {stuck:.4f} ({np.mean(ref.stuck):.4f})")


def against_karnopp() -> None:
    print("2. the literature generator's Karnopp element as its stick band narrows")
    dev, tb, y2, v_rms = ed.karnopp_drive(3)
    sim = simulate(Layout.of(["sticking_friction", "sticking_stribeck"]),
                   [dev.M, dev.m, dev.k, dev.c, dev.F_c, 0.5 * dev.F_c, 1e-3 * v_rms, 2.0],
                   y2[:2 * tb.n_int:2], tb.h_int)
    print(f"   device f_n {dev.f_n:.3g} Hz, M {dev.M:.3g} kg, F_c {dev.F_c:.3g} N; sticking "
          f"law stuck {np.mean(sim.rel_vel[0] == 0):.4f}")
    for share in (1e-2, 1e-3, 1e-4):
        p = dev.params()
        p[lit.E:lit.E + 3] = 1.0, 1.5, share * v_rms
        _, z, v = lit.simulate(lit.KARNOPP, p, y2, tb, 8)
        err = np.max(np.abs(sim.rel_disp[0] - z)) / np.max(np.abs(z))
        print(f"   band {share:g} x v_rms: Karnopp stuck (|v| < band) "
              f"{np.mean(np.abs(v) < p[lit.E + 2]):.4f}, max |dz| / max |z| {err:.1e}")


def continuity() -> None:
    print("3. log-likelihood on grids of F_dry (1.8-2.2 N): largest step between neighbours")
    f = forcing(6.0, 2.2)
    lay = Layout.of(["sticking_friction"])
    truth = simulate(lay, [M, 1.0, K, C, 2.0], f, 1 / FS, force_input=True).rel_disp[0]
    sigma = 1e-5
    obs = truth + sigma * np.random.default_rng(0).standard_normal(truth.size)
    for num in (41, 81, 161, 321):
        P = np.tile([M, 1.0, K, C, 0.0], (num, 1))
        P[:, 4] = np.linspace(1.8, 2.2, num)
        sse, _ = residual_sums(lay, P, f, 1 / FS, obs, (0, f.size), output_kind="rel_disp",
                               force_input=True)
        print(f"   {num:4d} points: {np.max(np.abs(np.diff(sse / (2 * sigma**2)))):.4g} nats")


if __name__ == "__main__":
    against_reference()
    against_karnopp()
    continuity()
