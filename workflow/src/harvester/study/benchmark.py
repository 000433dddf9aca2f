"""A public benchmark's test errors beside the published ones: the Silverbox (Wigren and
Schoukens 2013), each identified model simulated for each test's input alone, as the
benchmark scores a model (``data.public.SILVERBOX_TESTS``), its RMS error in mV after the
loader's initialisation window, in one table with the published errors on the same tests
(``data.published.SILVERBOX_PUBLISHED``, each read in its source, labelled black-box or
grey-box, with where it stands and whether its test is ours).

Our figures rest on how the test input is reconstructed between its samples: the simulator
interpolates it band-limited (``model.simulate``: ``scipy.signal.resample_poly``, a
non-causal FIR) before integrating. The table gives each of our models' errors with the
input held between samples (zero-order hold) and interpolated linearly too
(:func:`reconstruction_errors`), so that a reader sees what that choice is worth.
"""

from __future__ import annotations

from collections.abc import Mapping

import arviz as az
import numpy as np
import pandas as pd

from harvester.data.public import SILVERBOX_FS, SILVERBOX_INIT, SILVERBOX_TESTS, BenchmarkSplit
from harvester.data.published import (GREY_BOX, SILVERBOX_NOT_SHOWN, SILVERBOX_PUBLISHED,
                                      Published)
from harvester.inference.likelihood import DAQ_OVERSAMPLE

#: Posterior rows simulated for a test's predictive mean.
SAMPLES = 100
COLUMNS = ["model", "kind", *SILVERBOX_TESTS, "input between samples", "same test", "source",
           "notes"]
#: Our reconstruction of the input between samples, in words.
BAND_LIMITED = (f"band-limited (non-causal: scipy resample_poly to {DAQ_OVERSAMPLE} x the "
                "rate, then RK4 with the input linear between those points)")
#: The other reconstructions our errors are given under: name -> words.
RECONSTRUCTIONS = {"held": "held (zero-order hold)", "linear": "linear between samples"}
#: Points per sample of the fine grid the other reconstructions are integrated on, and the
#: posterior rows simulated there (fewer: each costs FINE / 4 times a band-limited one).
FINE = 16
RECONSTRUCTION_SAMPLES = 10
OURS = f"{GREY_BOX}, this study"


def simulation_errors(idata: az.InferenceData, split: BenchmarkSplit,
                      samples: int = SAMPLES, seed: int = 0) -> dict[str, float]:
    """Per test, the RMS error (mV) of the posterior's predictive mean (``samples`` thinned
    rows, simulated from rest for the test's input alone) after the first
    :data:`SILVERBOX_INIT` samples (``inference.unseen.heldout_error``)."""
    from harvester.inference.posterior import posterior_theta
    from harvester.inference.predictive import thin
    from harvester.inference.unseen import heldout_error, unseen_problem
    theta = thin(posterior_theta(idata), samples, seed)
    out = {}
    for name, (u, y) in split.tests.items():
        df = pd.DataFrame({"time": np.arange(len(u)) / SILVERBOX_FS, "force": u,
                           "rel_disp": y})
        problem = unseen_problem(idata, df, "posterior", f"SNLS80mV.mat {name}")
        out[name] = 1e3 * heldout_error(problem, theta, u, y, (SILVERBOX_INIT, len(y)))[
            "rms_error"]
    return out


def reconstructed(u: np.ndarray, how: str, q: int = FINE) -> np.ndarray:
    """The input ``u`` on a grid ``q`` times finer: ``held`` (each sample held until the
    next), ``linear`` (straight lines between samples; the last one held)."""
    if how == "held":
        return np.repeat(u, q)
    if how == "linear":
        return np.interp(np.arange(u.size * q) / q, np.arange(u.size), u)
    raise ValueError(f"reconstruction {how!r}: expected one of {sorted(RECONSTRUCTIONS)}")


def reconstruction_errors(idata: az.InferenceData, split: BenchmarkSplit, how: str,
                          samples: int = RECONSTRUCTION_SAMPLES, seed: int = 0
                          ) -> dict[str, float]:
    """As :func:`simulation_errors` with each test's input reconstructed ``how``
    (:func:`reconstructed`) on a grid :data:`FINE` times finer, the model integrated there
    without further oversampling and read at the test's samples."""
    from harvester.inference.posterior import posterior_theta
    from harvester.inference.predictive import posterior_predictive, thin
    from harvester.inference.unseen import unseen_problem
    theta = thin(posterior_theta(idata), samples, seed)
    out = {}
    for name, (u, y) in split.tests.items():
        uf = reconstructed(u, how)
        t = np.arange(uf.size) / (FINE * SILVERBOX_FS)
        df = pd.DataFrame({"time": t, "force": uf, "rel_disp": np.repeat(y, FINE)})
        problem = unseen_problem(idata, df, "posterior", f"SNLS80mV.mat {name}, {how}")
        mean = posterior_predictive(problem.replace(oversample=1), theta, uf, t).mean[::FINE]
        out[name] = 1e3 * float(np.sqrt(np.mean((y - mean)[SILVERBOX_INIT:] ** 2)))
    return out


def _published_row(p: Published) -> dict:
    return {"model": p.method, "kind": p.kind, **p.errors, "input between samples": "",
            "same test": p.same_test, "source": p.source, "notes": p.notes}


def benchmark_table(posteriors: Mapping[str, az.InferenceData], split: BenchmarkSplit,
                    samples: int = SAMPLES, seed: int = 0) -> pd.DataFrame:
    """One row per identified model (this study, its input band-limited), one per model and
    other reconstruction of the input (held, linear), then one per published method; a
    column per test (mV; empty where a source gives none)."""
    same = "the benchmark's three tests, after the loader's 50-sample window"
    rows = [{"model": m, "kind": OURS, **simulation_errors(idata, split, samples, seed),
             "input between samples": BAND_LIMITED, "same test": same, "source": "this study",
             "notes": ""} for m, idata in posteriors.items()]
    for how, words in RECONSTRUCTIONS.items():
        rows += [{"model": m, "kind": OURS,
                  **reconstruction_errors(idata, split, how, seed=seed),
                  "input between samples": words, "same test": same, "source": "this study",
                  "notes": "the same posterior; only the test input's reconstruction differs"}
                 for m, idata in posteriors.items()]
    rows += [_published_row(p) for p in SILVERBOX_PUBLISHED]
    return pd.DataFrame(rows, columns=COLUMNS)


def _cells(r: pd.Series) -> str:
    return "".join("<td>-</td>" if pd.isna(r[c]) else f"<td>{r[c]:.3f}</td>"
                   for c in SILVERBOX_TESTS)


def best_lines(table: pd.DataFrame) -> list[str]:
    """Per test, this study's lowest error (input band-limited) beside the lowest published
    one and their ratio, read from ``table``."""
    ours = table[(table["source"] == "this study")
                 & (table["input between samples"] == BAND_LIMITED)]
    published = table[table["source"] != "this study"]
    lines = []
    for test in SILVERBOX_TESTS:
        o, p = ours.dropna(subset=[test]), published.dropna(subset=[test])
        if o.empty or p.empty:
            continue
        a, b = o.loc[o[test].idxmin()], p.loc[p[test].idxmin()]
        lines.append(f"{test.replace('_', ' ')}: {a['model']} {a[test]:.3f} mV, best published "
                     f"{b[test]:.3f} mV ({b['model']}), ratio {b[test] / a[test]:.2f}")
    return lines


def benchmark_html(table: pd.DataFrame, fit_samples: int) -> str:
    """The table as a report page in the project's style (``harvester.report_style``), with
    how it was made, how to read it, and the quoted figures left out."""
    from harvester.report_style import esc, page
    head = "".join(f"<th>{esc(c.replace('_', ' '))} (mV)</th>" for c in SILVERBOX_TESTS)
    body = "".join(
        f"<tr><td>{esc(r['model'])}</td><td>{esc(r['kind'])}</td>{_cells(r)}"
        f"<td>{esc(r['input between samples'])}</td><td>{esc(r['same test'])}</td>"
        f"<td>{esc(r['source'])}</td><td>{esc(r['notes'])}</td></tr>"
        for _, r in table.iterrows())
    left_out = "".join(f"<li>{esc(n.method)} ({esc(n.reference)}): {esc(n.reason)}</li>"
                       for n in SILVERBOX_NOT_SHOWN)
    return page("The Silverbox benchmark: simulation error on its own tests", (
        f'<p class="headline">Each model identified on the first {fit_samples} samples '
        f"({fit_samples / SILVERBOX_FS:.1f} s) of the benchmark's training multisine "
        "(SNLS80mV.mat), simulated from rest for each test's input alone; RMS error of the "
        f"predictive mean in mV after the first {SILVERBOX_INIT} samples.</p>"
        "<p>The full arrow extrapolates in amplitude beyond the training record; its first "
        "32000 samples do not. This study's models are grey-box: the circuit's own "
        "structure (a mass-spring-damper, with a cubic spring) with a few parameters; the "
        "published rows are black-box models. Our errors depend on how the test input is "
        "reconstructed between its samples (a 68 Hz resonance sampled at 610 Hz): the first "
        "rows use the simulator's band-limited interpolation, which looks ahead (non-causal); "
        "the rows below give the same posterior with the input held or linear between "
        "samples. Each published figure was read in the source named beside it.</p>"
        "<h2>Best on each test</h2><ul>"
        + "".join(f"<li>{esc(line)}</li>" for line in best_lines(table)) + "</ul>"
        f"<h2>Errors</h2><table><tr><th>model</th><th>kind</th>{head}"
        "<th>input between samples</th><th>same test as ours</th><th>source</th>"
        f"<th>notes</th></tr>{body}</table>"
        f"<h2>Quoted figures not shown</h2><ul>{left_out}</ul>"))
