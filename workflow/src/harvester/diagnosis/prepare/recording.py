"""Everything the diagnosis of a recording's file decides before it starts, in one place: the
device from the sidecar (and the user's defaults), the low-pass the output went through, the
validation record, what the friction acts on where the sidecar does not say
(``topology.choose_topology``), and the priors from the recording (``initial.recording.
diagnosis_priors``: an FRF fit of the base parameters it does not know).

:func:`diagnosis_input` is what ``harvester diagnose`` and ``harvester.diagnose`` (through
``run.diagnose_recording``) share, so that a recording gets the same diagnosis from the shell
and from Python.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path

import pandas as pd

from harvester.data.device_recording import read_device_recording
from harvester.data.errors import DataError
from harvester.data.kinds import INPUTS, OUTPUTS, input_kind, on_ground
from harvester.data.recording import Accepted
from harvester.data.sidecar import Sidecar
from harvester.data.signals import filter_recording
from harvester.data.units import SI
from harvester.diagnosis.prepare.analysis import check_recording
from harvester.diagnosis.prepare.settings import DiagnosisSettings
from harvester.diagnosis.prepare.topology import choose_topology, comparable
from harvester.inference.priors import PriorSpec

log = logging.getLogger("harvester.diagnosis")

#: Why a base-driven recording needs one of M, m, k (eq. 1 fixes only ratios to a mass).
DIAGNOSE_NEEDS = ("harvester diagnose (with a base input eq. (1) fixes only ratios to a "
                  "mass: at least one of M, m, k must be known; the others are identified)")
#: Every kind of recording (``data.kinds``): the diagnosis takes them all.
ACCEPT = Accepted(tuple(INPUTS), tuple(OUTPUTS), "harvester diagnose",
                  "time, one input and one output column")


@dataclass
class DiagnosisInput:
    """What :func:`run.diagnose` is given for a recording's file: the recording and its
    validation record in the form the friction acts in, the device parameters held known,
    the priors, the settings (low-pass and units from the sidecar), and the notes on every
    choice made (they open diagnosis.json's notes)."""

    recording: pd.DataFrame
    validation: pd.DataFrame | None
    known: dict[str, float]
    priors: dict[str, PriorSpec]
    settings: DiagnosisSettings
    sidecar: Sidecar
    source: str
    notes: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    started: float | None = None  # time.time() when its preparation began: the budget's start


def diagnosis_input(recording: str | Path, baseline: str, *,
                    validation: str | Path | None = None,
                    settings: DiagnosisSettings = DiagnosisSettings(),
                    lowpass_output_hz: float | None = None,
                    defaults: Mapping[str, float] | None = None,
                    defaults_from: str = "") -> DiagnosisInput:
    """The diagnosis's input for the file ``recording`` (CSV with its sidecar) against
    ``baseline``. ``settings.lowpass_hz``: the low-pass the recording already went through
    (None: the sidecar's ``filtered_at_hz``, else looked for by the diagnosis; 0: none);
    ``lowpass_output_hz``: low-pass the output here (zero-phase, ``settings.filter_order``);
    ``defaults``: device parameters assumed where the sidecar lacks them (e.g. the paper's
    Table 1, ``defaults_from`` says so). DataError naming the file for bad input."""
    source, started = str(recording), time.time()
    dev = read_device_recording(recording, defaults, defaults_from, accept=ACCEPT)
    checked, kp = dev.checked, dev.known
    if not input_kind(checked.kinds.input_kind).force_input and \
            not {"M", "m", "k"} & set(kp.values):  # eq. (1) cannot fix the scale
        kp.require(("M", "m", "k"), DIAGNOSE_NEEDS, checked.sidecar)
    warnings = [str(w) for w in checked.warnings]
    notes = warnings + dev.notes
    val = None
    if validation is not None:
        vd = read_device_recording(validation, accept=ACCEPT, known=kp.values,
                                   known_from=kp.source)
        val = vd.checked.data
        warnings += [str(w) for w in vd.checked.warnings]
        notes += [str(w) for w in vd.checked.warnings]
    df, val, lowpass = _filtered(checked, val, settings, lowpass_output_hz, source,
                                 validation)
    notes += dev.rewritten  # friction on the ground (sidecar friction_on): how it is read
    settings = replace(settings.with_sidecar(checked.sidecar), lowpass_hz=lowpass,
                       units=checked.sidecar.units or SI)
    check_recording(df, source, settings.lead_in_s,
                    0.0 if val is not None else settings.holdout_fraction)
    df, val, known, form_notes = friction_form(df, val, dict(kp.values), checked.sidecar,
                                               baseline, settings, source, validation)
    priors, prior_notes = _priors(df, baseline, known, checked.sidecar, settings, source)
    for w in warnings:
        log.warning("%s", w)
    return DiagnosisInput(df, val, known, priors, settings, checked.sidecar, source,
                          notes + form_notes + prior_notes, warnings, started)


def _filtered(checked, validation: pd.DataFrame | None, settings: DiagnosisSettings,
              lowpass_output_hz: float | None, source: str, validation_source
              ) -> tuple[pd.DataFrame, pd.DataFrame | None, float | None]:
    """(recording, validation, the low-pass they went through: Hz or None): the output
    low-passed here where ``lowpass_output_hz`` asks (the output alone)."""
    df = checked.data
    lowpass = (settings.lowpass_hz if settings.lowpass_hz is not None
               else checked.sidecar.filtered_at_hz)
    if lowpass_output_hz is None:
        return df, validation, lowpass
    if not 0 < lowpass_output_hz < 0.5 / checked.dt:
        raise DataError(source, f"--lowpass {lowpass_output_hz} Hz must lie in (0, "
                        f"{0.5 / checked.dt:g}) Hz")
    output = (checked.kinds.output_kind,)
    df = filter_recording(df, lowpass_output_hz, settings.filter_order, source, output)
    if validation is not None:
        validation = filter_recording(validation, lowpass_output_hz, settings.filter_order,
                                      str(validation_source), output)
    return df, validation, lowpass_output_hz


def friction_form(df: pd.DataFrame, validation: pd.DataFrame | None, known: dict[str, float],
                  sidecar: Sidecar, baseline: str, settings: DiagnosisSettings, source: str,
                  validation_source=None):
    """(recording, validation, known, notes) in the form the device's friction acts in where
    the sidecar does not say and both forms can be compared (``topology``): the recording as
    it is, or rewritten with its friction on the ground (``data.kinds.on_ground``)."""
    if sidecar.friction_on is not None or not comparable(df, known, source):
        return df, validation, known, []

    def priors_of(d, k):
        return _priors(d, baseline, k, sidecar, settings, source)[0]
    choice = choose_topology(df, known, baseline, priors_of, settings, source)
    notes = [choice.sentence(source)]
    if choice.chosen == "ground":
        if validation is not None:
            validation = on_ground(validation, known, str(validation_source))[0]
        df, known, done = on_ground(df, known, source)
        notes += done
    return df, validation, known, notes


def _priors(df: pd.DataFrame, baseline: str, known: Mapping[str, float], sidecar: Sidecar,
            settings: DiagnosisSettings, source: str) -> tuple[dict[str, PriorSpec], list[str]]:
    """The diagnosis's priors from the recording (``initial.recording.diagnosis_priors``);
    DataError naming the sidecar or the recording where they cannot be had."""
    from harvester.initial.recording import diagnosis_priors
    try:
        return diagnosis_priors(df, baseline, known, sidecar.priors,
                                settings.lowpass_hz or None, source)
    except KeyError as err:  # a prior in the sidecar for a parameter the library lacks
        raise DataError(sidecar.path, str(err.args[0])) from None
    except ValueError as err:  # the FRF fit of unknown M, m, k failed
        raise DataError(source, f"the priors of the unknown device parameters: "
                        f"{err}") from None

