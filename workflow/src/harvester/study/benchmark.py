"""A public benchmark's test errors beside the published ones: the Silverbox (Wigren and
Schoukens 2013), each identified model simulated for each test's input alone, as the
benchmark scores a model (``data.public.SILVERBOX_TESTS``), its RMS error in mV after the
loader's initialisation window, in one table with the published errors on the same tests
(``data.public.SILVERBOX_PUBLISHED``, each read in its source)."""

from __future__ import annotations

from collections.abc import Mapping

import arviz as az
import numpy as np
import pandas as pd

from harvester.data.public import (SILVERBOX_FS, SILVERBOX_INIT, SILVERBOX_PUBLISHED,
                                   SILVERBOX_TESTS, BenchmarkSplit)

#: Posterior rows simulated for a test's predictive mean.
SAMPLES = 100
COLUMNS = ["model", "source", *SILVERBOX_TESTS]


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


def benchmark_table(posteriors: Mapping[str, az.InferenceData], split: BenchmarkSplit,
                    samples: int = SAMPLES, seed: int = 0) -> pd.DataFrame:
    """One row per identified model (source "this study"), then one per published method,
    a column per test (mV; empty where a publication gives none)."""
    rows = [{"model": m, "source": "this study", **simulation_errors(idata, split, samples, seed)}
            for m, idata in posteriors.items()]
    rows += [{"model": method, "source": ref, **errors}
             for method, ref, errors in SILVERBOX_PUBLISHED]
    return pd.DataFrame(rows, columns=COLUMNS)


def benchmark_html(table: pd.DataFrame, fit_samples: int) -> str:
    """The table as a report page, with how it was made and how to read it."""
    head = "".join(f"<th>{c.replace('_', ' ')} (mV)</th>" for c in SILVERBOX_TESTS)
    body = ""
    for _, r in table.iterrows():
        cells = "".join("<td>-</td>" if pd.isna(r[c]) else f"<td>{r[c]:.3f}</td>"
                        for c in SILVERBOX_TESTS)
        body += f"<tr><td>{r['model']}</td>{cells}<td>{r['source']}</td></tr>"
    return (
        "<h2>The Silverbox benchmark: simulation error on its own tests</h2>"
        f"<p>Each model identified on the first {fit_samples} samples "
        f"({fit_samples / SILVERBOX_FS:.1f} s) of the benchmark's training multisine "
        "(SNLS80mV.mat), simulated from rest for each test's input alone; RMS error of the "
        f"predictive mean in mV after the first {SILVERBOX_INIT} samples, as the benchmark "
        "scores it. The arrow's full test extrapolates in amplitude beyond the training "
        "record; its first 32000 samples do not. Published errors on the same tests, each "
        "read in its source, below this study's.</p>"
        f"<table><tr><th>model</th>{head}<th>source</th></tr>{body}</table>")
