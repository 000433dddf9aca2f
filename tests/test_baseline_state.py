"""The baseline's state where its posterior mean cannot be simulated (map_fit.representative):
a softening cubic spring's draws, some of which leave the well over the record, read at the
best-fitting draw that can be simulated, with a note; none simulable is a named error."""

import numpy as np
import pytest

from harvester.inference.likelihood import DAQ_OVERSAMPLE
from harvester.inference.map_fit import ChainProblem, baseline_state
from harvester.model.structures import structure
from harvester.synthetic.measured import TABLE1_KNOWN

from latent_records import C_M, FS, LOWPASS_HZ, recording, rk4_record


@pytest.fixture(scope="module")
def problem() -> ChainProblem:
    df = recording(rk4_record(lambda z, v, t: 0.0, seconds=6.0), noise=0.02)
    n = len(df)
    return ChainProblem(structure("linear+cubic_stiffness"), df["base_acc"].to_numpy(),
                        df["rel_acc"].to_numpy(), 1.0 / FS, dict(TABLE1_KNOWN),
                        (int(FS), n - int(0.5 * FS)), lowpass_hz=LOWPASS_HZ,
                        oversample=DAQ_OVERSAMPLE)


def draws(k_cubic: list[float], c_m: list[float]) -> np.ndarray:
    return np.column_stack([c_m, k_cubic, np.full(len(c_m), 0.02)])


def test_mean_used_where_it_simulates(problem):
    samples = draws([-5.0, 5.0, 0.0], [C_M - 1.0, C_M + 1.0, C_M])
    state = baseline_state(problem, samples)
    assert state.note is None
    assert np.allclose(state.theta, samples.mean(axis=0))


def test_best_simulable_draw_where_the_mean_escapes(problem):
    # the spring leaves its well (k z^2 < |k_cubic| z^4) for the far draws and for the mean
    far = -1e7
    assert not problem.simulate(draws([far], [C_M])).ok[0]
    samples = draws([0.0, 0.0, 0.0, 0.0, far, far], [C_M - 20.0, C_M, C_M + 20.0, C_M + 5.0,
                                                      C_M, C_M])
    assert not problem.simulate(samples.mean(axis=0)).ok[0]
    state = baseline_state(problem, samples)
    assert np.allclose(state.theta, samples[1])  # the truth's c_m fits the record best
    assert "4 of 6 posterior samples" in state.note
    assert np.all(np.isfinite(state.residual)) and np.all(np.isfinite(state.jacobian))
    assert np.std(state.residual[problem.samples]) < 0.05  # the noise (0.02) and the chain


def test_no_simulable_draw_is_a_named_error(problem):
    with pytest.raises(RuntimeError, match="none|neither.*2 posterior samples"):
        baseline_state(problem, draws([-1e7, -2e7], [C_M, C_M]))


def result(effect: str, problem: ChainProblem, samples: np.ndarray, gain: float):
    from harvester.diagnosis.name.results import CandidateResult
    from harvester.diagnosis.name.fits import ModelFit
    fit = ModelFit(problem.structure, problem, samples, np.array([gain, gain]))
    return CandidateResult(effect, fit, gain, 0.5, 6.0, True)


def test_divergent_accepted_candidate_withdrawn(problem):
    from harvester.diagnosis.name.results import ConfirmSettings
    from harvester.diagnosis.name.simulable import withdraw_divergent
    far = draws([-1e7, -2e7, 0.0], [C_M, C_M, C_M])  # 1 of 3 draws simulable
    near = draws([0.0, 1.0, -1.0], [C_M, C_M + 1.0, C_M - 1.0])
    first, second = result("cubic_stiffness", problem, far, 40.0), \
        result("end_stop", problem, near, 38.0)
    results = [first, second]
    from harvester.diagnosis.name.confirm import mark_ties
    mark_ties(results, ConfirmSettings())
    assert second.indistinguishable_from == ["cubic_stiffness"]
    notes = withdraw_divergent(results, lambda s: problem, ConfirmSettings())
    assert not first.accepted and second.accepted and second.named
    assert len(notes) == 1 and "33 % of its posterior draws" in notes[0]
    # a candidate that holds is left as it was, and so is everything after it
    again = [result("end_stop", problem, near, 38.0), result("cubic_stiffness", problem, far,
                                                              30.0)]
    assert withdraw_divergent(again, lambda s: problem, ConfirmSettings()) == []
    assert again[1].accepted
