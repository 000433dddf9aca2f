"""Figure 7's question (``study.sticking``) on records whose answer is known."""

import numpy as np
import pytest

from harvester.study.sticking import near_sticks, stick_misfit, stick_runs

FS = 100.0


def test_runs_and_their_neighbourhood():
    stuck = np.zeros(50, dtype=bool)
    stuck[[3, 4, 20]] = True
    starts, ends = stick_runs(stuck)
    assert list(starts) == [3, 20] and list(ends) == [5, 21]
    near = near_sticks(stuck, FS, near_s=0.02)  # 2 samples either side
    assert np.flatnonzero(near).tolist() == [1, 2, 3, 4, 5, 6, 18, 19, 20, 21, 22]


def test_a_misfit_made_near_the_sticks_reads_above_one_and_by_speed():
    """Residual 3 near the sticks, 1 elsewhere; the record 2 near them, 4 elsewhere: 3 x
    absolute, 6 x relative. Speed 1 mm/s where stuck, 50 mm/s elsewhere: two bands used."""
    n = 1000
    stuck = np.zeros(n, dtype=bool)
    stuck[100:110] = stuck[500:505] = True
    near = near_sticks(stuck, FS)
    residual = np.where(near, 3.0, 1.0) * np.where(np.arange(n) % 2, 1.0, -1.0)
    measured = np.where(near, 2.0, 4.0)
    speed = np.where(stuck, 1e-3, 0.05)
    m = stick_misfit(residual, measured, stuck, speed, FS)
    assert m.sticks == 2 and m.longest_ms == pytest.approx(100.0)
    assert m.absolute_ratio == pytest.approx(3.0) and m.relative_ratio == pytest.approx(6.0)
    shares = {(lo, hi): share for lo, hi, share, _, _ in m.by_speed}
    assert shares[(0.0, 2.0)] == 0.0 and shares[(30.0, 60.0)] == pytest.approx(0.985)
    assert m.to_dict()["nrmse_near_over_elsewhere"] == 6.0
    # while stuck (all near): residual 3 on a record of 2; moving: near (3 on 2) and far (1 on
    # 4) mixed by their counts
    assert m.stuck == pytest.approx((3.0, 2.0)) and m.stuck_nrmse == pytest.approx(1.5)
    moving = ~stuck
    expected = np.sqrt(np.mean(residual[moving] ** 2) / np.mean(measured[moving] ** 2))
    assert m.moving_nrmse == pytest.approx(expected)
    assert m.moving[0] == pytest.approx(np.sqrt(np.mean(residual[moving] ** 2)))


def test_the_zoom_is_centred_on_the_longest_stick_and_kept_inside():
    from harvester.study.sticking import longest_stick_window
    t = np.arange(1000) / FS
    stuck = np.zeros(1000, dtype=bool)
    stuck[100:103] = stuck[500:520] = True  # the longest: 5.00-5.19 s
    assert longest_stick_window(stuck, t, 1.0) == pytest.approx((4.595, 5.595))
    stuck[:] = False
    stuck[2:30] = True  # near the start: the section starts at the record's start
    assert longest_stick_window(stuck, t, 1.0) == pytest.approx((0.0, 1.0))
    assert longest_stick_window(np.zeros(1000, dtype=bool), t, 1.0) is None
