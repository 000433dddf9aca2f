"""The Bouc-Wen benchmark's generator (harvester.synthetic.bouc_wen_benchmark): its Newmark
integrator against a tight reference, the multisine as the benchmark designs it, and the
record set it writes."""

from __future__ import annotations

import ast
import json
from pathlib import Path

import numpy as np
import pytest
from harvester.synthetic import bouc_wen_benchmark as B

H = 1.0 / (B.FS * B.UPSAMPLE)


def _rms(x):
    return float(np.sqrt(np.mean(np.square(x))))


def test_newmark_against_a_tight_reference_at_second_order():
    """0.25 s from rest under the benchmark's 50 N multisine: Newmark at 15 kHz within 1e-3 of
    the response's RMS of DOP853 at rtol 1e-10 (below the benchmark's noise), and a halved
    step four times closer (second order)."""
    exc = B.draw_multisine(np.random.default_rng(1))
    n = int(0.25 / H) + 1
    t = np.arange(n) * H
    ref = B.reference_solution(exc, t[-1], t)
    y = B.newmark(exc.on_grid(n), H)[0]
    fine = B.newmark(exc.at(np.arange(2 * n - 1) * H / 2), H / 2)[0][::2]
    err, err_fine = _rms(y - ref), _rms(fine - ref)
    assert err < 1e-3 * _rms(ref)
    assert np.max(np.abs(y - ref)) < 0.1 * B.NOISE_SD_M
    assert 3.0 < err / err_fine < 5.0


def test_newmark_hysteresis_in_the_limits():
    """beta = 0: z = alpha y exactly (a linear spring k_L + alpha), against the same scheme's
    linear system; the loop in (y, z) encloses positive work (dissipates) otherwise."""
    exc = B.draw_multisine(np.random.default_rng(2))
    u = exc.on_grid(int(0.2 / H))
    y, _, z = B.newmark(u, H, {"beta": 0.0})
    assert np.max(np.abs(z - B.PARAMETERS["alpha"] * y)) < 1e-9 * np.max(np.abs(z))
    y, v, z = B.newmark(u, H)
    assert np.sum(z[1:] * np.diff(y)) > 0.0  # work done on the hysteretic element (J)


def test_multisine_is_the_benchmarks_design():
    """Lines every 750/8192 Hz from 5 to 150 Hz, RMS 50 N, the grid equal to the sum of
    cosines, periodic over 8192 output samples."""
    exc = B.draw_multisine(np.random.default_rng(0))
    f = exc.lines * B.FS / B.PERIOD
    assert f[0] <= B.F_MIN < f[0] + B.FS / B.PERIOD and f[-1] >= B.F_MAX > f[-2]
    u = exc.on_grid(2 * B.PERIOD * B.UPSAMPLE)
    assert _rms(u) == pytest.approx(B.RMS_N, rel=1e-9)
    idx = np.arange(0, u.size, 997)
    assert np.allclose(u[idx], exc.at(idx * H), atol=1e-9)
    assert np.allclose(u[: B.PERIOD * B.UPSAMPLE], u[B.PERIOD * B.UPSAMPLE:])


def test_record_set_member(tmp_path: Path):
    """The recording, sidecar and truth as a record set reads them; reproducible per seed."""
    from harvester.grid.peers import read_set
    made = B.generate(0, duration_s=3.0)
    again = B.generate(0, duration_s=3.0)
    assert np.array_equal(made.recording["rel_disp"], again.recording["rel_disp"])
    assert not np.array_equal(made.recording["rel_disp"],
                              B.generate(1, duration_s=3.0).recording["rel_disp"])
    made.write(tmp_path, "bw")
    rec, = read_set(tmp_path)
    assert list(rec.data.columns[:3]) == ["time", "force", "rel_disp"]
    assert rec.correct == {"hysteresis", "hysteretic_spring"} and not rec.effect_free
    assert rec.known == {"M": 2.0, "m": 2.0, "k": 1.0e5}
    truth = json.loads((tmp_path / "bw.json").read_text())
    noise = made.recording["rel_disp"].to_numpy() - made.clean
    assert _rms(noise) == pytest.approx(B.NOISE_SD_M, rel=0.1)
    assert truth["ratio"] > 10.0  # the hysteresis far above the noise


def test_imports_nothing_of_the_library():
    """A second statement of the physics: no import from harvester."""
    tree = ast.parse(Path(B.__file__).read_text())
    modules = [n.module or "" for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)]
    modules += [a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names]
    assert not [m for m in modules if m.startswith("harvester")]


def test_library_term_reproduces_the_benchmark():
    """The library's hysteretic_spring at the benchmark's values (k = k_L + alpha, k_bw =
    alpha, d_bw = 1 / (beta gamma), e_bw = delta / gamma), driven by the recorded 750 Hz force,
    follows the independent generator's y within its noise sd (0.90 x measured; the input
    interpolated between samples); its force along the simulated path is eq. (1)'s residual
    within 3 % (2.2 % measured: the path's velocity linear between 750 Hz samples)."""
    from harvester.model.simulate import simulate
    from harvester.model.structures import Layout
    from harvester.model.term_forces import term_force
    from harvester.model.terms import term
    p = B.PARAMETERS
    made = B.generate(0, duration_s=4.0)
    u = made.recording["force"].to_numpy()
    values = {"M": p["m_L"], "m": p["m_L"], "k": p["k_L"] + p["alpha"], "c_m": p["c_L"],
              "k_bw": p["alpha"], "d_bw": 1.0 / (p["beta"] * p["gamma"]),
              "e_bw": p["delta"] / p["gamma"]}
    lay = Layout.of(["hysteretic_spring"])
    sim = simulate(lay, [values[n] for n in lay.parameter_names], u, 1.0 / B.FS,
                   force_input=True)
    lead = int(B.FS)
    assert _rms((sim.rel_disp[0] - made.clean)[lead:]) < B.NOISE_SD_M
    f = term_force(term("hysteretic_spring"), values, sim.rel_disp, sim.rel_vel, sim.rel_acc,
                   np.zeros(u.size), 1.0 / B.FS)[0]
    residual = u - (values["M"] * sim.rel_acc[0] + values["c_m"] * sim.rel_vel[0]
                    + values["k"] * sim.rel_disp[0])
    assert _rms((f - residual)[lead:]) < 0.03 * _rms(residual[lead:])


def test_a_loop_nominates_the_hysteretic_spring():
    """A missing force read as a loop in (z, f) points to both places of the hysteresis
    family: the friction's (hysteresis) and the spring's (hysteretic_spring)."""
    from harvester.diagnosis.size.shapes import library_terms
    from harvester.model.terms import same_physics
    assert {"hysteresis", "hysteretic_spring"} <= set(library_terms("loop"))
    assert "hysteretic_spring" not in library_terms("friction")
    assert same_physics("hysteretic_spring", "hysteresis")
