"""Signal processing of the converted recordings: zero-phase low-pass filter, PSD and FRF.

A converted recording is a DataFrame with columns ``time`` (s, uniform), ``base_acc``
(base acceleration y'', m/s^2) and ``rel_acc`` (relative acceleration z'' of eq. (1), m/s^2).

The paper low-passes the training data at 20 Hz to remove the 30-80 Hz rocking mode of the
mass (Figures 4 and 5). We apply the SAME zero-phase Butterworth filter to both channels, so
the filter cancels from the frequency response z''/y'' and introduces no delay between them.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray
from scipy import signal

from harvester.data.errors import DataError

#: Channels of a converted recording.
CHANNELS: tuple[str, str] = ("base_acc", "rel_acc")
#: Channels filtered by default: the measured output only. The filter is part of how the output
#: is measured; the likelihood applies the same filter to the simulated output
#: (``Problem.output_filter``) and drives the model with the unfiltered input, which is what
#: the device felt (at the rig's true parameters this halves the misfit: 0.035 -> 0.020 m/s^2).
OUTPUT_CHANNELS: tuple[str, ...] = ("rel_acc",)

#: Default Welch segment length (s): 0.5 Hz resolution and about seven 50 %-overlapped
#: averages over the paper's 2000-sample (7.8 s) training record.
SEGMENT_S = 2.0


def butterworth_sos(fs: float, cutoff_hz: float, order: int) -> NDArray[np.float64]:
    """Digital Butterworth low-pass in second-order sections (cut-off in Hz, fs in Hz)."""
    if not 0.0 < cutoff_hz < fs / 2.0:
        raise ValueError(f"cut-off {cutoff_hz} Hz must lie in (0, {fs / 2.0}) Hz")
    if order < 1:
        raise ValueError(f"filter order must be >= 1, got {order}")
    return signal.butter(order, cutoff_hz, btype="low", fs=fs, output="sos")


def settling_samples(sos: NDArray[np.float64], tol: float = 1e-12) -> int:
    """Samples after which the filter's impulse response has fallen below ``tol`` of its
    start: ln(tol) / ln(r), r the largest pole radius. A zero-phase filter's values this far
    from a record's end do not depend (to ``tol``) on where the record ends."""
    radius = max(np.max(np.abs(np.roots(section[3:]))) for section in np.atleast_2d(sos))
    return int(np.ceil(np.log(tol) / np.log(radius)))


def apply_gain(x: ArrayLike, fs: float, gain, pad: int) -> NDArray[np.float64]:
    """``x`` (last axis, sampled at ``fs`` Hz) through the zero-phase gain ``gain(f)`` (f in
    Hz on the DFT grid), applied in the frequency domain; the record is mirrored by ``pad``
    samples at both ends first, so that the gain's response does not wrap round."""
    x = np.asarray(x, dtype=float)
    pad = min(x.shape[-1] - 1, int(pad))
    ext = np.concatenate([x[..., pad:0:-1], x, x[..., -2:-pad - 2:-1]], axis=-1)
    g = gain(np.fft.rfftfreq(ext.shape[-1], 1.0 / fs))
    out = np.fft.irfft(np.fft.rfft(ext, axis=-1) * g, n=ext.shape[-1], axis=-1)
    return out[..., pad:pad + x.shape[-1]]


def lowpass(x: ArrayLike, fs: float, cutoff_hz: float, order: int) -> NDArray[np.float64]:
    """Zero-phase low-pass of ``x`` (forward-backward Butterworth, ``sosfiltfilt``).

    The effective magnitude is the squared Butterworth response (see
    :func:`filter_response_db`) and the phase is exactly zero.
    """
    sos = butterworth_sos(fs, cutoff_hz, order)
    return signal.sosfiltfilt(sos, np.asarray(x, dtype=float))


def filter_response_db(freqs: ArrayLike, fs: float, cutoff_hz: float,
                       order: int) -> NDArray[np.float64]:
    """Effective gain (dB) of :func:`lowpass` at ``freqs`` (Hz): 20 log10 |H_b(f)|^2.

    The forward-backward pass squares the digital Butterworth magnitude |H_b| and cancels
    its phase, so the zero-phase attenuation in dB is twice the single-pass value.
    """
    sos = butterworth_sos(fs, cutoff_hz, order)
    _, h = signal.sosfreqz(sos, worN=np.asarray(freqs, dtype=float), fs=fs)
    return 20.0 * np.log10(np.maximum(np.abs(h) ** 2, 1e-300))


#: Largest deviation of one time step from the mean step, as a fraction of it: times written
#: with few digits (``%.9g``, ``%.6f`` at 1 kHz) pass, a dropped or doubled sample does not.
STEP_REL_TOL = 0.05


def time_base(t: ArrayLike) -> tuple[float, int | None, str]:
    """(mean step (s), index of the first sample off a uniform time base or None, why).

    The mean step is (t_end - t_0) / (n - 1). A sample is off when the step into it differs
    from the mean by more than :data:`STEP_REL_TOL` of it, or when it lies more than half a
    step off the uniform grid (a drifting clock). Time must increase.
    """
    t = np.asarray(t, dtype=float)
    steps = np.diff(t)
    if steps.size < 1:
        return float("nan"), 0, "fewer than 2 samples: no time step"
    step = float((t[-1] - t[0]) / steps.size)
    bad = np.flatnonzero((steps <= 0.0) | (np.abs(steps - step) > STEP_REL_TOL * step))
    if bad.size:
        i = int(bad[0])
        usual = float(np.median(steps))
        if steps[i] <= 0.0:
            why = (f"time does not increase: {t[i + 1]:.9g} s after {t[i]:.9g} s (a repeated "
                   f"or reordered sample; the usual step is {usual:.9g} s)")
        else:
            why = (f"non-uniform time base: step {steps[i]:.9g} s from {t[i]:.9g} s, expected "
                   f"{usual:.9g} s (the usual step)")
            if steps[i] > 1.5 * usual:
                why += f": about {steps[i] / usual - 1:.0f} samples missing"
        return step, i + 1, why
    off = np.flatnonzero(np.abs(t - (t[0] + step * np.arange(t.size))) > 0.5 * step)
    if off.size:
        i = int(off[0])
        return step, i, (f"non-uniform time base: time {t[i]:.9g} s is more than half a step "
                         f"off the uniform grid of step {step:.9g} s")
    return step, None, ""


def uniform_step(t: ArrayLike, source: str | Path = "<recording>") -> float:
    """Mean step (s) of a time column (:func:`time_base`); DataError naming the first row
    (1 = header) off a uniform time base."""
    step, bad, why = time_base(t)
    if bad is not None:
        raise DataError(source, f"{why} (row {bad + 2})", column="time")
    return step


def sampling_rate(df: pd.DataFrame, source: str = "<recording>") -> float:
    """Sampling rate (Hz) of a converted recording, checking its time column is uniform."""
    if "time" not in df.columns:
        raise DataError(source, "no time column", column="time")
    t = df["time"].to_numpy(dtype=float)
    uniform_step(t, source)
    return float((t.size - 1) / (t[-1] - t[0]))


def filter_recording(df: pd.DataFrame, cutoff: float, order: int,
                     source: str = "<recording>",
                     channels: tuple[str, ...] = OUTPUT_CHANNELS) -> pd.DataFrame:
    """Copy of a converted recording with ``channels`` low-passed (zero phase).

    cutoff in Hz (config ``preprocess.lowpass_hz``, 20 Hz in the paper); order of the
    Butterworth prototype (config ``preprocess.filter_order``). By default only the measured
    output z'' is filtered (see :data:`OUTPUT_CHANNELS`).
    """
    missing = [c for c in channels if c not in df.columns]
    if missing:
        raise DataError(source, f"missing channel(s) {missing}", column=missing[0])
    fs = sampling_rate(df, source)
    out = df.copy()
    for channel in channels:
        out[channel] = lowpass(df[channel].to_numpy(dtype=float), fs, cutoff, order)
    return out


#: Samples per second kept per hertz of a recording's low-pass cut-off when it is resampled for
#: the model: the study's 256 Hz for its 20 Hz filter.
RATE_PER_CUTOFF = 12.8


def decimation_factor(fs: float, cutoff_hz: float | None,
                      rate_per_cutoff: float = RATE_PER_CUTOFF) -> int:
    """Largest integer q with fs / q >= ``rate_per_cutoff`` x ``cutoff_hz`` (1: keep fs).

    A recording low-passed at ``cutoff_hz`` carries nothing the model needs above it, and
    simulating it at a higher rate only costs time (the integrator sub-steps on its own).
    Unfiltered recordings (``cutoff_hz`` None) keep their rate.
    """
    if cutoff_hz is None or not cutoff_hz > 0:
        return 1
    return max(1, int(np.floor(fs / (rate_per_cutoff * cutoff_hz) + 1e-9)))


#: Largest denominator of a rational resampling ratio (``resampling_ratio``), and the least
#: saving in rate for which a recording is resampled by a non-integer ratio.
MAX_RESAMPLE_DOWN = 8
MIN_RESAMPLE_SAVING = 1.25


def resampling_ratio(fs: float, cutoff_hz: float | None,
                     rate_per_cutoff: float = RATE_PER_CUTOFF) -> tuple[int, int]:
    """(up, down): the recording is resampled to fs up / down >= ``rate_per_cutoff`` x
    ``cutoff_hz``. An integer decimation (1, q) where one exists (:func:`decimation_factor`);
    else the smallest such rate with down <= MAX_RESAMPLE_DOWN, if it saves at least
    MIN_RESAMPLE_SAVING (500 Hz with a 25 Hz filter: (2, 3), 333 Hz); else (1, 1)."""
    q = decimation_factor(fs, cutoff_hz, rate_per_cutoff)
    if q > 1 or cutoff_hz is None or not cutoff_hz > 0:
        return 1, q
    need = rate_per_cutoff * cutoff_hz
    ratios = [(int(np.ceil(need * down / fs - 1e-9)), down)
              for down in range(2, MAX_RESAMPLE_DOWN + 1)]
    up, down = min(((u, d) for u, d in ratios if u < d), key=lambda r: r[0] / r[1],
                   default=(1, 1))  # equal ratios: the first, coprime one
    return (up, down) if down >= MIN_RESAMPLE_SAVING * up else (1, 1)


#: Anti-alias low-pass before keeping every q-th sample: zero-phase Butterworth of this order
#: at this fraction of the new Nyquist frequency (gain 1 - 1e-10 below 0.2 x that frequency).
ANTIALIAS_ORDER = 8
ANTIALIAS_FRACTION = 0.8


def chain_cutoff(fs: float, lowpass_hz: float | None = None) -> float:
    """Cut-off (Hz) of the measurement chain a recording sampled at ``fs`` (Hz) went through:
    its low-pass ``lowpass_hz``, or without one the model's own DAQ anti-alias edge
    (ANTIALIAS_FRACTION x Nyquist). Above that edge the model's acquisition and the
    recording's unknown anti-alias filter differ (a flat FIR keeps at 105 Hz of a 256 Hz record
    what the model's Butterworth cuts to 0.14), so the residual there is the two filters'
    difference, not physics."""
    return float(lowpass_hz) if lowpass_hz else ANTIALIAS_FRACTION * 0.5 * float(fs)


def antialias_decimate(x: ArrayLike, fs: float, q: int) -> NDArray[np.float64]:
    """Every q-th sample along the last axis after the anti-alias low-pass (ANTIALIAS_*), as a
    data acquisition samples a faster signal."""
    x = np.asarray(x, dtype=float)
    if q == 1:
        return x.copy()
    return lowpass(x, fs, ANTIALIAS_FRACTION * fs / (2.0 * q), ANTIALIAS_ORDER)[..., ::q]


def decimate_recording(df: pd.DataFrame, q: int) -> pd.DataFrame:
    """Every q-th sample of a recording: time, and each other column through
    :func:`antialias_decimate`. Every channel gets the same linear filter, so an
    input-output relation in the retained band is kept."""
    if q < 1:
        raise ValueError(f"decimation factor must be >= 1, got {q}")
    t = df["time"].to_numpy(dtype=float)
    fs = 1.0 / uniform_step(t)
    out = {c: t[::q] if c == "time" else antialias_decimate(df[c].to_numpy(dtype=float), fs, q)
           for c in df.columns}
    return pd.DataFrame(out, columns=list(df.columns))


#: The polyphase FIR of a non-integer resampling: half-length in zero crossings of the new
#: rate, and its Kaiser window's beta (sines below 0.2 x the new Nyquist frequency come
#: through with RMS error < 5e-7 of their amplitude, measured at 2/3 and 5/8; scipy's
#: default, 10 crossings and beta 5, leaves 1e-3).
RESAMPLE_ZERO_CROSSINGS = 32
RESAMPLE_KAISER_BETA = 12.0


def resample_recording(df: pd.DataFrame, up: int, down: int) -> pd.DataFrame:
    """A recording at up / down its rate: an integer decimation (up 1) by
    :func:`decimate_recording`, else every column but time by ``scipy.signal.resample_poly``
    with the FIR of RESAMPLE_* (the same linear filter on every channel) and time on the new
    uniform grid from the first sample."""
    if up == 1:
        return decimate_recording(df, down)
    if up < 1 or down <= up:
        raise ValueError(f"resampling ratio must be up/down < 1, got {up}/{down}")
    t = df["time"].to_numpy(dtype=float)
    dt = uniform_step(t)
    fir = signal.firwin(2 * RESAMPLE_ZERO_CROSSINGS * down + 1, 1.0 / down,
                        window=("kaiser", RESAMPLE_KAISER_BETA))
    out = {c: signal.resample_poly(df[c].to_numpy(dtype=float), up, down, window=fir,
                                   padtype="line")
           for c in df.columns if c != "time"}
    n = len(next(iter(out.values())))
    out["time"] = t[0] + np.arange(n) * dt * down / up
    return pd.DataFrame(out, columns=list(df.columns))


def _nperseg(n: int, fs: float, segment_s: float) -> int:
    """Welch segment length (samples): ``segment_s`` seconds, at most half the record."""
    return int(max(8, min(round(segment_s * fs), n // 2 if n >= 16 else n)))


def psd(x: ArrayLike, fs: float, segment_s: float = SEGMENT_S
        ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """One-sided Welch PSD of ``x``: (frequencies in Hz, PSD in units^2/Hz).

    Hann windows of ``segment_s`` seconds (at most half the record), 50 % overlap,
    linear detrend per segment.
    """
    x = np.asarray(x, dtype=float)
    nperseg = _nperseg(x.size, fs, segment_s)
    return signal.welch(x, fs=fs, nperseg=nperseg, noverlap=nperseg // 2, detrend="linear")


def frf_h1(u: ArrayLike, y: ArrayLike, fs: float, segment_s: float = SEGMENT_S
           ) -> tuple[NDArray[np.float64], NDArray[np.complex128], NDArray[np.float64]]:
    """H1 estimate of the FRF from input ``u`` to output ``y``, with coherence.

    H1(f) = S_uy(f) / S_uu(f) (Welch cross- and auto-spectra, same segments as :func:`psd`);
    returns (frequencies in Hz, complex H1 in units(y)/units(u), coherence in [0, 1]).
    """
    u = np.asarray(u, dtype=float)
    y = np.asarray(y, dtype=float)
    if u.shape != y.shape:
        raise ValueError(f"input and output differ in length: {u.shape} vs {y.shape}")
    nperseg = _nperseg(u.size, fs, segment_s)
    kw = dict(fs=fs, nperseg=nperseg, noverlap=nperseg // 2, detrend="linear")
    f, s_uu = signal.welch(u, **kw)
    _, s_yy = signal.welch(y, **kw)
    _, s_uy = signal.csd(u, y, **kw)
    h1 = s_uy / np.where(s_uu > 0.0, s_uu, np.inf)
    denom = s_uu * s_yy
    coh = np.where(denom > 0.0, np.abs(s_uy) ** 2 / np.where(denom > 0.0, denom, 1.0), 0.0)
    return f, h1, np.clip(coh, 0.0, 1.0)
