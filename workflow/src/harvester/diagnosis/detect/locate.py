"""Where the mismatch lies: time windows, regions of the state and frequency bands.

Each location family turns band-limited residuals (the data's and the noise replicates') into
shares of residual energy, so the same code computes the observed value and its calibration:

* time windows (1 s by default): share of the residual energy in each window;
* state regions of the baseline's simulated motion (near velocity reversals, large
  displacement, large acceleration, either direction of motion, ...): share of residual
  energy against the share of time;
* frequency bands (octaves): share of residual energy, the share white noise through the
  passband would hold, and the share explained by the candidates' signatures.

A location is flagged when its statistic exceeds the 95 % quantile of the family's maximum
over noise replicates (a simultaneous, family-wise 5 % level).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from harvester.diagnosis.detect.spectral import Frame

#: Octave band edges (Hz); the first and last are clipped to the analysed band.
BAND_EDGES_HZ = (0.0, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0, 128.0, 256.0, 512.0)
#: Quantile defining "small" and "large" in the state regions.
REGION_QUANTILE = 0.2


def _log_share(energy: np.ndarray, total: np.ndarray) -> np.ndarray:
    return np.log(np.maximum(energy, 1e-300) / np.maximum(total, 1e-300)[..., None])


@dataclass
class Standardised:
    """Observed statistics, their replicates' mean and sd, z-scores and simultaneous flags."""

    observed: np.ndarray  # (k,)
    z: np.ndarray  # (k,)
    z_replicates: np.ndarray  # (B, k)
    replicate_values: np.ndarray  # (B, k) the replicates' statistics

    @property
    def family_max(self) -> float:
        return float(np.max(self.z)) if self.z.size else -np.inf

    @property
    def family_max_replicates(self) -> np.ndarray:
        if self.z.size == 0:
            return np.full(self.z_replicates.shape[0], -np.inf)
        return np.max(self.z_replicates, axis=1)

    def threshold(self, level: float = 0.95) -> float:
        return float(np.quantile(self.family_max_replicates, level))

    def pointwise_p(self) -> np.ndarray:
        b = self.z_replicates.shape[0]
        return (1.0 + np.sum(self.z_replicates >= self.z[None, :], axis=0)) / (1.0 + b)


def standardise(observed: np.ndarray, replicates: np.ndarray) -> Standardised:
    mean = replicates.mean(axis=0)
    sd = replicates.std(axis=0, ddof=1)
    sd = np.where(sd > 0, sd, np.inf)
    return Standardised(observed, (observed - mean) / sd, (replicates - mean) / sd, replicates)


class TimeWindows:
    """Consecutive windows of ``seconds`` over the analysis window (last one merged if short)."""

    def __init__(self, frame: Frame, time: np.ndarray, seconds: float = 1.0) -> None:
        n = frame.n
        width = max(8, int(round(seconds * frame.fs)))
        edges = list(range(0, n, width))
        if len(edges) > 1 and n - edges[-1] < width // 2:
            edges.pop()
        self.edges = np.array(edges + [n])
        self.time = time[frame.start:frame.stop]
        self.weight = frame.time_weight

    @property
    def bounds_s(self) -> list[tuple[float, float]]:
        t = self.time
        dt = t[1] - t[0]
        return [(float(t[a]), float(t[b - 1] + dt))
                for a, b in zip(self.edges[:-1], self.edges[1:])]

    def energies(self, series: np.ndarray) -> np.ndarray:
        """(..., windows) residual energy per window of band-limited series (..., n)."""
        e = series**2
        return np.add.reduceat(e, self.edges[:-1], axis=-1)

    def statistic(self, series: np.ndarray) -> np.ndarray:
        e = self.energies(series)
        return _log_share(e, e.sum(axis=-1))

    def expected_share(self) -> np.ndarray:
        w = np.add.reduceat(self.weight, self.edges[:-1])
        return w / w.sum()


class StateRegions:
    """Regions of the baseline's simulated motion (boolean masks over the analysis window)."""

    def __init__(self, frame: Frame, rel_disp: np.ndarray, rel_vel: np.ndarray,
                 rel_acc: np.ndarray, base_acc: np.ndarray, input_kind=None,
                 quantile: float = REGION_QUANTILE) -> None:
        """``base_acc``: the model's input (a force for a force input), ``input_kind`` its
        ``harvester.data.kinds.InputKind`` (None: a base acceleration), which names the
        region where it is large."""
        from harvester.data.kinds import input_kind as kind_of
        kind = input_kind or kind_of("base_acc")
        sl = slice(frame.start, frame.stop)
        z = rel_disp[sl] - np.median(rel_disp[sl])
        v, a, y = rel_vel[sl], rel_acc[sl], base_acc[sl]
        av, az, aa, ay = np.abs(v), np.abs(z), np.abs(a), np.abs(y)
        lo, hi = quantile, 1.0 - quantile
        self.masks: dict[str, np.ndarray] = {
            "velocity_reversal": av <= np.quantile(av, lo),
            "high_velocity": av >= np.quantile(av, hi),
            "large_displacement": az >= np.quantile(az, hi),
            "small_displacement": az <= np.quantile(az, lo),
            "large_acceleration": aa >= np.quantile(aa, hi),
            kind.region_name: ay >= np.quantile(ay, hi),
            "positive_velocity": v > 0,
            "negative_velocity": v < 0,
            "positive_displacement": z > 0,
            "negative_displacement": z < 0,
        }
        self.descriptions = {
            "velocity_reversal": f"|z'| below its {lo:.0%} quantile (near velocity reversals, "
                                 "where friction sticks)",
            "high_velocity": f"|z'| above its {hi:.0%} quantile",
            "large_displacement": f"|z| above its {hi:.0%} quantile (end stops, stiffness)",
            "small_displacement": f"|z| below its {lo:.0%} quantile (near the rest position)",
            "large_acceleration": f"|z''| above its {hi:.0%} quantile (inertia, modes)",
            kind.region_name: kind.region.format(hi=hi),
            "positive_velocity": "z' > 0 (mass moving up)",
            "negative_velocity": "z' < 0 (mass moving down)",
            "positive_displacement": "z above its median",
            "negative_displacement": "z below its median",
        }
        self.names = list(self.masks)
        self.matrix = np.array([self.masks[k] for k in self.names], dtype=float)  # (regions, n)
        self.weight = frame.time_weight

        self.extra_time_share: list[float] = []

    def statistic(self, series: np.ndarray) -> np.ndarray:
        e = series**2
        return _log_share(e @ self.matrix.T, e.sum(axis=-1))

    def add(self, region, time_share: float) -> None:
        """Append a data-dependent region (its statistic is log(share / time share))."""
        self.names.append(region.name)
        self.descriptions[region.name] = region.description
        self.extra_time_share.append(time_share)

    def time_share(self) -> np.ndarray:
        fixed = (self.matrix @ self.weight) / self.weight.sum()
        return np.append(fixed, self.extra_time_share)

    def energy_share(self, statistic: np.ndarray) -> np.ndarray:
        """Energy shares from the statistics (log share; log ratio for added regions)."""
        k = self.matrix.shape[0]
        out = np.exp(statistic).copy()
        out[k:] *= np.array(self.extra_time_share)
        return out


class FrequencyBands:
    """Octave bands of the analysed band."""

    def __init__(self, frame: Frame) -> None:
        edges = [e for e in BAND_EDGES_HZ if frame.f_low < e < frame.f_high]
        self.edges = np.array([frame.f_low, *edges, frame.f_high])
        f = frame.freqs
        self.index = [np.flatnonzero((f >= lo) & (f < hi))
                      for lo, hi in zip(self.edges[:-1], self.edges[1:])]
        self.power_weight = frame.mask**2

    @property
    def bounds_hz(self) -> list[tuple[float, float]]:
        return [(float(a), float(b)) for a, b in zip(self.edges[:-1], self.edges[1:])]

    def band_energy(self, X: np.ndarray) -> np.ndarray:
        p = np.abs(X) ** 2 * self.power_weight
        return np.stack([p[..., i].sum(axis=-1) for i in self.index], axis=-1)

    def flat_share(self) -> np.ndarray:
        e = np.array([self.power_weight[i].sum() for i in self.index])
        return e / e.sum()


#: Half-width (s) of the running maximum that defines a standstill of the measured motion.
STANDSTILL_HALF_S = 0.02


class MeasuredStandstill:
    """Where the MEASURED relative motion stays near zero for a while: the mass moving
    with the base (friction sticking), whatever the model does there.

    Samples whose running maximum of |z''| (of |z'| for a displacement output: the output
    kind's ``motion``, ``harvester.data.kinds``) over +-STANDSTILL_HALF_S is below that
    maximum's ``quantile``; the mask depends on the data, so it is recomputed for each
    replicate (model + replicate residual), which calibrates the selection.
    """

    name = "measured_standstill"

    def __init__(self, frame: Frame, model: np.ndarray, output_kind=None,
                 quantile: float = REGION_QUANTILE) -> None:
        """``model``: the model's output through the chain, of ``output_kind``
        (``harvester.data.kinds.OutputKind``; None: z'')."""
        from harvester.data.kinds import output_kind as kind_of
        self.kind = output_kind or kind_of("rel_acc")
        self.dt = 1.0 / frame.fs
        self.description = (f"measured |{self.kind.motion_symbol}| near zero for 40 ms or "
                            "more (the mass moving with the base: sticking)")
        self.model = model[frame.start:frame.stop] * frame.taper
        self.width = max(3, int(round(2 * STANDSTILL_HALF_S * frame.fs)) | 1)
        self.quantile = quantile
        self.weight = frame.time_weight

    def mask(self, series: np.ndarray) -> np.ndarray:
        from scipy import ndimage
        motion = self.kind.motion(self.model + series, self.dt)
        peak = ndimage.maximum_filter1d(np.abs(motion), self.width, axis=-1)
        return peak <= np.quantile(peak, self.quantile, axis=-1, keepdims=True)

    def statistic(self, series: np.ndarray) -> np.ndarray:
        """log(energy share / time share) in the standstill mask, (...,)."""
        m = self.mask(series)
        e = series**2
        share = np.sum(e * m, axis=-1) / np.maximum(np.sum(e, axis=-1), 1e-300)
        time = np.sum(self.weight * m, axis=-1) / self.weight.sum()
        return np.log(np.maximum(share, 1e-300) / np.maximum(time, 1e-300))
