"""Numbers reported by Green et al. (2015), kept in one place so tables can set ours beside them.

Source: PL Green, M Hendijanizadeh, L Simeone, SJ Elliott, "Probabilistic modelling of a
rotational energy harvester", J. Intelligent Material Systems and Structures (2015).
"""

from __future__ import annotations

#: Table 1, initial parameter estimates (SI units).
TABLE1: dict[str, float] = {"M": 12.8, "m": 8.0, "k": 250.0, "F_c": 8.4, "c_m": 170.0}
#: The parameters held known (fixed) in every model of the paper.
TABLE1_KNOWN: dict[str, float] = {k: TABLE1[k] for k in ("M", "m", "k")}
TABLE1_UNITS: dict[str, str] = {"M": "kg", "m": "kg", "k": "N/m", "F_c": "N", "c_m": "N s/m"}

#: Static friction test: x2 - x1 (m), used in 2 F_c = k (x2 - x1).
STATIC_TEST_SPAN_M = 0.067

#: Tables 2 and 4: prior moments (mean, sd); sigma's sd is missing from Table 2.
TABLE2: dict[str, tuple[float, float | None]] = {"c_m": (170.0, 50.0), "sigma": (0.07, None)}
TABLE4: dict[str, tuple[float, float]] = {
    "c_m": (170.0, 50.0), "F_c": (8.4, 5.0), "beta": (100.0, 100.0), "sigma": (0.07, 0.03),
}

#: Tables 3 and 5: posterior means (1000 TMCMC samples).
TABLE3: dict[str, float] = {"c_m": 432.6, "sigma": 0.1035}
TABLE5: dict[str, float] = {"c_m": 109.5, "F_c": 11.86, "beta": 88.35, "sigma": 0.0956}
POSTERIOR_MEANS: dict[str, dict[str, float]] = {"linear": TABLE3, "tanh": TABLE5}

#: Equation (12): log Bayes factor, tanh (M2) over linear (M1).
LOG_BAYES_FACTOR_TANH_LINEAR = 24.2

#: Fraction of the 80 s of unseen data outside the tanh model's 3-sigma bounds.
OUTSIDE_3SIGMA_UNSEEN = 0.013

#: Acquisition: sampling rate (Hz), training length (samples), validation length (s).
SAMPLING_RATE_HZ = 256.0
TRAINING_SAMPLES = 2000
VALIDATION_SECONDS = 80.0
