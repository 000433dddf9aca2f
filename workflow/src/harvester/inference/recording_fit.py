"""Identification of one recording's model structure, and what a run writes (``harvester
identify``, ``harvester compare``).

A run's directory holds ``posterior.nc`` (ArviZ InferenceData: posterior samples and the
TMCMC statistics), ``summary.csv`` (parameter, unit, posterior mean, sd, 2.5 and 97.5 %
quantiles, prior mean and sd), ``evidence.json`` (log evidence per chain, pooled over chains,
its standard error) and ``posterior_pairs.png``. ``evidence.json`` is written last: a
directory holding it holds a finished run (:func:`load_fit` resumes from it).
"""

from __future__ import annotations

import json
import logging
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path

import arviz as az
import numpy as np
import pandas as pd

from harvester.data.errors import DataError
from harvester.data.fileio import atomic_path, write_json
from harvester.data.signals import uniform_step
from harvester.inference.identify import TMCMCSettings, identify
from harvester.inference.problems import make_problem
from harvester.inference.likelihood import Problem
from harvester.inference.posterior import (adjusted_draws, interval_columns, log_evidence,
                                          parameter_names,
                                          pooled_log_evidence)
from harvester.inference.priors import PriorSpec

log = logging.getLogger("harvester.inference.recording_fit")

#: Columns of summary.csv.
SUMMARY_COLUMNS = ["parameter", "unit", "mean", "sd", "q2.5", "q97.5", "sd_adj", "q2.5_adj",
                   "q97.5_adj", "prior"]
#: Seconds at the end of a low-passed record left out of the likelihood (the zero-phase
#: filter's end effects).
END_EFFECTS_S = 0.5


@dataclass(frozen=True)
class FitWindow:
    """The samples a recording's likelihood uses: after ``lead_in_s`` (s; the model starts at
    rest), at most ``fit_seconds`` (s; None: to the end), and ``lowpass_hz`` (Hz, or None),
    the zero-phase low-pass the recording went through, applied to the simulated output too
    (order ``filter_order``; its end effects, END_EFFECTS_S, are left out)."""

    lead_in_s: float = 1.0
    lowpass_hz: float | None = None
    filter_order: int = 8
    fit_seconds: float | None = None


def recording_problem(df: pd.DataFrame, model: str, known: Mapping[str, float],
                      window: FitWindow, source: str = "<recording>", hint: str = "") -> Problem:
    """The identification problem of a recording (``make_problem``), with DataError naming
    ``source`` for a record too short for the lead-in, a low-pass above its Nyquist frequency,
    or base parameters that the data cannot scale (``hint`` says where to give them)."""
    dt = uniform_step(df["time"].to_numpy(dtype=float), source)
    n = len(df)
    lead = int(round(window.lead_in_s / dt))
    stop = n - (int(round(END_EFFECTS_S / dt)) if window.lowpass_hz else 0)
    if window.fit_seconds is not None:
        stop = min(stop, lead + int(round(window.fit_seconds / dt)))
    if stop - lead < 64:
        raise DataError(source, f"too short: {n * dt:.3g} s leaves {max(stop - lead, 0)} samples "
                        f"after the {window.lead_in_s:g} s lead-in; at least 64 are needed")
    fs = 1.0 / dt
    if window.lowpass_hz is not None and not 0 < window.lowpass_hz < fs / 2:
        raise DataError(source, f"low-pass {window.lowpass_hz:g} Hz must lie in (0, {fs / 2:g}) "
                        "Hz, below the recording's Nyquist frequency")
    flt = (window.lowpass_hz, window.filter_order) if window.lowpass_hz else None
    try:
        return make_problem(df, model, known, window=(lead, stop), output_filter=flt)
    except ValueError as err:  # e.g. a base_acc input with no known scale
        raise DataError(source, str(err) + hint) from None


def parameter_table(idata: az.InferenceData, priors: Mapping[str, PriorSpec]) -> pd.DataFrame:
    """Posterior mean, sd and 95 % interval of each parameter (eq. (10)'s, and adjusted for
    correlated residuals: ``*_adj``), with its unit and prior."""
    adjusted = adjusted_draws(idata)
    rows = []
    for name in parameter_names(idata):
        x = idata.posterior[name].values.reshape(-1)
        spec = priors.get(name)
        rows.append({"parameter": name, "unit": spec.unit if spec else "",
                     **interval_columns(x, adjusted.get(name)),
                     "prior": spec.describe() if spec else ""})
    return pd.DataFrame(rows, columns=SUMMARY_COLUMNS)


def interval_lines(table: pd.DataFrame) -> list[str]:
    """One line per parameter of a :func:`parameter_table`: its mean and 95 % interval, and
    where stored the interval adjusted for correlated residuals."""
    lines = []
    for r in table.to_dict("records"):
        line = (f"  {r['parameter']} = {r['mean']:.5g} {r['unit']}".rstrip()
                + f", 95 % [{r['q2.5']:.5g}, {r['q97.5']:.5g}]")
        if np.isfinite(r["sd_adj"]):
            line += f"; for correlated residuals [{r['q2.5_adj']:.5g}, {r['q97.5_adj']:.5g}]"
        lines.append(line)
    return lines


def evidence_summary(idata: az.InferenceData) -> dict:
    """Log evidence (nats) per chain, pooled over chains (log of the mean evidence) and its
    standard error: the sd over chains / sqrt(chains); with one chain the kernel's own
    estimate (``sample_stats.log_evidence_se``) where it gives one, else None."""
    chains = np.asarray(log_evidence(idata), dtype=float)
    stats = idata.sample_stats
    within = (np.asarray(stats["log_evidence_se"].values, dtype=float).reshape(-1)
              if "log_evidence_se" in stats else None)
    if chains.size > 1:
        se, note = float(np.std(chains, ddof=1) / np.sqrt(chains.size)), \
            "standard error: sd of the chains' log evidences / sqrt(chains)"
    elif within is not None:
        se, note = float(within[0]), "one chain: the kernel's within-chain standard error"
    else:
        se, note = None, "one chain: no error estimate (use --chains >= 2)"
    out = {"log_evidence_per_chain": chains.tolist(), "log_evidence": pooled_log_evidence(chains),
           "standard_error": se, "chains": int(chains.size), "note": note}
    if within is not None:
        out["standard_error_per_chain"] = within.tolist()
    return out


@dataclass
class Fit:
    """One identified structure: its problem, posterior, priors and evidence summary."""

    problem: Problem
    idata: az.InferenceData
    priors: dict[str, PriorSpec]
    evidence: dict

    def summary(self) -> pd.DataFrame:
        """Each parameter's mean, sd and 95 % interval with its unit (:func:`parameter_table`,
        the run's summary.csv)."""
        return parameter_table(self.idata, self.priors)


#: Draws a fit's figure in a directory and returns its file name (the inference layer writes
#: no figure itself: ``harvester.plots.posterior.fit_pair_figure``).
FitFigure = Callable[[Fit, Path], str]


def load_fit(directory: Path, problem: Problem, priors: dict[str, PriorSpec]) -> Fit | None:
    """A finished run in ``directory`` (evidence.json and posterior.nc), or None."""
    ev, nc = directory / "evidence.json", directory / "posterior.nc"
    if not (ev.exists() and nc.exists()):
        return None
    log.info("%s: resuming from the finished run in %s", problem.structure.name, directory)
    return Fit(problem, az.from_netcdf(nc), priors, json.loads(ev.read_text()))


def fit_recording(problem: Problem, priors: dict[str, PriorSpec], settings: TMCMCSettings,
                  directory: Path, figure: FitFigure | None = None) -> Fit:
    """TMCMC on ``problem`` and its files in ``directory`` (resumed when finished there);
    ``figure`` draws the posterior's figure (``plots.posterior.fit_pair_figure``)."""
    done = load_fit(directory, problem, priors)
    if done is not None:
        return done
    idata = identify(problem, priors, settings)
    fit = Fit(problem, idata, priors, evidence_summary(idata))
    write_fit(fit, directory, figure)
    log.info("%s: log evidence %.2f%s", problem.structure.name, fit.evidence["log_evidence"],
             f" +- {fit.evidence['standard_error']:.2f}" if fit.evidence["standard_error"]
             else "")
    return fit


def write_fit(fit: Fit, directory: Path, figure: FitFigure | None = None) -> list[str]:
    """posterior.nc, summary.csv, ``figure``'s file (the pair figure,
    ``plots.posterior.fit_pair_figure``), then evidence.json; the file names."""
    directory.mkdir(parents=True, exist_ok=True)
    with atomic_path(directory / "posterior.nc") as tmp:
        fit.idata.to_netcdf(str(tmp))
    table = parameter_table(fit.idata, fit.priors)
    with atomic_path(directory / "summary.csv") as tmp:
        table.to_csv(tmp, index=False, float_format="%.6g")
    files = ["posterior.nc", "summary.csv"]
    if figure is not None:
        files.append(figure(fit, directory))
    write_json(fit.evidence, directory / "evidence.json")
    return files + ["evidence.json"]
