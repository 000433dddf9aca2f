"""The effective mass differs from the assumed value: M -> M + dM, m -> m + m_share dM
(eq. 2: M = m + J (2 pi / l)^2).
"""

from __future__ import annotations


from harvester.model.terms import Motion, Parameter, RateBound, Term


def masses(M, m, dM, m_share):
    """(M + dM, m + m_share dM) in kg; also evaluated on arrays for the step bound."""
    return M + dM, m + m_share * dM


def force(z, dM, m_share):
    """No force: the term changes the masses (``masses``)."""
    return 0.0 * z


def rate_bound(p: dict, motion: Motion) -> RateBound:
    """No rate of its own: the step bound uses the changed masses."""
    return RateBound()


TERM = Term(
    name="inertia_error", kind="inertia",
    parameters=(
        Parameter("dM", "kg", 0.0, 1.0, None, "error of the assumed effective mass"),
        Parameter("m_share", "-", 0.5, 0.5, 0.0,
                  "share of dM on the oscillating mass, which also drives the device (-m y''): "
                  "1 for a payload error, 0 for an error of the screw-side inertia "
                  "J (2 pi / l)^2 alone, above 1 when the two errors differ in sign"),
    ),
    equation="M -> M + dM, m -> m + m_share dM (eq. 2: M = m + J (2 pi / l)^2)",
    description="effective mass differs from the assumed value",
    force=force, masses=masses, rate_bound=rate_bound, source=__file__)
