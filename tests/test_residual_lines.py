"""A sensor's or the acquisition's line in what the missing force leaves (``lines``): found
with its frequency and amplitude, not on noise at more than its nominal rate, not in a comb
of lines (a periodic motion's) and not where the input holds the line."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from harvester.diagnosis.size.lines import LINE_ALPHA, residual_line
from test_latent_shapes import _noisy_latent

pytestmark = pytest.mark.filterwarnings("ignore::UserWarning", "ignore::RuntimeWarning")


def _with(residual, inp=None, seed=0):
    lf = _noisy_latent(0.0, n=residual.size, draws=2, seed=seed)
    broadband = np.random.default_rng(seed + 100).standard_normal(residual.size)
    return dataclasses.replace(lf, output_residual=residual,
                               input=broadband if inp is None else inp)


def test_a_line_in_the_residual_is_found_with_its_size():
    """0.03 m at 23.4 Hz under white noise of sd 0.1 m (4000 samples at 100 Hz)."""
    rng = np.random.default_rng(1)
    t = np.arange(4000) * 0.01
    found = residual_line(_with(0.1 * rng.standard_normal(t.size)
                                + 0.03 * np.sin(2 * np.pi * 23.4 * t + 1.0)))
    assert found is not None
    assert found.frequency_hz == pytest.approx(23.4, abs=0.005)
    assert found.amplitude == pytest.approx(0.03, rel=0.1)
    assert found.p_value < LINE_ALPHA and found.unit == "m"
    assert "23.4 Hz" in found.sentence()


def test_noise_alone_gives_no_line_beyond_its_rate():
    """White and low-passed (coloured) noise, 300 records each: LINE_ALPHA = 1e-3 lets
    0.6 through on average; none came (with the level the neighbours' median, taken as
    exact: 3 and 50, the coloured ones where the filter's zero at Nyquist bends the
    spectrum)."""
    from scipy import signal
    sos = signal.butter(4, 0.2, output="sos")
    found = 0
    for seed in range(300):
        rng = np.random.default_rng(seed)
        white = rng.standard_normal(4000)
        found += residual_line(_with(white, seed=seed)) is not None
        found += residual_line(_with(signal.sosfilt(sos, white), seed=seed)) is not None
    assert found <= 2


def test_a_comb_of_lines_is_the_motions_and_a_line_of_the_input_is_the_excitations():
    """Lines at every 0.5 Hz from 5 to 15 Hz (a periodic response's misfit) are not one
    sensor's line; nor is a line the input holds at the same frequency."""
    rng = np.random.default_rng(2)
    t = np.arange(4000) * 0.01
    comb = sum(0.02 * np.sin(2 * np.pi * f * t + rng.uniform(0, 6)) for f in
               np.arange(5.0, 15.01, 0.5))
    assert residual_line(_with(0.1 * rng.standard_normal(t.size) + comb)) is None
    hum = 0.03 * np.sin(2 * np.pi * 23.4 * t)
    inp = rng.standard_normal(t.size) + 5.0 * np.sin(2 * np.pi * 23.4 * t)
    assert residual_line(_with(0.1 * rng.standard_normal(t.size) + hum, inp)) is None


def test_a_sensor_line_on_a_recording_is_noted_by_the_diagnosis():
    """0.05 m/s^2 at 13.3 Hz added to the rel_acc channel of a linear device's recording
    (f_n 0.7 Hz, 20 Hz low-pass): the missing force's run finds it in the residual and the
    verdict notes it; without it, no such note."""
    from types import SimpleNamespace

    from latent_records import linear_state, recording, rk4_record
    from harvester.diagnosis.size.missing_force import missing_force
    from harvester.diagnosis.prepare.settings import DiagnosisSettings
    from harvester.diagnosis.name.verdict import Conclusion, FitJudgement, judge
    found = Conclusion("adequate", [], [], False, [], None, False)
    detection = SimpleNamespace(p_value=0.3, significant=False, conflict=False)
    fit = FitJudgement(0.98, 0.14, "holdout", 1.0, None, None)
    notes = {}
    for amplitude in (0.05, 0.0):
        rec = recording(rk4_record(lambda z, v, t: 0.0 * z, 16.0), "rel_acc")
        rec["rel_acc"] += amplitude * np.sin(2 * np.pi * 13.3 * rec["time"] + 0.5)
        out = missing_force(linear_state(rec), draws=20)
        if amplitude:
            assert out.residual_line.frequency_hz == pytest.approx(13.3, abs=0.01)
            assert out.residual_line.amplitude == pytest.approx(amplitude, rel=0.1)
            assert out.to_dict()["residual_line"]["unit"] == "m/s^2"
        judged = judge(found, detection, fit, "linear", DiagnosisSettings(), out)
        notes[amplitude] = [n for n in judged.notes if "holds a line" in n]
    assert len(notes[0.05]) == 1 and "13.3 Hz" in notes[0.05][0]
    assert notes[0.0] == []
