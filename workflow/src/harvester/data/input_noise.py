"""The input channel's sensor noise, and the input without the bands where it is noise alone.

The model is driven by the recorded base acceleration y''_m = y'' + n_y, while the recorded
relative acceleration of a two-sensor rig is z''_m = z'' + n_x - n_y. At the right parameters
the residual z''_m - G y''_m (G the device's z''/y'' response) therefore holds
-(1 + G) n_y: input noise that reaches the residual through the model, correlated with the
output of every effect the input drives. Where the excitation leaves a band, the input there
is noise alone, and a mass error or a mode above the band fits that noise (errors in
variables). Measured on an effect-free record of ``synthetic.literature`` (excitation 0.4-3.1
Hz, 0.064 m/s^2 per sensor): coherence 0.25-0.29 between the residual and the input from 3 to
90 Hz, cross-spectral ratio -0.54 against -(1 - m / M) = -0.55, and a detection p = 0.0025
naming modes at 29-88 Hz and a mass error.

Remedy: drive the model with the input's bins that carry excitation only, W y''_m, with
W(f) = 0 where the input's Welch PSD S_y(f) lies on its white noise floor N0 (below
FLOOR_EDGE x N0), 1 where it lies above FLOOR_SPREAD x N0, a raised cosine between. A
Wiener gain 1 - N0 / S_y would leave the floor's upward scatter in (measured: the detection's
largest score fell from 6.9 to 4.7 sd only) and scale the excitation's lines by
S / (S + N0), a mass-like error of its own. N0 is found only where the input shows one
(:func:`noise_floor`): a flat floor over at least FLOOR_SHARE of the analysed band,
at least FLOOR_RANGE below the input's strongest line. An input whose excitation fills the band
has no floor to find, and its model input is left as recorded: there the noise is a small
share of every line, and a floor fitted to a flat excitation would take away signal.

The remedy leaves the noise within the excitation's band, where it still biases what the
input's own share of the output fixes: a named mass error's dM lay 0.6-2.4 posterior sds
from the truth on six of the literature grid's mass-error records (4.9 on another), and within
0.8 sd on the same records with the output's noise its own (docs/measurements.md). :func:`shared_noise` says
whether a record is of that kind: on the floor's bins, where the input is its sensor's noise
alone, an output formed as a difference with that sensor holds the same noise with gain -1.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from harvester.data.signals import apply_gain, frf_h1, psd

#: Welch segment (s) of the floor's PSD.
FLOOR_SEGMENT_S = 2.0
#: Bins within this factor of the 10th percentile of the band's PSD count as floor bins (a
#: white floor's Welch estimate over 20 or more segments scatters by < 30 %).
FLOOR_SPREAD = 3.0
#: The model input's gain starts to rise at this factor above the floor (3 sd of the
#: floor's scatter above it).
FLOOR_EDGE = 1.5
#: A floor must hold at least this share of the analysed band's bins ...
FLOOR_SHARE = 0.3
#: ... and lie at least this factor below the band's strongest bin (the excitation).
FLOOR_RANGE = 30.0
#: Lowest frequency (Hz) of the band the floor is looked for in.
FLOOR_F_LOW = 0.1


@dataclass(frozen=True)
class NoiseFloor:
    """A white noise floor of the input channel over ``band_hz``.

    level: N0 (units^2/Hz); share: share of the band's bins on the floor; dynamic_range: the
    band's strongest bin / N0; rms: the noise's RMS over the band (units).
    """

    level: float
    band_hz: tuple[float, float]
    share: float
    dynamic_range: float

    @property
    def rms(self) -> float:
        return float(np.sqrt(self.level * (self.band_hz[1] - self.band_hz[0])))


def noise_floor(x: ArrayLike, fs: float, f_high: float) -> NoiseFloor | None:
    """The white floor of ``x`` (sampled at ``fs`` Hz) below ``f_high`` Hz, or None where the
    record shows none (module docstring)."""
    f, s = psd(x, fs, FLOOR_SEGMENT_S)
    band = (f >= FLOOR_F_LOW) & (f <= f_high)
    if band.sum() < 8:
        return None
    sb = s[band]
    low = float(np.quantile(sb, 0.1))
    on_floor = sb <= FLOOR_SPREAD * low
    share = float(on_floor.mean())
    level = float(np.mean(sb[on_floor])) if on_floor.any() else 0.0
    if level <= 0.0 or share < FLOOR_SHARE:
        return None
    dynamic = float(sb.max()) / level
    if dynamic < FLOOR_RANGE:
        return None
    return NoiseFloor(level, (float(f[band][0]), float(f[band][-1])), share, dynamic)


def input_gain(f: ArrayLike, s: ArrayLike, floor: NoiseFloor) -> NDArray[np.float64]:
    """The gain (0-1) that keeps the input's bins with PSD ``s`` above FLOOR_SPREAD x the
    floor and removes the bins on it, rising as a raised cosine between FLOOR_EDGE and
    FLOOR_SPREAD x the floor (module docstring)."""
    ratio = np.asarray(s, dtype=float) / floor.level
    rise = np.clip((ratio - FLOOR_EDGE) / (FLOOR_SPREAD - FLOOR_EDGE), 0.0, 1.0)
    return 0.5 - 0.5 * np.cos(np.pi * rise)


def without_floor(x: ArrayLike, fs: float, floor: NoiseFloor) -> NDArray[np.float64]:
    """``x`` without its bins on the noise floor: zero-phase gain :func:`input_gain` of its
    Welch PSD, interpolated to the record's DFT grid (``signals.apply_gain``)."""
    f, s = psd(x, fs, FLOOR_SEGMENT_S)
    gain = input_gain(f, s, floor)
    return apply_gain(x, fs, lambda freqs: np.interp(freqs, f, gain),
                      round(2.0 * FLOOR_SEGMENT_S * fs))


#: On the floor's bins, a mean coherence of at least this between input and output, with a
#: transfer within SHARED_GAIN_TOL of -1, says the output holds the input sensor's noise (two
#: equal sensors give 0.5; unrelated noise about 1 / the Welch segments, 0.03 on 40 s). On
#: 15 literature records with two accelerometers: gain -0.97 to -1.02, coherence 0.28-0.49.
SHARED_COHERENCE = 0.2
SHARED_GAIN_TOL = 0.15


@dataclass(frozen=True)
class SharedNoise:
    """The input-to-output transfer over the input's floor bins: ``gain``, the median real
    part of the H1 estimate; ``coherence``, its mean coherence; ``bins``: how many."""

    gain: float
    coherence: float
    bins: int

    def shared(self, mass_ratio: float | None = None) -> bool:
        """The output holds the input sensor's noise with gain -1 (a difference with it).
        With the device's m/M, the gain must also lie nearer -1 than -m/M, a base input's
        gain above resonance where the floor is real base motion, not the sensor's noise."""
        near = abs(self.gain + 1.0) <= SHARED_GAIN_TOL
        if mass_ratio is not None:
            near = near and abs(self.gain + 1.0) < abs(self.gain + mass_ratio)
        return self.coherence >= SHARED_COHERENCE and near


def shared_noise(u: ArrayLike, y: ArrayLike, fs: float, floor: NoiseFloor) -> SharedNoise | None:
    """The transfer from the recorded input ``u`` to the output ``y`` (same units) over the
    bins where ``u`` is its noise floor alone (:func:`input_gain` zero); None with fewer
    than 8 such bins."""
    f, h1, coh = frf_h1(u, y, fs, FLOOR_SEGMENT_S)
    _, s = psd(u, fs, FLOOR_SEGMENT_S)
    on = (f > 0) & (input_gain(f, s, floor) == 0.0)
    if on.sum() < 8:
        return None
    return SharedNoise(float(np.median(h1.real[on])), float(np.mean(coh[on])), int(on.sum()))
