"""The vectorisable elementary functions against the C library's."""

import numba as nb
import numpy as np
import pytest

from harvester.model import fastmath as fm


@nb.njit(error_model="numpy")
def _apply(kind, x):
    out = np.empty_like(x)
    for i in range(x.shape[0]):
        if kind == 0:
            out[i] = fm.exp(x[i])
        elif kind == 1:
            out[i] = fm.expm1(x[i])
        elif kind == 3:
            out[i] = fm.log(x[i])
        else:
            out[i] = fm.tanh(x[i])
    return out


def _arguments():
    rng = np.random.default_rng(0)
    return np.concatenate([rng.normal(0.0, 3.0, 20000), rng.uniform(-700, 700, 20000),
                           rng.uniform(-1e-3, 1e-3, 20000), [0.0, -0.0, 1e-300, -1e-300,
                                                             700.0, -700.0, 0.5 * np.log(2)]])


@pytest.mark.parametrize("kind, reference, ulps", [(0, np.exp, 2), (1, np.expm1, 2),
                                                  (2, np.tanh, 3)])
def test_within_a_few_ulp_of_the_c_library(kind, reference, ulps):
    x = _arguments()
    ours, ref = _apply(kind, x), reference(x)
    ulp = np.spacing(np.abs(ref))
    assert np.all(np.abs(ours - ref) <= ulps * ulp + 1e-300)


def test_log_within_a_few_ulp_and_vectorised_loop():
    rng = np.random.default_rng(4)
    x = np.concatenate([np.exp(rng.uniform(-690, 690, 40000)), rng.uniform(0.5, 2.0, 20000),
                        [1.0, 2.0, 0.5, np.sqrt(2.0), 1e-300, 1e300]])
    ours, ref = _apply(3, x), np.log(x)
    assert np.all(np.abs(ours - ref) <= 2 * np.spacing(np.abs(ref)) + 1e-300)
    assert _apply(3, np.array([0.0]))[0] == pytest.approx(np.log(1e-300))


def test_tanh_keeps_its_sign_and_saturates():
    x = np.array([-1e6, -40.0, -1e-20, 0.0, 1e-20, 40.0, 1e6])
    t = _apply(2, x)
    np.testing.assert_array_equal(np.sign(t), np.sign(x))
    assert t[0] == -1.0 and t[-1] == 1.0


def test_exp_clamps_instead_of_overflowing():
    assert _apply(0, np.array([800.0]))[0] == pytest.approx(np.exp(700.0), rel=1e-15)
    assert _apply(0, np.array([-800.0]))[0] == pytest.approx(np.exp(-700.0), rel=1e-15)


def test_sign():
    @nb.njit
    def signs(x):
        return np.array([fm.sign(v) for v in x])
    np.testing.assert_array_equal(signs(np.array([-2.0, 0.0, 3.0])), [-1.0, 0.0, 1.0])
