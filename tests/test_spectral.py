"""The diagnosis's noise replicates against a case with a known answer."""

from __future__ import annotations

import numpy as np

from harvester.diagnosis.detect.spectral import Frame, Metric, Projector, noise_replicates


def test_replicates_calibrate_a_low_frequency_score_with_an_estimated_spectrum():
    """Records of red noise; each is calibrated as the detection calibrates the data: its
    spectrum estimated from itself, replicates drawn from that estimate. z of a score below
    0.5 Hz, where the running median spans the fewest bins, must have unit spread (measured:
    1.02; 1.10 when the replicates' levels keep the estimate's mean)."""
    frame = Frame(fs=64.0, start=0, stop=2048, f_high=18.0)
    rng = np.random.default_rng(7)
    t = np.arange(frame.n) / frame.fs
    G = frame.dft(np.sin(2 * np.pi * 0.17 * t) + 0.7 * np.sin(2 * np.pi * 0.31 * t + 1.0))
    basis = frame.dft(np.ones(frame.n))[None, :]  # an offset the "baseline" absorbs
    true = (1.0 + (frame.freqs / 3.0) ** 2) ** -1.0 * frame.n
    z = []
    for _ in range(400):
        x = noise_replicates(true, frame, 1, rng, scatter=False)
        spectrum = frame.smoothed_periodogram(Projector(Metric(frame.mask), basis).apply(x)[0])
        metric = Metric(frame.mask / spectrum)
        proj = Projector(metric, basis)
        gp = proj.apply(G)
        s_obs = metric.inner(proj.apply(x), gp)[0, 0]
        s_rep = metric.inner(proj.apply(noise_replicates(spectrum, frame, 150, rng)), gp)[:, 0]
        z.append(s_obs / s_rep.std(ddof=1))
    z = np.array(z)
    assert 0.95 < z.std() < 1.05, z.std()
    assert abs(z.mean()) < 0.15
