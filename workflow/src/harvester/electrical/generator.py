"""The generator of Green et al. (2015, Figure 2) as the identification models it.

A three-phase permanent-magnet generator turned by the ball screw (rotor speed G z', G = 2 pi /
l rad/m) feeds three equal resistors R_L in star. In the rotor's dq frame (amplitude-invariant,
peak phase quantities) with e_q = K_e G z' the back-EMF (K_e: peak line-to-neutral volts per
rad/s, V s/rad), R = R_s + R_L and the phase inductance L_s:

    L_s i_q' = e_q - R i_q - omega_e L_s i_d,    L_s i_d' = -R i_d + omega_e L_s i_q,
    F_e = (3/2) G K_e i_q                          (force on the mass, opposing z')

The electrical time constant tau = L_s / R (at most 0.5 ms on the rig) is far below the
mechanical periods (over 100 ms), so the currents follow the EMF: to first order in tau and
second in omega_e tau,

    i_q = (K_e G / R) (z' - tau z''),   i_d = O(omega_e tau),
    F_e = c_e (z' - tau z''),           c_e = K^2 / R,  K^2 = (3/2) G^2 K_e^2,

which is viscous damping c_e plus a mass change -c_e tau: eq. (1) with c_m + c_e and
M - c_e tau, integrated by the project's compiled simulator, with no state and no stiff
electrical rate. The structure ``resistive`` is tau = 0 (L_s = 0); ``inductive`` identifies L_s.
The expansion holds while tau is small beside the sample period and the mass change small
beside M (:func:`first_order_valid`: tau <= MAX_LAG_S, c_e tau <= MAX_MASS_SHARE M); outside,
a parameter vector is not simulated (zero likelihood): the structure's domain. On the rig
tau <= 0.5 ms and c_e tau <= 0.03 kg.

Observables: the magnitude of the space vector of the line voltages, V = sqrt(3) R_L |i|
(peak line-to-line), which does not depend on the rotor angle:

    V = sqrt(3) K_e G |z' - tau z''| / (1 + R_s g),    g = 1 / R_L (0: open circuit)

and the power into the three load resistors, P = (3/2) R_L |i|^2 = V^2 / (2 R_L) =
K^2 g (z' - tau z'')^2 / (1 + R_s g)^2. Loads enter as conductances g (1/ohm; a scalar or
one per particle) so that open circuit (g = 0: no current, no force, V the back-EMF) is one
case of the same formulae.
"""

from __future__ import annotations

import math

import numpy as np

SQRT3 = math.sqrt(3.0)
#: Largest electrical time constant (s) of the first-order model: half the 256 Hz sample time.
MAX_LAG_S = 2.0e-3
#: Largest mass change c_e tau, as a share of M, of the first-order model.
MAX_MASS_SHARE = 0.05


def screw_ratio(lead_m: float) -> float:
    """G = 2 pi / l (rad/m), rotor angle per metre of travel, from the lead l (m)."""
    return 2.0 * math.pi / float(lead_m)


def conductance(load_ohm: float | None) -> float:
    """g = 1 / R_L (1/ohm) of a star of R_L per phase; 0 in open circuit (None or inf)."""
    if load_ohm is None or not math.isfinite(load_ohm):
        return 0.0
    if load_ohm <= 0.0:
        raise ValueError(f"load resistance must be positive, got {load_ohm} ohm")
    return 1.0 / float(load_ohm)


def coupling(K_e, G: float):
    """K^2 = (3/2) G^2 K_e^2 (N s/m x ohm): electrical damping times the circuit resistance."""
    return 1.5 * (G * np.asarray(K_e)) ** 2


def divider(R_s, g):
    """1 / (1 + R_s g) = R_L / (R_s + R_L): the share of the EMF across the load."""
    return 1.0 / (1.0 + np.asarray(R_s) * g)


def electrical_damping(K_e, R_s, g, G: float):
    """c_e = K^2 g / (1 + R_s g) = K^2 / (R_s + R_L) (N s/m); 0 in open circuit."""
    return coupling(K_e, G) * g * divider(R_s, g)


def time_constant(R_s, L_s, g):
    """tau = L_s / (R_s + R_L) = L_s g / (1 + R_s g) (s); 0 in open circuit."""
    return np.asarray(L_s) * g * divider(R_s, g)


def mechanical_equivalent(M, c_m, K_e, R_s, L_s, g, G: float):
    """(M - c_e tau, c_m + c_e): the effective mass (kg) and damping (N s/m) of eq. (1) with
    the generator at load conductance g (first order in tau); the mass is NaN outside the
    first-order model's domain (:func:`first_order_valid`)."""
    c_e = electrical_damping(K_e, R_s, g, G)
    tau = time_constant(R_s, L_s, g)
    mass = np.where(first_order_valid(M, c_e, tau), M - c_e * tau, np.nan)
    return mass, c_m + c_e


def first_order_valid(M, c_e, tau):
    """Whether the first-order model holds: tau <= MAX_LAG_S (s) and the mass change c_e tau
    <= MAX_MASS_SHARE M (kg)."""
    return (np.asarray(tau) <= MAX_LAG_S) & (np.asarray(c_e) * tau <= MAX_MASS_SHARE * M)


def drive_speed(v, a, tau):
    """u = z' - tau z'' (m/s): the speed the currents follow, lagged by tau (s)."""
    return v - np.asarray(tau)[..., None] * a if np.ndim(tau) else v - tau * a


def line_voltage_magnitude(v, a, K_e, R_s, L_s, g, G: float):
    """V = sqrt(3) K_e G |z' - tau z''| / (1 + R_s g) (V), peak line-to-line; rows of v, a
    (m/s, m/s^2) are particles, parameters one per particle (or scalars)."""
    tau = time_constant(R_s, L_s, g)
    scale = SQRT3 * G * np.asarray(K_e) * divider(R_s, g)
    return _per_row(scale) * np.abs(drive_speed(v, a, tau))


def load_power(v, a, K_e, R_s, L_s, g, G: float):
    """P = K^2 g u^2 / (1 + R_s g)^2 (W), u = z' - tau z'': instantaneous power into the
    three load resistors; 0 in open circuit."""
    tau = time_constant(R_s, L_s, g)
    scale = coupling(K_e, G) * g * divider(R_s, g) ** 2
    return _per_row(scale) * drive_speed(v, a, tau) ** 2


def space_vector_magnitude(v_ab, v_bc):
    """V = sqrt((2/3)(v_ab^2 + v_bc^2 + v_ca^2)) (V), v_ca = -v_ab - v_bc: the peak
    line-to-line voltage of a balanced set, independent of the rotor angle."""
    v_ab, v_bc = np.asarray(v_ab, dtype=float), np.asarray(v_bc, dtype=float)
    return np.sqrt((2.0 / 3.0) * (v_ab ** 2 + v_bc ** 2 + (v_ab + v_bc) ** 2))


def _per_row(x):
    """A per-particle vector as a column (broadcasts over samples); scalars unchanged."""
    x = np.asarray(x, dtype=float)
    return x[..., None] if x.ndim else x
