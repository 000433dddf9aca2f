"""The literature-form generator (harvester.synthetic.literature): forms in their limits,
integrator convergence against a tight implicit reference, calibration, reproducibility, the
DAQ's anti-alias decimator and the files it writes."""

from __future__ import annotations

import ast
import itertools
import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml
from harvester.synthetic import literature as L
from scipy.integrate import solve_ivp

LIBRARY_TERMS = {"coulomb_friction", "tanh_friction", "stribeck_friction", "asymmetric_friction",
                 "quadratic_damping", "cubic_stiffness", "end_stop", "backlash", "hysteresis",
                 "unmodelled_mode", "inertia_error", "offset_force", "sticking_friction",
                 "sticking_stribeck", "ground_friction", "hysteretic_spring"}
NOISE = 0.09
FS = 256.0

#: A fixed, moderate device for the reference comparisons (2 Hz, friction 20 % of m max|y''|).
DEVICE = L.Device(M=2.0, m=1.5, k=2.0 * (2 * np.pi * 2.0) ** 2, c=2 * 0.03 * np.sqrt(
    2.0 * (2 * np.pi * 2.0) ** 2 * 2.0), F_c=1.2, v_t=0.01, friction_form="tanh",
    transition_ratio=0.1, f_n=2.0, zeta=0.03, peak_base_acc=4.0)


def _setup(duration_s: float = 2.0, device: L.Device = DEVICE, seed: int = 3):
    """(time base, run, context) of a short record of ``device``."""
    tb = L.TimeBase(FS, round(duration_s * FS))
    exc = L.draw_excitation(np.random.default_rng(seed), device, tb.period, duration_s, FS)
    run = L._Run(exc, tb)
    _, _, z, v = run.output(L.NONE, device.params(), 2, internal=True)
    return tb, run, L.Context.of(device, FS, z, v, L._internal_window(tb))


def _output(run, tb, kind, p, n_sub=2):
    return run.output(kind, p, n_sub)


# --------------------------------------------------------------------------- registry

def test_registry_names_families_and_citations():
    families = {}
    for name, scen in L.SCENARIOS.items():
        assert scen.name == name and scen.citation and scen.form and scen.description
        assert set(scen.correct_names) <= LIBRARY_TERMS
        assert set(scen.related_names) <= LIBRARY_TERMS
        assert not set(scen.correct_names) & set(scen.related_names)
        families.setdefault(scen.family, []).append(name)
    counts = {f: len(v) for f, v in families.items()}
    assert counts["pre-sliding friction with memory"] == 4
    assert counts["stiction/breakaway"] == 3
    assert counts["end stop contact"] == 3
    assert counts["hardening spring"] == 2
    assert counts["flexible mount / secondary mode"] == 2
    assert counts["mass error"] == 2
    assert counts["fluid damping"] == 2
    assert counts["direction-dependent friction"] == 1
    assert L.SCENARIOS["none"].correct_names == ()


def test_module_stands_alone():
    tree = ast.parse(Path(L.__file__).read_text())
    imported = {a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names}
    imported |= {n.module for n in ast.walk(tree) if isinstance(n, ast.ImportFrom) and n.module}
    assert not any(m.split(".")[0] == "harvester" for m in imported)


# --------------------------------------------------------------------------- forms in their limits

def test_every_effect_at_zero_strength_is_the_baseline():
    tb, run, ctx = _setup()
    base = _output(run, tb, L.NONE, DEVICE.params())
    rng = np.random.default_rng(0)
    for name, scen in L.SCENARIOS.items():
        if name == "none" or scen.family in ("end stop contact", "backlash",
                                              "flexible mount / secondary mode"):
            continue  # a rigid mount / massless mode / grazing stop / contact: tested apart
        kind, p = L.effect_params(DEVICE, scen.effect(ctx, scen.draw_shape(rng, ctx), 0.0))
        out = _output(run, tb, kind, p)
        # equal up to the finer sub-steps taken near a stop or the stick band
        assert np.max(np.abs(out - base)) < 1e-7, name


def test_maxwell_slip_elements_hold_then_slip_at_their_levels():
    """Iwan's elements on a prescribed z: inside D_1 a spring (no loop), far beyond D_2 the
    whole level s F_c, never more; the loop's width at z = 0 is the elements' level."""
    p = np.zeros(L.E + 4)
    p[L._FC] = 2.0
    p[L.E:L.E + 4] = [0.5, 0.4, 1e-6, 5e-6]  # s, a, D_1, D_2: levels 0.4 and 0.6 N

    def forces(amplitude):
        x = np.zeros(5)
        out = []
        for z in amplitude * np.sin(np.linspace(0.0, 4 * np.pi, 4001)):
            x[0] = z
            L._play(p, x)
            out.append(L._slip_force(p, z, x[2], x[3]))
        return np.array(out)
    small = forces(0.5e-6)
    stiffness = 0.4 / 1e-6 + 0.6 / 5e-6
    z = 0.5e-6 * np.sin(np.linspace(0.0, 4 * np.pi, 4001))
    assert np.allclose(small, stiffness * z, rtol=1e-12, atol=1e-15)  # elastic, no loop
    large = forces(1e-4)
    assert np.max(np.abs(large)) == pytest.approx(1.0, rel=1e-12)  # s F_c, never more
    crossing = large[np.argmin(np.abs(z[2000:] / 0.5e-6 * 1e-4)) + 2000]
    assert abs(crossing) == pytest.approx(1.0, rel=1e-3)  # both elements slipping at z = 0


def test_mode_and_mount_vanish_with_their_strength():
    tb, run, ctx = _setup()
    base = _output(run, tb, L.NONE, DEVICE.params())
    win = tb.window
    for name in ("secondary_mode", "flexible_mount"):
        scen = L.SCENARIOS[name]
        shape = scen.draw_shape(np.random.default_rng(1), ctx)
        lo, _ = scen.bounds(ctx, shape)
        small = lo if name == "flexible_mount" else 1e-6
        rms = [L._rms((_output(run, tb, *L.effect_params(DEVICE, scen.effect(
            ctx, shape, s))) - base)[win]) for s in (small, small / 4)]
        assert rms[1] < 0.3 * rms[0], name  # shrinks with the strength (linearly or faster)


def test_stiff_bristles_slide_like_coulomb_after_a_presliding_distance():
    """LuGre, Dahl (alpha 1) and Bouc-Wen (n 1): driven at constant velocity from rest, the
    friction reaches 99 % of F_c within 10 F_c / stiffness, i.e. Coulomb sliding as the
    stiffness grows (Canudas de Wit et al. 1995; Dahl 1968)."""
    v, f_c = 0.01, DEVICE.F_c
    for stiffness in (1e3, 1e6):
        for kind, extra in ((L.LUGRE, [0.0]), (L.DAHL, [1.0]), (L.BOUC_WEN, [1.0, 1.0, 0.0])):
            p = DEVICE.params()
            p[L.E: L.E + 2 + len(extra)] = [1.0, stiffness, *extra]
            x = np.array([0.0, v, 0.0, 0.0, 0.0])
            steps = 200
            h = 10.0 * f_c / stiffness / v / steps
            for _ in range(steps):
                L._relax(kind, p, x, h)
            force = L._memory_force(kind, p, v, x[2])
            assert 0.99 * f_c < force <= 1.0001 * f_c, (kind, stiffness, force)


def test_stop_with_gap_beyond_the_motion_does_nothing():
    tb, run, ctx = _setup()
    base = _output(run, tb, L.NONE, DEVICE.params())
    for kind, values in ((L.STOP_POWER, [1e7, 1.5, 0.0, 2 * ctx.z_max, 1e-3]),
                         (L.STOP_KV, [1e7, 1.0, 100.0, 2 * ctx.z_max])):
        p = DEVICE.params()
        p[L.E: L.E + len(values)] = values
        np.testing.assert_array_equal(_output(run, tb, kind, p), base)


def test_karnopp_sticks_below_breakaway_and_slides_above():
    """A constant base acceleration a0 after a 0.1 s ramp: Karnopp's element (breakaway
    1.5 F_c = 1.8 N) holds the mass while m a0 < 1.8 N; the tanh law alone lets it creep."""
    tb = L.TimeBase(FS, 256)
    t = np.arange(2 * tb.n_int + 8) * tb.h_int / 2
    ramp = np.clip(t / 0.1, 0.0, 1.0)
    p = DEVICE.params()
    p[L.E: L.E + 3] = [1.0, 1.5, 1e-3]
    moved = {}
    for a0 in (0.8, 1.6):  # m a0 = 1.2 N (below), 2.4 N (above)
        for kind in (L.KARNOPP, L.NONE):
            _, z, _ = L.simulate(kind, p, a0 * ramp, tb, 4)
            moved[a0, kind] = np.max(np.abs(z))
    assert moved[0.8, L.KARNOPP] == 0.0
    assert moved[0.8, L.NONE] > 1e-3
    assert moved[1.6, L.KARNOPP] > 1e-3


def test_stribeck_and_asymmetric_force_laws():
    p = DEVICE.params()
    for delta in (1.0, 2.0):
        p[L.E: L.E + 3] = [0.5, 0.02, delta]
        f = L._friction(L.STRIBECK, p, 0.02, 0.0, 0.0)
        assert f == pytest.approx(DEVICE.F_c * np.tanh(2.0) * (1 + 0.5 * np.exp(-1.0)))
        assert L._friction(L.STRIBECK, p, 5.0, 0.0, 0.0) == pytest.approx(DEVICE.F_c, rel=1e-9)
    p[L.E: L.E + 2] = [0.3, 0.005]
    assert L._friction(L.ASYMMETRIC, p, 2.0, 0.0, 0.0) == pytest.approx(1.3 * DEVICE.F_c)
    assert L._friction(L.ASYMMETRIC, p, -2.0, 0.0, 0.0) == pytest.approx(-0.7 * DEVICE.F_c)


# --------------------------------------------------------------------------- integrator

def _reference(kind, p, tb, run, t_end):
    """z'' at the internal samples up to t_end by Radau (rtol 1e-10) on the full ODE, the
    memory variable integrated as an ordinary state and the input summed exactly."""
    memory = L.LUGRE <= kind <= L.BOUC_WEN
    exc = run.excitation

    ground = kind == L.GROUND_FRICTION  # x[4], the base velocity, is a state of its own

    def f(t, x):
        xx, dx = (x.copy() if ground else np.append(x, p[L._VREF])), np.zeros(5)
        L._rhs(kind, p, xx, float(exc.at(t)[0]), dx)
        if memory:
            rate_p, rate_q = L._memory_rates(kind, p, x[1], x[2])
            dx[2] = rate_p - rate_q * x[2]
        return dx if ground else dx[:4]

    times = np.arange(int(t_end / tb.h_int)) * tb.h_int
    start = np.append(np.zeros(4), p[L._VREF]) if ground else np.zeros(4)
    sol = solve_ivp(f, (0.0, times[-1]), start, method="Radau", t_eval=times,
                    rtol=1e-10, atol=1e-13)
    assert sol.success
    dx = np.zeros(5)
    states = sol.y if ground else np.vstack([sol.y, np.full(times.size, p[L._VREF])])
    return np.array([L._rhs(kind, p, states[:, i], float(exc.at(t)[0]), dx)
                     for i, t in enumerate(times)])


def _convergence(kind, values, t_end=1.0):
    """RMS z'' error against the reference at 1, 2, 4, 8 sub-steps, and the sub-step count
    the generator's criterion accepts (halving changes the output by <= CONVERGENCE_TOL x
    the noise)."""
    tb, run, _ = _setup()
    p = DEVICE.params()
    p[L.E: L.E + len(values)] = values
    ref = _reference(kind, p, tb, run, t_end)
    accs = [L.simulate(kind, p, run.grid, tb, n)[0][: ref.size] for n in (1, 2, 4, 8)]
    errs = [L._rms(acc - ref) for acc in accs]
    changes = [L._rms(b - a) for a, b in itertools.pairwise(accs)]
    accepted = next(i for i, c in enumerate(changes + [0.0]) if c <= L.CONVERGENCE_TOL * NOISE)
    return errs, accepted


@pytest.mark.parametrize("kind,values", [
    (L.NONE, []),
    (L.LUGRE, [0.5, 1e4, 2 * 0.5 * np.sqrt(1e4 * 2.0)]),
    (L.GROUND_FRICTION, [0.6]),
    (L.SPRING_DEAD_ZONE, [2e-3]),
])
def test_integrator_converges_to_the_radau_reference(kind, values):
    """Errors shrink under step halving (RK4; the memory laws' splitting is ~2nd order) and
    the accepted step's error is within twice the criterion (first order's worst case)."""
    errs, accepted = _convergence(kind, values)
    assert errs[accepted] <= 2 * L.CONVERGENCE_TOL * NOISE, (errs, accepted)
    assert all(b < a for a, b in itertools.pairwise(errs)) or errs[0] < 1e-6 * NOISE, errs


@pytest.mark.slow
@pytest.mark.parametrize("kind,values", [
    (L.DAHL, [0.7, 3e4, 1.5]),
    (L.BOUC_WEN, [0.7, 3e4, 2.0, 0.7, 0.3]),
    (L.STRIBECK, [1.0, 0.02, 2.0]),
    (L.STOP_POWER, [1e6, 1.5, 0.0, 0.01, 1e-3]),
    (L.SPRING_POWER, [5e4, 3.0]),
    (L.DAMP_POWER, [20.0, 2.0]),
    (L.MOUNT, [3.0, 3.0 * (2 * np.pi * 12.0) ** 2, 2 * 0.05 * 3.0 * 2 * np.pi * 12.0]),
    (L.SECONDARY, [0.3, 0.3 * (2 * np.pi * 9.0) ** 2, 2 * 0.02 * 0.3 * 2 * np.pi * 9.0]),
])
def test_integrator_converges_for_every_smooth_form(kind, values):
    errs, accepted = _convergence(kind, values)
    assert errs[accepted] <= 2 * L.CONVERGENCE_TOL * NOISE, (errs, accepted)
    assert errs[-1] < errs[0], errs


def test_karnopp_converges_under_step_halving():
    """Karnopp's force jumps at its stick band: the change under step halving shrinks."""
    _, run, _ = _setup()
    p = DEVICE.params()
    p[L.E: L.E + 3] = [1.0, 1.5, 5e-3]
    outs = [run.output(L.KARNOPP, p, n) for n in (1, 2, 4, 8)]
    changes = [L._rms(b - a) for a, b in itertools.pairwise(outs)]
    assert changes[-1] < 0.3 * changes[0] and changes[-1] < 1e-2 * NOISE, changes


# --------------------------------------------------------------------------- acquisition

def test_fir_decimator_passes_the_band_and_rejects_above_nyquist():
    q, n_out = L.OVERSAMPLE, 2048
    h = L.anti_alias_fir(q)
    delay = (h.size - 1) // 2
    t = np.arange((n_out - 1) * q + delay + 1) / (q * FS)
    keep = slice(delay // q + 1, n_out - 1)
    for f in (1.0, 30.0, 0.25 * FS, L.PASSBAND * FS):
        out = L.daq(np.sin(2 * np.pi * f * t + 0.3), n_out)
        expected = np.sin(2 * np.pi * f * t[:: q][:n_out] + 0.3)
        assert np.max(np.abs(out - expected)[keep]) < 1e-4, f
    for f in (L.STOPBAND * FS, 0.6 * FS, FS, 2.3 * FS, 3.9 * FS):
        out = L.daq(np.sin(2 * np.pi * f * t), n_out)
        assert np.max(np.abs(out[keep])) < 1e-3, f  # > 60 dB down


def test_sensor_noise_has_its_rms():
    noise = L.sensor_noise(np.random.default_rng(0), 0.05, 20000)
    assert L._rms(noise) == pytest.approx(0.05, rel=0.03)


# --------------------------------------------------------------------------- generation

def test_effect_free_recording_is_the_baseline_plus_noise():
    g = L.generate("none", 4, duration_s=6.0)
    assert np.all(g.contribution == 0.0)
    np.testing.assert_array_equal(g.clean_rel_acc, g.baseline_rel_acc)
    noise = g.recording["rel_acc"].to_numpy() - g.clean_rel_acc
    assert L._rms(noise[256:]) == pytest.approx(g.truth["noise_rms_rel_acc"], rel=1e-9)
    assert g.truth["noise_rms_rel_acc"] == pytest.approx(NOISE, rel=0.1)
    assert g.truth["ratio_achieved"] == 0.0 and g.truth["effect"]["strength"] is None


@pytest.mark.parametrize("name,ratio", [("lugre", 0.5), ("end_stop_linear", 1.5),
                                        ("payload_error", 0.5), ("karnopp", 0.8)])
def test_calibration_reaches_the_ratio(name, ratio):
    g = L.generate(name, 11, ratio=ratio, duration_s=8.0)
    achieved = L._rms(g.contribution[256:]) / g.truth["noise_rms_rel_acc"]
    assert achieved == pytest.approx(ratio, rel=0.01)
    assert g.truth["ratio_achieved"] == pytest.approx(achieved, rel=1e-12)
    assert 0.0 <= g.truth["unabsorbed_to_noise"] <= achieved + 1e-12
    assert g.truth["peak_to_noise"] >= achieved
    tol = L.KARNOPP_CONVERGENCE_TOL if name == "karnopp" else L.CONVERGENCE_TOL
    assert g.truth["integration"]["step_halving_change_to_noise"] <= tol
    np.testing.assert_allclose(g.clean_rel_acc - g.baseline_rel_acc, g.contribution)


def test_the_recorded_input_contribution_is_the_effect_a_model_driven_by_the_record_makes():
    # the effect as a model driven by the recorded base acceleration makes it: the true
    # excitation's contribution plus a part that grows with the recording error (a
    # Duffing spring: 0.07 % of it at 1e-3 m/s^2 of noise, 6 % at the grid's 0.09)
    def moved(g):
        return L._rms((g.input_contribution - g.contribution)[256:]) / L._rms(
            g.contribution[256:])

    quiet = L.generate("duffing", 5, duration_s=6.0, noise_rel_acc=1e-3, ratio=45.0)
    loud = L.generate("duffing", 5, duration_s=6.0)
    assert moved(quiet) < 2e-3
    assert 30.0 < moved(loud) / moved(quiet) < 300.0  # ~ the 90x of the noise
    assert loud.truth["input_driven_to_clean_contribution"] == pytest.approx(moved(loud))


def test_same_seed_same_recording_other_seed_other_device():
    a, b = (L.generate("stribeck_gaussian", 7, duration_s=6.0) for _ in range(2))
    pd.testing.assert_frame_equal(a.recording, b.recording, check_exact=True)
    assert json.dumps(a.truth) == json.dumps(b.truth)
    c = L.generate("stribeck_gaussian", 8, duration_s=6.0)
    assert c.truth["device"] != a.truth["device"]


def _project_reader():
    """The project's reader of converted recordings (moved between releases)."""
    import importlib

    for module in ("harvester.data.daq", "harvester.daq"):
        try:
            return importlib.import_module(module).read_recording
        except ModuleNotFoundError:
            continue
    pytest.skip("the project's read_recording is not importable")


def test_files_are_written_atomically_and_read_back(tmp_path, monkeypatch):
    read_recording = _project_reader()
    g = L.generate("duffing", 2, duration_s=6.0, lsb=1e-3)
    paths = g.write(tmp_path)
    df = read_recording(paths["recording"])
    pd.testing.assert_frame_equal(df, pd.read_csv(paths["recording"]))
    assert list(df.columns) == ["time", "base_acc", "rel_acc"]
    np.testing.assert_allclose(df.to_numpy(), g.recording.to_numpy(), rtol=1e-9, atol=1e-12)
    assert df["time"].iloc[0] == 0.0 and np.allclose(np.diff(df["time"]), 1 / FS)
    steps = df["base_acc"].to_numpy() / 1e-3
    assert np.allclose(steps, np.round(steps), atol=1e-6)  # quantised
    assert yaml.safe_load(paths["sidecar"].read_text()) == g.sidecar
    assert json.loads(paths["truth"].read_text())["scenario"] == "duffing"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["recording.csv", "recording.yaml",
                                                          "truth.json"]
    before = paths["truth"].read_text()

    def fail(*args):
        raise OSError("disk full")

    monkeypatch.setattr(L.os, "replace", fail)
    g.truth["scenario"] = "changed"
    with pytest.raises(OSError):
        g.write(tmp_path)
    assert paths["truth"].read_text() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["recording.csv", "recording.yaml",
                                                          "truth.json"]


def test_unknown_scenario_is_named():
    with pytest.raises(ValueError, match="unknown scenario"):
        L.generate("coulomb", 0)


@pytest.mark.slow
def test_every_scenario_generates_at_its_ratio():
    for name in L.SCENARIOS:
        g = L.generate(name, 21, duration_s=10.0)
        target = 0.0 if name == "none" else 0.5
        assert g.truth["ratio_achieved"] == pytest.approx(target, rel=0.01, abs=1e-12), name
        assert g.truth["integration"]["step_halving_change_to_noise"] <= (
            L.KARNOPP_CONVERGENCE_TOL if name == "karnopp" else L.CONVERGENCE_TOL), name
        json.dumps(g.truth)


@pytest.mark.slow
def test_a_40_s_record_generates_in_seconds():
    import time

    start = time.perf_counter()
    g = L.generate("lugre", 0)
    assert len(g.recording) == 40 * 256
    assert time.perf_counter() - start < 30.0


# --------------------------------------------------------------------------- forms outside the library

OUTSIDE = ("cogging", "quadratic_spring", "friction_drift", "mains_hum")


def test_forms_outside_the_library_have_no_correct_name_and_a_citation():
    for name in OUTSIDE:
        scen = L.SCENARIOS[name]
        assert scen.correct_names == () and scen.citation and scen.shapes, name
    # appended after the effect-free scenario, and Maxwell-slip after them: the grid's earlier
    # scenarios keep their places
    names = list(L.SCENARIOS)
    at = names.index("none")
    assert names[at:at + len(OUTSIDE) + 2] == ["none", *OUTSIDE, "maxwell_slip"]


def _shape_and_effect(name, strength, seed=0):
    _, _, ctx = _setup()
    scen = L.SCENARIOS[name]
    shape = scen.draw_shape(np.random.default_rng(seed), ctx)
    return ctx, shape, L.effect_params(DEVICE, scen.effect(ctx, shape, strength))


def test_cogging_is_periodic_in_z_with_its_drawn_period():
    for seed in range(5):
        ctx, shape, (kind, p) = _shape_and_effect("cogging", 0.1, seed)
        period = p[L.E + 1]
        assert 2.0 <= 4.0 * ctx.z_rms / period <= 6.0  # 2-6 periods over +-2 z_rms
        z = np.linspace(-2 * ctx.z_rms, 2 * ctx.z_rms, 41)
        force = np.array([L._extra_force(kind, p, x, 0.3, 0.0) for x in z])
        shifted = np.array([L._extra_force(kind, p, x + period, -0.1, 0.0) for x in z])
        amplitude = 0.1 * DEVICE.m * DEVICE.peak_base_acc
        np.testing.assert_allclose(force, amplitude * np.sin(2 * np.pi * z / period
                                                             + shape["phase_rad"]), atol=1e-12)
        np.testing.assert_allclose(shifted, force, atol=1e-9 * amplitude)


def test_quadratic_spring_is_even_in_z():
    ctx, shape, (kind, p) = _shape_and_effect("quadratic_spring", 0.2)
    k2 = shape["sign"] * 0.2 * DEVICE.k / ctx.z_max
    for z in (1e-4, 3e-3, ctx.z_max):
        assert L._extra_force(kind, p, z, 0.1, 0.0) == pytest.approx(k2 * z * z, rel=1e-12)
        assert L._extra_force(kind, p, -z, -0.2, 0.0) == L._extra_force(kind, p, z, 0.1, 0.0)


def test_friction_drift_changes_the_level_linearly_over_the_record():
    """The friction's level is F_c (1 + sign s (t - T/2) / T): its ratio to the device's
    friction at equal velocity is that line; the state x[4] runs as the time."""
    ctx, shape, (kind, p) = _shape_and_effect("friction_drift", 0.6)
    T = ctx.record_s
    assert T == pytest.approx(2.0 - 1 / FS)
    rest = np.zeros(5)
    for t in (0.0, 0.5 * T, T):
        x = np.array([0.0, 0.02, 0.0, 0.0, t])
        viscous = -DEVICE.c * x[1]  # the other forces at z = 0, y'' = 0
        drifted = viscous - L._rhs(kind, p, x, 0.0, rest) * DEVICE.M
        assert rest[4] == 1.0
        plain = viscous - L._rhs(L.NONE, DEVICE.params(), x, 0.0, rest) * DEVICE.M
        assert drifted / plain == pytest.approx(1 + shape["sign"] * 0.6 * (t / T - 0.5))
    assert p[L._VREF] == 0.0  # x[4] starts at t = 0


def test_mains_hum_is_a_line_on_the_mass_channel_only():
    g = L.generate("mains_hum", 3, ratio=1.0, duration_s=6.0)
    par = g.truth["effect"]["parameters"]
    assert par["frequency_hz"] in L.MAINS_HZ
    t = g.recording["time"].to_numpy()
    line = par["amplitude_m_per_s2"] * np.sin(2 * np.pi * par["frequency_hz"] * t
                                               + par["phase_rad"])
    win = slice(256, None)
    np.testing.assert_allclose(g.contribution[win], line[win], atol=1e-4 * NOISE)
    # the amplitude is the ratio's: RMS A / sqrt(2) = ratio x noise RMS
    assert par["amplitude_m_per_s2"] / np.sqrt(2) == pytest.approx(
        g.truth["noise_rms_rel_acc"], rel=0.01)


@pytest.mark.parametrize("name", OUTSIDE)
def test_forms_outside_the_library_reach_their_ratio(name):
    g = L.generate(name, 11, ratio=1.0, duration_s=8.0)
    achieved = L._rms(g.contribution[256:]) / g.truth["noise_rms_rel_acc"]
    assert achieved == pytest.approx(1.0, rel=L.CALIBRATION_RTOL)
    assert g.truth["correct_names"] == []
    assert g.truth["integration"]["step_halving_change_to_noise"] <= L.CONVERGENCE_TOL
    json.dumps(g.truth)


@pytest.mark.slow
def test_a_cogging_record_is_described_periodic_in_z_with_its_period(tmp_path):
    """The literature grid's cogging record (seed 1 with the grid's seed, ratio 1, 40 s): the
    missing force of the diagnosis's tanh baseline (its posterior under the diagnosis's
    likelihood, over the analysed window) is periodic in z at the drawn period within 10 %
    (measured 6.78 mm for 6.78 mm). Seed 0's period (0.10 mm) lies below the displacement's
    uncertainty from z'' (0.11 mm) and is not seen."""
    from harvester.diagnosis.prepare.analysis import prepare, start_baseline
    from harvester.inference.map_fit import baseline_state
    from harvester.diagnosis.size.missing_force import missing_force
    from harvester.diagnosis.prepare.settings import DiagnosisSettings
    from harvester.initial.recording import diagnosis_priors

    g = L.generate("cogging", 1 + 20260501, ratio=1.0, duration_s=40.0)
    rec, settings = g.recording, DiagnosisSettings(figures=False)
    priors, _ = diagnosis_priors(rec, "tanh", g.sidecar)
    a = prepare(rec, None, "tanh", g.sidecar, settings, "<cogging>")
    start = start_baseline(a, priors, None, settings)
    state = baseline_state(a.chain(start.detection_problem, start.temper, structure=a.structure),
                           start.samples)
    desc = missing_force(state, (a.lead, a.hold)).description
    assert desc.best.name == "periodic in z"
    assert desc.best.parameters["period_m"] == pytest.approx(
        g.truth["effect"]["parameters"]["period_m"], rel=0.1)


def test_the_missing_force_is_the_effects_own_force_along_the_true_path():
    """missing_force_truth: zero for the device alone (the equation of motion closes to
    rounding); a spring even in z added to it: the RMS, mean and RMS about the mean of that
    spring's own force along the path the record was made of; a mass error: dM z'' + dm y''."""
    from types import SimpleNamespace
    tb, run, ctx = _setup(4.0)
    window = L._internal_window(tb)
    none = SimpleNamespace(kind=L.NONE, p=DEVICE.params(), n_sub=2, context=ctx)
    assert L.missing_force_truth(run, none)["missing_force_rms_N"] < (
        1e-9 * DEVICE.m * DEVICE.peak_base_acc)
    _, _, (kind, p) = _shape_and_effect("quadratic_spring", 0.2)
    _, _, z, v = run.output(kind, p, 2, internal=True)
    own = np.array([L._extra_force(kind, p, a, b, 0.0) for a, b in zip(z, v)])[window]
    spring = L.missing_force_truth(run, SimpleNamespace(kind=kind, p=p, n_sub=2, context=ctx))
    assert spring["missing_force_rms_N"] == pytest.approx(np.sqrt(np.mean(own**2)), rel=1e-9)
    assert spring["missing_force_mean_N"] == pytest.approx(np.mean(own), rel=1e-9)
    assert spring["missing_force_varying_rms_N"] == pytest.approx(np.std(own), rel=1e-9)
    assert abs(spring["missing_force_mean_N"]) > 0.1 * spring["missing_force_rms_N"]  # even
    heavier = DEVICE.params(M=DEVICE.M + 0.3, m=DEVICE.m + 0.2)
    _, acc, _, _ = run.output(L.NONE, heavier, 2, internal=True)
    own = (0.3 * acc + 0.2 * run.base_internal())[window]
    mass = SimpleNamespace(kind=L.NONE, p=heavier, n_sub=2, context=ctx)
    assert L.missing_force_truth(run, mass)["missing_force_rms_N"] == pytest.approx(
        np.sqrt(np.mean(own**2)), rel=1e-9)


def test_the_input_noise_can_be_the_recordings_own():
    """Without shared input noise the base channel is the DAQ's clean base (the shared
    record's base less the base sensor's noise), rel_acc keeps its noise level, and the
    device, effect and missing force are the same."""
    shared = L.generate("payload_error", 6, duration_s=6.0)
    own = L.generate("payload_error", 6, duration_s=6.0, shared_input_noise=False)
    assert shared.truth["shared_input_noise"] and not own.truth["shared_input_noise"]
    assert own.truth["device"] == shared.truth["device"]
    assert own.truth["missing_force_rms_N"] == pytest.approx(
        shared.truth["missing_force_rms_N"], rel=0.02)
    base_noise = (shared.recording.base_acc - own.recording.base_acc).to_numpy()
    assert np.sqrt(np.mean(base_noise ** 2)) == pytest.approx(NOISE / np.sqrt(2.0), rel=0.1)
    # rel_acc's noise: the same level, and no longer the negative of the base sensor's
    rel_noise = (own.recording.rel_acc - own.clean_rel_acc).to_numpy()
    assert np.sqrt(np.mean(rel_noise ** 2)) == pytest.approx(NOISE, rel=0.1)
    assert abs(np.corrcoef(rel_noise, base_noise)[0, 1]) < 0.1
    shared_noise = (shared.recording.rel_acc - shared.clean_rel_acc).to_numpy()
    assert np.corrcoef(shared_noise, base_noise)[0, 1] < -0.6


# --------------------------------------------------------------------------- recording kinds

#: base_acc -> rel_acc records of the code before the recording kinds were added (seed 0, 6 s):
#: samples 300, 900, 1400 of base_acc and rel_acc, to the CSV's 10 digits.
DEFAULT_KIND_SAMPLES = {
    "karnopp": ([-1.95477209871, 0.328763643106, -3.40808783658],
                [4.05951833655, -0.660854962993, 3.32710127204]),
    "none": ([1.53388276967, -0.334465717394, 0.030945919602],
             [-2.6513424038, -0.364115839082, -0.0605895895612]),
}


@pytest.mark.parametrize("name", sorted(DEFAULT_KIND_SAMPLES))
def test_the_default_kind_records_what_it_recorded_before(name):
    g = L.generate(name, 0, duration_s=6.0)
    assert list(g.recording.columns) == ["time", "base_acc", "rel_acc"]
    base, rel = DEFAULT_KIND_SAMPLES[name]
    np.testing.assert_allclose(g.recording["base_acc"].to_numpy()[[300, 900, 1400]], base,
                               rtol=1e-9)
    np.testing.assert_allclose(g.recording["rel_acc"].to_numpy()[[300, 900, 1400]], rel,
                               rtol=1e-9)
    assert "recording_kind" not in g.truth


def test_the_base_motion_is_the_double_integral_of_the_input_without_a_trend():
    tb, run, _ = _setup(4.0)
    v, y = run.base_motion
    h = tb.h_int
    inner = slice(8, -8)
    acc = np.gradient(np.gradient(y, h), h)
    np.testing.assert_allclose(acc[inner], run.base_internal()[inner], atol=2e-3 * np.std(
        run.base_internal()))
    np.testing.assert_allclose(np.gradient(y, h)[inner], v[inner], atol=1e-3 * np.std(v))
    record = slice(0, (tb.n_out - 1) * L.OVERSAMPLE + 1)
    t = h * np.arange(y.size)
    slope = np.polyfit(t[record], y[record], 1)[0]
    assert abs(slope) * t[record][-1] < 1e-4 * np.std(y[record])


def _quiet(name, kind, seed=5):
    return L.generate(name, seed, duration_s=6.0, kind=kind, noise_scale=1e-6)


def test_the_kinds_record_one_motion_through_their_own_channels():
    """One device and excitation per seed, whatever the kind: rel_acc is z'' of rel_disp, the
    base displacement's second derivative the base acceleration, and the force -m y''
    moves the mass (base fixed) as the base acceleration y'' moves it relative to the base."""
    dd, da, fd = (_quiet("none", k) for k in L.KINDS[1:])
    assert dd.sidecar == da.sidecar == fd.sidecar
    assert list(dd.recording.columns) == ["time", "base_disp", "rel_disp"]
    assert list(da.recording.columns) == ["time", "base_disp", "rel_acc"]
    assert list(fd.recording.columns) == ["time", "force", "rel_disp"]
    from harvester.data.kinds import derivative  # the diagnosis's own (band-limited)
    dt, inner = 1.0 / FS, slice(256, -256)
    z, acc = dd.recording["rel_disp"].to_numpy(), da.recording["rel_acc"].to_numpy()
    z2 = derivative(z, dt, 2, None)
    assert L._rms((z2 - acc)[inner]) < 1e-2 * L._rms(acc[inner])  # its low-pass: 0.45 %
    np.testing.assert_allclose(fd.recording["rel_disp"], dd.recording["rel_disp"],
                               atol=1e-5 * L._rms(z))
    y2 = derivative(dd.recording["base_disp"].to_numpy(), dt, 2, None)
    force = fd.recording["force"].to_numpy()
    assert L._rms((force + dd.sidecar["m"] * y2)[inner]) < 1e-2 * L._rms(force[inner])


@pytest.mark.parametrize("kind", L.KINDS[1:])
def test_each_channel_has_its_share_of_noise(kind):
    """In what the diagnosis takes of each channel (its own band-limited derivative:
    y'' of a base displacement, z' of a relative one)."""
    from harvester.data.kinds import derivative
    g = L.generate("none", 5, duration_s=6.0, kind=kind)
    quiet = _quiet("none", kind)
    inp, out = kind.split("->")
    inner = slice(256, -256)
    for col in (inp, out):
        order = L.NOISE_ORDER[col]  # order 0: the channel (derivative takes its end line off)
        noisy, clean = ((derivative(r.recording[col].to_numpy(), 1.0 / FS, order, None)
                         if order else r.recording[col].to_numpy())[inner] for r in (g, quiet))
        assert L._rms(noisy - clean) == pytest.approx(L.NOISE_SHARES[col] * L._rms(clean),
                                                      rel=0.15), col
    assert g.truth["noise_rms_output"] == pytest.approx(L._rms(
        (g.recording[out] - quiet.recording[out]).to_numpy()[256:]), rel=1e-3)
    assert g.truth["recording_kind"] == kind


NEW = ("spring_dead_zone", "backlash", "ground_friction")


@pytest.mark.parametrize("name,kind", [(n, k) for n in NEW for k in L.KINDS
                                       if not (n == "ground_friction" and k[0] == "f")])
def test_the_new_scenarios_reach_their_ratio_on_every_kind(name, kind):
    g = L.generate(name, 11, duration_s=6.0, kind=kind)
    noise = g.truth.get("noise_rms_output", g.truth.get("noise_rms_rel_acc"))
    achieved = L._rms(g.contribution[256:]) / noise
    assert achieved == pytest.approx(0.5, rel=0.01)
    assert g.truth["ratio_achieved"] == pytest.approx(achieved, rel=1e-12)
    assert g.truth["integration"]["step_halving_change_to_noise"] <= L.CONVERGENCE_TOL


def test_ground_friction_is_refused_with_a_force_input_and_an_unknown_kind_is_named():
    with pytest.raises(ValueError, match="the base is fixed"):
        L.generate("ground_friction", 0, duration_s=4.0, kind="force->rel_disp")
    with pytest.raises(ValueError, match="unknown recording kind"):
        L.generate("none", 0, duration_s=4.0, kind="force->rel_acc")
    with pytest.raises(ValueError, match="accelerometer pair"):
        L.generate("none", 0, duration_s=4.0, kind="base_disp->rel_disp", lsb=1e-3)


def test_the_spring_dead_zone_and_the_backlash_contact_are_dead_zones():
    """k z + the dead zone's extra force = k dz(z, g); the coupling is zero inside the gap,
    compressive only outside."""
    p = DEVICE.params()
    p[L.E] = 2e-3
    for z in (-5e-3, -1e-3, 0.0, 1.5e-3, 4e-3):
        dz = np.sign(z) * max(abs(z) - 2e-3, 0.0)
        assert DEVICE.k * z + L._extra_force(L.SPRING_DEAD_ZONE, p, z, 0.0, 0.0) == \
            pytest.approx(DEVICE.k * dz, abs=1e-12)
    p[L.E: L.E + 3] = [1e-3, 1e5, 10.0]
    assert L._contact(p, 0.9e-3, 5.0) == 0.0 and L._contact(p, -0.5e-3, -5.0) == 0.0
    assert L._contact(p, 2e-3, 0.0) == pytest.approx(1e5 * 1e-3)
    assert L._contact(p, 1.1e-3, -2.0) == 0.0  # separating faster than pressed: no pull


def test_backlash_without_a_gap_and_a_stiff_contact_is_the_one_body_device():
    tb, run, ctx = _setup()
    base = _output(run, tb, L.NONE, DEVICE.params())
    mu = DEVICE.m * (DEVICE.M - DEVICE.m) / DEVICE.M
    k_b = mu * (2 * np.pi * 400.0) ** 2
    p = DEVICE.params()
    p[L.E: L.E + 3] = [0.0, k_b, 2 * 0.7 * np.sqrt(k_b * mu)]
    out = _output(run, tb, L.BACKLASH, p, n_sub=8)
    assert L._rms(out - base) < 0.02 * L._rms(base)
    p[L.E] = 0.5 * ctx.z_rms  # a gap: the mass loses the screw side's inertia in it
    assert L._rms(_output(run, tb, L.BACKLASH, p, n_sub=8) - base) > 0.05 * L._rms(base)
