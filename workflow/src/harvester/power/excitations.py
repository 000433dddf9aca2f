"""Base-acceleration records the device never saw.

``sea_state``: the vertical acceleration of a body that follows the sea surface (heave
response 1 up to ``band_hz[1]``), in a sea of the JONSWAP spectrum (Hasselmann et al. 1973,
"Measurements of wind-wave growth and swell decay during the Joint North Sea Wave Project",
Dtsch. Hydrogr. Z. A8(12); in the form of DNV-RP-C205 (2010), sec. 3.5.5):

    S_eta(w) = A_gamma (5/16) H_s^2 w_p^4 w^-5 exp(-5/4 (w/w_p)^-4) gamma^r,
    r = exp(-(w - w_p)^2 / (2 s^2 w_p^2)),  s = 0.07 (w <= w_p), 0.09 (w > w_p),
    A_gamma = 1 - 0.287 ln gamma,          S_acc(w) = w^4 S_eta(w),

synthesised with random phases and scaled to the paper's peak of 6 m/s^2 (measured on a boat,
Green et al. 2015, Discussion); the scaling makes H_s irrelevant, only the spectrum's shape
(T_p, gamma, band) matters. ``white_noise``: a flat spectrum over a band with random phases,
scaled to the same peak, the road-roughness case. Both are periodic in their duration (no
filter transient at their ends). ``read_excitation``: a
user's CSV with columns time (s, uniform) and base_acc (m/s^2).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from harvester.data.signals import uniform_step


@dataclass(frozen=True)
class Excitation:
    """A base-acceleration record: y'' (m/s^2) every dt (s), and what it is."""

    name: str
    base_acc: np.ndarray
    dt: float
    description: str

    @property
    def duration_s(self) -> float:
        return self.base_acc.size * self.dt

    def frame(self) -> pd.DataFrame:
        return pd.DataFrame({"time": np.arange(self.base_acc.size) * self.dt,
                             "base_acc": self.base_acc})


def jonswap(f_hz: np.ndarray, hs_m: float, tp_s: float, gamma: float) -> np.ndarray:
    """JONSWAP wave-elevation spectrum S_eta(w) (m^2 s/rad) at frequencies f (Hz)."""
    w = 2.0 * np.pi * np.asarray(f_hz, dtype=float)
    wp = 2.0 * np.pi / tp_s
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        pm = 5.0 / 16.0 * hs_m ** 2 * wp ** 4 * w ** -5.0 * np.exp(-1.25 * (w / wp) ** -4.0)
        s = np.where(w <= wp, 0.07, 0.09)
        peak = gamma ** np.exp(-((w - wp) ** 2) / (2.0 * s ** 2 * wp ** 2))
    out = (1.0 - 0.287 * np.log(gamma)) * pm * peak
    return np.where(w > 0, np.nan_to_num(out), 0.0)


def scaled_to_peak(x: np.ndarray, peak: float) -> np.ndarray:
    """x scaled so that max |x| = peak."""
    return x * (peak / np.max(np.abs(x)))


def random_phase(amplitude: np.ndarray, n: int, rng: np.random.Generator) -> np.ndarray:
    """A record of n samples with the given one-sided amplitude spectrum (rfft bins) and
    uniformly random phases: stationary and periodic, so no filter edge distorts its ends."""
    spectrum = amplitude * np.exp(2j * np.pi * rng.uniform(size=amplitude.size))
    return np.fft.irfft(spectrum, n)


def sea_state(cfg: Mapping, fs: float, rng: np.random.Generator) -> Excitation:
    """JONSWAP heave acceleration (module docstring); cfg: duration_s, tp_s, gamma, hs_m,
    band_hz, peak_m_s2."""
    n = int(round(float(cfg["duration_s"]) * fs))
    f = np.fft.rfftfreq(n, 1.0 / fs)
    lo, hi = (float(b) for b in cfg["band_hz"])
    s_acc = (2.0 * np.pi * f) ** 4 * jonswap(f, float(cfg["hs_m"]), float(cfg["tp_s"]),
                                            float(cfg["gamma"]))
    acc = random_phase(np.sqrt(s_acc * ((f >= lo) & (f <= hi))), n, rng)
    return Excitation("sea_state", scaled_to_peak(acc, float(cfg["peak_m_s2"])), 1.0 / fs,
                      describe("sea_state", cfg))


def white_noise(cfg: Mapping, fs: float, rng: np.random.Generator) -> Excitation:
    """Band-limited white noise: a flat spectrum over band_hz with random phases (Gaussian by
    the central limit theorem); cfg: duration_s, band_hz, peak_m_s2."""
    n = int(round(float(cfg["duration_s"]) * fs))
    f = np.fft.rfftfreq(n, 1.0 / fs)
    lo, hi = (float(b) for b in cfg["band_hz"])
    acc = random_phase(((f >= lo) & (f <= hi)).astype(float), n, rng)
    return Excitation("white_noise", scaled_to_peak(acc, float(cfg["peak_m_s2"])), 1.0 / fs,
                      describe("white_noise", cfg))


GENERATORS = {"sea_state": sea_state, "white_noise": white_noise}


def describe(name: str, cfg: Mapping) -> str:
    """One line saying what a shipped excitation is (figure titles, tables)."""
    lo, hi = cfg["band_hz"]
    if name == "sea_state":
        return (f"JONSWAP sea state, T_p {cfg['tp_s']:g} s, gamma {cfg['gamma']:g}, "
                f"{lo:g}-{hi:g} Hz, peak {cfg['peak_m_s2']:g} m/s^2")
    return f"white noise {lo:g}-{hi:g} Hz, peak {cfg['peak_m_s2']:g} m/s^2"


def make_excitation(name: str, cfg: Mapping, fs: float, seed: int) -> Excitation:
    """The shipped excitation ``name`` (config ``power.excitations``), seeded."""
    if name not in GENERATORS:
        raise KeyError(f"unknown excitation {name!r}; known: {sorted(GENERATORS)}")
    return GENERATORS[name](cfg, fs, np.random.default_rng(seed))


def read_excitation(path: str | Path, name: str | None = None) -> Excitation:
    """A user's base acceleration: CSV with time (s, uniform steps) and base_acc (m/s^2)."""
    df = pd.read_csv(path)
    missing = {"time", "base_acc"} - set(df.columns)
    if missing:
        raise ValueError(f"{path}: an excitation needs columns time (s) and base_acc "
                         f"(m/s^2); missing {sorted(missing)}")
    acc = df["base_acc"].to_numpy(dtype=float)
    if not np.isfinite(acc).all():
        raise ValueError(f"{path}: base_acc has non-numeric or missing values")
    dt = uniform_step(df["time"].to_numpy(dtype=float), path)
    return Excitation(name or Path(path).stem, acc, dt, f"user record {Path(path).name}")
