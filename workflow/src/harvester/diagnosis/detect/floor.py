"""The recording's own noise floor, measured where the model has no say.

The detection calibrates its statistics by replicates that take the residual's own spectrum
and level (``detect.replicates``): on a model that explains nothing, the residual is the whole
signal, the replicates are as large as the mismatch, and sigma swallows it. The floor here is
found from the recording alone, so that the mismatch cannot set it, by the first of these that
the recording allows:

* ``repeated_periods``: the input repeats with a period of P samples (a harmonic or periodic
  multisine excitation): where u(t + P) = u(t) to within PERIOD_INPUT_TOL of its RMS, a device
  in steady state answers alike, and half the mean square of y(t + P) - y(t) is the noise's
  variance (Pintelon and Schoukens, *System Identification: A Frequency Domain Approach*,
  2012, sec. 2.4). Transients and responses that do not repeat (stick-slip that varies from
  cycle to cycle) add to it: it is an upper bound of the floor.
* ``quiet_lead_in``: the record starts with the input at rest (moving RMS below QUIET_SHARE of
  its RMS for at least QUIET_MIN_S): the output there is the sensors' noise. Disturbances that
  only act while the device moves are not in it: a lower bound of the floor under motion.
* ``white_band``: the output's spectrum shows a white floor over part of the analysed band
  (``data.input_noise.noise_floor``, the same test as for the input channel), extrapolated over
  the band.

Each estimate is taken on the output as the residual sees it (through the measurement chain's
low-pass), so that it compares with the residual's RMS over the same band. Where none applies
the floor is None and the verdict rests on the detection and on the share of unseen data the
model explains (``verdict``), and says so.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from harvester.data.input_noise import noise_floor

#: A period is accepted where the input's normalised autocorrelation reaches this value.
PERIOD_CORRELATION = 0.98
#: Shortest period (s) searched, and the longest as a share of the analysed window.
PERIOD_MIN_S = 0.1
PERIOD_MAX_SHARE = 1.0 / 3.0
#: Pairs t, t + P count as repeated where |u(t + P) - u(t)| is below this share of u's RMS ...
PERIOD_INPUT_TOL = 0.05
#: ... and the floor needs at least this many periods' worth of such pairs.
PERIOD_MIN_COUNT = 2.0
#: Seconds dropped at each end of the shifted signals.
PERIOD_EDGE_S = 0.5
#: A quiet lead-in: moving RMS (window QUIET_WINDOW_S) of the input below QUIET_SHARE of its
#: RMS, from the record's start, for at least QUIET_MIN_S; QUIET_EDGE_S dropped at each end.
QUIET_SHARE = 0.02
QUIET_WINDOW_S = 0.25
QUIET_MIN_S = 0.5
QUIET_EDGE_S = 0.1


@dataclass(frozen=True)
class Floor:
    """The output's noise floor: its RMS over the analysed band (output units), the method
    (module docstring), what it rests on (``detail``) and whether it bounds the floor from
    above (``bound``: "upper", "lower" or "estimate")."""

    rms: float
    method: str
    detail: str
    bound: str

    def to_dict(self) -> dict:
        return dict(self.__dict__)


def input_period(u: np.ndarray, fs: float) -> int | None:
    """The input's period in samples (the lag of its normalised autocorrelation's highest
    peak above PERIOD_CORRELATION, the shortest of ties), or None."""
    x = np.asarray(u, dtype=float) - np.mean(u)
    n = x.size
    lo, hi = int(np.ceil(PERIOD_MIN_S * fs)), int(n * PERIOD_MAX_SHARE)
    if hi <= lo + 2 or not np.any(x):
        return None
    spec = np.fft.rfft(x, 2 * n)
    ac = np.fft.irfft(np.abs(spec) ** 2)[:n]
    ac = ac / (ac[0] * (n - np.arange(n)) / n)  # unbiased, normalised
    seg = ac[lo:hi]
    peaks = np.flatnonzero((seg[1:-1] >= seg[:-2]) & (seg[1:-1] >= seg[2:])
                           & (seg[1:-1] >= PERIOD_CORRELATION)) + 1
    if peaks.size == 0:
        return None
    best = float(seg[peaks].max())
    return int(lo + peaks[np.argmax(seg[peaks] >= best - 1e-3)])


def advanced(x: np.ndarray, lag: float) -> np.ndarray:
    """x(t + lag) for a fractional ``lag`` in samples, by a band-limited (DFT) shift; the
    last ``ceil(lag)`` samples wrap round and are not to be used."""
    n = x.size
    k = np.fft.rfftfreq(n)
    return np.fft.irfft(np.fft.rfft(x) * np.exp(2j * np.pi * k * lag), n=n)


def refined_period(u: np.ndarray, period: int) -> float:
    """The fractional period (samples) near ``period`` that best repeats ``u``."""
    from scipy.optimize import minimize_scalar

    m = u.size - period - 2

    def mismatch(lag: float) -> float:
        return float(np.mean((advanced(u, lag)[:m] - u[:m]) ** 2))

    return float(minimize_scalar(mismatch, bounds=(period - 1.0, period + 1.0),
                                 method="bounded", options={"xatol": 1e-3}).x)


def periodic_floor(u: np.ndarray, y: np.ndarray, fs: float) -> Floor | None:
    """``repeated_periods`` (module docstring) over the given stretch of input ``u`` and
    chained output ``y``: the period refined to a fraction of a sample and both signals
    advanced by it (``advanced``), PERIOD_EDGE_S dropped at each end (the shift's wrap)."""
    whole = input_period(u, fs)
    if whole is None:
        return None
    period = refined_period(np.asarray(u, dtype=float), whole)
    edge = int(round(PERIOD_EDGE_S * fs))
    keep = slice(edge, u.size - int(np.ceil(period)) - edge)
    du = (advanced(u, period) - u)[keep]
    same = np.abs(du) <= PERIOD_INPUT_TOL * np.std(u)
    if same.sum() < PERIOD_MIN_COUNT * period:
        return None
    dy = (advanced(y, period) - y)[keep][same]
    rms = float(np.sqrt(0.5 * np.mean(dy**2)))
    return Floor(rms, "repeated_periods",
                 f"input period {period / fs:.5g} s ({period:.2f} samples), "
                 f"{same.sum() / period:.1f} periods' worth of repeated input", "upper")


def quiet_floor(u: np.ndarray, y: np.ndarray, fs: float) -> Floor | None:
    """``quiet_lead_in`` (module docstring) from the record's first sample."""
    w = max(int(round(QUIET_WINDOW_S * fs)), 1)
    u = np.asarray(u, dtype=float)
    power = np.convolve(u**2, np.ones(w) / w, mode="same")
    quiet = np.sqrt(power) < QUIET_SHARE * np.sqrt(np.mean(u**2))
    stop = int(np.argmin(quiet)) if not quiet.all() else quiet.size
    edge = int(round(QUIET_EDGE_S * fs))
    if (stop - 2 * edge) / fs < QUIET_MIN_S:
        return None
    seg = np.asarray(y[edge:stop - edge], dtype=float)
    return Floor(float(np.std(seg)), "quiet_lead_in",
                 f"{(stop - 2 * edge) / fs:.3g} s before the input moves", "lower")


def white_floor(y_recorded: np.ndarray, fs: float, band_hz: float) -> Floor | None:
    """``white_band`` (module docstring): the white floor of the recorded output below
    ``band_hz`` (the likelihood's low-pass), over that band."""
    found = noise_floor(y_recorded, fs, band_hz)
    if found is None:
        return None
    return Floor(float(np.sqrt(found.level * band_hz)), "white_band",
                 f"white over {found.share:.0%} of {found.band_hz[0]:.2g}-{found.band_hz[1]:.3g} "
                 f"Hz, {found.dynamic_range:.3g} x below the strongest line", "estimate")


def output_floor(u: np.ndarray, y_recorded: np.ndarray, y_chain: np.ndarray,
                 window: tuple[int, int], fs: float, band_hz: float) -> Floor | None:
    """The first floor the recording allows (module docstring): input ``u`` and recorded
    output ``y_recorded`` as recorded, ``y_chain`` the output through the measurement chain,
    ``window`` the analysed samples, ``band_hz`` the chain's band. Repeated periods are
    sought over the whole record given (the floor owes nothing to the model, so the lead-in
    counts too: a window of 2.9 periods of the Silverbox's multisine holds too few)."""
    a, b = window
    return (periodic_floor(u, y_chain, fs) or quiet_floor(u, y_chain, fs)
            or white_floor(y_recorded[a:b], fs, band_hz))


def problem_floor(p) -> Floor | None:
    """:func:`output_floor` of a likelihood's problem (``inference.map_fit.ChainProblem``):
    its recorded input and output, the output through its chain, its window and band."""
    return output_floor(p.base_acc, p.rel_acc, p.measured_chain, p.window, 1.0 / p.dt,
                        p.band_hz)
