"""The compiled acquisition (anti-alias decimation, zero-phase filter, residual sums) against
scipy and the trajectories it replaces."""

import numpy as np
import pytest
from scipy import signal

from harvester.data.signals import antialias_decimate, lowpass
from harvester.model import acquisition
from harvester.model.simulate import Acquisition, residual_sums, simulate
from harvester.model.structures import Layout

FS = 256.0


@pytest.mark.parametrize("order, cutoff", [(8, 20.0), (4, 5.0), (2, 100.0)])
def test_zero_phase_filter_is_scipys_sosfiltfilt(order, cutoff):
    rng = np.random.default_rng(order)
    x = rng.standard_normal((1000, 7)).cumsum(axis=0)
    rows, pad = acquisition.filter_rows(signal.butter(order, cutoff, fs=FS, output="sos"))
    ours = x.copy()
    acquisition.zero_phase_inplace(ours, rows, pad)
    np.testing.assert_allclose(ours, lowpass(x.T, FS, cutoff, order).T, rtol=0, atol=1e-12)


def test_zero_phase_filter_refuses_a_record_shorter_than_its_padding():
    rows, pad = acquisition.filter_rows(signal.butter(8, 20.0, fs=FS, output="sos"))
    with pytest.raises(ValueError, match="too short"):
        acquisition.zero_phase_inplace(np.ones((pad, 2)), rows, pad)


def test_decimation_is_the_antialias_decimation_of_the_signals_module():
    rng = np.random.default_rng(1)
    x = rng.standard_normal((4096, 3))
    from harvester.data.signals import ANTIALIAS_FRACTION, ANTIALIAS_ORDER
    rows, pad = acquisition.filter_rows(signal.butter(
        ANTIALIAS_ORDER, ANTIALIAS_FRACTION * 4 * FS / 8.0, fs=4 * FS, output="sos"))
    ours = acquisition.decimate(x.copy(), 4, rows, pad)
    np.testing.assert_allclose(ours, antialias_decimate(x.T, 4 * FS, 4).T, atol=1e-12)


@pytest.fixture(scope="module")
def record():
    rng = np.random.default_rng(2)
    y = signal.sosfilt(signal.butter(4, 15.0, fs=FS, output="sos"), rng.standard_normal(1500))
    return 4.0 * y / np.abs(y).max()


@pytest.mark.parametrize("q, filt, kind", [(1, None, "rel_acc"), (4, (20.0, 8), "rel_acc"),
                                           (4, None, "rel_disp"), (2, (16.0, 8), "rel_disp")])
def test_residual_sums_equal_those_of_the_trajectories(record, q, filt, kind):
    """The fused path (no trajectories kept) gives the sums of the explicit one."""
    layout = Layout.of(["tanh_friction"])
    rng = np.random.default_rng(3)
    p = np.tile([12.8, 8.0, 250.0, 109.5, 11.86, 88.35], (70, 1))
    p[:, 5] *= rng.uniform(0.3, 3.0, 70)
    p[3, 0] = np.nan  # a particle that cannot be simulated
    window, stride = (256, 1400), 3
    sim = simulate(layout, p, record, 1.0 / FS, oversample=q)
    out = sim.rel_acc if kind == "rel_acc" else sim.rel_disp
    if filt is not None:
        out = np.where(sim.ok[:, None], out, 0.0)
        out = lowpass(out, FS, *filt)
    observed = 0.1 * rng.standard_normal(len(range(*window, stride)))
    explicit = np.sum((observed - out[:, window[0]:window[1]:stride]) ** 2, axis=1)
    sse, ok = residual_sums(layout, p, record, 1.0 / FS, observed, window, stride, kind,
                            Acquisition(q, filt))
    np.testing.assert_array_equal(ok, sim.ok)
    assert not ok[3] and sse[3] == np.inf
    np.testing.assert_allclose(sse[ok], explicit[ok], rtol=1e-10)
