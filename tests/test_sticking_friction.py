"""Dry friction that sticks (``stick`` terms, ``harvester.model.stick``) against an
event-driven reference at tight tolerance (``harvester.synthetic.event_driven``), Marino and
Cicirello's simulated friction oscillator, the literature generator's Karnopp element, and the
continuity of the likelihood in the friction's level."""

from pathlib import Path

import numpy as np
import pytest

from harvester.model.simulate import residual_sums, simulate
from harvester.model.structures import Layout
from harvester.model.terms import TERMS, load_term_file
from harvester.synthetic import event_driven as ed

FS = 200.0
M, C, K = 1.0, 0.5, 400.0


def forcing(seconds: float, amplitude: float = 2.2) -> np.ndarray:
    """Two sines (N) at FS: long stick phases against a holding level of about 2 N."""
    t = np.arange(int(seconds * FS) + 1) / FS
    return amplitude * np.sin(2 * np.pi * 1.5 * t) + 0.8 * np.sin(2 * np.pi * 4.1 * t + 0.3)


def stuck_share(v: np.ndarray) -> float:
    return float(np.mean(v == 0.0))


def test_coulomb_holds_on_the_ground_as_the_reference():
    """Force input (friction on the absolute velocity, ``data.kinds.on_ground``'s form)."""
    f, F = forcing(6.0), 2.0
    ref = ed.simulate(ed.Oscillator(M, C, K, lambda s: F + 0.0 * s, F), f, 1 / FS, 0.01)
    sim = simulate(Layout.of(["sticking_friction"]), [M, 1.0, K, C, F], f, 1 / FS,
                   force_input=True)
    assert 0.3 < stuck_share(ref.v) < 0.6  # long stick phases
    assert stuck_share(sim.rel_vel[0]) == stuck_share(ref.v)
    assert np.max(np.abs(sim.rel_disp[0] - ref.x)) < 1e-6 * np.max(np.abs(ref.x))
    assert np.max(np.abs(sim.rel_acc[0] - ref.a)) < 1e-5 * np.max(np.abs(ref.a))
    stuck = sim.rel_vel[0] == 0.0  # held exactly, the force needed within the level
    assert np.all(np.abs(f[stuck] - K * sim.rel_disp[0][stuck]) <= F * (1 + 1e-9))


@pytest.mark.parametrize("delta", [1.0, 2.0])
def test_stribeck_sticks_on_the_base_as_the_reference(delta):
    """Base input (friction on the relative velocity): drive -m y'' as the reference's force."""
    m, F, Fb, vb = 0.8, 1.5, 1.0, 0.01
    y2 = forcing(6.0, 3.0) / m
    law = lambda s: F + Fb * np.exp(-(s / vb) ** delta)  # noqa: E731
    ref = ed.simulate(ed.Oscillator(M, C, K, law, F + Fb), -m * y2, 1 / FS, 0.01)
    sim = simulate(Layout.of(["sticking_friction", "sticking_stribeck"]),
                   [M, m, K, C, F, Fb, vb, delta], y2, 1 / FS)
    assert stuck_share(sim.rel_vel[0]) == stuck_share(ref.v) > 0.1
    assert np.max(np.abs(sim.rel_disp[0] - ref.x)) < 1e-4 * np.max(np.abs(ref.x))


def test_refining_the_step_converges_to_the_reference():
    f, F = forcing(4.0), 2.0
    ref = ed.simulate(ed.Oscillator(M, C, K, lambda s: F + 0.0 * s, F), f, 1 / FS, 0.01)
    lay = Layout.of(["sticking_friction"])
    err = [np.max(np.abs(simulate(lay, [M, 1.0, K, C, F], f, 1 / FS, n_substeps=n,
                                  force_input=True).rel_disp[0] - ref.x)) for n in (4, 8)]
    assert err[1] < err[0] < 1e-7


def test_likelihood_is_continuous_in_the_level():
    """On a fine grid of F_dry, the largest change of the log-likelihood between neighbours
    halves when the grid's spacing halves (Lipschitz): no jump where an event crosses a step."""
    f = forcing(6.0)
    lay = Layout.of(["sticking_friction"])
    truth = simulate(lay, [M, 1.0, K, C, 2.0], f, 1 / FS, force_input=True).rel_disp[0]
    sigma = 1e-5
    obs = truth + sigma * np.random.default_rng(0).standard_normal(truth.size)
    steps = []
    for num in (41, 81):
        P = np.tile([M, 1.0, K, C, 0.0], (num, 1))
        P[:, 4] = np.linspace(1.8, 2.2, num)
        sse, ok = residual_sums(lay, P, f, 1 / FS, obs, (0, f.size), output_kind="rel_disp",
                                force_input=True)
        assert ok.all()
        steps.append(np.max(np.abs(np.diff(-sse / (2 * sigma**2)))))
    assert 1.7 < steps[0] / steps[1] < 2.3


def test_batched_equals_one_at_a_time():
    f = forcing(2.0)
    lay = Layout.of(["sticking_friction", "sticking_stribeck"])
    P = np.tile([M, 1.0, K, C, 1.5, 0.5, 0.02, 1.5], (9, 1))
    P[:, 4] = np.linspace(0.0, 3.0, 9)
    batch = simulate(lay, P, f, 1 / FS, force_input=True)
    for i in range(9):
        one = simulate(lay, P[i], f, 1 / FS, force_input=True, n_substeps=batch.substeps[i])
        np.testing.assert_array_equal(batch.rel_disp[i], one.rel_disp[0])


def test_no_friction_is_the_linear_model():
    f = forcing(2.0)
    stick = simulate(Layout.of(["sticking_friction"]), [M, 1.0, K, C, 0.0], f, 1 / FS,
                     force_input=True, n_substeps=8)
    linear = simulate(Layout.of([]), [M, 1.0, K, C], f, 1 / FS, force_input=True, n_substeps=8)
    assert np.max(np.abs(stick.rel_disp[0] - linear.rel_disp[0])) < 1e-9 * np.std(linear.rel_disp)


def test_a_coupling_is_refused():
    with pytest.raises(ValueError, match="cannot hold"):
        simulate(Layout.of(["sticking_friction", "backlash"]),
                 [M, 1.0, K, C, 1.0] + [q.prior_on().mean for q in TERMS["backlash"].parameters],
                 forcing(1.0), 1 / FS)


RUINA = '''"""Steady-state Dieterich-Ruina friction that sticks (Marino and Cicirello's law).

Priors:

- F_r: reference level
- a_r: shape a
- b_r: shape b
- c_r: shape c
- V_r: reference velocity
"""
from harvester.model import fastmath as fm
from harvester.model.priors import Prior
from harvester.model.terms import Parameter, Probe, RateBound, Term

EPS = 1e-6


def force(speed, F_r, a_r, b_r, c_r, V_r):
    u = speed + EPS
    return F_r + a_r * fm.log(u / V_r) + b_r * fm.log(c_r + (V_r + EPS) / u)


def static(F_r, a_r, b_r, c_r, V_r):
    return F_r + a_r * fm.log(EPS / V_r) + b_r * fm.log(c_r + (V_r + EPS) / EPS)


TERM = Term(
    name="ruina_friction", kind="stick",
    parameters=tuple(Parameter(n, u, Prior("normal", 1.0, 1.0, lower=0.0), n)
                     for n, u in (("F_r", "N"), ("a_r", "N"), ("b_r", "N"), ("c_r", "-"),
                                  ("V_r", "m/s"))),
    equation="F_r + a log((v + eps) / V) + b log(c + (V + eps) / (v + eps))",
    description="Dieterich-Ruina friction that sticks", force=force, static=static,
    rate_bound=lambda p, m: RateBound(), probe=Probe("F_r", lambda d: 1.0), source=__file__)
'''


def marino_load(fs: float, seconds: float) -> np.ndarray:
    """The load of their ``switching_GPLFM_main.m`` (Simulated friction oscillator): a
    random-phase multisine on a JONSWAP spectrum (Hs 10, Tp 0.5 s, gamma 3.3), 0.02-100
    rad/s; the phases drawn by numpy's Mersenne Twister seeded 1 (MATLAB's rng(1) seeds
    the same generator; not checked against MATLAB)."""
    om = np.arange(1, 5001) * 0.02
    omp = 2 * np.pi / 0.5
    sig = np.where(om <= omp, 0.07, 0.09)
    spectrum = (5.058 * (1 - 0.287 * np.log(3.3)) * (10 / 0.5**2) ** 2 * 9.806**2 * om**-5
                * np.exp(-1.25 * (om / omp) ** -4)
                * 3.3 ** np.exp(-((om / omp - 1) / (sig * np.sqrt(2))) ** 2))
    amp = np.sqrt(2 * spectrum * 0.02)
    phase = 2 * np.pi * np.random.RandomState(1).rand(om.size)
    t = np.arange(int(seconds * fs) + 1) / fs
    return np.array([np.sum(amp * np.cos(om * tt + phase)) for tt in t])


@pytest.mark.slow
def test_marino_cicirello_friction_oscillator(tmp_path: Path):
    """Their simulated case (M 1 kg, C 5 N s/m, K 500 N/m, the steady-state Dieterich-Ruina
    law with F 1 N, a 0.07, b 0.09, c 0.022, V 3 mm/s, 5 s at 500 Hz), as a term file of the
    stick kind, against the event-driven reference (their scheme, ``FrictionSDOF.m``)."""
    path = tmp_path / "ruina_friction.py"
    path.write_text(RUINA)
    if "ruina_friction" not in TERMS:
        load_term_file(path)
    p = dict(F_r=1.0, a_r=0.07, b_r=0.09, c_r=0.022, V_r=0.003)
    eps = 1e-6

    def law(u):
        u = np.abs(u) + eps
        return p["F_r"] + p["a_r"] * np.log(u / p["V_r"]) + p["b_r"] * np.log(
            p["c_r"] + (p["V_r"] + eps) / u)
    load = marino_load(500.0, 5.0)
    ref = ed.simulate(ed.Oscillator(1.0, 5.0, 500.0, law, float(law(0.0))), load, 1 / 500.0,
                      0.1)
    sim = simulate(Layout.of(["ruina_friction"]), [1.0, 1.0, 500.0, 5.0, *p.values()], load,
                   1 / 500.0, force_input=True)
    assert stuck_share(sim.rel_vel[0]) == stuck_share(ref.v) > 0.05
    assert np.max(np.abs(sim.rel_disp[0] - ref.x)) < 1e-4 * np.max(np.abs(ref.x))


@pytest.mark.slow
def test_karnopp_element_converges_to_the_sticking_law():
    """The literature generator's Karnopp element (its own integrator; share 1, breakaway
    1.5 x sliding) with its stick band narrowed to 1e-4 of the RMS velocity against
    sticking_friction + sticking_stribeck with the same levels and a Stribeck velocity of
    1e-3 of it (the jump), driven by the same base acceleration at the generator's rate."""
    from harvester.synthetic import literature as lit
    dev, tb, y2, v_rms = ed.karnopp_drive(3)
    p = dev.params()
    p[lit.E:lit.E + 3] = 1.0, 1.5, 1e-4 * v_rms
    _, z, v = lit.simulate(lit.KARNOPP, p, y2, tb, 8)
    sim = simulate(Layout.of(["sticking_friction", "sticking_stribeck"]),
                   [dev.M, dev.m, dev.k, dev.c, dev.F_c, 0.5 * dev.F_c, 1e-3 * v_rms, 2.0],
                   y2[:2 * tb.n_int:2], tb.h_int)
    karnopp_stuck = np.mean(np.abs(v) < p[lit.E + 2])
    assert karnopp_stuck > 0.15
    assert abs(stuck_share(sim.rel_vel[0]) - karnopp_stuck) < 0.005
    assert np.max(np.abs(sim.rel_disp[0] - z)) < 3e-3 * np.max(np.abs(z))


def test_named_force_holds_where_stuck():
    """Along a simulated path the named sticking law's force closes eq. (1) at every sample:
    its sliding law while moving, the holding force where stuck."""
    from harvester.model.term_forces import named_force, term_force
    f = forcing(3.0)
    lay = Layout.of(["sticking_friction"])
    sim = simulate(lay, [M, 1.0, K, C, 2.0], f, 1 / FS, force_input=True)
    values = {"M": M, "m": 1.0, "k": K, "c_m": C, "F_dry": 2.0}
    z, v, a = sim.rel_disp, sim.rel_vel, sim.rel_acc
    x = named_force(lay, values, z, v, a, np.zeros_like(f), f, 1 / FS, ("sticking_friction",))
    stuck = v[0] == 0.0
    assert 0.3 < stuck.mean() < 0.7
    closure = M * a + C * v + K * z + x - f
    assert np.max(np.abs(closure)) < 1e-6 * np.max(np.abs(f))
    sliding = term_force(TERMS["sticking_friction"], values, z, v, a, np.zeros_like(f), 1 / FS)
    np.testing.assert_array_equal(x[0, ~stuck], sliding[0, ~stuck])
    assert np.all(np.abs(x[0, stuck]) <= 2.0 * (1 + 1e-9))
