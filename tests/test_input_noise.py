"""The input channel's noise floor and the input without its noise-only bins."""

import numpy as np
import pytest

from harvester.data.input_noise import NoiseFloor, input_gain, noise_floor, without_floor
from harvester.data.signals import psd

FS = 256.0
N = int(40 * FS)


def _multisine(rng, f_lo, f_hi, lines=60, peak=2.0):
    t = np.arange(N) / FS
    freqs = np.linspace(f_lo, f_hi, lines)
    x = np.sum(np.sin(2 * np.pi * freqs[:, None] * t + rng.uniform(0, 2 * np.pi, (lines, 1))),
               axis=0)
    return peak * x / np.abs(x).max()


def test_the_floor_of_a_narrow_excitation_is_its_sensor_noise():
    rng = np.random.default_rng(0)
    noise = 0.06 * rng.standard_normal(N)            # white: N0 = 0.06^2 / (FS / 2)
    floor = noise_floor(_multisine(rng, 0.4, 3.0) + noise, FS, 92.0)
    assert floor is not None
    assert floor.level == pytest.approx(0.06 ** 2 / (FS / 2), rel=0.1)
    assert floor.share > 0.8 and floor.dynamic_range > 1e3


def test_an_excitation_that_fills_the_band_has_no_floor():
    # a flat excitation looks like a floor on the input channel alone: not taken for noise
    rng = np.random.default_rng(1)
    white = rng.standard_normal(N)
    assert noise_floor(white + 0.01 * rng.standard_normal(N), FS, 92.0) is None
    assert noise_floor(_multisine(rng, 0.5, 90.0, lines=400) + 0.01 * rng.standard_normal(N),
                       FS, 92.0) is None


def test_the_model_input_keeps_the_excitation_and_drops_the_noise_only_bins():
    rng = np.random.default_rng(2)
    clean = _multisine(rng, 0.4, 3.0)
    noisy = clean + 0.06 * rng.standard_normal(N)
    floor = noise_floor(noisy, FS, 92.0)
    out = without_floor(noisy, FS, floor)
    f, s_out = psd(out, FS, 2.0)
    quiet = (f > 10.0) & (f < 92.0)
    assert np.max(s_out[quiet]) < 1e-3 * floor.level
    inner = slice(int(2 * FS), -int(2 * FS))
    # the excitation's band keeps its noise (small against the lines), nothing else is lost
    assert np.sqrt(np.mean((out - clean)[inner] ** 2)) < 0.25 * 0.06   # 0.06 as recorded


def test_the_gain_rises_from_the_floor_to_its_spread():
    floor = NoiseFloor(1.0, (0.1, 90.0), 0.9, 100.0)
    g = input_gain(np.zeros(4), np.array([0.5, 1.5, 2.0, 3.0]), floor)
    assert g[0] == g[1] == 0.0 and g[3] == 1.0 and 0.0 < g[2] < 1.0


def _two_sensor_record(output_noise, seed=0, fs=256.0, n=10240):
    """A low-frequency multisine base input with its sensor's white noise n0, and an output
    of the device's response plus ``output_noise(n0, n1)``."""
    from scipy import signal
    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs
    exc = sum(np.sin(2 * np.pi * f0 * t + rng.uniform(0, 6.3)) for f0 in np.arange(0.5, 3.0, 0.25))
    n0, n1 = 0.064 * rng.standard_normal((2, n))
    resp = 0.3 * signal.sosfilt(signal.butter(2, 3.0, fs=fs, output="sos"), exc)
    return exc + n0, resp + output_noise(n0, n1), fs


def test_an_output_formed_with_the_inputs_sensor_holds_its_noise():
    """Two accelerometers (rel = mass - base): gain -1, coherence 0.5 where the input is its
    noise alone; a relative sensor of its own: none; real base motion on the floor seen
    through the device above resonance (-m/M = -0.9) is not taken for a shared sensor where
    m/M is known."""
    from harvester.data.input_noise import noise_floor, shared_noise
    u, y, fs = _two_sensor_record(lambda n0, n1: n1 - n0)
    floor = noise_floor(u, fs, 100.0)
    two = shared_noise(u, y, fs, floor)
    assert two.gain == pytest.approx(-1.0, abs=0.05) and two.coherence == pytest.approx(
        0.5, abs=0.05) and two.shared() and two.shared(0.6)
    u, y, fs = _two_sensor_record(lambda n0, n1: np.sqrt(2.0) * n1)
    own = shared_noise(u, y, fs, noise_floor(u, fs, 100.0))
    assert own.coherence < 0.05 and not own.shared()
    u, y, fs = _two_sensor_record(lambda n0, n1: -0.9 * n0 + 0.2 * n1)
    base_motion = shared_noise(u, y, fs, noise_floor(u, fs, 100.0))
    assert base_motion.shared() and not base_motion.shared(0.9)


def test_a_named_mass_error_on_such_a_record_is_said_not_fixed():
    """The diagnosis's note: only where an effect of the masses is named or tied and the
    output holds the input sensor's noise."""
    from types import SimpleNamespace

    from harvester.data.input_noise import SharedNoise
    from harvester.diagnosis.size.estimate import mass_size_caveat
    shared = SimpleNamespace(shared_input_noise=SharedNoise(-1.0, 0.45, 240))
    own = SimpleNamespace(shared_input_noise=None)
    tie = SimpleNamespace(effects=["inertia_error", "unmodelled_mode"])
    named = SimpleNamespace(missing=["inertia_error"], ties=[])
    tied = SimpleNamespace(missing=[], ties=[tie])
    other = SimpleNamespace(missing=["cubic_stiffness"], ties=[])
    assert mass_size_caveat(shared, named).startswith("inertia_error: the record does not fix")
    assert mass_size_caveat(shared, tied).startswith("inertia_error:")
    assert mass_size_caveat(shared, other) is None and mass_size_caveat(own, named) is None
