"""The frequency-domain frame of the diagnosis: analysis window, passband, noise spectrum,
weighted projections and noise replicates for calibration.

Residuals of a correct model are not white: the recordings are zero-phase low-passed (20 Hz
at 256 Hz in the study) and sensors add coloured noise. Every statistic of the diagnosis is
therefore computed from the residual's DFT restricted to the passband of the measurement
chain, weighted by the inverse of the residual's own smoothed spectrum (a generalised least
squares metric), and calibrated by replicates of stationary Gaussian noise with that spectrum
passed through exactly the same computations.

Conventions: x is a record (..., n_record); the analysis window is samples [start, stop);
``dft(x)`` is rfft(taper * x[start:stop]); inner products are
<A, B> = sum_k W_k Re(conj(A_k) B_k) with W_k = mask_k / S_k (S_k the smoothed periodogram).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy import ndimage, signal

#: Lowest analysed frequency (Hz): below it z'' holds almost no energy (z'' ~ w^2 z).
F_LOW_HZ = 0.1
#: Width (Hz) of the running median that smooths the periodogram into the noise spectrum,
#: and the fewest DFT bins it spans (the estimate's scatter is about 1.25 / sqrt(bins)).
SMOOTHING_HZ = 1.0
SMOOTHING_BINS = 41
#: At low frequencies the running estimates narrow to SMOOTHING_Q x f (never below
#: MIN_SMOOTHING_BINS bins): the noise floor changes fastest there. Base-sensor noise passes
#: into the residual in full below the resonance and only in part above it, and a median over
#: 1-2 Hz had put the floor at 0.1-0.2 Hz ninefold too low (measured on a linear device),
#: which made low-frequency signatures (an offset force) look significant.
SMOOTHING_Q = 0.5
MIN_SMOOTHING_BINS = 5
#: Local slope (dB per octave) beyond which a roll-off is taken for an anti-alias or
#: preprocessing low-pass rather than mechanics.
STEEP_DB_PER_OCTAVE = 40.0
#: Fraction of the window tapered (Tukey) to avoid leakage from the window's edges.
TAPER_FRACTION = 0.1


def filter_cutoff(x: np.ndarray, fs: float) -> float | None:
    """Cut-off (Hz) of a steep low-pass the record went through, from its spectrum alone.

    A zero-phase Butterworth of order 8 cuts 96 dB per octave, far steeper than any
    mechanical response or excitation spectrum (a resonance flank does not fall 40 dB in an
    octave). The cut-off is the lowest frequency above 2 Hz where the log-PSD falls faster
    than ``STEEP_DB_PER_OCTAVE`` locally and, from there, by more than that over the next
    octave (or to 0.95 x Nyquist). Found a little below the -6 dB point, so the diagnosis's
    own low-pass at that frequency keeps nothing the record's filter removed. None for a
    record with no such roll-off.
    """
    x = np.asarray(x, dtype=float)
    nyq = 0.5 * fs
    nper = int(min(len(x) // 4, round(8.0 * fs)))
    f, p = signal.welch(x - np.mean(x), fs=fs, nperseg=nper)
    keep = f > 0
    f, level = f[keep], 10.0 * np.log10(np.maximum(p[keep], 1e-300))
    grid = 2.0 ** np.arange(np.log2(max(f[0], 0.5)), np.log2(0.95 * nyq), 1.0 / 32.0)
    # average the log-PSD over 1/8 octave around each grid point
    smooth = np.array([np.mean(level[(f >= g * 2**-0.0625) & (f <= g * 2**0.0625)])
                       if np.any((f >= g * 2**-0.0625) & (f <= g * 2**0.0625))
                       else np.interp(g, f, level) for g in grid])
    step = 4  # 1/8 octave either side
    for i in range(step, len(grid) - step):
        if grid[i] < 2.0:
            continue
        slope = (smooth[i + step] - smooth[i - step]) / 0.25  # dB per octave
        if slope > -STEEP_DB_PER_OCTAVE:
            continue
        j = min(i + 32, len(grid) - 1)
        octaves = (j - i) / 32.0
        if octaves >= 0.25 and smooth[i] - smooth[j] >= STEEP_DB_PER_OCTAVE * octaves:
            return float(grid[i])
    return None


def recording_lowpass(given: float | None, input: np.ndarray, output: np.ndarray, fs: float
                      ) -> tuple[float | None, str | None]:
    """(the low-pass (Hz) a recording's output went through, a note or None): ``given`` (a
    sidecar's ``filtered_at_hz``, ``--filtered-at``; 0: none, and none is looked for), else
    the one the output's spectrum shows (:func:`filter_cutoff`) with :func:`shared_roll_off`'s
    note on it, else None."""
    if given is not None:
        return float(given) or None, None
    found = filter_cutoff(output, fs)
    return found, shared_roll_off(input, found, fs)


#: A found roll-off the input shows within this factor of the output's is noted as shared.
SHARED_ROLL_OFF = 1.1


def shared_roll_off(input: np.ndarray, cutoff: float | None, fs: float) -> str | None:
    """A note when the input rolls off where the output's low-pass was found: an excitation's
    band edge (a multisine's, the Silverbox's at 190 Hz) looks like a filter in both channels
    but is none, and filtering the model's output there as well removes response the
    recording holds (on the Silverbox: its cubic fit's noise sd 0.76 mV against 0.33 mV with
    ``filtered_at_hz: 0``). Either may be right; the note gives the evidence and the remedy."""
    if cutoff is None:
        return None
    own = filter_cutoff(input, fs)
    if own is None or not own <= SHARED_ROLL_OFF * cutoff:
        return None
    return (f"the input rolls off at {own:.4g} Hz too, where the output's low-pass was found "
            f"({cutoff:.4g} Hz): if that is the excitation's band edge and the recording went "
            "through no low-pass, say filtered_at_hz: 0 in its sidecar (--filtered-at 0)")


@dataclass
class Frame:
    """Analysis window, taper, frequency grid and passband mask."""

    fs: float
    start: int
    stop: int
    f_high: float
    f_low: float = F_LOW_HZ
    taper: np.ndarray = field(init=False, repr=False)
    freqs: np.ndarray = field(init=False, repr=False)
    mask: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        n = self.n
        self.taper = signal.windows.tukey(n, TAPER_FRACTION)
        self.freqs = np.fft.rfftfreq(n, 1.0 / self.fs)
        f = self.freqs
        mask = ((f >= self.f_low) & (f <= self.f_high)).astype(float)
        # cosine roll-off over the top 10 % of the band, so band-limited series do not ring
        top = 0.9 * self.f_high
        roll = (f > top) & (f <= self.f_high)
        mask[roll] = 0.5 * (1 + np.cos(np.pi * (f[roll] - top) / (self.f_high - top)))
        self.mask = mask

    @property
    def n(self) -> int:
        return self.stop - self.start

    @property
    def time_weight(self) -> np.ndarray:
        """Squared taper: the weight of each sample in band-limited energies."""
        return self.taper**2

    def dft(self, x: np.ndarray) -> np.ndarray:
        """rfft of the tapered window of x (..., n_record) -> (..., n_bins)."""
        x = np.asarray(x, dtype=float)
        return np.fft.rfft(self.taper * x[..., self.start:self.stop], axis=-1)

    def band_limited(self, X: np.ndarray) -> np.ndarray:
        """Time series (..., n) of a DFT restricted to the passband."""
        return np.fft.irfft(X * self.mask, n=self.n, axis=-1)

    def smoothed_periodogram(self, X: np.ndarray) -> np.ndarray:
        """Running median of |X_k|^2 over SMOOTHING_HZ (at least SMOOTHING_BINS bins), / ln 2.

        The median ignores narrow lines and intermittent bursts, so the estimate is the level
        of the broadband (noise) floor; zero-mean noise periodogram ordinates are exponential,
        whose median is ln 2 x mean.
        """
        p = np.abs(X) ** 2
        s = self._running(p, lambda x, w: ndimage.median_filter(
            x, size=(1,) * (x.ndim - 1) + (w,), mode="nearest")) / np.log(2.0)
        floor = 1e-12 * max(float(np.max(s)), 1e-300)
        return np.maximum(s, floor)

    @property
    def smoothing_bins(self) -> int:
        """Bins of the running estimates away from the lowest frequencies."""
        return max(SMOOTHING_BINS, int(round(SMOOTHING_HZ * self.n / self.fs)) | 1)

    @property
    def bin_widths(self) -> np.ndarray:
        """Odd number of bins of the running estimates at each bin: ``smoothing_bins``,
        narrowed to SMOOTHING_Q x f at low frequencies (at least MIN_SMOOTHING_BINS)."""
        df = self.fs / self.n
        w = np.round(SMOOTHING_Q * self.freqs / df).astype(int) | 1
        return np.clip(w, MIN_SMOOTHING_BINS, self.smoothing_bins)

    def _running(self, p: np.ndarray, smooth) -> np.ndarray:
        """``smooth(p, width)`` along the last axis with each bin's own width."""
        widths = self.bin_widths
        out = np.empty(p.shape, dtype=float)
        for w in np.unique(widths):
            sel = widths == w
            out[..., sel] = smooth(p, int(w))[..., sel]
        return out

    def smoothed_mean(self, p: np.ndarray) -> np.ndarray:
        """Running mean of a spectrum over SMOOTHING_HZ (narrower at low frequencies)."""
        return self._running(np.asarray(p, dtype=float), lambda x, w: ndimage.uniform_filter1d(
            x, w, axis=-1, mode="nearest"))


@dataclass
class Metric:
    """The weighted inner product <A, B> = sum_k W_k Re(conj(A_k) B_k), W = mask / S."""

    weight: np.ndarray  # (bins,)

    def inner(self, A: np.ndarray, B: np.ndarray) -> np.ndarray:
        """<A_i, B_j> for A (..., bins) and B (..., bins): matrix over the leading dims."""
        A, B = np.atleast_2d(A), np.atleast_2d(B)
        return (A.real * self.weight) @ B.real.T + (A.imag * self.weight) @ B.imag.T

    def gram(self, A: np.ndarray) -> np.ndarray:
        return self.inner(A, A)


class Projector:
    """Removes from DFTs the part the baseline's own parameters can absorb.

    ``basis`` (P, bins) holds the DFTs of the baseline's sensitivities d z''/d theta_j;
    ``apply(X)`` returns X - basis^T beta with beta the weighted least-squares coefficients.
    """

    def __init__(self, metric: Metric, basis: np.ndarray) -> None:
        self.metric = metric
        self.basis = np.atleast_2d(basis)
        if self.basis.size == 0 or self.basis.shape[0] == 0:
            self.solve = None
            return
        g = metric.gram(self.basis)
        scale = np.sqrt(np.maximum(np.diag(g), 1e-300))
        gs = g / np.outer(scale, scale)
        self._pinv = np.linalg.pinv(gs, rcond=1e-10) / np.outer(scale, scale)
        self.solve = True

    def coefficients(self, X: np.ndarray) -> np.ndarray:
        X = np.atleast_2d(X)
        return self.metric.inner(X, self.basis) @ self._pinv.T

    def apply(self, X: np.ndarray) -> np.ndarray:
        X2 = np.atleast_2d(X)
        if self.solve is None:
            return X2.copy() if X.ndim > 1 else X.copy()
        out = X2 - self.coefficients(X2) @ self.basis
        return out if X.ndim > 1 else out[0]


def noise_replicates(spectrum: np.ndarray, frame: Frame, count: int,
                     rng: np.random.Generator, envelope: np.ndarray | None = None,
                     scatter: bool = True) -> np.ndarray:
    """DFTs (count, bins) of Gaussian noise with the given periodogram level.

    ``spectrum`` is the expected |dft(x)|^2 of the tapered window (as
    :meth:`Frame.smoothed_periodogram` estimates it). Each replicate is generated as a whole
    series, optionally multiplied by a slowly varying ``envelope`` (n,) of mean square 1 (noise
    whose level drifts with time, as the residual's does), then tapered and transformed like
    the data, so edge effects and bin correlations match. ``scatter=False``: the level is
    ``spectrum`` itself (noise of a known spectrum).
    """
    n = frame.n
    level = spectrum / np.mean(frame.taper**2)
    # the spectrum is itself an estimate: each replicate draws its own level from what the
    # estimate allows, log-normal about it with the scatter of a running median over the
    # frame's bin widths (~1.25/sqrt(bins)). Not mean-preserving on purpose: given the
    # estimate S^, the true level has mean S^ exp(var/2), and the data's score, weighted by
    # 1/S^, has that much more variance than a fixed S^ implies. (With the mean kept at S^,
    # z of a score below 0.5 Hz, where the median spans 5 bins, had sd 1.10; now 1.02:
    # tests/test_spectral.py.)
    if scatter:
        level = level * np.exp(1.25 * frame.smoothed_mean(
            rng.standard_normal((count, level.size))))
    white = np.fft.rfft(rng.standard_normal((count, n)), axis=-1)
    series = np.fft.irfft(white * np.sqrt(level / n), n=n, axis=-1)
    if envelope is not None:
        series *= envelope
    return np.fft.rfft(frame.taper * series, axis=-1)


def level_envelope(x: np.ndarray, fs: float, seconds: float = 1.0) -> np.ndarray:
    """Slowly varying RMS level of x (Hann-weighted moving average of x^2 over ``seconds``),
    scaled to mean square 1."""
    width = max(3, int(round(seconds * fs)))
    kernel = np.hanning(width + 2)[1:-1]
    kernel /= kernel.sum()
    power = np.convolve(np.asarray(x, dtype=float) ** 2, kernel, mode="same")
    # edges: the kernel is cut, renormalise by its mass inside
    mass = np.convolve(np.ones_like(power), kernel, mode="same")
    power = power / np.maximum(mass, 1e-12)
    power = np.maximum(power, 1e-6 * max(float(np.mean(power)), 1e-300))
    return np.sqrt(power / np.mean(power))


def removed_input_psd(base_acc: np.ndarray, fs: float, cutoff_hz: float, order: int
                      ) -> tuple[np.ndarray, np.ndarray]:
    """(frequencies, PSD) of what a zero-phase low-pass at ``cutoff_hz`` removed from the input.

    The base acceleration's PSD is divided by the filter's power response where that is
    above 0.3, its log-log slope over the top of that range is continued beyond it (clipped
    to [-100, 0] dB per decade, so that it errs towards too much content), and the result is
    weighted by 1 - |H|^4, the share the filter took away.
    """
    x = np.asarray(base_acc, dtype=float)
    nper = int(min(len(x) // 4, round(4.0 * fs)))
    f, p = signal.welch(x - x.mean(), fs=fs, nperseg=nper)
    h4 = (1.0 / (1.0 + (np.maximum(f, 0.0) / cutoff_hz) ** (2 * order))) ** 2
    trusted = (h4 > 0.3) & (f > 0)
    unfiltered = np.where(trusted, p / np.maximum(h4, 1e-12), 0.0)
    top = np.flatnonzero(trusted)
    if top.size < 4:
        return f, np.zeros_like(f)
    fit = top[f[top] >= 0.7 * f[top[-1]]]
    if fit.size < 3:
        fit = top[-3:]
    slope, icpt = np.polyfit(np.log10(f[fit]), np.log10(np.maximum(unfiltered[fit], 1e-300)), 1)
    slope = float(np.clip(slope, -10.0, 0.0))
    pivot = f[top[-1]]
    level = 10.0 ** (icpt + slope * np.log10(pivot))
    beyond = f > pivot
    unfiltered[beyond] = level * (f[beyond] / pivot) ** slope
    return f, unfiltered * (1.0 - h4)
