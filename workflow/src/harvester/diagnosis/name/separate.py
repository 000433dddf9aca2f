"""Which measurement would separate two effects the recording cannot tell apart.

When two physically different candidates explain a mismatch about equally well (a mode far
above the band and a mass error; a bristle stiffness and a stiff mode during sticking; an
offset force and a direction-dependent friction under one-sided motion), the diagnosis names
neither alone; it says what each would mean and which experiment would decide between them.

For a proposed excitation u (the recording's own at twice and at half its amplitude, and a
logarithmic sine sweep over the analysed band at its RMS level) and a candidate A taken as
the truth: A's posterior-mean response to u is the noise-free data, the rival B is refitted to
it (its MAP in its prior coordinates, started from its posterior mean, ``map_fit.fit_map``),
and what B cannot follow is the evidence A would gain on such a recording,

    gap_A(u) = lambda sum_t (y_A(t) - y_B*(t))^2 / (2 sigma^2)      (nats),

(y the output in the recording's kind, z'' or z) through the likelihood's low-pass, over a
window as long as the one analysed, lambda and sigma the diagnosis's tempering and noise level
(an expected log Bayes factor, the parameters' Occam factors left out). The experiment whose smaller gap (A true, or B true) is largest is
the one recommended.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np
from scipy import signal

from harvester.inference.map_fit import ChainProblem, fit_map
from harvester.inference.likelihood import Problem

log = logging.getLogger("harvester.diagnosis")


@dataclass(frozen=True)
class Experiment:
    """A proposed excitation: its name, what it is, and the input in the model's input kind
    (a base acceleration in m/s^2, or a force in N); the field keeps the paper-case name."""

    name: str
    description: str
    base_acc: np.ndarray = field(repr=False)


def proposed_experiments(base_acc: np.ndarray, dt: float, f_high: float) -> list[Experiment]:
    """The recording's excitation at twice and at half its amplitude, and a logarithmic sine
    sweep from 0.3 Hz to the analysed band's edge at its RMS (same length)."""
    u = np.asarray(base_acc, dtype=float)
    t = np.arange(u.size) * dt
    f0, f1 = 0.3, max(f_high, 0.6)
    sweep = signal.chirp(t, f0=f0, t1=t[-1], f1=f1, method="logarithmic")
    taper = np.minimum(1.0, np.minimum(t, t[-1] - t) / 1.0)  # 1 s ramps at the ends
    sweep = sweep * taper * np.sqrt(2.0) * np.std(u)
    return [Experiment("twice_amplitude", "the same excitation at twice its amplitude", 2 * u),
            Experiment("half_amplitude", "the same excitation at half its amplitude", 0.5 * u),
            Experiment("sine_sweep", f"a logarithmic sine sweep {f0:g}-{f1:.3g} Hz at the "
                                     "recording's RMS level", sweep)]


@dataclass
class Separation:
    """Expected evidence gaps of one experiment: ``gaps[e]`` is what effect e would gain over
    the other if e were the truth (nats)."""

    experiment: str
    description: str
    gaps: dict[str, float]

    @property
    def decisive(self) -> float:
        """The smaller of the two gaps: how well the experiment separates them either way."""
        return float(min(self.gaps.values()))

    def to_dict(self) -> dict:
        return {"experiment": self.experiment, "description": self.description,
                "expected_gap_nats": self.gaps, "smaller_gap_nats": self.decisive}


def _on_input(fit, u: np.ndarray, output: np.ndarray) -> ChainProblem:
    """The fit's likelihood (its chain and tempering) on another input and output."""
    p = fit.problem
    base = Problem(p.structure, u, output, p.dt, dict(p.known), p.window,
                   input_kind=p.input_kind, output_kind=p.output_kind, v_bound=p.v_bound,
                   oversample=p.oversample)
    return ChainProblem(p.structure, base.input, base.output, p.dt, dict(p.known), p.window,
                        input_kind=p.input_kind, output_kind=p.output_kind,
                        v_bound=p.v_bound, oversample=p.oversample, temper=p.temper,
                        lowpass_hz=p.lowpass_hz, filter_order=p.filter_order,
                        band_fraction=p.band_fraction)


def expected_gap(truth, rival, u: np.ndarray, sigma: float) -> float:
    """gap_truth(u) of the module docstring (nats): ``truth`` and ``rival`` are ModelFits."""
    mean = truth.samples.mean(axis=0)
    sim = truth.problem.simulate(mean[None, :], input=u)
    if not sim.ok[0]:
        return float("nan")
    problem = _on_input(rival, u, truth.problem.output_type.simulated(sim)[0])
    start = rival.samples.mean(axis=0)[:-1]
    try:
        fit = fit_map(problem, rival.priors, n_starts=16, start=start)
    except (ValueError, np.linalg.LinAlgError) as err:
        log.warning("refit of %s failed (%s)", rival.structure.name, err)
        return float("nan")
    r = fit.residual[problem.samples]
    return float(problem.temper * np.sum(r * r) / (2.0 * sigma**2))


def separations(fits: dict, f_high: float) -> list[Separation]:
    """Each proposed experiment's expected gaps for two candidates (``fits``: effect ->
    ModelFit, exactly two), best-separating first."""
    (a, fit_a), (b, fit_b) = fits.items()
    p = fit_a.problem
    sigma = float(np.mean([fit_a.samples[:, -1].mean(), fit_b.samples[:, -1].mean()]))
    out = []
    for exp in proposed_experiments(p.base_acc, p.dt, f_high):
        gaps = {a: expected_gap(fit_a, fit_b, exp.base_acc, sigma),
                b: expected_gap(fit_b, fit_a, exp.base_acc, sigma)}
        log.info("separating %s and %s by %s: expected gap %.1f nats if %s, %.1f if %s", a, b,
                 exp.name, gaps[a], a, gaps[b], b)
        out.append(Separation(exp.name, exp.description, gaps))
    return sorted(out, key=lambda s: -np.nan_to_num(s.decisive, nan=-np.inf))
