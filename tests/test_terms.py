"""The physics library's registry: a term is one complete object, refused when it is not."""

from dataclasses import replace

import numpy as np
import pytest

from harvester.model import codegen
from harvester.model.structures import Layout
from harvester.model.priors import Prior
from harvester.model.terms import BASE_PARAMETERS, TERMS, Parameter, check_term, register

GOOD = Prior("loguniform", 0.1, 1.0, why="a reason")


def test_every_term_is_complete_and_in_a_file_named_for_it():
    for name, t in TERMS.items():
        check_term(t)
        assert t.source.endswith(f"{name}.py")


def test_a_terms_limits_name_terms_of_the_library():
    for t in TERMS.values():
        for parameter, side, other in t.limits:
            assert other in TERMS and other in t.limit_terms(parameter, side)
    assert TERMS["hysteresis"].limit_terms("delta_hyst", "lower") == ("sticking_friction",
                                                                      "coulomb_friction")
    assert TERMS["hysteresis"].limit("delta_hyst", "lower") == "sticking_friction"
    assert TERMS["hysteresis"].limit("delta_hyst", "upper") is None


def test_parameter_names_are_unique_across_the_library():
    names = [p.name for p in BASE_PARAMETERS] + [p for t in TERMS.values()
                                                 for p in t.parameter_names]
    assert len(names) == len(set(names))


@pytest.mark.parametrize("change, message", [
    (dict(kind="spring"), "kind"),
    (dict(equation=""), "no equation"),
    (dict(description=""), "no description"),
    (dict(n_states=1), "state_rates"),
    (dict(probe=None), "probe"),
    (dict(parameters=(Parameter("F_x", "", GOOD, "d"),)), "unit"),
    (dict(parameters=(Parameter("_F", "N", GOOD, "d"),)), "identifiers"),
    (dict(parameters=(Parameter("F_x", "N", Prior("loguniform", 0.1, 1.0), "d"),)), "why"),
    (dict(parameters=(Parameter("F_x", "N", Prior("loguniform", 1.0, 0.1, why="r"), "d"),)),
     "lower < upper"),
    (dict(limits=(("F_x", "lower", "coulomb_friction"),)), "limit"),
])
def test_registry_refuses_an_incomplete_term(change, message):
    bad = replace(TERMS["coulomb_friction"], name="bad_term", **change)
    with pytest.raises(ValueError, match=message):
        register(bad)
    assert "bad_term" not in TERMS


def test_registry_refuses_a_parameter_name_taken_by_another_term():
    clash = replace(TERMS["coulomb_friction"], name="clash_term")
    with pytest.raises(ValueError, match="already taken"):
        register(clash)


def test_generated_kernel_is_the_same_module_for_the_same_structure():
    a = codegen.kernel(("tanh_friction",), "base")
    assert codegen.kernel(("tanh_friction",), "base") is a
    assert codegen.source(("tanh_friction",), "base") == codegen.source(("tanh_friction",),
                                                                        "base")
    assert "F_c * " not in codegen.source(("tanh_friction",), "base")  # the law is the term's


def test_layout_refuses_a_repeated_term_and_two_couplings():
    with pytest.raises(ValueError, match="repeat"):
        Layout.of(["tanh_friction", "tanh_friction"])
    assert Layout.of(["backlash"]).n_states == 4
    assert Layout.of([]).parameter_names == ("M", "m", "k", "c_m")
    assert np.all([Layout.of([n]).names == (n,) for n in TERMS])


def test_friction_laws_and_their_refinements_are_friction_and_nothing_else_is():
    from harvester.model.terms import is_friction, term
    friction = {n for n in TERMS if is_friction(term(n))}
    assert {"tanh_friction", "coulomb_friction", "hysteresis", "stribeck_friction",
            "asymmetric_friction"} <= friction
    assert not friction & {"cubic_stiffness", "unmodelled_mode", "inertia_error",
                           "quadratic_damping", "end_stop", "offset_force"}


def test_a_named_effect_is_said_with_its_kind_and_its_fitted_strength_in_its_unit():
    from harvester.diagnosis.name.verdict import _level

    class Fit:
        def summary(self):
            return {"F_hyst": {"mean": 0.6612, "sd": 0.0049}, "k_cubic": {"mean": 2.0e6,
                                                                         "sd": 1.0e5}}
    assert _level("hysteresis", Fit()) == "hysteresis (friction, F_hyst 0.661 +- 0.0049 N)"
    assert _level("cubic_stiffness", Fit()).startswith("cubic_stiffness (k_cubic 2e+06 +- 1e+05 ")
    assert _level("coulomb_friction", None) == "coulomb_friction (friction)"
    assert _level("inertia_error", None) == "inertia_error"


def test_a_named_effect_s_strength_comes_from_the_round_that_named_it():
    """A later round's tie fits a model that need not describe the named effect (on the frame
    at 450 g a tied cubic stiffness took F_hyst from 1.12 to 0.028 N): the strength shown is
    the named round's (Conclusion.named_fit), the improved fit only when none is kept."""
    from harvester.diagnosis.name.verdict import Conclusion, Tie, _named

    class Fit:
        def __init__(self, f):
            self.f = f

        def summary(self):
            return {"F_hyst": {"mean": self.f, "sd": 0.01}}
    tie = Tie(["cubic_stiffness", "unmodelled_mode"], {})
    found = Conclusion("missing_physics", ["hysteresis"], [tie], False, [], Fit(0.028),
                       True, named_fit=Fit(1.12))
    said = _named(found, None)
    assert said.startswith("hysteresis (friction, F_hyst 1.12 +- 0.01 N)"), said
    assert "cubic_stiffness / unmodelled_mode" in said
    alone = Conclusion("missing_physics", ["hysteresis"], [], False, [], Fit(0.7), True)
    assert "F_hyst 0.7 +- 0.01 N" in _named(alone, None)
