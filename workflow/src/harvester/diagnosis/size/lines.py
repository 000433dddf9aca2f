"""A line in what the missing force leaves: a sensor's or the acquisition's own periodic
contamination (mains hum at 50 or 60 Hz, a pump, a clock), which is in the recording but not
a force of the device.

The latent force (``latent.py``) takes a smooth force with one length scale; a line far above
the motion's band, on a device whose missing force is slow, it leaves in the output's
residual (the recording less the smoother's output, ``LatentForce.output_residual``), where
the noise's level took it in. On the literature generator's slow device (0.75 Hz) with a
0.127 m/s^2 hum on the mass accelerometer the smoother's response at 50 Hz was 1.3e-5, and
"no missing force" was said.

Test (:func:`residual_line`): the residual's Hann-windowed periodogram, each bin over its
neighbourhood's level (:func:`_ratios`), a ratio that is Exp(1) for Gaussian noise whose log
spectrum is near linear there, less the level's own estimation error (:func:`_tail`). The
largest ratio among the bins tested gives p = (bins tested) x its tail. A line is reported
where p < LINE_ALPHA and it is alone in its neighbourhood (no other bin there with
2 NEIGHBOURS x its tail < LINE_ALPHA): a comb of lines is the motion's (a periodic
excitation's response, which a misfit leaves at every harmonic of its period), not a
sensor's. Not tested: the lowest NEIGHBOURS + GUARD bins (the slow part, where the level has
no ring of its own and a slow misfit piles up: 0.2-0.4 Hz on two grid records), those beyond
EDGE x the band, and those where the input itself holds a line. Its amplitude (output's
unit) is the least-squares sinusoid's at the peak's frequency refined within a bin. On 300 records each of white and of low-passed
noise (4000 samples) no line was reported (0.6 expected at LINE_ALPHA); with the level
taken as the neighbours' median, without its error, 3 and 50 were.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage, optimize, signal

from harvester.diagnosis.size.latent import LatentForce

#: Family-wise false-alarm rate over the bins tested.
LINE_ALPHA = 1e-3
#: Bins on each side of a bin whose mean log power sets its local level, beyond GUARD.
NEIGHBOURS = 64
#: Bins on each side of a line held by its own leakage (Hann: the main lobe is +-2 bins).
GUARD = 3
#: The input holds a line at a bin whose own ratio's tail is below this.
ISOLATION_P = 1e-3
#: Bins tested lie below this share of the band's edge (or of the Nyquist frequency): the
#: chain's low-pass bends the residual's spectrum there faster than its level can follow.
EDGE = 0.9


@dataclass(frozen=True)
class ResidualLine:
    """A line found in the output's residual."""

    frequency_hz: float
    amplitude: float  # output's unit
    p_value: float
    unit: str

    def sentence(self) -> str:
        return (f"the recording holds a line at {self.frequency_hz:.4g} Hz, amplitude "
                f"{self.amplitude:.3g} {self.unit}, that the missing force does not (p = "
                f"{self.p_value:.2g}, alone in its neighbourhood): a sensor's or the "
                "acquisition's own contamination (mains hum at 50 or 60 Hz, a pump, a clock) "
                "rather than a force of the device")

    def to_dict(self) -> dict:
        return {"frequency_hz": self.frequency_hz, "amplitude": self.amplitude,
                "p_value": self.p_value, "unit": self.unit}


def _ratios(x: np.ndarray) -> tuple[np.ndarray, float]:
    """(each bin of the Hann periodogram of ``x`` over its neighbourhood's level, the sd of
    that level's log). The level: exp(mean log power + Euler's gamma) over the NEIGHBOURS
    bins on each side beyond GUARD (the ring is symmetric, so a linear trend of the log
    spectrum cancels); its log's sd: pi^2/6 over half the ring's bins (adjacent bins of a
    Hann periodogram are correlated)."""
    power = np.abs(np.fft.rfft((x - x.mean()) * signal.windows.hann(x.size))) ** 2
    ring = np.ones(2 * (NEIGHBOURS + GUARD) + 1)
    ring[NEIGHBOURS:NEIGHBOURS + 2 * GUARD + 1] = 0.0
    log_power = np.log(np.maximum(power, 1e-300))
    level = ndimage.convolve1d(log_power, ring / ring.sum(), mode="mirror") + np.euler_gamma
    return power / np.exp(level), float(np.sqrt(np.pi**2 / 6.0 / (ring.sum() / 2.0)))


_NODES, _WEIGHTS = np.polynomial.hermite.hermgauss(40)


def _tail(x: np.ndarray, sd: float) -> np.ndarray:
    """P(ratio > x) for Gaussian noise: the bin's power is its level times an Exp(1), the
    estimated level the true one times exp(eps), eps ~ N(0, sd^2): E exp(-x exp(eps))."""
    eps = np.sqrt(2.0) * sd * _NODES
    return np.exp(-np.multiply.outer(np.asarray(x, dtype=float), np.exp(eps))) @ _WEIGHTS \
        / np.sqrt(np.pi)


def _amplitude(r: np.ndarray, t: np.ndarray, f0: float, df: float) -> tuple[float, float]:
    """(frequency, amplitude) of the least-squares sinusoid within a bin of f0."""
    def fit(f: float) -> tuple[float, float]:
        basis = np.column_stack([np.cos(2 * np.pi * f * t), np.sin(2 * np.pi * f * t)])
        coef, res, *_ = np.linalg.lstsq(basis, r - r.mean(), rcond=None)
        return float(np.hypot(*coef)), float(res[0]) if res.size else 0.0

    best = optimize.minimize_scalar(lambda f: fit(f)[1], bounds=(f0 - df, f0 + df),
                                    method="bounded", options={"xatol": df * 1e-3})
    return float(best.x), fit(float(best.x))[0]


def residual_line(lf: LatentForce) -> ResidualLine | None:
    """The line of the output's residual (module docstring), None where there is none or the
    residual is too short to test (fewer than 4 NEIGHBOURS bins)."""
    r = np.asarray(lf.output_residual, dtype=float)
    if r.size < 8 * NEIGHBOURS:
        return None
    x, sd = _ratios(r)
    dt = float(lf.time[1] - lf.time[0])
    freqs = np.fft.rfftfreq(r.size, dt)
    top = min(lf.band_hz, 0.5 / dt) if np.isfinite(lf.band_hz) else 0.5 / dt
    tested = (np.arange(x.size) > NEIGHBOURS + GUARD) & (freqs < EDGE * top)
    inp = np.asarray(lf.input, dtype=float)
    if inp.size == r.size and np.ptp(inp) > 0:
        x_in, sd_in = _ratios(inp)
        tested &= ~ndimage.binary_dilation(_tail(x_in, sd_in) < ISOLATION_P, iterations=GUARD)
    if not tested.any():
        return None
    k = int(np.flatnonzero(tested)[np.argmax(x[tested])])
    p = min(1.0, tested.sum() * float(_tail(x[k], sd)))
    near = np.abs(np.arange(x.size) - k)
    others = (near > GUARD) & (near <= NEIGHBOURS + GUARD) & tested
    if p >= LINE_ALPHA or np.any(2 * NEIGHBOURS * _tail(x[others], sd) < LINE_ALPHA):
        return None
    df = float(freqs[1])
    f0, amp = _amplitude(r, lf.time, float(freqs[k]), df)
    unit = lf.units.label("displacement" if lf.output_kind == "rel_disp" else "acceleration")
    return ResidualLine(f0, amp, p, unit)
