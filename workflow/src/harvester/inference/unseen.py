"""A posterior's prediction of an unseen recording of the same device (``harvester predict``).

The posterior (``posterior.nc`` of ``harvester identify``) carries the structure, its known
parameters, the recording kinds and the output filter in its attributes
(``identify.identify``); the new recording must have the same kinds. Every posterior sample
(or a random ``samples`` of them) is simulated from rest for the new input; the output's
predictive mean and +-3 sd bounds (parameters and noise sigma), the share of the measured
output outside +-1, 2, 3 sd of those and of the parameter samples' ensemble alone (the paper's
bounds, ``outside_ksd_parameter``), the NRMSE and the mean log predictive density are computed
after the lead-in (and before the filter's end effects).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import arviz as az
import numpy as np
import pandas as pd

from harvester.data.errors import DataError
from harvester.data.recording import UNITS, recording_kinds
from harvester.data.signals import uniform_step
from harvester.inference.posterior import posterior_theta, known_values
from harvester.inference.likelihood import DAQ_OVERSAMPLE, Problem
from harvester.inference.predictive import (NOMINAL_OUTSIDE, PredictiveBand, mlpd, nrmse,
                                            outside_fraction, posterior_predictive, thin)
from harvester.inference.recording_fit import END_EFFECTS_S
from harvester.model.structures import ModelStructure

#: Columns of predictive.csv.
PREDICTIVE_COLUMNS = ["time", "measured", "mean", "lower_3sd", "upper_3sd", "sd_parameter"]


def _attr_list(value) -> list[str]:
    return [v for v in str(value or "").split(",") if v]


def posterior_structure(idata: az.InferenceData, source: str) -> tuple[ModelStructure, dict]:
    """(structure, known values) stored with a posterior by ``identify.identify``."""
    attrs = idata.posterior.attrs
    if "model" not in attrs or "free_base" not in attrs:
        raise DataError(source, "not a posterior written by harvester identify (no 'model' and "
                        "'free_base' attributes)")
    known = known_values(idata)
    terms = tuple(_attr_list(attrs.get("terms")))
    return ModelStructure(str(attrs["model"]), terms, tuple(_attr_list(attrs["free_base"]))), \
        known


def unseen_problem(idata: az.InferenceData, df: pd.DataFrame, posterior_source: str,
                   source: str) -> Problem:
    """The posterior's problem on a new recording; DataError when its kinds or rate do not
    fit the posterior's."""
    structure, known = posterior_structure(idata, posterior_source)
    attrs = idata.posterior.attrs
    kinds = recording_kinds(df, source)
    was = (attrs.get("input_kind", "base_acc"), attrs.get("output_kind", "rel_acc"))
    if (kinds.input_kind, kinds.output_kind) != was:
        raise DataError(source, f"has {kinds.input_kind} -> {kinds.output_kind}; the posterior "
                        f"({posterior_source}) was identified from {was[0]} -> {was[1]}: "
                        "predict a recording of the same kinds")
    dt = uniform_step(df["time"].to_numpy(dtype=float), source)
    flt = attrs.get("output_filter")
    flt = (float(flt[0]), int(flt[1])) if flt is not None and len(flt) == 2 else None
    if flt is not None and not flt[0] < 0.5 / dt:
        raise DataError(source, f"sampled at {1 / dt:.4g} Hz: the posterior's output filter at "
                        f"{flt[0]:g} Hz lies above this recording's Nyquist frequency")
    return Problem(structure, df[kinds.input_kind].to_numpy(float),
                   df[kinds.output_kind].to_numpy(float), dt, known, output_filter=flt,
                   input_kind=kinds.input_kind, output_kind=kinds.output_kind,
                   oversample=DAQ_OVERSAMPLE)


@dataclass
class Prediction:
    """The predictive band over the whole record, the measured output, and the section
    (samples [start, stop)) the metrics are computed on."""

    band: PredictiveBand
    measured: np.ndarray
    section: tuple[int, int]
    metrics: dict


def predict_unseen(problem: Problem, idata: az.InferenceData, samples: int = 200,
                   seed: int = 0, lead_in_s: float = 1.0) -> Prediction:
    """Simulate ``samples`` posterior rows for the problem's input; metrics on the section
    after ``lead_in_s`` (and END_EFFECTS_S before the end when the output is filtered)."""
    theta = thin(posterior_theta(idata), samples, seed)
    t = np.arange(problem.output.size) * problem.dt
    band = posterior_predictive(problem, theta, problem.input, t)
    start = int(round(lead_in_s / problem.dt))
    stop = problem.output.size - (int(round(END_EFFECTS_S / problem.dt))
                                  if problem.output_filter else 0)
    sec = slice(start, stop)
    y, mean, sd = problem.output[sec], band.mean[sec], band.sd_predictive[sec]
    part = PredictiveBand(t[sec], band.responses[:, sec], band.sigma)
    metrics = {"model": problem.structure.name, "samples": int(len(band.sigma)),
               "section_s": [float(t[start]), float(t[stop - 1])],
               "unit": UNITS[problem.output_kind], "nrmse": nrmse(y, mean),
               "mlpd": mlpd(y, part, "predictive"),
               **{f"outside_{k}sd": outside_fraction(y, mean, sd, k) for k in (1, 2, 3)},
               **{f"outside_{k}sd_parameter": outside_fraction(y, mean, part.sd_parameter, k)
                  for k in (1, 2, 3)},
               **{f"nominal_outside_{k}sd": NOMINAL_OUTSIDE[k] for k in (1, 2, 3)}}
    return Prediction(band, problem.output, (start, stop), metrics)


def predictive_frame(pred: Prediction) -> pd.DataFrame:
    """time, measured, predictive mean, its +-3 sd bounds and the parameter-only sd."""
    b = pred.band
    sd = b.sd_predictive
    return pd.DataFrame({"time": b.time, "measured": pred.measured, "mean": b.mean,
                         "lower_3sd": b.mean - 3 * sd, "upper_3sd": b.mean + 3 * sd,
                         "sd_parameter": b.sd_parameter}, columns=PREDICTIVE_COLUMNS)


def write_prediction(pred: Prediction, directory: Path,
                     figure: Callable[[Prediction, Path], str] | None = None) -> list[str]:
    """predictive.csv, ``figure``'s file (the response figure,
    ``plots.predictive.prediction_figure``) and validation.json (last); the file names."""
    from harvester.data.fileio import atomic_path, write_json
    directory.mkdir(parents=True, exist_ok=True)
    with atomic_path(directory / "predictive.csv") as tmp:
        predictive_frame(pred).to_csv(tmp, index=False, float_format="%.9g")
    files = ["predictive.csv"]
    if figure is not None:
        files.append(figure(pred, directory))
    write_json(pred.metrics, directory / "validation.json")
    return files + ["validation.json"]


def heldout_error(problem: Problem, theta: np.ndarray, input: np.ndarray,
                  output: np.ndarray, section: tuple[int, int]) -> dict:
    """The simulation error of a fit on samples it did not use: each row of ``theta``
    (free parameters..., sigma; e.g. thinned posterior samples) simulated from rest for
    ``input`` alone (the problem's input kind and sampling step: the fitted record's input
    continued by the held-out one), through the problem's output filter; their mean (the
    predictive mean) against the measured ``output`` over samples [start, stop) of
    ``section``. Returns the RMS error and the RMS of the measured output there (both in
    the output's unit), the NRMSE, the section (s) and the rows simulated."""
    start, stop = section
    if not 0 <= start < stop <= len(output) == len(input):
        raise ValueError(f"section {section} outside the {len(output)} samples given "
                         f"(input {len(input)})")
    held = problem.replace(input=np.asarray(input, dtype=float),
                           output=np.asarray(output, dtype=float), window=(start, stop))
    t = np.arange(len(input)) * problem.dt
    band = posterior_predictive(held, np.atleast_2d(theta), held.input, t)
    y, mean = held.output[start:stop], band.mean[start:stop]
    return {"model": problem.structure.name, "rms_error": float(np.sqrt(np.mean((y - mean)**2))),
            "rms_output": float(np.std(y)), "nrmse": nrmse(y, mean),
            "section_s": [float(t[start]), float(t[stop - 1])], "samples": len(band.sigma),
            "unit": UNITS[problem.output_kind]}
