"""The recording's own noise floor (diagnosis.detect.floor) against known noise levels."""

from __future__ import annotations

import numpy as np
import pytest

from harvester.data.signals import lowpass
from harvester.diagnosis.detect.floor import input_period, output_floor, periodic_floor, quiet_floor

FS = 250.0


def _sine_record(noise: float, seconds: float = 10.0, f0: float = 1.1, lead_s: float = 0.0,
                 seed: int = 0):
    rng = np.random.default_rng(seed)
    t = np.arange(int(seconds * FS)) / FS
    u = np.sin(2 * np.pi * f0 * t) * (t >= lead_s)
    # a nonlinear steady-state response: clipped and shifted in phase
    y = np.clip(np.sin(2 * np.pi * f0 * t - 0.7), -0.6, 0.6) * (t >= lead_s)
    return t, u, y + noise * rng.standard_normal(t.size)


def test_repeated_periods_give_the_noise_of_a_periodic_response():
    # the input repeats every 227.27 samples (1.1 Hz at 250 Hz): refined to a fraction
    _, u, y = _sine_record(0.01)
    assert abs(input_period(u, FS) - FS / 1.1) < 1.0
    floor = periodic_floor(u, y, FS)
    assert floor.method == "repeated_periods" and floor.bound == "upper"
    assert floor.rms == pytest.approx(0.01, rel=0.1)


def test_a_random_input_has_no_period():
    rng = np.random.default_rng(3)
    u = lowpass(rng.standard_normal(2500), FS, 15.0, 4)
    assert input_period(u, FS) is None
    assert periodic_floor(u, u, FS) is None


def test_a_quiet_lead_in_gives_the_sensor_noise():
    _, u, y = _sine_record(0.02, lead_s=2.0)
    floor = quiet_floor(u, y, FS)
    assert floor.method == "quiet_lead_in" and floor.bound == "lower"
    assert floor.rms == pytest.approx(0.02, rel=0.15)


def test_no_floor_where_the_recording_allows_none():
    rng = np.random.default_rng(4)
    u = lowpass(rng.standard_normal(5000), FS, 40.0, 4)
    y = lowpass(rng.standard_normal(5000), FS, 40.0, 4)
    assert output_floor(u, y, y, (250, 4750), FS, 40.0) is None
