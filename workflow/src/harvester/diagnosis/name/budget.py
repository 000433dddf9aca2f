"""The diagnosis's time budget (``DiagnosisSettings.budget_s``): the search's deadline,
whether it has passed, what the search left unfinished when it did, and where the time went.

The budget is a target for the whole diagnosis (by default from the recording's length,
:func:`budget_seconds`); the search for names (the rounds' screens and TMCMC runs, the second
pass) gets what is left of it once the later steps' reserve is kept (:func:`search_seconds`).
The baseline's own sampling is not cut, nor the fit on unseen data, the missing force and the
figures that follow the search. Past the deadline a candidate's TMCMC stops at its next stage
or move (``inference.tmcmc.OutOfTime``) and no further candidate, round or pass starts. A candidate
stopped or not started is neither named nor rejected: diagnosis.json lists it
(``budget.unfinished``) and the headline says the budget ran out, so that a user knows which
decision a larger budget (``--budget``) would make.
"""

from __future__ import annotations

import time
from contextlib import contextmanager
from dataclasses import dataclass, field, replace

from harvester.inference.tmcmc import OutOfTime

__all__ = ["OutOfTime", "Timeline", "Unfinished", "budget_dict", "budget_seconds",
           "search_seconds", "spent", "with_deadline"]


#: The default budget (``DiagnosisSettings.budget_s`` None): the whole diagnosis's target,
#: BASE_S + PER_RECORD_S per second of the recording, within [MIN_S, MAX_S]: 160 s for a 10 s
#: record and 280 s for a 40 s one, under the 3 and 5 minutes asked of them on 2 cores.
BUDGET_BASE_S = 120.0
BUDGET_PER_RECORD_S = 4.0
BUDGET_MIN_S = 150.0
BUDGET_MAX_S = 600.0
#: Seconds kept for the steps after the search (the fit on unseen data, the missing force, the
#: figures): RESERVE_BASE_S + RESERVE_PER_RECORD_S per second of the recording. Measured
#: after the search: 13 s on the frame's 10 s record, 55 s on the Silverbox's 40 s record
#: (2 cores shared with other work; docs/measurements.md, "Time budget").
RESERVE_BASE_S = 10.0
RESERVE_PER_RECORD_S = 1.5


def budget_seconds(settings, record_s: float) -> float | None:
    """The diagnosis's time target (s) for a recording of ``record_s`` seconds: the settings'
    ``budget_s``, else the default rule (module constants); None where ``budget`` is off."""
    if not settings.budget:
        return None
    if settings.budget_s is not None:
        return float(settings.budget_s)
    return float(min(max(BUDGET_BASE_S + BUDGET_PER_RECORD_S * record_s, BUDGET_MIN_S),
                     BUDGET_MAX_S))


def search_seconds(budget_s: float, record_s: float) -> float:
    """The search's share of a budget: what is left once the later steps' reserve is kept
    (at least a fifth of the budget)."""
    return max(budget_s - RESERVE_BASE_S - RESERVE_PER_RECORD_S * record_s, 0.2 * budget_s)


def with_deadline(settings, record_s: float, start: float | None = None):
    """``settings`` (DiagnosisSettings) with the search's deadline (``time.time()``, s) set
    from ``start`` (default now) for a recording of ``record_s`` seconds; None without a
    budget."""
    total = budget_seconds(settings, record_s)
    if total is None:
        return replace(settings, deadline=None)
    begun = time.time() if start is None else start
    return replace(settings, deadline=begun + search_seconds(total, record_s))


def spent(settings) -> bool:
    """Whether the settings' deadline has passed (False without one)."""
    return settings.deadline is not None and time.time() > settings.deadline


@dataclass(frozen=True)
class Unfinished:
    """A step of the search the budget cut: ``where`` ("round 2"), ``what`` (the model or
    step), ``how`` (how far it got)."""

    where: str
    what: str
    how: str

    @classmethod
    def stopped(cls, where: str, what: str, stop: OutOfTime) -> "Unfinished":
        return cls(where, what, f"its TMCMC stopped at stage {stop.stage} of chain "
                                f"{stop.chain + 1} (tempering exponent {stop.beta:.3g})")

    def sentence(self) -> str:
        return f"{self.where}: {self.what}: {self.how}"

    def to_dict(self) -> dict:
        return {"where": self.where, "what": self.what, "how": self.how}


@dataclass
class Timeline:
    """Where a diagnosis's time went: seconds per step, in the order the steps ran."""

    steps: list[tuple[str, float]] = field(default_factory=list)

    @contextmanager
    def step(self, name: str):
        """Time the block as step ``name``."""
        begun = time.perf_counter()
        try:
            yield
        finally:
            self.steps.append((name, time.perf_counter() - begun))

    def to_list(self) -> list[dict]:
        return [{"step": name, "seconds": float(s)} for name, s in self.steps]


def budget_dict(settings, record_s: float, search_s: float, unfinished: list[Unfinished],
                timeline: Timeline | None = None) -> dict:
    """diagnosis.json's ``budget``: the diagnosis's time target (s, None: none) and the
    search's share of it, the seconds the search took from the diagnosis's start, whether the
    budget cut it, what it left unfinished, and where the time went (``timeline``)."""
    total = budget_seconds(settings, record_s)
    return {"seconds": total,
            "search_budget_seconds": None if total is None else search_seconds(total, record_s),
            "search_seconds": float(search_s),
            "cut": bool(unfinished), "unfinished": [u.to_dict() for u in unfinished],
            "timeline": [] if timeline is None else timeline.to_list()}
