"""Where a model misses on the virtual rig: near its sticks or at speed (Figure 7's question).

The paper reads its Figure 7 as the linear model failing "where the device sticks". On the rig
the truth says where it stuck and how fast the screw moved, so the claim can be measured: the
model's residual (measured minus its mean) while the rig is stuck and within ``near_s`` of a
stick against elsewhere, each also relative to the record's own RMS there (the record is
smaller near a stick: a model that cannot stick misses a larger part of it there), and its
RMS per band of screw speed over the moving samples. Used by Figure 7 and by
``benchmarks/bench_rig_session.py``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: A sample within this many seconds of a stick is "near" it.
NEAR_S = 0.02

#: Screw-speed bands (mm/s) of the misfit panel.
SPEED_EDGES_MM_S = (0.0, 2.0, 10.0, 30.0, 60.0, np.inf)


def stick_runs(stuck: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(first sample, one past the last) of each run of True in ``stuck``."""
    edge = np.diff(np.r_[0, np.asarray(stuck, dtype=int), 0])
    return np.flatnonzero(edge == 1), np.flatnonzero(edge == -1)


def near_sticks(stuck: np.ndarray, fs: float, near_s: float = NEAR_S) -> np.ndarray:
    """True within ``near_s`` (s) of a stick (the stick included)."""
    pad = int(round(near_s * fs))
    near = np.zeros(len(stuck), dtype=bool)
    for a, b in zip(*stick_runs(stuck)):
        near[max(a - pad, 0):b + pad] = True
    return near


def longest_stick_window(stuck: np.ndarray, time: np.ndarray,
                         width_s: float) -> tuple[float, float] | None:
    """(start, end) s of a ``width_s`` section centred on the longest stick and kept inside
    ``time``; None without a stick (Figure 7's zoom)."""
    runs = list(zip(*stick_runs(stuck)))
    if not runs:
        return None
    a, b = max(runs, key=lambda r: r[1] - r[0])
    half = 0.5 * float(width_s)
    mid = 0.5 * (time[a] + time[b - 1])
    lo = min(max(mid - half, time[0]), time[-1] - 2 * half)
    return lo, lo + 2 * half


@dataclass(frozen=True)
class StickMisfit:
    """A model's misfit while the rig is stuck, near its sticks against elsewhere, and per
    band of speed."""

    sticks: int
    longest_ms: float
    stuck_share: float
    near_share: float
    #: RMS residual near sticks / elsewhere
    absolute_ratio: float
    #: the same, each relative to the measured record's RMS there
    relative_ratio: float
    #: (RMS residual, RMS of the record) over the stuck samples, and over the moving ones
    stuck: tuple[float, float]
    moving: tuple[float, float]
    #: (low, high mm/s, share of the samples, RMS residual, RMS of the record) per speed band
    #: of the samples where the rig moves
    by_speed: tuple[tuple[float, float, float, float, float], ...]

    @property
    def stuck_nrmse(self) -> float:
        """RMS residual / RMS of the record while the rig is stuck."""
        return self.stuck[0] / self.stuck[1]

    @property
    def moving_nrmse(self) -> float:
        """RMS residual / RMS of the record while the rig moves (every band)."""
        return self.moving[0] / self.moving[1]

    def to_dict(self) -> dict:
        return {"sticks": self.sticks, "longest_stick_ms": round(self.longest_ms, 1),
                "stuck_pct": round(100.0 * self.stuck_share, 2),
                "near_stick_pct": round(100.0 * self.near_share, 2),
                "rms_near_over_elsewhere": round(self.absolute_ratio, 3),
                "nrmse_near_over_elsewhere": round(self.relative_ratio, 3),
                "nrmse_stuck": round(self.stuck_nrmse, 3),
                "nrmse_moving": round(self.moving_nrmse, 3),
                "rms_stuck": round(self.stuck[0], 4), "rms_moving": round(self.moving[0], 4),
                "rms_fastest_band": round(self.by_speed[-1][3], 4)}


def _rms(x: np.ndarray, mask: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(x[mask])))) if mask.any() else np.nan


def stick_misfit(residual: np.ndarray, measured: np.ndarray, stuck: np.ndarray,
                 speed: np.ndarray, fs: float, near_s: float = NEAR_S) -> StickMisfit:
    """The misfit of ``residual`` (measured - model) on samples where the rig's truth gives
    ``stuck`` and the screw ``speed`` (m/s); the speed bands over the samples where it moves;
    NaN ratios where there is no stick."""
    near = near_sticks(stuck, fs, near_s)
    starts, ends = stick_runs(stuck)
    far = ~near
    ratio = _rms(residual, near) / _rms(residual, far)
    relative = ratio / (_rms(measured, near) / _rms(measured, far))
    mm_s = 1e3 * np.abs(speed)
    stuck = np.asarray(stuck, dtype=bool)
    bands = []
    for lo, hi in zip(SPEED_EDGES_MM_S[:-1], SPEED_EDGES_MM_S[1:]):
        sel = (mm_s >= lo) & (mm_s < hi) & ~stuck
        bands.append((lo, hi, float(sel.mean()), _rms(residual, sel), _rms(measured, sel)))
    return StickMisfit(int(starts.size), 1e3 * float((ends - starts).max(initial=0)) / fs,
                       float(np.mean(stuck)), float(near.mean()), float(ratio),
                       float(relative), (_rms(residual, stuck), _rms(measured, stuck)),
                       (_rms(residual, ~stuck), _rms(measured, ~stuck)), tuple(bands))
