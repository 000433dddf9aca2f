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
input (``diagnosis.prepare.analysis.model_input``), measurement chain and priors
(``initial.recording.recording_priors``). The baseline's MAP is fitted over the TMCMC window
to the recording as it is, and to the recording with the effect's contribution taken out.
The result is the RMS that the effect adds to the refit residual, in quadrature, over the
noise RMS.

The contribution taken out is the one a model driven by the recorded base acceleration
produces (``synthetic.literature.recorded_input_contribution``), not the one made from the
true excitation: the diagnosis's models are driven by the recording. Refitted to noise-free
records made from the true excitation, an exponential Stribeck excess (literature grid,
record stribeck_exponential, seed 0) left 0.107 x the noise RMS, 19 nats; with the
contribution a recorded-input model makes, it leaves none, and the true law itself, fitted
by MAP from the truth to the recording, gained 0.4 nats over the tanh baseline.

Neither measure bounds what a fitted model gains. On the grid's second seed the measure
above read 0 for two records the diagnosis named: a LuGre contact with stiff bristles
(3.3e5 N/m), whose contribution the recorded input moves by 48 % of its RMS, gained +51.8
nats as a Dahl law, and an exponential Stribeck excess gained +8.8. A law fitted to the
recording is less sensitive to the input's noise than the true law at its true parameters.
The measure made from the true excitation read 0.21 and 0.10 x the noise RMS there, and 0.11
on the first seed's exponential Stribeck record, which nothing fitted gains from. The grid's
rates are given under both (``docs/measurements.md``).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd

#: The sigma prior of the refits (the grid's, ``scoring.SIGMA_PRIOR``).
REFIT_SIGMA = {"mean": 0.07, "sd": 0.03, "unit": "m/s^2"}


def refit_residual_rms(recording: pd.DataFrame, rel_acc: np.ndarray, known: Mapping[str, float],
                       baseline: str, window: tuple[int, int],
                       start: np.ndarray | None = None) -> float:
    """RMS (m/s^2) of the baseline's MAP residual, through the diagnosis's chain, when the
    recording's z'' is replaced by ``rel_acc`` (its input as the diagnosis drives models).
    ``start``: the baseline's free parameters to start the MAP from besides prior draws (the
    device's own: from prior draws alone, the refit of a noise-free literature record stopped
    at c_m = 4e-9 N s/m, F_c 0.30 N against the device's 0.50 and 0.78)."""
    from harvester.data.signals import uniform_step
    from harvester.diagnosis.prepare.analysis import model_input
    from harvester.inference.map_fit import chain_problem, fit_map
    from harvester.diagnosis.detect.scores import band_top
    from harvester.inference.problems import make_problem
    from harvester.initial.recording import recording_priors

    fs = 1.0 / uniform_step(recording["time"].to_numpy())
    rec, _, _ = model_input(recording.assign(rel_acc=rel_acc), None, fs, band_top(fs, None), [])
    priors = recording_priors(rec, known, {"sigma": REFIT_SIGMA}, "<scenario>")
    problem = chain_problem(make_problem(rec, baseline, known, window=window), 1.0, None)
    fit = fit_map(problem, priors, seed=0, start=start)
    return float(np.std(problem.residuals(fit.theta[None])[0]))


def refit_unabsorbed(recording: pd.DataFrame, contribution: np.ndarray,
                     known: Mapping[str, float], noise_rms: float, baseline: str = "tanh",
                     window: tuple[int, int] | None = None,
                     start: np.ndarray | None = None) -> float:
    """What the baseline's refit leaves of the effect, over the noise RMS (module
    docstring): sqrt(max(0, r_with^2 - r_without^2)) / noise_rms, r_with the refit residual
    RMS of ``recording``'s rel_acc, r_without that of rel_acc - ``contribution`` (the effect
    as a model driven by the recording's base_acc produces it). ``start``: the device's
    baseline parameters (:func:`refit_residual_rms`)."""
    window = window or (0, len(recording))
    rel = recording["rel_acc"].to_numpy()
    with_effect = refit_residual_rms(recording, rel, known, baseline, window, start)
    without = refit_residual_rms(recording, rel - contribution, known, baseline, window, start)
    return float(np.sqrt(max(0.0, with_effect**2 - without**2)) / noise_rms)
