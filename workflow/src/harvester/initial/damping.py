"""The viscous coefficient c_m of eq. (1) from the measured FRF z''/y'' (Table 1).

Eq. (1) with Coulomb friction f(z') = F_c sgn(z'), fitted to the measured FRF of the training
data. The friction is replaced by its Gaussian equivalent linearisation
c_eq = sqrt(2/pi) F_c / sigma_v, where sigma_v is the RMS relative velocity of the linearised
model driven by the measured base acceleration, solved self-consistently for every trial c_m.

The linearised eq. (1), M z'' + (c_m + c_eq) z' + k z = -m y'', has the FRF from base to
relative acceleration

    H(w) = Z''/Y'' = m w^2 / (k - M w^2 + i c w),      c = c_m + c_eq,

which tends to -m/M above resonance, and from base acceleration to relative velocity
H_v(w) = H(w) / (i w) = -i m w / (k - M w^2 + i c w).
"""

from __future__ import annotations

import logging
from dataclasses import asdict, dataclass, fields
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray
from scipy import optimize

from harvester.data.errors import DataError
from harvester.data.signals import SEGMENT_S, frf_h1, sampling_rate

log = logging.getLogger("harvester.initial")


#: Gaussian equivalent-linearisation factor of Coulomb friction: E|v| / sigma_v = sqrt(2/pi).
COULOMB_GAIN = float(np.sqrt(2.0 / np.pi))

#: Weight cap for coherence weighting: gamma^2 is clipped at this value.
MAX_COHERENCE = 0.99


# --------------------------------------------------------------------------- linearised model


def frf_relative_acceleration(freqs_hz: ArrayLike, M: float, m: float, k: float,
                              c: float) -> NDArray[np.complex128]:
    """FRF z''/y'' of the linear eq. (1): m w^2 / (k - M w^2 + i c w) (dimensionless).

    M, m in kg, k in N/m, c = total viscous coefficient in N s/m, frequencies in Hz.
    """
    w = 2.0 * np.pi * np.asarray(freqs_hz, dtype=float)
    return m * w**2 / (k - M * w**2 + 1j * c * w)


def frf_relative_velocity(freqs_hz: ArrayLike, M: float, m: float, k: float,
                          c: float) -> NDArray[np.complex128]:
    """FRF z'/y'' of the linear eq. (1): -i m w / (k - M w^2 + i c w), in s."""
    w = 2.0 * np.pi * np.asarray(freqs_hz, dtype=float)
    return -1j * m * w / (k - M * w**2 + 1j * c * w)


def linear_relative_acceleration(base_acc: ArrayLike, fs: float, M: float, m: float, k: float,
                                 c: float, from_rest: bool = False) -> NDArray[np.float64]:
    """z'' (m/s^2) of the linear eq. (1) driven by ``base_acc`` (m/s^2, fs Hz), via the FFT.

    ``from_rest=False``: steady-state (circular) response, for a record much longer than the
    decay time 2M/c. ``from_rest=True``: the response of the model starting at rest at the
    first sample (zero-padded, linear convolution).
    """
    y = np.asarray(base_acc, dtype=float)
    n_fft = 2 * y.size if from_rest else y.size
    f = np.fft.rfftfreq(n_fft, 1.0 / fs)
    h = frf_relative_acceleration(f, M, m, k, c)
    return np.fft.irfft(h * np.fft.rfft(y, n=n_fft), n=n_fft)[: y.size]


def coulomb_equivalent_damping(F_c: float, sigma_v: float) -> float:
    """Gaussian equivalent linearisation of F_c sgn(z'): c_eq = sqrt(2/pi) F_c / sigma_v (N s/m)."""
    return COULOMB_GAIN * F_c / sigma_v


class _VelocityRms:
    """RMS relative velocity (m/s) of the linear eq. (1) driven by a fixed base acceleration.

    Uses Parseval on the record's FFT, so sigma_v(c) is exact for the circular response.
    """

    def __init__(self, base_acc: NDArray[np.float64], fs: float, M: float, m: float,
                 k: float) -> None:
        y = base_acc - base_acc.mean()
        n = y.size
        self.freqs = np.fft.rfftfreq(n, 1.0 / fs)
        weight = np.full(self.freqs.size, 2.0)
        weight[0] = 1.0
        if n % 2 == 0:
            weight[-1] = 1.0
        self.power = weight * np.abs(np.fft.rfft(y)) ** 2 / n**2
        self.M, self.m, self.k = M, m, k

    def __call__(self, c: float) -> float:
        h_v = frf_relative_velocity(self.freqs, self.M, self.m, self.k, c)
        return float(np.sqrt(np.sum(self.power * np.abs(h_v) ** 2)))


def _self_consistent_sigma_v(rms: _VelocityRms, c_m: float, F_c: float) -> float:
    """Solve sigma_v = RMS velocity of the model with c = c_m + sqrt(2/pi) F_c / sigma_v.

    g(log s) = log s - log rms(c_m + c_eq(s)) is negative as s -> 0 (the friction
    locks the model) and positive for large s, so a bracketing root search converges.
    """
    if F_c <= 0.0:
        return rms(c_m)
    upper = rms(max(c_m, 1e-9))

    def g(log_s: float) -> float:
        s = np.exp(log_s)
        return log_s - np.log(rms(c_m + coulomb_equivalent_damping(F_c, s)))

    lower = np.log(upper) - 1.0
    while g(lower) > 0.0:
        lower -= 2.0
    return float(np.exp(optimize.brentq(g, lower, np.log(upper) + 1e-9, xtol=1e-10)))


def equivalent_linearisation(base_acc: ArrayLike, fs: float, M: float, m: float, k: float,
                             c_m: float, F_c: float) -> tuple[float, float]:
    """(c_eq in N s/m, sigma_v in m/s) of eq. (1) with Coulomb friction F_c (N), self-consistent.

    sigma_v is the RMS relative velocity of the linearised model driven by ``base_acc``
    (m/s^2, sampled at fs Hz) with total damping c_m + c_eq, c_eq = sqrt(2/pi) F_c / sigma_v.
    """
    rms = _VelocityRms(np.asarray(base_acc, dtype=float), fs, M, m, k)
    sigma_v = _self_consistent_sigma_v(rms, c_m, F_c)
    return (coulomb_equivalent_damping(F_c, sigma_v) if F_c > 0.0 else 0.0), sigma_v


# --------------------------------------------------------------------------- damping fit


@dataclass(frozen=True)
class DampingSummary:
    """The scalars of a :class:`DampingFit` (N s/m, m/s, N; band in Hz), as stored in JSON."""

    c_m: float
    c_eq: float
    sigma_v: float
    F_c: float
    residual: float
    band_hz: tuple[float, float]

    def to_dict(self) -> dict[str, Any]:
        """Plain dict (for JSON), with c_total = c_m + c_eq added for the reader."""
        return {**asdict(self), "band_hz": list(self.band_hz), "c_total": self.c_m + self.c_eq}

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> DampingSummary:
        """Inverse of :meth:`to_dict` (extra keys ignored)."""
        kw = {f.name: d[f.name] for f in fields(cls)}
        return cls(**{**kw, "band_hz": (float(d["band_hz"][0]), float(d["band_hz"][1]))})


@dataclass(frozen=True)
class DampingFit:
    """Viscous damping fitted by equivalent linearisation to the measured FRF z''/y''.

    c_m: fitted viscous coefficient (N s/m); c_eq: equivalent viscous coefficient of the
    Coulomb friction at the fit (N s/m); sigma_v: self-consistent RMS relative velocity (m/s);
    F_c: Coulomb friction used (N); residual: weighted RMS of the log-FRF misfit over the band
    (log-magnitude in nepers, with the phase in rad if it was fitted); freqs_hz: frequencies of the
    FRFs (Hz, the whole Welch grid); h_measured, h_model: H1 estimates of z''/y'' from the
    record and from the fitted linearised model driven by the same base acceleration;
    h_model_exact: the model's exact FRF; coherence: measured coherence; band_hz: fit band.
    """

    c_m: float
    c_eq: float
    sigma_v: float
    F_c: float
    residual: float
    freqs_hz: NDArray[np.float64]
    h_measured: NDArray[np.complex128]
    h_model: NDArray[np.complex128]
    h_model_exact: NDArray[np.complex128]
    coherence: NDArray[np.float64]
    band_hz: tuple[float, float]

    @property
    def c_total(self) -> float:
        """Total equivalent viscous coefficient c_m + c_eq (N s/m)."""
        return self.c_m + self.c_eq

    def summary(self) -> DampingSummary:
        """The fit's scalars, without the FRFs."""
        return DampingSummary(c_m=self.c_m, c_eq=self.c_eq, sigma_v=self.sigma_v, F_c=self.F_c,
                              residual=self.residual, band_hz=self.band_hz)


class _FrfMisfit:
    """Weighted misfit between the measured H1 and the linearised model's H1 over a band.

    The model FRF goes through the same estimator (H1 of the model's response to the
    measured base acceleration, same samples and Welch segments), so window leakage - large
    below 1 Hz where |H| rises as w^2 - and the finite record bias both sides alike. With a
    lead-in the model runs from rest at the first sample and both FRFs use the samples after
    the lead-in; without, the model response is the steady-state (circular) one. Weights
    gamma^2 / (1 - gamma^2) are the inverse variance of the H1 log-magnitude and phase.
    """

    def __init__(self, base_acc: NDArray[np.float64], rel_acc: NDArray[np.float64], fs: float,
                 M: float, m: float, k: float, F_c: float, band_hz: tuple[float, float],
                 segment_s: float, use_phase: bool, lead_in: int) -> None:
        self.base_acc, self.fs, self.segment_s = base_acc, fs, segment_s
        self.use_phase, self.lead_in = use_phase, lead_in
        self.M, self.m, self.k, self.F_c = M, m, k, F_c
        self.freqs, self.h_meas, self.coh = frf_h1(base_acc[lead_in:], rel_acc[lead_in:], fs,
                                                   segment_s)
        self.in_band = (self.freqs >= band_hz[0]) & (self.freqs <= band_hz[1])
        if self.in_band.sum() < 2:
            raise ValueError(f"fewer than two FRF lines in the band {band_hz} Hz")
        gamma2 = np.minimum(self.coh[self.in_band], MAX_COHERENCE)
        self.weight = gamma2 / (1.0 - gamma2)
        self.rms = _VelocityRms(base_acc[lead_in:], fs, M, m, k)

    def model(self, c_m: float) -> tuple[float, float, NDArray[np.complex128]]:
        """(c_eq, sigma_v, model H1 on the Welch grid) for a trial c_m (N s/m)."""
        sigma_v = _self_consistent_sigma_v(self.rms, c_m, self.F_c)
        c_eq = coulomb_equivalent_damping(self.F_c, sigma_v) if self.F_c > 0.0 else 0.0
        z_model = linear_relative_acceleration(self.base_acc, self.fs, self.M, self.m, self.k,
                                               c_m + c_eq, from_rest=self.lead_in > 0)
        _, h_model, _ = frf_h1(self.base_acc[self.lead_in:], z_model[self.lead_in:], self.fs,
                               self.segment_s)
        return c_eq, sigma_v, h_model

    def residuals(self, h_model: NDArray[np.complex128]) -> NDArray[np.float64]:
        """Log-magnitude misfit (nepers), plus phase misfit (rad) if ``use_phase``, in band."""
        r = np.log(self.h_meas[self.in_band] / h_model[self.in_band])
        return np.abs(r) if self.use_phase else np.abs(r.real)

    def __call__(self, c_m: float) -> float:
        """Weighted mean square of the log-FRF misfit over the band."""
        _, _, h_model = self.model(c_m)
        return float(np.sum(self.weight * self.residuals(h_model) ** 2) / np.sum(self.weight))


def _minimise_over_c(cost: _FrfMisfit, c_max: float) -> float:
    """Minimise cost(c_m) on [0, c_max]: log-spaced grid, then bounded Brent refinement."""
    grid = np.concatenate([[0.0], np.geomspace(1e-2, c_max, 40)])
    values = [cost(c) for c in grid]
    i = int(np.argmin(values))
    lo, hi = grid[max(i - 1, 0)], grid[min(i + 1, grid.size - 1)]
    res = optimize.minimize_scalar(cost, bounds=(lo, hi), method="bounded",
                                   options={"xatol": 1e-4 * max(hi, 1.0)})
    return float(res.x) if res.fun <= values[i] else float(grid[i])


def fit_viscous_damping(df: pd.DataFrame, M: float, m: float, k: float, F_c: float,
                        band_hz: tuple[float, float], lead_in: int = 0,
                        segment_s: float = SEGMENT_S, use_phase: bool = False,
                        source: str = "<recording>") -> DampingFit:
    """Fit c_m (N s/m) of eq. (1) with Coulomb friction F_c sgn(z') to the measured FRF z''/y''.

    ``df`` is a converted (normally low-passed) recording with ``time``, ``base_acc`` and
    ``rel_acc``; M, m (kg), k (N/m) and F_c (N) are held at their Table 1 values; band_hz is
    the fit band (config ``initial.damping_fit_band_hz``). For each trial c_m the Coulomb
    term is linearised as c_eq = sqrt(2/pi) F_c / sigma_v with sigma_v the self-consistent
    RMS relative velocity of the linearised model under the measured base acceleration; c_m
    minimises the coherence-weighted least-squares misfit of log |H| over the band (and of the
    phase if ``use_phase``: off by default, because with stick-slip the measured phase departs
    from any viscous model and pulls c_m further from the truth; see the tests). F_c = 0 fits a
    purely viscous model.

    lead_in (samples, config ``preprocess.training_lead_in``): the FRFs use the samples after
    it, and the linearised model runs from rest at the record's first sample, as the Bayesian
    models do; 0 uses the whole record with a steady-state model. segment_s is the Welch
    segment length (s).

    Accuracy (tests/test_initial.py): a linear system gives c_m back to 0.1 %; with Coulomb
    friction at the rig's level (c_eq about 6 c_m) the error is about +-10 % on 30 s records
    but +-25 % (and biased low) on 2000 samples, where c_m is a small part of c_m + c_eq.
    """
    for column in ("base_acc", "rel_acc"):
        if column not in df.columns:
            raise DataError(source, "missing channel", column=column)
    fs = sampling_rate(df, source)
    if not 0 <= lead_in < len(df) // 2:
        raise ValueError(f"lead_in must be in [0, {len(df) // 2}) samples, got {lead_in}")
    base = df["base_acc"].to_numpy(dtype=float)
    cost = _FrfMisfit(base, df["rel_acc"].to_numpy(dtype=float), fs, M, m, k, F_c,
                      (float(band_hz[0]), float(band_hz[1])), segment_s, use_phase, lead_in)
    c_m = _minimise_over_c(cost, c_max=40.0 * np.sqrt(k * M))
    c_eq, sigma_v, h_model = cost.model(c_m)
    return DampingFit(
        c_m=c_m, c_eq=c_eq, sigma_v=sigma_v, F_c=F_c, residual=float(np.sqrt(cost(c_m))),
        freqs_hz=cost.freqs, h_measured=cost.h_meas, h_model=h_model,
        h_model_exact=frf_relative_acceleration(cost.freqs, M, m, k, c_m + c_eq),
        coherence=cost.coh, band_hz=(float(band_hz[0]), float(band_hz[1])),
    )


#: Band (Hz) of the FRF damping fit of a single recording (the study's config
#: ``initial.damping_fit_band_hz``).
