"""The diagnosis's summary page: one self-contained page, the verdict's headline first."""

from __future__ import annotations

import re
import shutil
import subprocess

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from harvester.diagnosis.report.summary_page import summary_page  # noqa: E402

DOC = {
    "verdict": "missing_physics",
    "headline": "missing_physics; linear explains 94 % of the validation output (NRMSE 0.233); "
                "no independent noise floor measured; missing: tanh_friction",
    "missing": ["tanh_friction"],
    "ties": [],
    "candidates": [{"round": 1, "effect": "tanh_friction", "delta_log_evidence": 812.0,
                    "delta_log_evidence_se": 0.4, "threshold": 5.4, "accepted": True,
                    "implies": "friction F_c tanh(beta z'): F_c 11.8 +- 0.1 N"}],
    "fit": {"baseline": {"structure": "linear", "nrmse": 0.233, "unseen_data": "validation"},
            "improved": {"structure": "tanh", "nrmse": 0.065, "unseen_data": "validation"}},
    "notes": ["a note <with> markup"],
    "figures": ["candidates.png", "extra_view.png"],
}


def _png(path):
    fig, ax = plt.subplots(figsize=(2, 1))
    ax.plot([0, 1], [0, 1])
    fig.savefig(path)
    plt.close(fig)


def test_the_page_opens_alone_with_the_headline_first(tmp_path):
    for name in ("candidates.png", "before_after.png", "extra_view.png"):
        _png(tmp_path / name)
    page = summary_page(DOC, tmp_path, "Diagnosis of linear")
    body = page[page.index("<body>"):]
    # the headline is the first thing after the title
    assert re.search(r"<h1>Diagnosis of linear</h1><p class=\"headline\">missing_physics; "
                     r"linear explains 94 %", body)
    # every figure embedded, none referenced as a file
    assert body.count("data:image/png;base64,") == 3
    assert not re.search(r"src=\"(?!data:)", body)
    assert "tanh_friction</b>: friction F_c tanh" in body
    assert "0.233" in body and "94.6%" in body  # the fit before and after, with its share
    assert "a note &lt;with&gt; markup" in body  # text is escaped


def test_sections_without_figures_are_left_out(tmp_path):
    page = summary_page({**DOC, "figures": []}, tmp_path, "t")
    assert "data:image" not in page and "The missing force" not in page
    assert "<h2>The candidates</h2><table>" in page  # the table stands without its figure


def test_withheld_names_are_said_beside_the_missing_force(tmp_path):
    """A diagnosis whose names were withheld (``verdict.withheld_names``) lists them as not
    named, with the missing force's description, and no "no library effect named"."""
    doc = {**DOC, "missing": [], "ties": [], "withheld": ["stribeck_friction"],
           "missing_force": {"shape": {"sentence": "a friction drifting in time"}}}
    page = summary_page(doc, tmp_path, "t")
    assert "not named, their force lacks the missing force's shape: stribeck_friction" in page
    assert "a friction drifting in time" in page and "no library effect named" not in page


def test_names_sized_together_are_said_with_their_interval(tmp_path):
    """Two names sized from one fit (``missing_force.together_force``): their summed own
    force with its interval, in the recording's force unit."""
    doc = {**DOC, "missing": ["cubic_stiffness", "inertia_error"], "missing_force": {
        "named_effects": [{"term": "cubic_stiffness", "force_unit": "V", "sentence": "s"}],
        "together": {"terms": ["cubic_stiffness", "inertia_error"], "rms_N": 0.00448,
                     "rms_interval_N": [0.00407, 0.00492], "mean_unfixed": False}}}
    page = summary_page(doc, tmp_path, "t")
    assert ("together, cubic_stiffness + inertia_error: their own force 0.00448 V RMS "
            "(95 % 0.00407-0.00492)") in page


def test_a_shape_fitted_as_a_term_is_said_where_it_speaks(tmp_path):
    """The periodic shape fitted as a term (``shape_terms``) is said where it speaks
    (``MissingForce.shape_speaks``: it withheld the names); elsewhere it is not (beside
    names whose model beats it, a flexible shape takes part of their force)."""
    shaped = {"speaks": True, "named": "tanh+hysteresis",
              "named_gain_nats": 91.0, "sentence": "a force periodic in z, period 0.101 mm"}
    doc = {**DOC, "missing": [], "withheld": ["hysteresis"],
           "missing_force": {"fitted_shape": shaped}}
    page = summary_page(doc, tmp_path, "t")
    assert ("fitted as a term of the model: a force periodic in z, period 0.101 mm; "
            "tanh+hysteresis gains +91 nats by the same measure") in page
    beaten = {**shaped, "speaks": False}
    page = summary_page({**DOC, "missing_force": {"fitted_shape": beaten}}, tmp_path, "t")
    assert "fitted as a term" not in page


CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")


@pytest.mark.skipif(CHROMIUM is None, reason="no chromium on this machine (.ci/run installs it)")
def test_the_page_renders_in_a_real_browser(tmp_path):
    """Headless Chromium opens the page alone (no file beside it): the headline is in its
    DOM first, and the embedded figure is drawn (a black square covering a known share of the
    screenshot; a broken image would leave the page white)."""
    fig_dir = tmp_path / "figs"
    fig_dir.mkdir()
    fig = plt.figure(figsize=(4, 4), dpi=100)
    fig.add_axes([0, 0, 1, 1]).add_patch(plt.Rectangle((0, 0), 1, 1, color="black"))
    fig.savefig(fig_dir / "candidates.png")
    plt.close(fig)
    page = tmp_path / "alone" / "summary.html"
    page.parent.mkdir()
    page.write_text(summary_page({**DOC, "figures": []}, fig_dir, "Diagnosis of linear"))
    shot = tmp_path / "shot.png"
    args = [CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
            "--window-size=1000,2000"]
    dom = subprocess.run(args + ["--dump-dom", page.as_uri()], capture_output=True, text=True,
                         timeout=120).stdout
    subprocess.run(args + [f"--screenshot={shot}", page.as_uri()], capture_output=True,
                   timeout=120, check=True)
    body = dom[dom.index("<body>"):]
    assert body.index('class="headline"') < body.index("<h2>")
    assert "linear explains 94 %" in body
    pixels = plt.imread(shot)[..., :3]
    dark = float(np.mean(pixels.max(axis=-1) < 0.1))
    assert dark > 0.05, f"only {dark:.1%} of the screenshot is dark: the figure was not drawn"
