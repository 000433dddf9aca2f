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


def test_a_displacement_is_differentiated_within_its_band() -> None:
    """z' and z'' of a band-limited displacement, spectrally, against the analytic ones: at
    0.3 x the rate (the Silverbox's band edge) central differences lose half the slope."""
    fs, f = 610.0, 0.3 * 610.0
    t = np.arange(4096) / fs
    z = np.sin(2 * np.pi * 5.0 * t) + 0.01 * np.sin(2 * np.pi * f * t)
    v, a = peers.differentiate(z, fs)
    w1, w2 = 2 * np.pi * 5.0, 2 * np.pi * f
    inner = slice(200, -200)
    v_true = w1 * np.cos(w1 * t) + 0.01 * w2 * np.cos(w2 * t)
    a_true = -w1**2 * np.sin(w1 * t) - 0.01 * w2**2 * np.sin(w2 * t)
    assert np.max(np.abs(v - v_true)[inner]) < 1e-3 * np.max(np.abs(v_true))
    assert np.max(np.abs(a - a_true)[inner]) < 1e-3 * np.max(np.abs(a_true))


REPO = __import__("pathlib").Path(__file__).resolve().parents[1]


def test_the_real_recordings_are_a_record_set_with_their_truths(tmp_path) -> None:
    """The frame and the Silverbox written with their truth files (``grid.recorded``) and
    read back as a record set: the frame's friction on the ground, the Silverbox a force
    record without M; a real record is not effect-free (its strength is not known), and the
    diagnosis of one is scored against the names its truth counts right."""
    from harvester.grid.recorded import DRY_FRICTION, write_recorded_set
    write_recorded_set(REPO / "data" / "public", tmp_path)
    recs = {r.path.stem: r for r in peers.read_set(tmp_path)}
    assert sorted(recs) == ["frame_250g", "frame_450g", "silverbox"]
    frame, box = recs["frame_450g"], recs["silverbox"]
    assert frame.friction_on == "ground" and frame.baseline == "linear"
    assert frame.correct == set(DRY_FRICTION) and "asymmetric_friction" not in frame.correct
    assert box.correct == {"cubic_stiffness"} and "M" not in box.known
    assert not frame.effect_free and not box.effect_free
    assert frame.truth["diagnose"] == "recording"
    mo = peers.motion(frame.data, str(frame.path), frame.friction_on)
    assert not np.allclose(mo.w, mo.v)  # the absolute velocity z' + y'
    said = {"verdict": "missing_physics", "missing": ["hysteresis"], "runtime_s": 1.0}
    assert peers.diagnosis_row(frame, lambda r: said)["outcome"] == "right"
    assert peers.diagnosis_row(box, lambda r: said)["outcome"] == "wrong"


def test_a_cubic_spring_is_named_on_a_force_record_whose_mass_is_not_known() -> None:
    """The force-driven form (the Silverbox's): F = M z'' + f(z, z'), M a free column."""
    rec = _record(k3=4e5)
    _, z = peers.integrate(rec["rel_acc"].to_numpy(), FS, 0.5)
    force = pd.DataFrame({"time": rec["time"], "force": -KNOWN["m"] * rec["base_acc"],
                          "rel_disp": z})
    mo = peers.motion(force)
    assert mo.force is not None and peers.inertia_free(mo, {})
    n = len(force)
    fit, held = slice(int(FS), int(0.75 * n)), slice(int(0.75 * n), n - int(0.5 * FS))
    (out,) = peers.sindy_names(mo, {}, fit, held, thresholds=(0.5,))
    assert out.names[:1] == ["cubic_stiffness"]


def test_the_benchmark_page_is_linked_from_the_report_and_the_diagnosis_page() -> None:
    """The Silverbox group's diagnosis page links its benchmark page (``summary_page``'s
    ``links``, given by the rule for a benchmark group), and the report's front page and the
    diagnosis caption link the benchmark page where the report holds one."""
    from harvester.diagnosis.report.summary_page import summary_page
    page = summary_page({"verdict": "adequate"}, REPO, "t", [("tests", "../../benchmark.html")])
    assert '<h2>See also</h2><ul><li><a href="../../benchmark.html">tests</a>' in page
    assert "See also" not in summary_page({"verdict": "adequate"}, REPO, "t")
    common = (REPO / "workflow" / "rules" / "common.smk").read_text()
    assert '"../../benchmark.html"' in common
    assert "links=lambda w: group_links(w.group)" in \
        (REPO / "workflow" / "rules" / "diagnose.smk").read_text()
    for rst in ("workflow.rst", "diagnosis.rst"):
        assert "`benchmark.html`_" in (REPO / "workflow" / "report" / rst).read_text()
    assert "docs/peers.md" in (REPO / "workflow" / "report" / "benchmark.rst").read_text()
