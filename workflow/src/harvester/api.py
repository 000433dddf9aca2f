"""The Python face of ``harvester identify``: one model structure identified on a checked
recording, with the command's steps and defaults, and no file unless asked for.

``from harvester import identify`` (the package's ``__init__`` maps the name here); the
recording comes from ``harvester.load_recording`` (``data.daq.read_checked_recording``), and
the diagnosis is ``harvester.diagnose`` (``diagnosis.diagnose``), with no wrapper.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path

from harvester.data.daq import CheckedRecording, read_checked_recording
from harvester.data.errors import DataError

log = logging.getLogger("harvester.api")

#: The sampler's defaults, those of ``harvester identify`` (``cli.CLI_TMCMC``).
PARTICLES, CHAINS, MCMC_STEPS, TARGET_ACCEPT = 500, 2, 3, 0.25


def _as_model_recording(checked: CheckedRecording, known: Mapping[str, float]
                        ) -> tuple[CheckedRecording, dict[str, float]]:
    """The recording and device values a model sees: as read, or, where the sidecar says
    ``friction_on: ground``, rewritten in absolute coordinates (``data.kinds.on_ground``)."""
    if checked.sidecar.friction_on != "ground":
        return checked, dict(known)
    from harvester.data.kinds import on_ground
    from harvester.data.recording import recording_kinds
    df, known, done = on_ground(checked.data, known, str(checked.sidecar.path))
    for line in done:
        log.info("%s", line)
    return replace(checked, data=df, kinds=recording_kinds(df, checked.sidecar.path)), known


def _output_lowpass(checked: CheckedRecording, lowpass_hz: float | None) -> float | None:
    """The zero-phase low-pass (Hz) the output went through: ``lowpass_hz`` (0: none), else
    the sidecar's ``filtered_at_hz``, else the one the output's spectrum shows, or None."""
    from harvester.diagnosis.spectral import recording_lowpass
    given = lowpass_hz if lowpass_hz is not None else checked.sidecar.filtered_at_hz
    df = checked.data
    found, shared = recording_lowpass(given, df[checked.kinds.input_kind].to_numpy(),
                                      df[checked.kinds.output_kind].to_numpy(), 1.0 / checked.dt)
    if shared:
        log.warning("%s: %s", checked.sidecar.path, shared)
    return found


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
    from harvester.inference.identify import TMCMCSettings
    from harvester.inference.identify import identify as tmcmc
    from harvester.inference.recording_fit import (Fit, FitWindow, evidence_summary,
                                                   fit_recording, recording_problem)
    from harvester.initial.recording import identification_priors
    if particles < 20 or chains < 1:
        raise ValueError(f"particles {particles} and chains {chains}: need at least 20 "
                         "particles and 1 chain")
    if isinstance(recording, CheckedRecording):
        checked, source = recording, str(recording.sidecar.path.with_suffix(".csv"))
    else:
        checked, source = read_checked_recording(recording), str(recording)
    checked, values = _as_model_recording(checked, {**checked.sidecar.known, **(known or {})})
    lowpass = _output_lowpass(checked, lowpass_hz)
    problem = recording_problem(checked.data, model, values,
                                FitWindow(lead_in_s, lowpass, filter_order, fit_seconds), source)
    try:
        priors, _ = identification_priors(checked.data, problem.structure.free_parameters,
                                          problem.known, checked.sidecar.priors, lowpass, source)
    except KeyError as err:  # a prior in the sidecar for a parameter the library lacks
        raise DataError(checked.sidecar.path, str(err.args[0])) from None
    settings = TMCMCSettings(particles=particles, chains=chains, seed=seed, start=start,
                             mcmc_steps=MCMC_STEPS, target_accept=TARGET_ACCEPT)
    if out is not None:
        return fit_recording(problem, priors, settings, Path(out), figures,
                             f"recording: {Path(source).name}")
    idata = tmcmc(problem, priors, settings)
    return Fit(problem, idata, priors, evidence_summary(idata))
