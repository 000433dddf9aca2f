"""The peers' restoring-force regression (``harvester.grid.peers``, issue 64) on tiny
synthetic records: a cubic spring is named by pysindy's STLSQ with the tanh baseline's terms
kept, an effect-free record gets no name, and the outcome is scored as the diagnosis is.

Fast (a 20 s record at 256 Hz, solved by scipy); skipped without the ``[peers]`` extras.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

pytest.importorskip("pysindy")

from harvester.grid import peers  # noqa: E402

FS = 256.0
KNOWN = {"M": 1.0, "m": 0.8, "k": 400.0}
FREQS = np.array([1.3, 2.1, 2.9, 3.7, 4.6, 6.2, 8.1])


def _record(k3: float, seconds: float = 20.0, noise: float = 0.02, seed: int = 1,
            settle: float = 10.0):
    """M z'' + c z' + k z + F_c tanh(z'/v_t) + k3 z^3 = -m y'' from rest, y'' a sum of
    sines (m/s^2), z'' sampled at FS with white noise of ``noise`` x its RMS; the first
    ``settle`` s (the start's transient, decay time 2 M / c = 1 s) dropped."""
    from scipy.integrate import solve_ivp
    rng = np.random.default_rng(seed)
    phase = rng.uniform(0, 2 * np.pi, FREQS.size)
    base = lambda t: 1.5 * np.sum(np.sin(2 * np.pi * FREQS * t + phase))  # noqa: E731
    M, m, k, c, fc, vt = KNOWN["M"], KNOWN["m"], KNOWN["k"], 2.0, 0.5, 0.01

    def force(z, v):
        return c * v + k * z + fc * np.tanh(v / vt) + k3 * z**3

    def rhs(t, x):
        return [x[1], (-m * base(t) - force(x[0], x[1])) / M]

    t = np.arange(int((settle + seconds) * FS)) / FS
    sol = solve_ivp(rhs, (0, t[-1]), [0.0, 0.0], t_eval=t, rtol=1e-9, atol=1e-12,
                    max_step=0.5 / FS)
    y2 = np.array([base(s) for s in t])
    a = (-m * y2 - force(sol.y[0], sol.y[1])) / M
    a = a + noise * np.std(a) * rng.standard_normal(a.size)
    keep = t >= settle
    return pd.DataFrame({"time": t[keep] - settle, "base_acc": y2[keep], "rel_acc": a[keep]})


def _names(rec: pd.DataFrame, threshold: float = 0.5) -> list[str]:
    """pysindy's names at ``threshold`` x the residual force's RMS; the integrals of z'' leave
    about 0.04 N (1 % of the force) in the residual of the effect-free record, which lower
    thresholds name (measured: cubic_stiffness and four more at 0.05)."""
    n = len(rec)
    mo = peers.motion(rec)
    fit, held = slice(int(FS), int(0.75 * n)), slice(int(0.75 * n), n - int(0.5 * FS))
    (out,) = peers.sindy_names(mo, KNOWN, fit, held, thresholds=(threshold,))
    assert out.heldout_nrmse < 0.3  # 0.17-0.18 measured: the integrals' end effects
    return out.names


def test_a_cubic_spring_is_named_and_an_effect_free_record_is_not() -> None:
    assert _names(_record(k3=4e5))[:1] == ["cubic_stiffness"]
    assert _names(_record(k3=0.0)) == []


def test_the_outcome_is_scored_as_the_diagnosis_is() -> None:
    assert peers.score_names(["end_stop", "cubic_stiffness"], {"end_stop"}, False) == "right"
    assert peers.score_names(["cubic_stiffness", "end_stop"], {"end_stop"}, False) == "wrong"
    assert peers.score_names([], {"end_stop"}, False) == "missed"
    assert peers.score_names(["offset_force"], set(), True) == "false_alarm"
    assert peers.score_names([], set(), True) == "quiet"


def test_a_record_set_without_truth_is_refused(tmp_path) -> None:
    from harvester.data.daq import write_recording
    from harvester.data.errors import DataError
    write_recording(_record(0.0, seconds=4.0), tmp_path / "r.csv")
    with pytest.raises(DataError, match="truth"):
        peers.read_set(tmp_path)
