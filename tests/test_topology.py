"""What the friction acts on, when the sidecar does not say (``diagnosis.prepare.topology``): a
frame-like device written here, friction on the velocity relative to the base or to the
ground, recorded as laser displacements (base_disp -> rel_disp) or with an accelerometer on
the mass (base_disp -> rel_acc), must be given its own form."""

import numpy as np
import pandas as pd
import pytest
from scipy.integrate import solve_ivp

from harvester.data.signals import lowpass
from harvester.diagnosis.prepare.settings import DiagnosisSettings
from harvester.diagnosis.prepare.topology import choose_topology, friction_structure
from harvester.initial.recording import diagnosis_priors

FS, SECONDS, CUT = 250.0, 8.0, 20.0
DEVICE = {"M": 3.0, "m": 3.0, "k": 1200.0}
C, F, V_SMOOTH = 0.7, 0.6, 1e-3  # N s/m, N, m/s (a sharp tanh: Coulomb friction)


def _base(t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A harmonic base motion near the frame's 1 Hz plus a weaker 2.7 Hz line (m, m/s, m/s^2)."""
    a = np.array([[2e-3, 1.1], [4e-4, 2.7]])
    w = 2 * np.pi * a[:, 1]
    y = sum(ai * np.sin(wi * t) for ai, wi in zip(a[:, 0], w))
    yd = sum(ai * wi * np.cos(wi * t) for ai, wi in zip(a[:, 0], w))
    ydd = sum(-ai * wi**2 * np.sin(wi * t) for ai, wi in zip(a[:, 0], w))
    return y, yd, ydd


def frame_record(on: str, seed: int = 0, output: str = "rel_disp") -> pd.DataFrame:
    """M z'' + C z' + k z + F tanh(v / V_SMOOTH) = -M y'', v = z' (on the base) or z' + y'
    (on the ground); laser noise 5 um on both channels (the output: or an accelerometer's
    0.02 m/s^2 on z''), low-passed at CUT Hz."""
    M, k = DEVICE["M"], DEVICE["k"]

    def rhs(t, s):
        _, yd, ydd = _base(np.array(t))
        v = s[1] + (yd if on == "ground" else 0.0)
        return [s[1], (-M * ydd - C * s[1] - k * s[0] - F * np.tanh(v / V_SMOOTH)) / M]

    t = np.arange(int(SECONDS * FS)) / FS
    sol = solve_ivp(rhs, (0, t[-1]), [0.0, 0.0], t_eval=t, method="LSODA", rtol=1e-8,
                    atol=1e-11, max_step=1e-3)
    rng = np.random.default_rng(seed)
    y = _base(t)[0] + 5e-6 * rng.standard_normal(t.size)
    if output == "rel_disp":
        z = sol.y[0] + 5e-6 * rng.standard_normal(t.size)
    else:
        z = np.array([rhs(ti, si)[1] for ti, si in zip(t, sol.y.T)])
        z = z + 0.02 * rng.standard_normal(t.size)
    return pd.DataFrame({"time": t, "base_disp": lowpass(y, FS, CUT, 8),
                         output: lowpass(z, FS, CUT, 8)})


def _choose(df: pd.DataFrame):
    settings = DiagnosisSettings(lowpass_hz=CUT)

    def priors_of(d, known):
        return diagnosis_priors(d, "linear", known, None, CUT, "<frame>")[0]
    return choose_topology(df, DEVICE, "linear", priors_of, settings, "<frame>")


def test_the_baseline_is_tested_with_its_own_friction_or_coulomb_friction():
    assert friction_structure("linear") == "linear+coulomb_friction"
    assert friction_structure("tanh") == "tanh"


@pytest.mark.parametrize("on", ["base", "ground"])
def test_each_form_is_told_by_its_evidence(on):
    choice = _choose(frame_record(on))
    assert choice.chosen == on, choice.to_dict()
    assert abs(choice.lead) > 3 * choice.threshold
    assert "taken: relative to the " + on in choice.sentence("<frame>")


@pytest.mark.parametrize("on", ["base", "ground"])
def test_each_form_is_told_on_an_acceleration_output(on):
    """base_disp -> rel_acc: the ground form reads x'' = z'' + y'' (y'' differentiated)."""
    choice = _choose(frame_record(on, output="rel_acc"))
    assert choice.chosen == on, choice.to_dict()
    assert abs(choice.lead) > 3 * choice.threshold
