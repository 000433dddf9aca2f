"""Candidates that would only restate what the baseline identifies.

A mass error (``inertia_error``: M -> M + dM, m -> m + m_share dM) is physics where the
sidecar states the masses: the record then says the stated ones are wrong. Where the baseline
identifies them itself (not given), dM only moves a quantity that is already free: the
likelihood of M + dM is that of M, and the term's evidence gain is M's prior conflict (the
prior from the recording's FRF), which the detection reports as such. On EMPS through the
command line (M from the FRF, 84.8 kg) such a term was named with dM = +135 kg beside the
offset force, a mass error on a device whose mass nobody stated. A term restates the
quantities of its ``Term.restates``; m counts only where the input is a base motion (the drive
-m y''), since a force input does not involve it.

Friction on the ground (a ``ground`` term, on the mass's absolute velocity) is the baseline's
own friction where the input is a force: the base is fixed, so the ground is the base. A
record rewritten with its friction on the ground (the sidecar's ``friction_on: ground`` or
the diagnosis's choice, ``topology``) is driven by a force too: its friction is all on the
ground already.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace

from harvester.model.terms import TERMS


def used_quantities(force_input: bool) -> tuple[str, ...]:
    """The stated device quantities the recording's model depends on."""
    return ("M", "k") if force_input else ("M", "m", "k")


def redundant_terms(known: Mapping[str, float], force_input: bool) -> dict[str, str]:
    """Terms that only restate quantities the baseline identifies: name -> why, in words."""
    used = used_quantities(force_input)
    out = {}
    for name, t in TERMS.items():
        restated = [q for q in t.restates if q in used]
        if restated and not any(q in known for q in restated):
            which = " and ".join(restated)
            out[name] = (f"{name} is not a candidate: it would only restate {which}, which "
                         f"the baseline identifies (not given), so its gain would be the "
                         f"prior conflict of {which}, reported as such; give {which} in the "
                         "sidecar to test a mass error")
        elif t.kind == "ground" and force_input:
            out[name] = (f"{name} is not a candidate: with a force input the base is fixed "
                         "(or the recording was rewritten with its friction on the ground), "
                         "so friction on the ground is the baseline's own")
    return out


def without_redundant(settings, known: Mapping[str, float], force_input: bool
                      ) -> tuple[object, list[str]]:
    """(``settings`` with the redundant terms left out of its candidates, the notes why)."""
    dropped = redundant_terms(known, force_input)
    allowed = settings.candidates
    pool = list(allowed) if allowed is not None else [n for n, t in TERMS.items() if t.nameable]
    kept = tuple(t for t in pool if t not in dropped)
    notes = [why for name, why in dropped.items() if name in pool]
    if not notes:
        return settings, []
    return replace(settings, candidates=kept), notes
