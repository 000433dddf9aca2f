"""Priors: a parameter's distribution before the data, in one place for every family, and
priors written relative to a device's own scales, which is how a term's prior travels from one
device to another.

Families (:class:`PriorSpec`):

``normal``      N(mean, sd^2) truncated below at ``lower`` (the paper's Tables 2 and 4);
``lognormal``   ln x ~ N(ln mean, sd^2): ``mean`` is the median and ``sd`` the sd of ln x
                (a factor exp(sd) per sd): a scale known to within a factor;
``loguniform``  ln x uniform between ln ``lower`` and ln ``upper``: every decade of the range
                equally likely, for a scale known only to lie within some decades (a contact
                stiffness, a pre-sliding displacement, a transition velocity).

Work that approximates a prior by a Gaussian (the MAP fit's prior-scaled coordinates, the
prior-data conflict check) does so in the prior's own coordinate, x for the normal family and
ln x for the others (:meth:`PriorSpec.to_coordinate`, :attr:`PriorSpec.center`,
:attr:`PriorSpec.scale`); there a log-uniform prior is flat (:attr:`PriorSpec.is_flat`).

A :class:`Prior` is a family with its two numbers in units of a :class:`DeviceScale`
quantity (the dissipative force, the RMS velocity, the spring stiffness, the analysed band...),
so that one term file states its prior once for every device; :data:`REFERENCE_DEVICE` is the
paper's rig as the study's virtual rig drives it, where a term's default prior is read.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from scipy import stats

FAMILIES = ("normal", "lognormal", "loguniform")


@dataclass(frozen=True)
class PriorSpec:
    """A parameter's prior in its unit (module docstring for the families' fields)."""

    name: str
    mean: float
    sd: float
    unit: str
    lower: float = 0.0
    family: str = "normal"
    upper: float = np.inf

    def __post_init__(self) -> None:
        if self.family not in FAMILIES:
            raise ValueError(f"prior of {self.name}: family must be one of {FAMILIES}, got "
                             f"{self.family!r}")
        if not self.sd > 0 and self.family != "loguniform":
            raise ValueError(f"prior of {self.name}: sd must be positive, got {self.sd}")
        if self.family == "lognormal" and not self.mean > 0:
            raise ValueError(f"prior of {self.name}: a log-normal median must be positive")
        if self.family == "loguniform" and not 0 < self.lower < self.upper < np.inf:
            raise ValueError(f"prior of {self.name}: a log-uniform range needs 0 < lower < "
                             f"upper < inf, got [{self.lower}, {self.upper}]")

    @classmethod
    def log_normal(cls, name: str, median: float, log_sd: float, unit: str) -> "PriorSpec":
        """ln x ~ N(ln median, log_sd^2)."""
        return cls(name, float(median), float(log_sd), unit, 0.0, "lognormal")

    @classmethod
    def log_uniform(cls, name: str, low: float, high: float, unit: str) -> "PriorSpec":
        """ln x uniform on [ln low, ln high]; mean and sd hold the geometric centre and the sd
        of ln x."""
        return cls(name, float(np.sqrt(low * high)), float(np.log(high / low) / np.sqrt(12.0)),
                   unit, float(low), "loguniform", float(high))

    # ---- the prior's own coordinate -------------------------------------------------------

    @property
    def is_log(self) -> bool:
        return self.family != "normal"

    @property
    def is_flat(self) -> bool:
        """Flat in its coordinate (log-uniform): no Gaussian penalty applies."""
        return self.family == "loguniform"

    def to_coordinate(self, x: Any) -> Any:
        """x for the normal family, ln x for the others."""
        return np.log(np.maximum(x, 1e-300)) if self.is_log else x

    def from_coordinate(self, u: Any) -> Any:
        """The inverse of :meth:`to_coordinate`; a coordinate beyond a float's range (a wild
        proposal's) gives inf, which the prior's bounds reject, without a warning."""
        if not self.is_log:
            return u
        with np.errstate(over="ignore"):
            return np.exp(u)

    @property
    def center(self) -> float:
        return float(self.to_coordinate(self.mean))

    @property
    def scale(self) -> float:
        return float(self.sd)

    @property
    def bounds(self) -> tuple[float, float]:
        """(low, high) in the prior's coordinate."""
        if self.family == "loguniform":
            return float(np.log(self.lower)), float(np.log(self.upper))
        if self.family == "lognormal":
            return -np.inf, np.inf
        return float(self.lower), float(self.upper)

    # ---- the distribution -------------------------------------------------------------------

    def distribution(self) -> Any:
        """The prior as a frozen scipy distribution."""
        if self.family == "lognormal":
            return stats.lognorm(s=self.sd, scale=self.mean)
        if self.family == "loguniform":
            return stats.loguniform(self.lower, self.upper)
        a = (self.lower - self.mean) / self.sd
        b = (self.upper - self.mean) / self.sd
        return stats.truncnorm(a, b, loc=self.mean, scale=self.sd)

    def logpdf(self, x: Any) -> Any:
        """Log density of the prior (-inf outside its support)."""
        return self.distribution().logpdf(x)

    def scaled(self, ratio: float) -> "PriorSpec":
        """The prior of ``ratio`` x the parameter (ratio > 0)."""
        if self.family == "normal":
            lower = self.lower * ratio if np.isfinite(self.lower) else self.lower
            upper = self.upper * ratio if np.isfinite(self.upper) else self.upper
            return replace(self, mean=self.mean * ratio, sd=self.sd * ratio, lower=lower,
                           upper=upper)
        if self.family == "lognormal":
            return replace(self, mean=self.mean * ratio)
        return PriorSpec.log_uniform(self.name, self.lower * ratio, self.upper * ratio,
                                     self.unit)

    def describe(self) -> str:
        """One line: the family and its numbers with the unit."""
        u = f" {self.unit}" if self.unit else ""
        if self.family == "loguniform":
            return f"log-uniform {self.lower:.3g}-{self.upper:.3g}{u}"
        if self.family == "lognormal":
            return f"log-normal, median {self.mean:.3g}{u}, x/ {np.exp(self.sd):.3g} per sd"
        low = "" if not np.isfinite(self.lower) else f", >= {self.lower:.3g}"
        return f"N({self.mean:.3g}, {self.sd:.3g}^2){u}{low}"


@dataclass(frozen=True)
class DeviceScale:
    """Magnitudes of a device and its motion that priors and probes are written in.

    force: the damping the motion shows as a force, c_eq sigma_v (N; the power the base puts
    in over the RMS velocity); v: RMS velocity (m/s); z: RMS displacement (m); z_quantiles:
    quantiles of |z| (m; 1.0 its largest value, ``z_max``); f_high: upper edge of the analysed
    band (Hz); M, m (kg), k (N/m): the device's masses and spring.
    """

    force: float
    v: float
    z: float
    f_high: float
    M: float
    m: float
    k: float
    z_quantiles: dict[float, float] = field(default_factory=dict)

    @property
    def z_max(self) -> float:
        """The largest |z| of the motion (m): a peaky excitation reaches 8 x the RMS (the
        literature generator's envelope-modulated multisine), a Gaussian one 3-4 x."""
        return float(self.z_quantiles.get(1.0, 4.0 * self.z))

    def value(self, name: str) -> float:
        """A named scale: an attribute, or one of '1/v', 'k/z^2', 'force/v^2', 'force/v',
        'f_high^2 M' (a stiffness whose resonance on M sits at the band's edge)."""
        derived = {"1/v": 1.0 / self.v, "k/z^2": self.k / self.z**2,
                   "force/v^2": self.force / self.v**2, "force/v": self.force / self.v,
                   "f_high^2 M": (2.0 * np.pi * self.f_high) ** 2 * self.M}
        if name in derived:
            return float(derived[name])
        return float(getattr(self, name))


#: Quantiles of |z| a device's scale records (``DeviceScale.z_quantiles``; 1.0: the largest),
#: as ``harvester.diagnosis.detect.signatures.Z_QUANTILES``.
Z_QUANTILES = (0.5, 0.75, 0.9, 0.97, 0.99, 0.999, 1.0)


#: The paper's rig as the study's virtual rig drives it: the tanh model at Table 5's means on
#: the filtered training record (results/data/training_filtered.csv, samples 256-2256):
#: dissipative force 7.36 N, RMS velocity 0.0115 m/s, RMS displacement 2.46 mm, quantiles of
#: |z| (0.5, 0.75, 0.9, 0.97, 0.99, 0.999, 1) 1.9, 2.9, 3.9, 4.9, 5.0, 5.2, 5.2 mm (measured);
#: the detection's band to 0.9 x 20 Hz; Table 1's M, m, k. A term's default prior is its
#: Prior read here.
REFERENCE_DEVICE = DeviceScale(force=7.36, v=0.0115, z=0.00246, f_high=18.0, M=12.8, m=8.0,
                               k=250.0, z_quantiles={0.5: 0.0019, 0.75: 0.0029, 0.9: 0.0039,
                                                     0.97: 0.0049, 0.99: 0.0050,
                                                     0.999: 0.0052, 1.0: 0.0052})


@dataclass(frozen=True)
class Prior:
    """A prior in units of a device scale: the family of :class:`PriorSpec` with its two
    numbers (normal: mean, sd; lognormal: median, sd of ln x; loguniform: low, high) times
    ``scale`` (a :meth:`DeviceScale.value` name, a function of the device, or None for
    absolute numbers), and for the normal family a lower bound in the same units (None: none).
    ``why``: the physical reasoning, shown with the term."""

    family: str
    a: float
    b: float
    scale: str | Callable[[DeviceScale], float] | None = None
    lower: float | None = 0.0
    why: str = ""
    upper: float | None = None

    def spec(self, name: str, unit: str, device: DeviceScale = REFERENCE_DEVICE) -> PriorSpec:
        """The prior of parameter ``name`` (in ``unit``) on ``device``."""
        s = 1.0 if self.scale is None else (self.scale(device) if callable(self.scale)
                                            else device.value(self.scale))
        if self.family == "loguniform":
            return PriorSpec.log_uniform(name, self.a * s, self.b * s, unit)
        if self.family == "lognormal":
            return PriorSpec.log_normal(name, self.a * s, self.b, unit)
        lower = -np.inf if self.lower is None else self.lower * s
        upper = np.inf if self.upper is None else self.upper * s
        return PriorSpec(name, self.a * s, self.b * s, unit, lower, upper=upper)
