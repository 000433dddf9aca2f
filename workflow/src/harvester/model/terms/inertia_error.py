"""The effective mass differs from the assumed value (a payload, a rotor inertia mis-stated):
M -> M + dM, m -> m + m_share dM (eq. 2: M = m + J (2 pi / l)^2). A secondary mode far above
the band acts the same way; the diagnosis reports the two together.

Priors:

- dM: a mass error of either sign, up to about a third of the effective mass per sd (a forgotten
  payload, a mis-stated rotor inertia)
- m_share: between an error of the screw-side inertia (0) and of the payload (1), unbounded:
  both ends are physical (a rotor error alone is exactly 0, and a bound there made its posterior
  pile against it), and errors of opposite sign lie beyond them
"""

from __future__ import annotations

from harvester.model.priors import Prior
from harvester.model.terms import Motion, Parameter, Probe, RateBound, Term


def masses(M, m, dM, m_share):
    """(M + dM, m + m_share dM) in kg; also evaluated on arrays for the step bound."""
    return M + dM, m + m_share * dM


def device(values):
    """The masses the term implies ({M, m}, kg) from every parameter's value (``values``:
    arrays over posterior draws), for the check against the sidecar's."""
    M, m = masses(values["M"], values["m"], values["dM"], values["m_share"])
    return {"M": M, "m": m}


def force(z, dM, m_share):
    """No force: the term changes the masses (``masses``)."""
    return 0.0 * z


def rate_bound(p: dict, motion: Motion) -> RateBound:
    """No rate of its own: the step bound uses the changed masses."""
    return RateBound()


TERM = Term(
    name="inertia_error", kind="inertia",
    parameters=(
        Parameter("dM", "kg", Prior("normal", 0.0, 0.3, "M", lower=None),
                  "error of the assumed effective mass"),
        Parameter("m_share", "-", Prior("normal", 0.5, 0.5, lower=None),
                  "share of dM on the oscillating mass, which also drives the device (-m y''): 1 "
                  "for a payload error, 0 for an error of the screw-side inertia J (2 pi / l)^2 "
                  "alone, below 0 or above 1 when the two errors differ in sign"),
    ),
    equation="M -> M + dM, m -> m + m_share dM (eq. 2: M = m + J (2 pi / l)^2)",
    description="effective mass differs from the assumed value",
    force=force, masses=masses, rate_bound=rate_bound, device=device, restates=("M", "m"),
    # named where none was put in on 3 of the 29 records of the new recording kinds' grid
    # (535fb08, docs/measurements.md): a round it leads fits the laws with memory first
    catch_all=True,
    probe=Probe("dM", lambda d: 0.008 * d.M, signed=True,
                shapes=lambda d: [{"m_share": share} for share in (0.0, 1.0)]),
    source=__file__)
