"""Whether a candidate's likelihood is smooth about its best fit, checked before TMCMC.

TMCMC moves its particles by a Metropolis random walk scaled to the population's spread,
which at the last stages is the posterior's width. It mixes where the tempered
log-likelihood is smooth on that scale. A simulation whose path switches with its
parameters (a mass that sticks in one cycle and slides through it after a change of 0.2 %
in a friction level) makes the log-likelihood jump by tens to hundreds of nats between
neighbouring points: the random walk then accepts a few per cent of its moves, every stage
runs to its cap, the chains disagree by tens of nats, and the evidence is not estimated (the
frame at 250 g: 27 min of TMCMC for one such candidate; docs/measurements.md).

The check (:func:`smoothness`): along each principal axis of the MAP's Laplace covariance
in the prior coordinates (``map_fit.PriorCoordinates``), the directions and the scales of
the random walk's proposals, the profiled log-likelihood at the MAP and at PROBES times the
axis's standard deviation from it (shortened to stay inside the prior's support; a point
whose simulation fails is a wall, as a bound, and left out), a quadratic fitted through
those points by least squares, and the largest distance of a point from it. A smooth
likelihood departs from its quadratic by its third and fourth derivatives over one sd, a
fraction of a nat to a few nats for a skewed posterior; a switching one by the size of its
jumps. Along the parameters' own axes, at their marginal sds, two correlated parameters
reach where the likelihood has fallen by hundreds of nats, and a smooth posterior looked as
rough as a switching one (the literature generator's Bouc-Wen record); at their conditional
sds, a switching one looked smooth (the frame at 250 g). ``ROUGH_NATS`` divides the two
(measured on every screened candidate of the literature grid's records and the frame's:
docs/measurements.md). 2 x 3 x d simulations, one batch.
"""

from __future__ import annotations

import time
from collections.abc import Collection, Mapping
from dataclasses import dataclass

import numpy as np

from harvester.inference.map_fit import PointFit, PriorCoordinates
from harvester.diagnosis.name.screen import profiled_rows
from harvester.inference.priors import PriorSpec

#: Steps from the MAP along each parameter, in its Laplace standard deviation.
PROBES = (-1.0, -0.5, -0.25, 0.25, 0.5, 1.0)
#: Largest departure (nats) of the log-likelihood from its quadratic along one axis that
#: still counts as smooth. A Metropolis move across a departure of d nats is accepted about
#: exp(-d) of the times it should be: a few nats slow the walk, 15 (3e-7) stop it. Measured
#: (docs/measurements.md): every candidate TMCMC sampled on the literature grid's records
#: 0.63 nats at most, the study's frame at 450 g 3.6 (its hysteresis, which TMCMC samples
#: with chains 0.3 nat apart); the frame at 250 g's Stribeck candidate 49 (its chains 17
#: nats apart after 27 min).
ROUGH_NATS = 15.0


@dataclass(frozen=True)
class Smoothness:
    """The check's result: the largest departure and where it lies."""

    departure: float  # nats, largest over the axes (nan: no axis could be probed)
    parameter: str  # the parameter that leads the axis along which it lies
    departures: dict[str, float]  # nats, per leading parameter (the largest of its axes)
    simulations: int
    seconds: float

    @property
    def rough(self) -> bool:
        return bool(self.departure > ROUGH_NATS)

    def phrase(self) -> str:
        return (f"along an axis of its Laplace covariance led by {self.parameter}, within one "
                f"sd of its best fit, the "
                f"log-likelihood departs from a quadratic by {self.departure:.1f} nats "
                f"(smooth: at most {ROUGH_NATS:g})")

    def to_dict(self) -> dict:
        return {"departure_nats": self.departure, "parameter": self.parameter,
                "departures_nats": self.departures, "rough": self.rough,
                "rough_nats": ROUGH_NATS, "probes_sd": list(PROBES),
                "simulations": self.simulations, "seconds": self.seconds}


def smoothness(problem, specs: Mapping[str, PriorSpec], point: PointFit,
               on_bound: Collection[str] = ()) -> Smoothness:
    """The check of the module docstring for ``problem`` (a ``ChainProblem``) at its MAP
    ``point`` under the priors ``specs``; ``parameter`` names the axis by the parameter that
    weighs most in it. Axes led by a parameter of ``on_bound`` (whose MAP lies on a bound
    of its prior: ``Screened.on_bound``) are left out: the fall towards the bound is the
    bound's check (``map_fit.bound_pull``), and along it the Laplace scale means nothing
    (the Dahl record's c_hyst fell 5000 nats within 0.06 sd of its MAP, a wall, and its
    TMCMC mixed)."""
    clock = time.perf_counter()
    names = problem.structure.free_parameters
    coords = PriorCoordinates.of(problem, specs)
    u0 = coords.u(point.theta[:len(names)])
    axes = _axes(coords, u0, point.cov)
    labels = [names[int(np.argmax(np.abs(a)))] for a in axes]
    axes = [a for a, n in zip(axes, labels) if n not in on_bound]
    labels = [n for n in labels if n not in on_bound]
    rows, where = [u0], []
    for k, step in enumerate(axes):
        for t in _steps(coords, u0, step):
            rows.append(u0 + t * step)
            where.append((k, t))
    ll, _ = profiled_rows(problem, coords.theta(np.array(rows)))
    departures: dict[str, float] = {}
    for k, dep in _departures(ll[0], ll[1:], where).items():
        departures[labels[k]] = max(dep, departures.get(labels[k], 0.0))
    worst = max(departures, key=departures.get, default="")
    return Smoothness(departures.get(worst, float("nan")), worst, departures, len(rows),
                      time.perf_counter() - clock)


def _axes(coords: PriorCoordinates, u0: np.ndarray, cov: np.ndarray) -> list[np.ndarray]:
    """The Laplace covariance's principal axes in prior coordinates, each scaled to its
    standard deviation (none where the covariance is not finite)."""
    d = coords.dtheta_du(u0)
    cov_u = np.asarray(cov, dtype=float) / np.outer(d, d)
    if not np.all(np.isfinite(cov_u)):
        return []
    lam, vec = np.linalg.eigh(0.5 * (cov_u + cov_u.T))
    return [vec[:, k] * np.sqrt(lam[k]) for k in range(len(lam)) if lam[k] > 0]


def _steps(coords: PriorCoordinates, u0: np.ndarray, step: np.ndarray) -> list[float]:
    """PROBES along ``step``, each side shortened to the part inside the prior's support."""
    low, high = coords.bounds()
    out = []
    for side in (-1.0, 1.0):
        with np.errstate(divide="ignore", invalid="ignore"):
            room = np.where(side * step > 0, (high - u0) / (side * step),
                            np.where(side * step < 0, (low - u0) / (side * step), np.inf))
        reach = min(1.0, float(np.min(room)) * (1.0 - 1e-9))
        if reach > 0:
            out += [t * reach for t in PROBES if t * side > 0]
    return out


def _departures(ll0: float, ll: np.ndarray, where: list[tuple[int, float]]
                ) -> dict[int, float]:
    """Per axis with at least four finite points (the MAP among them; a failed simulation is
    left out): the largest distance of a point's log-likelihood from the quadratic in the
    step fitted through them."""
    out = {}
    for k in sorted({k for k, _ in where}):
        pts = [(t, v) for (i, t), v in zip(where, ll) if i == k and np.isfinite(v)]
        if len(pts) < 3:
            continue
        t = np.array([0.0] + [p[0] for p in pts])
        y = np.array([ll0] + [p[1] for p in pts])
        fit = np.polynomial.polynomial.polyfit(t, y, 2)
        out[k] = float(np.max(np.abs(y - np.polynomial.polynomial.polyval(t, fit))))
    return out
