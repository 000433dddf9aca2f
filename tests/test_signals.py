"""Zero-phase low-pass filter, PSD and H1 estimate (harvester.data.signals), Figures 4 and 5."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from harvester.data.errors import DataError
from harvester.data.signals import (CHANNELS, butterworth_sos, filter_recording,
                               filter_response_db, frf_h1, lowpass, psd, settling_samples,
                               uniform_step)

CONFIG = yaml.safe_load((Path(__file__).parents[1] / "config" / "config.yaml").read_text())
FS = float(CONFIG["rig"]["daq"]["sampling_rate_hz"])
CUTOFF = float(CONFIG["preprocess"]["lowpass_hz"])
ORDER = int(CONFIG["preprocess"]["filter_order"])


def tone_fit(x: np.ndarray, t: np.ndarray, f: float) -> tuple[float, float]:
    """(amplitude, phase in rad) of the f-Hz component of x by least squares."""
    basis = np.column_stack([np.cos(2 * np.pi * f * t), np.sin(2 * np.pi * f * t)])
    a, b = np.linalg.lstsq(basis, x, rcond=None)[0]
    return float(np.hypot(a, b)), float(np.arctan2(-b, a))


@pytest.fixture(scope="module")
def two_tones() -> pd.DataFrame:
    """20 s of 5 Hz + 50 Hz unit tones (phase 0.7 rad at 5 Hz) in both channels."""
    t = np.arange(int(20 * FS)) / FS
    x = np.cos(2 * np.pi * 5.0 * t + 0.7) + np.cos(2 * np.pi * 50.0 * t)
    return pd.DataFrame({"time": t, "base_acc": x, "rel_acc": x})


def test_default_config_is_the_papers_filter() -> None:
    assert (CUTOFF, ORDER) == (20.0, 8)


def test_analytic_response_attenuates_rocking_band_40db() -> None:
    gain = filter_response_db(np.linspace(30.0, 80.0, 501), FS, CUTOFF, ORDER)
    assert gain.max() <= -40.0


def test_analytic_response_passes_0_to_10hz_within_half_db() -> None:
    gain = filter_response_db(np.linspace(0.0, 10.0, 201), FS, CUTOFF, ORDER)
    assert np.abs(gain).max() <= 0.5


def test_measured_attenuation_on_tones(two_tones: pd.DataFrame) -> None:
    out = filter_recording(two_tones, CUTOFF, ORDER, channels=CHANNELS)
    t = out["time"].to_numpy()
    mid = (t > 2.0) & (t < 18.0)
    for channel in ("base_acc", "rel_acc"):
        a50, _ = tone_fit(out[channel].to_numpy()[mid], t[mid], 50.0)
        a5, _ = tone_fit(out[channel].to_numpy()[mid], t[mid], 5.0)
        assert 20 * np.log10(a50) <= -40.0
        assert abs(20 * np.log10(a5)) <= 0.5


def test_zero_phase_no_delay(two_tones: pd.DataFrame) -> None:
    t = two_tones["time"].to_numpy()
    y = lowpass(two_tones["rel_acc"].to_numpy(), FS, CUTOFF, ORDER)
    mid = (t > 2.0) & (t < 18.0)
    _, phase = tone_fit(y[mid], t[mid], 5.0)
    assert abs(phase - 0.7) < np.radians(0.1)
    x5 = np.cos(2 * np.pi * 5.0 * t + 0.7)
    lags = np.arange(-10, 11)
    xc = [np.dot(np.roll(y, -lag)[mid], x5[mid]) for lag in lags]
    assert lags[int(np.argmax(xc))] == 0


def test_same_filter_on_both_channels(two_tones: pd.DataFrame) -> None:
    out = filter_recording(two_tones, CUTOFF, ORDER, channels=CHANNELS)
    np.testing.assert_array_equal(out["base_acc"], out["rel_acc"])
    np.testing.assert_array_equal(out["time"], two_tones["time"])


def test_non_uniform_time_is_a_data_error(two_tones: pd.DataFrame) -> None:
    bad = two_tones.copy()
    bad.loc[10, "time"] += 0.5 / FS
    with pytest.raises(DataError, match="uniform"):
        filter_recording(bad, CUTOFF, ORDER, source="bad.csv")


def test_psd_integrates_to_variance() -> None:
    x = np.random.default_rng(1).normal(0.0, 2.0, 2**14)
    f, p = psd(x, FS)
    assert np.sum(p) * (f[1] - f[0]) == pytest.approx(4.0, rel=0.05)


def test_h1_of_a_gain_with_output_noise() -> None:
    rng = np.random.default_rng(2)
    u = rng.standard_normal(4096)
    f, h, coh = frf_h1(u, -0.625 * u + 0.01 * rng.standard_normal(u.size), FS)
    np.testing.assert_allclose(h[1:], -0.625, atol=0.01)
    assert coh[1:].min() > 0.99


def test_data_figures_are_written(two_tones: pd.DataFrame, tmp_path: Path) -> None:
    from harvester.plots.data import fig04_psd, fig05_time_history

    out = filter_recording(two_tones, CUTOFF, ORDER, channels=CHANNELS)
    fig04_psd(two_tones, out, FS, CUTOFF, tmp_path / "fig04.png")
    fig05_time_history(two_tones, out, tmp_path / "fig05.png", window=(2.0, 4.0))
    assert (tmp_path / "fig04.png").stat().st_size > 10_000
    assert (tmp_path / "fig05.png").stat().st_size > 10_000


def test_default_filters_the_output_only(two_tones: pd.DataFrame) -> None:
    out = filter_recording(two_tones, CUTOFF, ORDER)
    np.testing.assert_array_equal(out["base_acc"], two_tones["base_acc"])
    assert not np.allclose(out["rel_acc"], two_tones["rel_acc"])


def test_decimation_factor_keeps_the_rate_per_cutoff():
    from harvester.data.signals import decimation_factor
    assert decimation_factor(1024.0, 20.0) == 4
    assert decimation_factor(256.0, 20.0) == 1
    assert decimation_factor(1000.0, 18.2) == 4      # 250 Hz >= 12.8 x 18.2 = 233 Hz
    assert decimation_factor(5000.0, None) == 1      # unfiltered: the rate is kept


def test_decimated_recording_keeps_the_band_and_its_time_base():
    from harvester.data.signals import decimate_recording
    fs, q = 1024.0, 4
    t = np.arange(int(20 * fs)) / fs
    rng = np.random.default_rng(3)
    x = lowpass(rng.standard_normal(t.size), fs, CUTOFF, ORDER)
    df = pd.DataFrame({"time": t, "base_acc": x, "rel_acc": 0.5 * x})
    out = decimate_recording(df, q)
    assert list(out.columns) == list(df.columns) and len(out) == t.size // q
    np.testing.assert_allclose(np.diff(out["time"]), q / fs)
    inner = slice(100, -100)   # beyond the FIR's end effects
    err = out["base_acc"].to_numpy()[inner] - x[::q][inner]
    assert np.sqrt(np.mean(err**2)) < 1e-6 * np.std(x)
    np.testing.assert_allclose(out["rel_acc"], 0.5 * out["base_acc"], atol=1e-12)


def test_a_rate_with_no_integer_factor_is_resampled_by_a_ratio():
    """500 Hz with a 25 Hz filter has no integer factor down to 12.8 x 25 = 320 Hz; it goes
    to 333 Hz (2/3), and the band's sines come through on the new time base."""
    from harvester.data.signals import resample_recording, resampling_ratio
    assert resampling_ratio(500.0, 25.0) == (2, 3)
    assert resampling_ratio(1024.0, 20.0) == (1, 4)       # an integer factor is kept
    assert resampling_ratio(300.0, 20.0) == (1, 1)        # too little to gain
    fs = 500.0
    t = np.arange(int(20 * fs)) / fs
    freqs, phases = np.array([0.7, 5.0, 12.0, 22.0]), np.array([0.1, 1.0, 2.0, 0.4])

    def tones(tt):
        return np.sin(2 * np.pi * freqs[:, None] * tt[None, :] + phases[:, None]).sum(axis=0)

    df = pd.DataFrame({"time": t, "base_acc": tones(t), "rel_acc": 0.5 * tones(t)})
    out = resample_recording(df, 2, 3)
    tt = out["time"].to_numpy()
    assert list(out.columns) == list(df.columns) and len(out) == pytest.approx(t.size * 2 / 3, abs=1)
    np.testing.assert_allclose(np.diff(tt), 3 / (2 * fs))
    err = out["base_acc"].to_numpy() - tones(tt)
    assert np.sqrt(np.mean(err[300:-300] ** 2)) < 2e-6 * np.std(tones(t))
    np.testing.assert_allclose(out["rel_acc"], 0.5 * out["base_acc"], atol=1e-12)


def test_sampling_rate_accepts_time_written_to_nine_decimals():
    from harvester.data.signals import sampling_rate
    t = np.round(np.arange(4096) / 1024.0, 9)      # 0.000976562, 0.001953125, ...
    assert sampling_rate(pd.DataFrame({"time": t})) == pytest.approx(1024.0, rel=1e-9)


@pytest.mark.parametrize("fmt", ["%.9g", "%.6f"])
def test_times_written_with_few_digits_are_uniform(fmt: str) -> None:
    fs = 1024.0
    t = np.array([float(fmt % x) for x in np.arange(40 * 1024) / fs])
    assert uniform_step(t) == pytest.approx(1.0 / fs, rel=1e-7)


def test_a_dropped_sample_is_named_by_row() -> None:
    t = np.delete(np.arange(2000) / 256.0, 700)
    with pytest.raises(DataError, match="row 702"):
        uniform_step(t, "x.csv")


def test_a_zero_phase_filter_does_not_see_a_record_end_past_its_settling_samples():
    """What the electrical likelihood relies on: the record may stop settling_samples after
    the last sample it compares, and the filtered values there do not change (to 1e-10)."""
    sos = butterworth_sos(FS, CUTOFF, ORDER)
    n = settling_samples(sos)
    assert 100 < n < 2000
    x = np.random.default_rng(5).standard_normal(4000)
    whole = lowpass(x, FS, CUTOFF, ORDER)
    cut = lowpass(x[: 1500 + n], FS, CUTOFF, ORDER)
    assert np.max(np.abs(cut[:1500] - whole[:1500])) < 1e-10 * np.std(whole)
    early = lowpass(x[: 1500 + n // 4], FS, CUTOFF, ORDER)
    assert np.max(np.abs(early[:1500] - whole[:1500])) > 1e-6 * np.std(whole)
