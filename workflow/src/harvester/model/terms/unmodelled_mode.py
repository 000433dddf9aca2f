"""A secondary resonance inside the band, on the mass or on the screw side.

u'' + 2 zeta w_n u' + w_n^2 u = -(z'' + drive_base y''), with w_n = 2 pi f_mode; the force
on the mass is m_2 (w_n^2 u + 2 zeta w_n u'), m_2 = mass_mode. drive_base = 1 is a mode
attached to the mass (driven by its absolute acceleration), 0 one on the screw side (a
rotor on a flexible coupling, driven by z'').
"""

from __future__ import annotations

import numpy as np

from harvester.model.terms import Motion, Parameter, RateBound, Term


def force(u, ud, f_mode, zeta_mode, mass_mode, drive_base):
    """Force of the mode on the mass (N): m_2 (w_n^2 u + 2 zeta w_n u')."""
    wn = 2.0 * np.pi * f_mode
    return mass_mode * (wn * wn * u + 2.0 * zeta_mode * wn * ud)


def state_rates(u, ud, a, yb, f_mode, zeta_mode, mass_mode, drive_base):
    """(u', u'') with u'' = -(w_n^2 u + 2 zeta w_n u') - (z'' + drive_base y'')."""
    wn = 2.0 * np.pi * f_mode
    return ud, -(wn * wn * u + 2.0 * zeta_mode * wn * ud) - (a + drive_base * yb)


def rate_bound(p: dict, motion: Motion) -> RateBound:
    """The mode's frequency, raised by its mass ratio and damping."""
    wn = 2.0 * np.pi * np.abs(p["f_mode"])
    ratio = np.abs(p["mass_mode"]) / motion.mass
    return RateBound(rate=wn * np.sqrt(1.0 + ratio) * (1.0 + 2.0 * np.abs(p["zeta_mode"])))


TERM = Term(
    name="unmodelled_mode", kind="mode", n_states=2,
    parameters=(
        Parameter("f_mode", "Hz", 5.0, 3.0, 0.1, "natural frequency of the secondary mode"),
        Parameter("zeta_mode", "-", 0.05, 0.05, 1e-3, "damping ratio of the secondary mode"),
        Parameter("mass_mode", "kg", 0.5, 0.5, 0.0, "modal mass of the secondary mode"),
        Parameter("drive_base", "-", 0.5, 0.5, 0.0,
                  "share of the base acceleration in the mode's drive: 1 for a mode attached "
                  "to the mass (driven by its absolute acceleration x'' = z'' + y''), 0 for "
                  "one on the screw side (a rotor on a flexible coupling, driven by z'')"),
    ),
    equation="u'' + 2 zeta w_n u' + w_n^2 u = -(z'' + drive_base y''), force on the mass "
             "m_2 (w_n^2 u + 2 zeta w_n u')",
    description="secondary resonance inside the band, on the mass or the screw side",
    force=force, state_rates=state_rates, rate_bound=rate_bound, source=__file__)
