"""The workflow's steps on the groups of a recording sheet (``harvester.data.sheet``; rules in
``workflow/rules/*.smk``).

Each step is a thin front on the library, as the command line is (``harvester.cli``): a
group's results are those ``harvester identify``, ``compare``, ``predict`` and ``diagnose``
give on the same recordings with the same settings. The steps, in the order they run:

* :func:`prepare_recording`: a recording copied to ``results/groups/{group}/data/`` with its
  sidecar beside it (``filtered_at_hz`` set), checked as an instrument would check it;
* :func:`group_priors`: the priors of every model of the group from its training recording
  (the sidecar's priors, the recording's FRF: ``harvester.initial.recording``);
* :func:`identify_model`: TMCMC of one model (``inference.recording_fit``: the problem, the
  summary with units, the evidence with its error);
* :func:`evidence_table`: evidence and Bayes factors of the group's models
  (``inference.compare``);
* :func:`validate_model`: the posterior predictive of one model on one validation recording
  (``inference.unseen``);
* :func:`diagnose_model`: the diagnosis of one identified model (``harvester.diagnosis``).

:func:`group_settings` gives a group's settings from the config. The workflow imports this
module when it parses the rules (``workflow/rules/common.smk``), so each step imports the
library it needs inside its function: parsing the workflow does not load PyMC.
"""

from __future__ import annotations

import html
import logging
import os
import shutil
import tempfile
from collections.abc import Mapping, Sequence
from dataclasses import asdict, replace
from pathlib import Path
from typing import Any

import pandas as pd

from harvester.data.errors import DataError

log = logging.getLogger("harvester.groups")

#: Identification settings of every group (config ``identification``; a group's entries in
#: config ``groups`` replace them).
IDENTIFICATION_DEFAULTS: dict[str, Any] = {
    "lead_in_s": 1.0, "fit_seconds": None, "lowpass_hz": None, "filter_order": 8,
    "validation_lead_in_s": None,
}
#: Keys of a group's entry that update a section of the config rather than replace a value.
SECTIONS = ("tmcmc", "predictive", "diagnosis")


def group_settings(config: Mapping[str, Any], group: str) -> dict[str, Any]:
    """A group's settings: config ``identification`` (window, low-pass), ``models``,
    ``tmcmc``, ``predictive`` and ``diagnosis``, then the group's own entry in config
    ``groups`` (its ``tmcmc``, ``predictive`` and ``diagnosis`` update the global ones).

    ``study: paper`` marks the paper study's group: its low-pass, lead-in and window are the
    study's preprocessing (config ``preprocess``, in samples of the rig's DAQ rate), and its
    priors are the study's initial modelling (``priors: study``).
    """
    own = dict((config.get("groups") or {}).get(group) or {})
    s: dict[str, Any] = {**IDENTIFICATION_DEFAULTS, **(config.get("identification") or {})}
    s.update(group=group, study=own.pop("study", None), models=list(config["models"]),
             priors=None, diagnose=True)
    for key in SECTIONS:
        s[key] = {**(config.get(key) or {}), **(own.pop(key, None) or {})}
    if s["study"] == "paper":
        fs = float(config["rig"]["daq"]["sampling_rate_hz"])
        pre = config["preprocess"]
        s.update(lowpass_hz=pre["lowpass_hz"], filter_order=pre["filter_order"],
                 lead_in_s=pre["training_lead_in"] / fs,
                 fit_seconds=pre["training_samples"] / fs,
                 validation_lead_in_s=pre["validation_lead_in"] / fs, priors="study")
    s.update(own)
    if s["validation_lead_in_s"] is None:
        s["validation_lead_in_s"] = s["lead_in_s"]
    return s


def window_samples(settings: Mapping[str, Any], fs: float) -> tuple[int, int | None]:
    """(lead-in, samples fitted or None) of a group's window at the rate ``fs`` (Hz)."""
    fit = settings["fit_seconds"]
    return int(round(settings["lead_in_s"] * fs)), (None if fit is None else
                                                    int(round(fit * fs)))


# --------------------------------------------------------------------------- prepare


def read_sidecar_file(path: str | Path):
    """The sidecar at ``path`` (a .yaml anywhere), read and checked as ``read_sidecar``."""
    from harvester.data.sidecar import read_sidecar
    return read_sidecar(Path(path).with_suffix(".csv"))


def _sidecar_text(known: Mapping[str, float], priors: Mapping, filtered_at: float | None,
                  notes: Sequence[str], units: Mapping[str, str] | None = None) -> str:
    """The prepared recording's sidecar: ``known``, ``priors``, ``filtered_at_hz`` (Hz) and
    ``units`` (the given sidecar's, left out when N and m), ``notes`` as comments."""
    import yaml
    body: dict[str, Any] = dict(known)
    if priors:
        body["priors"] = {k: dict(v) for k, v in priors.items()}
    if filtered_at is not None:
        body["filtered_at_hz"] = float(filtered_at)
    if units:
        body["units"] = dict(units)
    head = "".join(f"# {n}\n" for n in notes)
    return head + (yaml.safe_dump(body, sort_keys=False) if body else "")


def _cutoff(first, given, sidecar, lowpass_hz: float | None) -> tuple[float | None, str]:
    """(low-pass the recording went through, Hz or None; where that is from): the workflow's,
    unless the sidecar's is lower; else the sidecar's; else found in the output's spectrum."""
    from harvester.diagnosis.detect.spectral import recording_lowpass
    if lowpass_hz:
        if given.filtered_at_hz and given.filtered_at_hz < float(lowpass_hz):
            return given.filtered_at_hz, "the sidecar (below the workflow's low-pass)"
        return float(lowpass_hz), "the workflow's zero-phase low-pass (config)"
    if given.filtered_at_hz is not None:  # 0: none, kept so that no later step looks for one
        return given.filtered_at_hz, f"the sidecar {sidecar}" + (
            "" if given.filtered_at_hz else ": no low-pass")
    data = first.data
    found, shared = recording_lowpass(None, data[first.kinds.input_kind].to_numpy(float),
                                      data[first.kinds.output_kind].to_numpy(float), 1.0 / first.dt)
    if shared:
        log.warning("%s: %s", sidecar or "<no sidecar>", shared)
    return found, ("found from the output's spectrum" + (f" ({shared})" if shared else "")
                   if found else "none given, none found in the output's spectrum")


def prepare_recording(source: str | Path, sidecar: str | Path | None, out_csv: str | Path,
                      lowpass_hz: float | None = None, filter_order: int = 8,
                      name: str | None = None) -> dict[str, Any]:
    """Copy ``source`` (a recording in the format) to ``out_csv`` with its sidecar beside it,
    check it, and return what the checks found (for ``RECORDING.check.json``).

    The sidecar written is the sheet's (``sidecar``, or none) with ``filtered_at_hz``: the
    workflow's own low-pass (``lowpass_hz``, applied before: rule ``lowpass``), else the
    sheet sidecar's, else the cut-off found from the output's spectrum
    (``diagnosis.detect.spectral.recording_lowpass``), else none; every later step reads it from there,
    and the sheet sidecar's ``units`` where not N and m (the diagnosis's labels).
    Both files appear only when the checks pass (DataError naming the file otherwise). A
    sidecar's ``friction_on: ground`` rewrites the recording in absolute coordinates
    (``data.kinds.on_ground``), so that every later step fits the device's own form; the
    workflow does not choose the form when the sidecar is silent (``harvester diagnose``
    does: ``diagnosis.prepare.topology``).
    """
    from harvester.data.daq import read_checked_recording, sha256
    from harvester.data.sidecar import Sidecar, sidecar_path

    source, out_csv = Path(source), Path(out_csv)
    name = name or out_csv.stem
    given = read_sidecar_file(sidecar) if sidecar else Sidecar(Path("<none>"))
    first = read_checked_recording(source, known=given.known,
                                   known_from=str(sidecar) if sidecar else "no sidecar")
    cutoff, where = _cutoff(first, given, sidecar, lowpass_hz)
    notes = [f"{name}: sidecar written by the workflow (rule prepare_recording) from "
             + (str(sidecar) if sidecar else "no sidecar"),
             f"filtered_at_hz: {where}"]
    known, rewritten = dict(given.known), None
    if given.friction_on == "ground":
        from harvester.data.kinds import on_ground
        rewritten, known, done = on_ground(first.data, known, str(source))
        notes += done
    out_csv.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix=f".{name}.", dir=out_csv.parent) as staging:
        csv = Path(staging) / out_csv.name
        if rewritten is None:
            shutil.copyfile(source, csv)
        else:
            rewritten.to_csv(csv, index=False, float_format="%.10g")
        sidecar_path(csv).write_text(_sidecar_text(known, given.priors, cutoff, notes,
                                                   given.units.to_sidecar()))
        checked = read_checked_recording(csv, known_from="its sidecar")
        os.replace(sidecar_path(csv), sidecar_path(out_csv))
        os.replace(csv, out_csv)
    df = checked.data
    for w in checked.warnings:
        log.warning("%s", w)
    return {"recording": name, "source": str(source), "sidecar_given": str(sidecar or ""),
            "input": checked.kinds.input_kind, "output": checked.kinds.output_kind,
            "samples": len(df), "sampling_rate_hz": 1.0 / checked.dt,
            "duration_s": float(len(df) * checked.dt), "known": known,
            "friction_on": given.friction_on or "base (not stated)",
            "priors_given": dict(given.priors), "filtered_at_hz": cutoff,
            "filtered_at_from": where, "warnings": [str(w) for w in checked.warnings],
            "sha256": sha256(out_csv)}


# --------------------------------------------------------------------------- identify


def _window(settings: Mapping[str, Any], lowpass: float | None):
    from harvester.inference.recording_fit import FitWindow
    return FitWindow(float(settings["lead_in_s"]), lowpass or None, int(settings["filter_order"]),
                     settings["fit_seconds"])


HINT = ", in the recording's sidecar (the sheet's sidecar column)"


def group_priors(data: str | Path, models: Sequence[str],
                 settings: Mapping[str, Any]) -> dict[str, Any]:
    """The priors file of a group (``priors.json``: known, priors, notes) from its training
    recording as prepared: the free parameters of every model, priors from the sidecar's
    ``priors`` and the recording's FRF (``initial.recording.identification_priors``, as
    ``harvester identify`` sets them)."""
    from harvester.data.daq import read_checked_recording
    from harvester.inference.recording_fit import recording_problem
    from harvester.initial.recording import identification_priors

    checked = read_checked_recording(data)
    known, lowpass = dict(checked.sidecar.known), checked.sidecar.filtered_at_hz
    free: list[str] = []
    for model in models:
        problem = recording_problem(checked.data, model, known, _window(settings, lowpass),
                                    str(data), HINT)
        free += [p for p in problem.structure.free_parameters if p not in free]
    try:
        specs, notes = identification_priors(checked.data, tuple(free), known,
                                             checked.sidecar.priors, lowpass, str(data))
    except KeyError as err:  # a prior in the sidecar for a parameter the library lacks
        raise DataError(checked.sidecar.path, str(err.args[0])) from None
    for note in notes:
        log.info("%s", note)
    return {"known": known, "priors": {n: asdict(s) for n, s in specs.items()},
            "notes": notes, "recording": str(data), "models": list(models)}


def read_priors(path: str | Path):
    """(known, {name: PriorSpec}) of a priors file (this module's or the study's)."""
    from harvester.data.fileio import read_json
    from harvester.inference.priors import PriorSpec
    doc = read_json(path)
    return dict(doc["known"]), {n: PriorSpec(**p) for n, p in doc["priors"].items()}


def identify_model(data: str | Path, priors_file: str | Path, model: str,
                   settings: Mapping[str, Any], out_dir: str | Path):
    """TMCMC of ``model`` on the group's training recording; writes ``out_dir``/posterior.nc,
    summary.csv, posterior_pairs.png and evidence.json (``recording_fit.fit_recording``)."""
    from harvester.data.daq import read_checked_recording
    from harvester.inference.identify import TMCMCSettings
    from harvester.inference.recording_fit import fit_recording, recording_problem
    from harvester.plots.posterior import fit_pair_figure

    known, priors = read_priors(priors_file)
    checked = read_checked_recording(data, known=known, known_from=str(priors_file))
    for w in checked.warnings:
        log.warning("%s", w)
    problem = recording_problem(checked.data, model, known,
                                _window(settings, checked.sidecar.filtered_at_hz), str(data),
                                HINT)
    return fit_recording(problem, priors, TMCMCSettings.from_config(settings["tmcmc"]),
                         Path(out_dir), fit_pair_figure(f"recording: {Path(data).name}"))


def evidence_table(models: Sequence[str], summaries: Sequence[str | Path]
                   ) -> tuple[pd.DataFrame, str]:
    """(table, verdict in words) of the group's models from their evidence.json files:
    log evidence and its standard error, log Bayes factors against the first model."""
    from harvester.data.fileio import read_json
    from harvester.inference.compare import evidence_table as table_of
    from harvester.inference.compare import verdict
    table = table_of({m: read_json(p) for m, p in zip(models, summaries)})
    return table, verdict(table)


def table_html(table: pd.DataFrame, title: str, lines: Sequence[str] = ()) -> str:
    """A small HTML page for the report: a title, a table and lines of text."""
    body = table.to_html(index=False, float_format=lambda x: f"{x:.4g}", na_rep="-",
                         border=0)
    text = "".join(f"<p>{html.escape(t)}</p>" for t in lines)
    return (f"<html><body><h3>{html.escape(title)}</h3>{body}{text}</body></html>\n")


# --------------------------------------------------------------------------- validate


def validate_model(posterior: str | Path, recording: str | Path, samples: int, seed: int,
                   lead_in_s: float, out_dir: str | Path) -> dict[str, Any]:
    """Posterior predictive of a group's model on one of its validation recordings
    (``inference.unseen``: same kinds as the training recording, the posterior's device and
    output filter); writes predictive.csv, predictive.png and validation.json."""
    from harvester.data.daq import read_checked_recording
    from harvester.inference.posterior import read_posterior
    from harvester.inference.unseen import (posterior_structure, predict_unseen,
                                            unseen_problem, write_prediction)
    from harvester.plots.predictive import prediction_figure
    idata = read_posterior(posterior)
    _, known = posterior_structure(idata, str(posterior))
    checked = read_checked_recording(recording, known=known,
                                     known_from=f"the posterior {posterior}")
    for w in checked.warnings:
        log.warning("%s", w)
    problem = unseen_problem(idata, checked.data, str(posterior), str(recording))
    pred = predict_unseen(problem, idata, samples, seed, lead_in_s)
    pred.metrics["recording"] = Path(recording).stem
    write_prediction(pred, Path(out_dir),
                     prediction_figure(f"unseen recording: {Path(recording).name}"))
    return pred.metrics


#: Columns of a group's validation.csv.
VALIDATION_COLUMNS = ["model", "recording", "nrmse", "mlpd", "outside_1sd", "outside_2sd",
                      "outside_3sd", "nominal_outside_3sd", "samples", "section_s", "unit"]


def validation_table(metrics: Sequence[Mapping[str, Any]]) -> pd.DataFrame:
    """One row per model and validation recording from their validation.json."""
    rows = [{**m, "section_s": "{:.3g}-{:.3g}".format(*m["section_s"])} for m in metrics]
    return pd.DataFrame(rows, columns=VALIDATION_COLUMNS)


# --------------------------------------------------------------------------- diagnose


def diagnose_model(data: str | Path, validation: str | Path | None, posterior: str | Path,
                   priors_file: str | Path, model: str, settings: Mapping[str, Any],
                   out_dir: str | Path):
    """The diagnosis of one identified model on the group's training recording, with its
    first validation recording (if any) for the before/after comparison; the window is the
    group's (``window_samples``; without a validation recording the whole record, whose last
    quarter the diagnosis holds out: the group's ``fit_seconds`` should leave it unfitted),
    the settings config ``diagnosis`` (``DiagnosisSettings``), the low-pass and the units
    the sidecar's.
    Writes diagnosis.json and its figures in ``out_dir``."""
    import arviz as az

    from harvester.data.daq import read_checked_recording
    from harvester.data.sidecar import KnownParameters
    from harvester.diagnosis import DiagnosisSettings, diagnose_study

    from harvester.data.kinds import input_kind

    known, priors = read_priors(priors_file)
    checked = read_checked_recording(data, known=known, known_from=str(priors_file))
    force = input_kind(checked.kinds.input_kind).force_input  # any kind (data.kinds)
    if not force and not {"M", "m", "k"} & set(known):  # the others are identified
        KnownParameters(known, known, {}, "").require(("M", "m", "k"), "the diagnosis",
                                                      checked.sidecar)
    unseen = None if validation is None else \
        read_checked_recording(validation, known=known, known_from=str(priors_file)).data
    diag_settings = replace(DiagnosisSettings.from_config(settings["diagnosis"])
                            .with_sidecar(checked.sidecar),  # its units, its M_sd...
                            lowpass_hz=checked.sidecar.filtered_at_hz,
                            filter_order=int(settings["filter_order"]))
    lead_in, samples = window_samples(settings, 1.0 / checked.dt)
    if unseen is None:  # the diagnosis holds out the record's end, which no fit has seen
        samples = None
    return diagnose_study(checked.data, model, known, priors, unseen, diag_settings, out_dir,
                          posterior=az.from_netcdf(posterior), lead_in=lead_in,
                          samples=samples)
