"""The check of a candidate's likelihood for jumps before TMCMC (diagnosis.name.smoothness) and
what the rounds do with a candidate that fails it (confirm.rough, rounds.rough_rivals)."""

from __future__ import annotations

from dataclasses import dataclass, field
from types import SimpleNamespace

import numpy as np
import pytest

from harvester.inference.map_fit import PointFit
from harvester.diagnosis.name.confirm import rough, rough_reason
from harvester.diagnosis.name.rounds import rough_notes, rough_rivals
from harvester.diagnosis.name.screen import Screened
from harvester.diagnosis.name.smoothness import ROUGH_NATS, smoothness
from harvester.inference.priors import PriorSpec

SPECS = {"a": PriorSpec("a", 1.0, 1.0, "N"), "b": PriorSpec.log_normal("b", 2.0, 1.0, "m")}
TRUTH = np.array([1.2, 2.5])
SD = np.array([0.01, 0.05])


@dataclass
class FakeProblem:
    """A log-likelihood of two parameters, -1/2 ((theta - TRUTH) / SD)^2 summed, plus an
    optional quartic term in a and a jump of ``jump`` nats where a > TRUTH[0] + SD[0] / 3:
    ``profiled_loglike`` of the sums (one plus that) is minus them."""

    quartic: float = 0.0
    jump: float = 0.0
    calls: list = field(default_factory=list)
    structure = SimpleNamespace(free_parameters=("a", "b"))
    parameter_names = ("a", "b", "sigma")
    n_data = 100

    def residual_sums(self, theta):
        theta = np.atleast_2d(theta)[:, :2]
        self.calls.append(len(theta))
        x = (theta - TRUTH) / SD
        nll = 0.5 * (x**2).sum(axis=1) + self.quartic * x[:, 0]**4 \
            + self.jump * (x[:, 0] > 1.0 / 3.0)
        return 1.0 + nll, np.ones(len(theta), bool)  # sums are positive

    def profiled_loglike(self, sse):
        return -np.asarray(sse)


def point() -> PointFit:
    return PointFit(np.append(TRUTH, 0.1), np.diag(SD**2), np.zeros(3), ("a", "b", "sigma"))


def test_a_quadratic_log_likelihood_is_smooth():
    p = FakeProblem()
    s = smoothness(p, SPECS, point())
    assert s.departure < 0.01 and not s.rough
    assert p.calls == [13]  # the MAP and six probes per parameter, one batch
    assert set(s.departures) == {"a", "b"}


def test_a_skewed_but_smooth_log_likelihood_stays_below_the_threshold():
    s = smoothness(FakeProblem(quartic=0.1), SPECS, point())
    assert 0.01 < s.departure < ROUGH_NATS and not s.rough


@pytest.mark.parametrize("jump, rough_expected", [(2.0, False), (100.0, True)])
def test_a_jump_inside_one_sd_is_found_along_its_parameter(jump, rough_expected):
    s = smoothness(FakeProblem(jump=jump), SPECS, point())
    assert s.parameter == "a" and s.rough is rough_expected
    assert s.departures["b"] < 0.01  # quadratic in b, not quite in its prior coordinate ln b


def test_probes_stay_inside_the_prior_and_a_failed_simulation_is_a_wall():
    specs = {**SPECS, "a": PriorSpec("a", 1.0, 1.0, "N", lower=TRUTH[0])}  # MAP on the bound
    p = FakeProblem()
    s = smoothness(p, specs, point())
    assert s.departures["a"] < 1e-6 and p.calls == [10]  # the three steps above the bound

    class Failing(FakeProblem):
        def residual_sums(self, theta):
            sse, ok = super().residual_sums(theta)
            return sse, ok & (np.atleast_2d(theta)[:, 1] < TRUTH[1] + 0.9 * SD[1])

    s = smoothness(Failing(), SPECS, point())
    assert s.departures["b"] < 0.01 and not s.rough  # fitted through the five left


def test_an_axis_led_by_a_parameter_on_its_bound_is_left_to_the_bound_check():
    """A wall next to the MAP along a parameter on its bound (the Dahl record's c_hyst) is
    the bound's business (``baseline.bound_pull``), not a jump of the likelihood."""
    assert smoothness(FakeProblem(jump=100.0), SPECS, point()).rough
    s = smoothness(FakeProblem(jump=100.0), SPECS, point(), on_bound={"a": ("lower", 9.0)})
    assert set(s.departures) == {"b"} and not s.rough


def test_correlated_parameters_are_probed_along_their_principal_axes():
    """Two parameters correlated at 0.999 under a smooth log-likelihood -q/2 - q^2/100 (q the
    quadratic form): along either one's own axis at its marginal sd q reaches 500 and the
    quartic part departs from a quadratic by thousands of nats; along the principal axes q
    stays within 1."""
    rho = 0.999
    cov = np.array([[1.0, rho], [rho, 1.0]]) * np.outer(SD, SD)
    prec = np.linalg.inv(cov)

    class Correlated(FakeProblem):
        def residual_sums(self, theta):
            x = np.atleast_2d(theta)[:, :2] - TRUTH
            q = np.einsum("ij,jk,ik->i", x, prec, x)
            return 1.0 + 0.5 * q + 0.01 * q**2, np.ones(len(x), bool)

    fit = PointFit(np.append(TRUTH, 0.1), cov, np.zeros(3), ("a", "b", "sigma"))
    flat = {"a": SPECS["a"], "b": PriorSpec("b", 2.0, 1.0, "m")}
    s = smoothness(Correlated(), flat, fit)
    assert s.departure < 0.05 and not s.rough


def screened(jump: float) -> Screened:
    p = FakeProblem(jump=jump)
    return Screened("stribeck_friction", ("a", "b", "sigma"), np.append(TRUTH, 0.1), 0.0,
                    200.0, 250.0, False, 10, 1.0, laplace_gain=184.6, point=point(),
                    problem=p, specs=SPECS)


def test_a_rough_candidate_is_reported_with_its_departure_and_its_best_fit():
    s = screened(100.0)
    assert rough(s) and s.smooth.rough
    s.importance_gain, s.importance_trusted = 106.5, False
    why = rough_reason(s)
    assert "led by a" in why and "random walk cannot sample it" in why
    assert "at most 200.0 nats (Laplace +184.6)" in why
    assert s.to_dict()["smoothness"]["rough"] is True
    assert not rough(screened(0.0))


def test_a_rough_rival_better_than_the_name_is_noted():
    s = screened(100.0)
    rough(s)
    best = SimpleNamespace(effect="cubic_stiffness", delta_log_evidence=37.5)
    rnd = SimpleNamespace(screen=SimpleNamespace(candidates=[s]), accepted=best)
    assert rough_rivals(rnd) == [s]
    (note,) = rough_notes(rnd, 1)
    assert note.startswith("round 2: stribeck_friction fits better") and "+37.5" in note
    best.delta_log_evidence = 190.0
    assert rough_rivals(rnd) == [] and rough_notes(rnd, 1) == []
    s.sampled, best.delta_log_evidence = True, 37.5  # judged on its importance draws
    assert rough_rivals(rnd) == []


def test_the_headline_names_the_candidates_that_could_not_be_sampled():
    """One rough candidate is said in the singular, several in the plural."""
    from dataclasses import replace

    from harvester.diagnosis.name.verdict import Conclusion, FitJudgement, headline
    found = Conclusion("missing_physics", [], [], True, [], None, True)
    fit = FitJudgement(0.9, 0.3, "holdout", 1.0, None, None)
    one = headline("missing_physics", replace(found, unsampled=["stribeck_friction"]), fit,
                   "linear", 3.0)
    assert "stribeck_friction fits better at its best fit but could not be sampled (its " \
        "likelihood jumps)" in one
    two = headline("missing_physics", replace(found, unsampled=["quadratic_damping",
                                                                "unmodelled_mode"]),
                   fit, "linear", 3.0)
    assert "quadratic_damping, unmodelled_mode fit better at their best fits but could not " \
        "be sampled (their likelihoods jump)" in two
