"""What a device's friction acts on, when its sidecar does not say: the velocity relative to the
base (eq. 1 of Green et al. 2015, a screw between the base and the mass) or the mass's own
velocity (a contact fixed to the ground, as on the frame of Marino and Cicirello 2023).

Both forms are candidates of one recording (base_disp -> rel_disp or rel_acc, k known): the
recording as it is, and rewritten in absolute coordinates (``harvester.data.kinds.on_ground``:
driven by k y, output x = z + y, or x'' = z'' + y'' with y'' differentiated from the recorded
y). With a force input the base is fixed and both forms are one; a base acceleration does not
fix y (its double integral drifts, ``on_ground``), so neither is compared. Each form's model
is the baseline with a sliding friction law (the baseline's own, or ``coulomb_friction`` when
it has none), fitted at its posterior mode; the
forms are compared by the Laplace approximation of their evidence (``baseline.
laplace_log_evidence``) under one likelihood: the same samples, low-pass, tempering lambda and
noise prior. x and z differ by the recorded y, a shift with unit Jacobian, so the two
evidences are of the same data. The form with the larger evidence is taken when it leads by
more than log(1/alpha), the Bayes factor one named model must beat another by
(``settings.evidence_alpha``); otherwise the recording stays as recorded and the note
says the record cannot tell the forms apart.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Mapping
from dataclasses import dataclass, field, replace

import pandas as pd

from harvester.diagnosis.prepare.analysis import default_priors, prepare
from harvester.inference.map_fit import fit_map
from harvester.diagnosis.detect.scores import estimate_temper
from harvester.diagnosis.prepare.settings import DiagnosisSettings
from harvester.model.structures import structure as named_structure

log = logging.getLogger("harvester.diagnosis")

FORMS = ("base", "ground")
#: The friction law a form is tested with when the baseline has none.
TEST_FRICTION = "coulomb_friction"


@dataclass
class TopologyChoice:
    """The form taken, each form's Laplace log evidence (nats) and the model compared."""

    chosen: str
    log_evidence: dict[str, float]
    structure: str
    threshold: float
    seconds: float
    notes: list[str] = field(default_factory=list)

    @property
    def lead(self) -> float:
        """The ground form's evidence over the base form's (nats)."""
        return self.log_evidence["ground"] - self.log_evidence["base"]

    def sentence(self, source: str) -> str:
        told = abs(self.lead) > self.threshold
        where = {"base": "relative to the base", "ground": "relative to the ground"}
        return (f"{source}: the sidecar does not say what the friction acts on; {self.structure}"
                f" with friction {where['ground']} against {where['base']}: "
                f"{self.lead:+.1f} nats (Laplace, threshold {self.threshold:g}); "
                + (f"taken: {where[self.chosen]}" if told else
                   "the record cannot tell them apart: kept as recorded (relative to the base)"))

    def to_dict(self) -> dict:
        return {"chosen": self.chosen, "log_evidence": self.log_evidence,
                "ground_minus_base": self.lead, "structure": self.structure,
                "threshold": self.threshold, "seconds": self.seconds,
                "method": "Laplace evidence at the posterior mode, one likelihood for both"}


def comparable(df: pd.DataFrame, known: Mapping[str, float], source: str = "<recording>"
               ) -> bool:
    """Whether both forms can be compared: base_disp -> rel_disp or rel_acc with k known."""
    from harvester.data.recording import recording_kinds
    kinds = recording_kinds(df, source)
    return kinds.input_kind == "base_disp" and kinds.output_kind in ("rel_disp", "rel_acc") \
        and "k" in known


def friction_structure(baseline: str) -> str:
    """The baseline with a sliding friction law: its own if it has one."""
    from harvester.model.terms import is_friction, term
    s = named_structure(baseline)
    if any(is_friction(term(t)) for t in s.terms):
        return s.name
    return f"{s.name}+{TEST_FRICTION}"


def _form(df: pd.DataFrame, known: Mapping[str, float], form: str, source: str
          ) -> tuple[pd.DataFrame, dict[str, float]]:
    if form == "base":
        return df, dict(known)
    from harvester.data.kinds import on_ground
    out, k, _ = on_ground(df, known, source)
    return out, k


def choose_topology(df: pd.DataFrame, known: Mapping[str, float], baseline: str,
                    priors_of, settings: DiagnosisSettings, source: str = "<recording>"
                    ) -> TopologyChoice:
    """Compare the two forms (module docstring). ``priors_of(df, known)`` gives a form's
    priors (``initial.recording.diagnosis_priors``'s first item); ``settings.lowpass_hz``:
    the recording's low-pass, the same in both forms (None: found in its rel_disp's spectrum).
    """
    clock = time.perf_counter()
    s = friction_structure(baseline)
    forms = {f: _form(df, known, f, source) for f in FORMS}
    if settings.lowpass_hz is None:  # one low-pass for both: the recording's, as recorded
        from harvester.data.recording import recording_kinds
        from harvester.data.signals import uniform_step
        from harvester.diagnosis.detect.spectral import recording_lowpass
        dt = uniform_step(df["time"].to_numpy(dtype=float), source)
        output = recording_kinds(df, source).output_kind
        settings = replace(settings, lowpass_hz=recording_lowpass(
            None, df["base_disp"].to_numpy(dtype=float), df[output].to_numpy(dtype=float),
            1.0 / dt)[0])
    # per form: its analysis and priors, once; the mode at lambda = 1 sets lambda and sigma
    prepared = {f: (prepare(forms[f][0], None, s, forms[f][1], settings, source),
                    priors_of(*forms[f])) for f in FORMS}
    first = {f: fit_map(a.chain(a.fit_raw, 1.0), pr, seed=settings.seed)
             for f, (a, pr) in prepared.items()}
    temper = min(estimate_temper(first[f].residual, a.fit_window, a.fs, a.f_high)
                 for f, (a, _) in prepared.items())
    sigma = max(float(mp.theta[-1]) for mp in first.values())
    ev = {}
    for f, (a, pr) in prepared.items():  # one likelihood: the same lambda and noise prior
        specs = {**default_priors(a.structure, sigma, a.fit_raw.output_type.unit), **pr}
        ev[f] = fit_map(a.chain(a.fit_raw, temper), specs, seed=settings.seed,
                        start=first[f].theta[:-1]).log_evidence_laplace
    threshold = settings.confirmation().base_threshold
    lead = ev["ground"] - ev["base"]
    chosen = "ground" if lead > threshold else "base"
    out = TopologyChoice(chosen, ev, s, threshold, time.perf_counter() - clock)
    log.info("%s (%.0f s)", out.sentence(source), out.seconds)
    return out

