"""A pre-sliding displacement the record does not resolve is not named as pre-sliding
(``diagnosis.name.limits.unresolved``): below the smallest displacement the output tells from
its noise, hysteresis is taken at its limit, dry friction that holds."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from harvester.diagnosis.name.results import CandidateResult

from harvester.diagnosis.name.limits import becomes, resolution, unresolved
from harvester.model.terms import term


def _fit(order: int, band_hz: float, sigma: float, delta: float):
    """A stand-in for a hysteresis fit: delta_hyst's draws about ``delta``, sigma's (the
    misfit, which must not set the resolution) at 20 x ``sigma``, on an output of
    time-derivative ``order``."""
    rng = np.random.default_rng(0)
    names = ("c_m", "F_hyst", "delta_hyst", "c_hyst")
    samples = np.column_stack([rng.normal(1.0, 0.01, 200), rng.normal(0.6, 0.01, 200),
                               delta * np.exp(rng.normal(0, 0.1, 200)),
                               rng.normal(1.0, 0.01, 200),
                               20 * sigma * np.exp(rng.normal(0, 0.01, 200))])
    problem = SimpleNamespace(output_type=SimpleNamespace(order=order), band_hz=band_hz)
    return SimpleNamespace(names=names, samples=samples, problem=problem)


def test_resolution_is_the_noise_floor_carried_to_a_displacement():
    """The recording's own floor, not the model's misfit (sigma, 20 x the floor here)."""
    assert resolution(_fit(0, 20.0, 5e-6, 1e-6), 5e-6) == pytest.approx(5e-6)
    acc = resolution(_fit(2, 20.0, 0.01, 1e-6), 0.01)
    assert acc == pytest.approx(0.01 / (2 * np.pi * 20.0) ** 2)  # 0.63 um


@pytest.mark.parametrize("order, sigma, delta, hidden", [
    (0, 5e-6, 2e-7, True),    # a 0.2 um bristle on lasers that see 5 um: a contact that holds
    (0, 5e-6, 5e-5, False),   # 50 um of pre-sliding on the same lasers: resolved
    (2, 0.01, 1e-7, True),    # 0.1 um from an accelerometer resolving 0.63 um at 20 Hz
    (2, 0.01, 7e-6, False),   # a ball screw's 7 um from the same
])
def test_a_pre_sliding_displacement_below_the_resolution_is_unresolved(order, sigma, delta,
                                                                      hidden):
    found = unresolved("hysteresis", _fit(order, 20.0, sigma, delta), sigma)
    assert bool(found) is hidden
    if hidden:
        median, floor = found["delta_hyst"]
        assert median < floor


def test_an_unresolved_hysteresis_stands_for_friction_that_holds():
    assert term("hysteresis").resolved == ("delta_hyst",)
    assert term("hysteresis").limit_terms("delta_hyst", "lower")[0] == "sticking_friction"
    assert unresolved("coulomb_friction", _fit(0, 20.0, 5e-6, 1e-7), 5e-6) == {}  # none
    assert unresolved("hysteresis", _fit(0, 20.0, 5e-6, 1e-7), None) == {}  # no floor
    fit = _fit(0, 20.0, 5e-6, 2e-7)
    r = CandidateResult("hysteresis", fit, 1000.0, 1.0, 10.0, False,
                        unresolved=unresolved("hysteresis", fit, 5e-6))
    assert r.at_limit == {"delta_hyst": "lower"}
    assert becomes(r, "sticking_friction") and becomes(r, "coulomb_friction")
    assert not becomes(r, "cubic_stiffness")
    assert "0.2 um lies below the 5 um the record resolves" in r.unresolved_sentence()
