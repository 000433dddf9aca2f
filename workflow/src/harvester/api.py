"""The Python face of ``harvester identify``: one model structure identified on a checked
recording, with the command's steps and defaults, and no file unless asked for.

``from harvester import identify`` (the package's ``__init__`` maps the name here); the
recording comes from ``harvester.load_recording`` (``data.daq.read_checked_recording``), and
the diagnosis is ``harvester.diagnose`` (``diagnosis.diagnose``), with no wrapper.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping
from pathlib import Path

from harvester.data.daq import CheckedRecording, read_checked_recording
from harvester.data.errors import DataError

log = logging.getLogger("harvester.api")

#: The sampler's defaults, those of ``harvester identify`` (``cli.CLI_TMCMC``).
PARTICLES, CHAINS, MCMC_STEPS, TARGET_ACCEPT = 500, 2, 3, 0.25


def output_lowpass(checked: CheckedRecording, lowpass_hz: float | None = None,
                   option: str = "lowpass_hz") -> tuple[float | None, str]:
    """(the zero-phase low-pass (Hz) the output went through, where it is from):
    ``lowpass_hz`` (0: none; ``option`` names it), else the sidecar's ``filtered_at_hz``,
    else the one the output's spectrum shows, or None."""
    from harvester.diagnosis.detect.spectral import recording_lowpass
    if lowpass_hz is not None:
        return (lowpass_hz or None), option
    if checked.sidecar.filtered_at_hz is not None:
        return (checked.sidecar.filtered_at_hz or None), \
            f"filtered_at_hz in {checked.sidecar.path}"
    df = checked.data
    found, shared = recording_lowpass(None, df[checked.kinds.input_kind].to_numpy(),
                                      df[checked.kinds.output_kind].to_numpy(), 1.0 / checked.dt)
    if shared:
        log.warning("%s: %s", checked.sidecar.path, shared)
    return found, (f"found from the output's spectrum (give {option} to override)"
                   if found else "none found in the output's spectrum")


def fit_problem(checked: CheckedRecording, model: str, known: Mapping[str, float], *,
                lead_in_s: float = 1.0, lowpass_hz: float | None = None,
                filter_order: int = 8, fit_seconds: float | None = None, source: str = "",
                hint: str = "", option: str = "lowpass_hz"):
    """(problem, priors, notes) of ``model`` on the checked recording (in the form the model
    sees, ``data.device_recording.model_form``) with the device values ``known``: the
    likelihood over the samples after ``lead_in_s`` (at most ``fit_seconds``), through the
    low-pass the output went through (:func:`output_lowpass`); the priors from the recording
    (``initial.recording.identification_priors``); the notes say both. The one preparation
    of ``harvester identify``, ``harvester compare`` and :func:`identify`."""
    from harvester.inference.recording_fit import FitWindow, recording_problem
    from harvester.initial.recording import identification_priors
    lowpass, where = output_lowpass(checked, lowpass_hz, option)
    window = FitWindow(lead_in_s, lowpass, filter_order, fit_seconds)
    problem = recording_problem(checked.data, model, dict(known), window, source, hint)
    try:
        priors, notes = identification_priors(
            checked.data, problem.structure.free_parameters, problem.known,
            checked.sidecar.priors, lowpass, source)
    except KeyError as err:  # a prior in the sidecar for a parameter the library lacks
        raise DataError(checked.sidecar.path, str(err.args[0])) from None
    notes = [f"output low-pass: {f'{lowpass:.3g} Hz' if lowpass else 'none'} ({where})",
             f"{model}: identified {', '.join(problem.parameter_names)}; held "
             + (", ".join(f"{k} = {v:g}" for k, v in problem.known.items()
                          if not (k == "m" and problem.input_kind == "force")) or "none"),
             *notes]
    return problem, priors, notes


def identify(recording: CheckedRecording | str | Path, model: str, *,
             known: Mapping[str, float] | None = None, particles: int = PARTICLES,
             chains: int = CHAINS, seed: int = 0, start: str = "map", lead_in_s: float = 1.0,
             fit_seconds: float | None = None, lowpass_hz: float | None = None,
             filter_order: int = 8, out: str | Path | None = None, figures: bool = False):
    """Identify ``model`` (an expression ``base+term+...``, e.g. ``"tanh+cubic_stiffness"``;
    ``harvester terms`` lists the terms) on ``recording`` by TMCMC, as ``harvester identify``.

    ``recording``: a checked recording (``harvester.load_recording``) or its CSV path.
    ``known``: device values (M, m in kg, k in N/m) beside the sidecar's, which they override;
    the others are identified. The likelihood uses the samples after ``lead_in_s`` (s), at
    most ``fit_seconds`` of them; ``lowpass_hz``: the low-pass the recording went through
    (default: the sidecar's ``filtered_at_hz``, else found from its spectrum; 0: none).
    ``out``: a directory to write what the command writes (posterior.nc, summary.csv,
    evidence.json; the pair figure with ``figures``), and to resume from.

    Returns a :class:`~harvester.inference.recording_fit.Fit`: ``idata`` (the posterior,
    ArviZ), ``priors``, ``evidence`` (log evidence in nats per chain, pooled, its standard
    error), ``problem``; ``harvester.inference.recording_fit.parameter_table(fit.idata,
    fit.priors)`` gives each parameter's mean and 95 % interval with its unit.
    """
    from harvester.data.device_recording import model_form
    from harvester.data.sidecar import KnownParameters
    from harvester.inference.identify import TMCMCSettings
    from harvester.inference.identify import identify as tmcmc
    from harvester.inference.recording_fit import Fit, evidence_summary, fit_recording
    from harvester.plots.posterior import fit_pair_figure
    if particles < 20 or chains < 1:
        raise ValueError(f"particles {particles} and chains {chains}: need at least 20 "
                         "particles and 1 chain")
    if isinstance(recording, CheckedRecording):
        checked, source = recording, str(recording.sidecar.path.with_suffix(".csv"))
    else:
        checked, source = read_checked_recording(recording), str(recording)
    values = {**checked.sidecar.known, **(known or {})}
    dev = model_form(checked, KnownParameters(values, values, {}, ""), source)
    for line in dev.rewritten:
        log.info("%s", line)
    problem, priors, _ = fit_problem(dev.checked, model, dev.known.values,
                                     lead_in_s=lead_in_s, lowpass_hz=lowpass_hz,
                                     filter_order=filter_order, fit_seconds=fit_seconds,
                                     source=source)
    settings = TMCMCSettings(particles=particles, chains=chains, seed=seed, start=start,
                             mcmc_steps=MCMC_STEPS, target_accept=TARGET_ACCEPT)
    if out is not None:
        figure = fit_pair_figure(f"recording: {Path(source).name}") if figures else None
        return fit_recording(problem, priors, settings, Path(out), figure)
    idata = tmcmc(problem, priors, settings)
    return Fit(problem, idata, priors, evidence_summary(idata))
