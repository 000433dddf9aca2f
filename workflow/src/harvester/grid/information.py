"""What a scenario's effect leaves for an added term: the baseline refitted to its noise-free
recording.

``unabsorbed_to_noise`` of a generator is linearised least squares about the true
parameters. That understates what the baseline absorbs when absorbing needs a large move. On
the literature generator's power-law damping (c |v|^1.5 sgn v, half the noise RMS), c_m has to
rise from 0.75 to 2.2 N s/m. The linearised estimate left 0.37 x the noise RMS, 246 nats of
information by ``scoring.information_nats``. A MAP refit of the tanh baseline to the
noise-free record left a residual of 0.0047 m/s^2 RMS, against 0.0054 for the same record
without the effect (5 % of the noise).

:func:`refit_unabsorbed` measures it the way the diagnosis sees the record: the same model
input (``diagnosis.analysis.model_input``), measurement chain and priors
(``initial.recording.recording_priors``). The baseline's MAP is fitted over the TMCMC window
to the recording's noise-free z'' with the effect and without it. The result is the RMS
that the effect adds to the refit residual, in quadrature, over the noise RMS.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd

#: The sigma prior of the refits (the grid's, ``scoring.SIGMA_PRIOR``).
REFIT_SIGMA = {"mean": 0.07, "sd": 0.03, "unit": "m/s^2"}


def refit_residual_rms(recording: pd.DataFrame, rel_acc: np.ndarray, known: Mapping[str, float],
                       baseline: str, window: tuple[int, int]) -> float:
    """RMS (m/s^2) of the baseline's MAP residual, through the diagnosis's chain, when the
    recording's z'' is replaced by ``rel_acc`` (its input as the diagnosis drives models)."""
    from harvester.data.signals import uniform_step
    from harvester.diagnosis.analysis import model_input
    from harvester.diagnosis.baseline import chain_problem, fit_map
    from harvester.diagnosis.detect import band_top
    from harvester.inference.problems import make_problem
    from harvester.initial.recording import recording_priors

    fs = 1.0 / uniform_step(recording["time"].to_numpy())
    rec, _, _ = model_input(recording.assign(rel_acc=rel_acc), None, fs, band_top(fs, None), [])
    priors = recording_priors(rec, known, {"sigma": REFIT_SIGMA}, "<scenario>")
    problem = chain_problem(make_problem(rec, baseline, known, window=window), 1.0, None)
    fit = fit_map(problem, priors, seed=0)
    return float(np.std(problem.residuals(fit.theta[None])[0]))


def refit_unabsorbed(recording: pd.DataFrame, clean_rel_acc: np.ndarray,
                     baseline_rel_acc: np.ndarray, known: Mapping[str, float], noise_rms: float,
                     baseline: str = "tanh", window: tuple[int, int] | None = None) -> float:
    """What the baseline's refit leaves of the effect, over the noise RMS (module
    docstring): sqrt(max(0, r_with^2 - r_without^2)) / noise_rms."""
    window = window or (0, len(recording))
    with_effect = refit_residual_rms(recording, clean_rel_acc, known, baseline, window)
    without = refit_residual_rms(recording, baseline_rel_acc, known, baseline, window)
    return float(np.sqrt(max(0.0, with_effect**2 - without**2)) / noise_rms)
