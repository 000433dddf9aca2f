"""How big a named effect is and whether it matters: its force in newtons and as a share of
the device's forces, the share of the missing force it explains, the change it makes to the
predicted response on unseen data, and a floor of relevance below which it is "detectable but
negligible" rather than missing physics.

Sizes, along the latent force's smoothed states (``views.effect_force``):

    force_rms        RMS of dF, the improved model's force beyond the baseline's (N, or the
                     recording's force unit: ``units``, ``data.units``)
    share_of_drive   force_rms / RMS of the drive (m y'' or F): the force that moves the device
    share_of_latent  1 - sum (f - dF)^2 / sum f^2, f the latent (missing) force
    share_of_missing the same as the shapes read theirs (``shapes.ShapeDescription.share_of``:
                     less the means, within the force's determined band), comparable with
                     theirs
    response change  RMS of the improved minus the baseline's predicted output on unseen data,
                     through the measurement chain, and as a share of the output's RMS

The named term's own force X_T (``term_force``: what its law exerts, beside the re-fitted
baseline's share of dF) is the physical size a generator's truth is compared with: its RMS
over TERM_DRAWS posterior samples, each along its own simulated response to the recorded
input (``term_force_rms``): its median and 95 % interval; on an acceleration record, where
a mean is much of it, its RMS about the mean, the mean being the term's form's
(``OwnForce.mean_unfixed``).

Floor (``RelevanceFloor``, on by default): an effect is negligible when its force lies below
0.5 % of the drive and its response change below 1 % of the output. The false alarm of the
literature grid's damper device, an inertia error of 0.055 % of M, moved the force by 0.15 %
of the drive and the response by 0.19 %. Effects of that grid at half the noise RMS, once
the baseline is refitted beside them, changed the response by 0.29-1.8 % but their force
by 0.66-1.1 % (a Duffing spring, a power-law spring, a quadratic damper, a payload): the
response alone cannot tell them from the false alarm (a floor of 1 % on both made the
power-law spring "adequate"); the force can.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from harvester.data.units import SI, Units
from harvester.diagnosis.size.latent import LatentForce
from harvester.diagnosis.size.views import EffectForce, parameter_values
from harvester.model.term_forces import named_force
from harvester.model.structures import ModelStructure
from harvester.model.terms import term


@dataclass(frozen=True)
class RelevanceFloor:
    """Below both shares an effect is "detectable but negligible" (``enabled``: the
    setting; the summary states it)."""

    force_share: float = 0.005
    response_share: float = 0.01
    enabled: bool = True

    def to_dict(self) -> dict:
        return dataclasses.asdict(self)


#: Share of what is missing a named effect of relevant size must explain to be relevant
#: missing physics: of the missing force (its own force's, ``EffectSize.explains``) or of the
#: baseline's unexplained unseen output (the improved model's, ``verdict.FitJudgement``). The
#: literature generator's 18 library effects at 0.5 x the noise RMS (seeds 0-1, 36 records)
#: leave the tanh baseline, after it absorbs what it can, between 0.21 % (power damping, seed
#: 0) and 20 % of its unexplained output for the right name to explain (a^2 / (1 + a^2), a
#: the truth's ``unabsorbed_to_noise``; docs/diagnosis.md): the bar is half the least. A
#: correct name can read 0 % on the missing force alone (hysteresis on LuGre's and Bouc-Wen's
#: acceleration records: 0 % and -4 %, docs/measurements.md), so either counts.
MIN_SHARE_EXPLAINED = 0.001

#: Share of a named term's own force's mean square held by its mean above which, on an
#: acceleration record, its size is said apart from its mean (:attr:`OwnForce.mean_unfixed`).
#: Odd laws hold next to none of it as a mean (0.02 % or less for the cubic spring, the
#: quadratic damper, the Stribeck law and a mass error on literature records), an even one
#: most of it (direction-dependent friction: 77 % and 84 % on two).
MEAN_SHARE = 0.05


@dataclass(frozen=True)
class OwnForce:
    """A named term's own force over its posterior (:func:`term_force_rms`), N: the median
    and 95 % interval of its RMS, of its mean and of its RMS about the mean (its varying
    part); ``mean_seen``: whether the record's output sees a constant force."""

    rms: tuple[float, float, float]
    mean: tuple[float, float, float]
    varying: tuple[float, float, float]
    mean_seen: bool = True

    @property
    def mean_unfixed(self) -> bool:
        """Whether the record leaves its mean to the term's form: a constant force only
        moves the rest position, which an acceleration (rel_acc) does not see, so where the
        mean is a share of the mean square beyond MEAN_SHARE its RMS is the form's guess and
        the varying part is what the record fixes. On two literature records of
        direction-dependent friction F_c S(v/v_t)(1 + s tanh(v/v_a)) (two transitions, the
        library term's tanh(v/v_asym)^2 one) the term's varying part was the truth's to 3 %
        and its mean 14-15 % short, its RMS 12-13 % (docs/measurements.md)."""
        return (not self.mean_seen) and self.mean[0] ** 2 > MEAN_SHARE * self.rms[0] ** 2

    @property
    def fixed(self) -> tuple[float, float, float]:
        """The size the record fixes: the varying part where the mean is the form's
        (:attr:`mean_unfixed`), else the RMS."""
        return self.varying if self.mean_unfixed else self.rms

    def to_dict(self) -> dict:
        """Medians and intervals (N), and whether the mean is the form's."""
        return {"rms_N": self.rms[0], "rms_interval_N": list(self.rms[1:]),
                "mean_N": self.mean[0], "mean_interval_N": list(self.mean[1:]),
                "varying_rms_N": self.varying[0],
                "varying_rms_interval_N": list(self.varying[1:]),
                "mean_unfixed": self.mean_unfixed}


def _median_interval(x: list[float]) -> tuple[float, float, float]:
    mid, lo, hi = np.percentile(x, [50.0, 2.5, 97.5])
    return float(mid), float(lo), float(hi)


@dataclass
class EffectSize:
    """A named effect's physical size and relevance (module docstring)."""

    term: str
    force_rms_N: float
    share_of_drive: float
    share_of_latent: float
    response_change_rms: float | None  # unit of the output
    response_change_share: float | None
    negligible: bool
    floor: RelevanceFloor
    units: Units = SI  # the recording's (force_rms_N is in its force unit)
    share_of_missing: float | None = None
    #: the named term's own force X_T over the posterior (:func:`term_force_rms`)
    own: OwnForce | None = None
    #: (baseline parameter, posterior correlation) where the term's strength lies on a ridge
    ridge: tuple[str, float] | None = None
    #: whether the interval's posterior was adjusted for correlated residuals
    interval_adjusted: bool = False
    #: RMS of the drive (m y'' or F) the own force's share of the drive is of, over the
    #: same span as the own force (:func:`term_force_rms`)
    drive_rms_N: float | None = None
    #: of relevant size but explains too little of what is missing (``verdict.explains_little``)
    little: bool = False
    #: named beside these terms from one fit, its own force below the floor where theirs is
    #: above it (:func:`negligible_beside`): negligible, whatever their force together
    beside: tuple[str, ...] = ()

    @property
    def explains(self) -> float:
        """The share of the missing force it explains, as the shapes read theirs where given."""
        return self.share_of_latent if self.share_of_missing is None else self.share_of_missing

    @property
    def label(self) -> str:
        if self.negligible:
            return "detectable but negligible"
        return "explains too little of the mismatch to be relevant" if self.little \
            else "relevant"

    @property
    def term_rms_N(self) -> float | None:
        """The median RMS of the term's own force, None without it."""
        return None if self.own is None else self.own.rms[0]

    @property
    def term_rms_interval_N(self) -> tuple[float, float] | None:
        """The 95 % interval of the term's own force's RMS, None without it."""
        return None if self.own is None else self.own.rms[1:]

    def own_sentence(self) -> str | None:
        """The term's own force with its 95 % interval (its varying part apart from its mean
        where the record leaves the mean to the term's form, :attr:`OwnForce.mean_unfixed`),
        None without it."""
        if self.own is None:
            return None
        unit, how = self.units.label("force"), (", adjusted for correlated residuals"
                                                if self.interval_adjusted else "")
        (mid, lo, hi), (vmid, vlo, vhi) = self.own.rms, self.own.varying
        text = f"its own force {mid:.3g} {unit} RMS (95 %{how}: {lo:.3g}-{hi:.3g})"
        if not self.own.mean_unfixed:
            return text
        return (f"its own force {vmid:.3g} {unit} RMS about its mean (95 %{how}: "
                f"{vlo:.3g}-{vhi:.3g}; its mean, {self.own.mean[0]:.3g} {unit}, {mid:.3g} "
                "RMS with it, is the term's form's, not the record's: a constant force only "
                "moves the rest position, which an acceleration does not see)")

    @property
    def own_share_of_drive(self) -> float | None:
        """The term's own force (median RMS; about its mean where the record leaves the mean
        to the term's form) over the drive's RMS, None without either."""
        if self.own is None or not self.drive_rms_N:
            return None
        return self.own.fixed[0] / self.drive_rms_N

    def sentence(self) -> str:
        if self.beside:
            return (f"{self.term}: named beside {' and '.join(self.beside)}; "
                    f"{self.own_sentence()}, {100 * self.own_share_of_drive:.2g} % of the "
                    f"drive (the floor {100 * self.floor.force_share:g} %): {self.label}")
        text = (f"{self.term}: {self.force_rms_N:.3g} {self.units.label('force')} RMS "
                f"({100 * self.share_of_drive:.2g} % of the drive), explains "
                f"{100 * max(self.explains, 0):.0f} % of the missing force")
        if self.own is not None:
            text += f"; {self.own_sentence()}"
        if self.ridge is not None:
            text += (f", on a ridge with {self.ridge[0]} (posterior correlation "
                     f"{self.ridge[1]:.2f}): the record fixes their combination, not the "
                     "term's own size")
        if self.response_change_share is not None:
            text += (f", changes the predicted response by {100 * self.response_change_share:.2g}"
                     " % RMS on unseen data")
        return f"{text}: {self.label}"

    def _own_parts(self) -> dict:
        """The own force (``OwnForce.to_dict``, each key prefixed term_force_) for
        diagnosis.json; its RMS and interval None without it."""
        if self.own is None:
            return {"term_force_rms_N": None, "term_force_rms_interval_N": None}
        return {f"term_force_{k}": v for k, v in self.own.to_dict().items()}

    def to_dict(self) -> dict:
        return {"term": self.term, "force_rms_N": self.force_rms_N,
                "force_unit": self.units.label("force"),
                "share_of_drive": self.share_of_drive, "share_of_latent": self.share_of_latent,
                "share_of_missing": self.share_of_missing,
                **self._own_parts(),
                "ridge": None if self.ridge is None else {"parameter": self.ridge[0],
                                                          "correlation": self.ridge[1]},
                "interval_adjusted": self.interval_adjusted,
                "response_change_rms": self.response_change_rms,
                "response_change_share": self.response_change_share,
                "relevance": self.label, "named_beside": list(self.beside),
                "floor": self.floor.to_dict(),
                "sentence": self.sentence()}


def negligible_beside(sizes: Sequence[EffectSize]) -> list[str]:
    """Mark the terms named together whose own force (``EffectSize.own_share_of_drive``)
    lies below the floor's share of the drive while another's lies above it: their force
    together, along the smoothed states, is the others'. On the Bouc-Wen benchmark's 40 s
    record a mass error of 0.74 g was named beside the hysteretic spring (+14.5 nats), its own
    force 0.036 N RMS (0.07 % of the drive) against the spring's 22.6 N: "relevant" by their
    sum. Returns the terms marked."""
    shares = {s.term: s.own_share_of_drive for s in sizes}
    if len(sizes) < 2 or any(v is None for v in shares.values()):
        return []
    big = [s.term for s in sizes if shares[s.term] >= s.floor.force_share]
    marked = []
    for s in sizes:
        if s.floor.enabled and big and shares[s.term] < s.floor.force_share:
            s.negligible, s.beside = True, tuple(big)
            marked.append(s.term)
    return marked


def drive_rms(lf: LatentForce, input: np.ndarray | None = None) -> float:
    """RMS of the force that drives the device (N): m y'' for a base input, F for a force;
    over the latent force's window, or over ``input`` (the same kind) where given."""
    gain = lf.values.get("m", 0.0) if lf.input_kind == "base_acc" else 1.0
    u = lf.input if input is None else np.asarray(input, dtype=float)
    return float(max(np.sqrt(np.mean((gain * u) ** 2)), 1e-12))


def response_change(problem, theta: np.ndarray, improved: ModelStructure,
                    improved_theta: np.ndarray, input: np.ndarray, window: slice
                    ) -> tuple[float, float]:
    """(RMS change, as a share of the output's RMS) of the predicted output over ``window``
    when the baseline (``problem``'s structure at ``theta``) becomes ``improved`` at
    ``improved_theta``, both driven by ``input`` (unseen data) and through the chain."""
    other = dataclasses.replace(problem, structure=improved)
    kind = problem.output_kind
    out = []
    for p, th in ((problem, theta), (other, improved_theta)):
        sim = p.simulate(np.atleast_2d(th), input)
        if not sim.ok[0]:
            raise RuntimeError(f"{p.structure.name} cannot be simulated on the unseen input")
        y = sim.rel_disp[0] if kind == "rel_disp" else sim.rel_acc[0]
        out.append(problem.chain(y)[window] if hasattr(problem, "chain") else y[window])
    change = float(np.sqrt(np.mean((out[1] - out[0]) ** 2)))
    return change, change / float(max(np.sqrt(np.mean(out[0] ** 2)), 1e-300))


#: Posterior samples (evenly thinned) the interval of a term's own force is read from.
TERM_DRAWS = 40
#: |Posterior correlation| of a named term's strength with a parameter of the baseline above
#: which the record fixes their combination rather than the term's own size (its marginal
#: sd is then 2.3 x or more its sd with the other parameter held).
RIDGE_CORRELATION = 0.9


def ridge(improved: ModelStructure, samples: np.ndarray, term_name: str
          ) -> tuple[str, float] | None:
    """(the baseline's parameter, the posterior correlation) most correlated with
    ``term_name``'s strength (its probe's parameter) among ``samples`` of ``improved``, where
    beyond RIDGE_CORRELATION; else None. A quadratic damper's c_quad trades against the
    viscous c_m over the velocities a record spans."""
    names = list(improved.free_parameters)
    t = term(term_name)
    if t.probe.strength not in names:
        return None
    rows = np.asarray(samples, dtype=float)[:, :len(names)]
    corr = np.corrcoef(rows, rowvar=False)[names.index(t.probe.strength)]
    others = [(n, float(corr[i])) for i, n in enumerate(names)
              if n not in t.parameter_names and np.isfinite(corr[i])]
    best = max(others, key=lambda o: abs(o[1]), default=None)
    return best if best is not None and abs(best[1]) > RIDGE_CORRELATION else None


def own_span(problem, record_input: np.ndarray | None = None) -> tuple[np.ndarray, int]:
    """(the input, the first sample) of the span a named term's own force is read over: the
    input ``record_input`` (the whole record's; default ``problem``'s, which the diagnosis
    cuts after its analysed window), simulated from its start and read from the start of
    ``problem``'s window to its end: the lead-in left out, the held-out tail kept, the span a
    generator's truth is stated over."""
    u = problem.input if record_input is None else np.asarray(record_input, dtype=float)
    return u, int(problem.window[0])


def term_force_rms(problem, improved: ModelStructure, samples: np.ndarray,
                   term_name: str | Sequence[str], draws: int = TERM_DRAWS,
                   record_input: np.ndarray | None = None) -> OwnForce:
    """``term_name``'s own force (several terms': their sum) over ``draws`` posterior
    ``samples`` of ``improved`` (rows: free parameters, sigma last optional; evenly thinned),
    each along its own simulated response over :func:`own_span`: its RMS, mean and varying
    part (:class:`OwnForce`).
    Under a slow envelope the span matters: on three rotor-inertia records of the literature
    generator the truth's RMS over 1-29.9 s and over 1-40 s differed by -7.7 % to +6.2 %.
    Its own path, not the smoother's: a sign law along a path uncertain by a few mm/s never
    sticks (Coulomb 6 N that sticks 28 % of the time gave an RMS of 5.7 N along the
    smoothed states against 5.2 N along the true path). A friction that sticks carries, where
    the path is stuck, the holding force (``term_forces.named_force``)."""
    other = dataclasses.replace(problem, structure=improved)
    rows = np.asarray(samples, dtype=float)
    rows = rows[np.unique(np.linspace(0, len(rows) - 1, min(draws, len(rows))).astype(int))]
    u, start = own_span(problem, record_input)
    sim = other.simulate(rows, u)
    yb = u if problem.input_kind == "base_acc" else np.zeros_like(u)
    names = (term_name,) if isinstance(term_name, str) else tuple(term_name)
    layout = improved.layout
    forces = []
    for i in np.flatnonzero(sim.ok):
        values = parameter_values(improved, rows[i, :len(improved.free_parameters)],
                                  problem.known)
        drive = -values["m"] * u if problem.input_kind == "base_acc" else u
        forces.append(named_force(layout, values, sim.rel_disp[i], sim.rel_vel[i],
                                  sim.rel_acc[i], yb, drive, problem.dt, names)[0, start:])
    if not forces:
        raise RuntimeError(f"{improved.name} cannot be simulated at its posterior samples")
    return OwnForce(_median_interval([float(np.sqrt(np.mean(f**2))) for f in forces]),
                    _median_interval([float(np.mean(f)) for f in forces]),
                    _median_interval([float(np.std(f)) for f in forces]),
                    mean_seen=problem.output_kind == "rel_disp")


def effect_size(lf: LatentForce, ef: EffectForce, floor: RelevanceFloor = RelevanceFloor(),
                response: tuple[float, float] | None = None,
                share_of_missing: float | None = None,
                own: OwnForce | None = None,
                on_ridge: tuple[str, float] | None = None,
                adjusted: bool = False, own_drive_N: float | None = None) -> EffectSize:
    """The named effect's size from its force beside the latent force (``ef``) and, if
    given, its ``response`` change on unseen data (:func:`response_change`), its share as
    the shapes read theirs, its own force (:func:`term_force_rms`) and the ridge its
    strength lies on (:func:`ridge`), and whether that interval's posterior was adjusted for
    correlated residuals (``adjusted``); labelled in ``lf.units``. ``own_drive_N``: the
    drive's RMS over the own force's span (default: over the window, as the shares)."""
    drive = drive_rms(lf)
    share = ef.rms_N / drive
    small_response = response is None or response[1] < floor.response_share
    negligible = floor.enabled and share < floor.force_share and small_response
    return EffectSize(ef.term, ef.rms_N, share, ef.share,
                      None if response is None else response[0],
                      None if response is None else response[1], negligible, floor, lf.units,
                      share_of_missing, own, on_ridge, adjusted,
                      drive if own_drive_N is None else own_drive_N)
