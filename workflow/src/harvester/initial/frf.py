"""Initial modelling for unknown M, m, k, c_m: priors from a linear frequency-response fit.

The paper fixed M, m, k from Table 1 and fitted c_m to the measured FRF ('Initial
modelling'). For a recording whose sidecar does not give M, m or k, the same step fits the
linear part of eq. (1),

    M z'' + c z' + k z = drive,        drive = -m y'' (base_acc) or F (force),

to the measured FRF from the input to the output, and the fit's values become the means of
the Gaussian priors (truncated at 0) of the parameters that are identified. The FRF of the
linear model, with D(w) = k - M w^2 + i c w the dynamic stiffness:

============== ============= ==================
input, output  FRF           D from the FRF H
============== ============= ==================
force, rel_disp 1 / D        1 / H
force, rel_acc  -w^2 / D     -w^2 / H
base, rel_disp  -m / D       -m / H
base, rel_acc   m w^2 / D    m w^2 / H
============== ============= ==================

Method: (1) H is estimated by Welch spectra, H1 = S_uy / S_uu, or, for a record taken in
closed loop, with an instrument r that drives the loop but is independent of the noise
(the position reference): H = S_ry / S_ru, which H1 would bias towards the controller's
inverse. (2) D(w) is linear in (k, M, c) (in (k/m, M/m, c/m) for a base input, where eq. (1)
fixes only ratios and a known parameter sets the scale): a coherence- and magnitude-weighted
linear least squares over the band gives the start. (3) The parameters are refined by least
squares on the log of H (log-magnitude and phase), weighted by gamma^2 / (1 - gamma^2).

Friction and other nonlinearities make c an equivalent damping (larger than the viscous
c_m, as in the paper: its Coulomb-model c_m was a third of the linear model's), so the prior
widths are relative (config), not the fit's statistical errors, which are far smaller than
its modelling error.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray
from scipy import optimize, signal

from harvester.data.errors import DataError
from harvester.data.recording import RecordingKinds, check_scale, input_output
from harvester.inference.priors import PriorSpec

log = logging.getLogger("harvester.initial")

#: Default relative prior sd of each base parameter (fraction of the fitted value).
REL_SD: dict[str, float] = {"M": 0.25, "m": 0.25, "k": 0.5, "c_m": 0.5}
#: Coherence is clipped at this value for the weights gamma^2 / (1 - gamma^2).
MAX_COHERENCE = 0.99
#: Lines with coherence below this are left out of the fit.
MIN_COHERENCE = 0.5
#: Default Welch segment length (s).
SEGMENT_S = 2.0
#: Default prior of sigma: mean and sd this fraction of the output's standard deviation.
SIGMA_FRACTION = 0.1


def dynamic_stiffness_factor(freqs_hz: ArrayLike, kinds: RecordingKinds) -> NDArray:
    """G(w) with H = G / D: 1, -w^2, -1 (x m), w^2 (x m) by kind (m left out)."""
    w = 2.0 * np.pi * np.asarray(freqs_hz, dtype=float)
    sign = 1.0 if kinds.input_kind == "force" else -1.0
    return sign * (np.ones_like(w) if kinds.output_kind == "rel_disp" else -w**2)


def linear_frf(freqs_hz: ArrayLike, M: float, m: float, k: float, c: float,
               kinds: RecordingKinds) -> NDArray[np.complex128]:
    """FRF of the linear eq. (1) from the input to the output of ``kinds`` (SI units)."""
    w = 2.0 * np.pi * np.asarray(freqs_hz, dtype=float)
    scale = 1.0 if kinds.input_kind == "force" else m
    with np.errstate(divide="ignore", invalid="ignore"):  # w = 0 with k = 0: a free mass
        return scale * dynamic_stiffness_factor(freqs_hz, kinds) / (k - M * w**2 + 1j * c * w)


def measured_frf(u: ArrayLike, y: ArrayLike, fs: float, segment_s: float = SEGMENT_S,
                 reference: ArrayLike | None = None
                 ) -> tuple[NDArray, NDArray[np.complex128], NDArray]:
    """(frequencies Hz, FRF y/u, coherence) by Welch spectra (Hann, 50 % overlap, detrended).

    Without ``reference``: H1 = S_uy / S_uu and the coherence of u and y. With a
    ``reference`` r (closed loop): H = S_ry / S_ru and the coherence of r and u (how much of
    the input the instrument explains).
    """
    u, y = np.asarray(u, dtype=float), np.asarray(y, dtype=float)
    nper = int(max(8, min(round(segment_s * fs), u.size // 2)))
    kw = dict(fs=fs, nperseg=nper, noverlap=nper // 2, detrend="linear")
    f, s_uu = signal.welch(u, **kw)
    if reference is None:
        _, s_yy = signal.welch(y, **kw)
        _, s_uy = signal.csd(u, y, **kw)
        h = s_uy / np.where(s_uu > 0, s_uu, np.inf)
        coh = np.abs(s_uy) ** 2 / np.where(s_uu * s_yy > 0, s_uu * s_yy, np.inf)
    else:
        r = np.asarray(reference, dtype=float)
        _, s_rr = signal.welch(r, **kw)
        _, s_ry = signal.csd(r, y, **kw)
        _, s_ru = signal.csd(r, u, **kw)
        h = s_ry / np.where(np.abs(s_ru) > 0, s_ru, np.inf)
        coh = np.abs(s_ru) ** 2 / np.where(s_rr * s_uu > 0, s_rr * s_uu, np.inf)
    return f, h, np.clip(coh, 0.0, 1.0)


@dataclass
class FrfFit:
    """Linear eq. (1) fitted to a measured FRF.

    values: M, m, k, c_m (kg, kg, N/m, N s/m) of the fit, known ones as given (for a base
    input the scale comes from a known one; m is NaN for a force input); fitted: the names
    estimated from the data; residual: weighted RMS of the log-FRF misfit (nepers/rad);
    freqs_hz, h_measured, h_model, coherence: on the Welch grid; band_hz: fit band.
    """

    values: dict[str, float]
    fitted: tuple[str, ...]
    residual: float
    kinds: RecordingKinds
    band_hz: tuple[float, float]
    freqs_hz: NDArray = field(repr=False)
    h_measured: NDArray = field(repr=False)
    h_model: NDArray = field(repr=False)
    coherence: NDArray = field(repr=False)
    notes: list[str] = field(default_factory=list)  # warnings with their evidence

    def summary(self) -> dict:
        """Scalars for JSON."""
        values = {k: (v if np.isfinite(v) else None) for k, v in self.values.items()}
        return {"values": values, "fitted": list(self.fitted), "residual": self.residual,
                "input_kind": self.kinds.input_kind, "output_kind": self.kinds.output_kind,
                "band_hz": list(self.band_hz)}


def _linear_start(f: NDArray, d: NDArray, weight: NDArray) -> NDArray:
    """(k, M, c) (or ratios to m) from D(w) = k - M w^2 + i c w by weighted linear LS."""
    w = 2.0 * np.pi * f
    rel = weight / np.abs(d) ** 2  # relative errors of D
    a_re = np.column_stack([np.ones_like(w), -w**2]) * np.sqrt(rel)[:, None]
    k, M = np.linalg.lstsq(a_re, d.real * np.sqrt(rel), rcond=None)[0]
    c = float(np.sum(rel * w * d.imag) / np.sum(rel * w * w))
    return np.array([max(k, 0.0), max(M, 1e-12), max(c, 1e-12)])


def _fit_band(f: NDArray, h: NDArray, coh: NDArray, band_hz: tuple[float, float],
              source: str) -> tuple[NDArray, NDArray, NDArray]:
    """(frequencies Hz, FRF, weight gamma^2 / (1 - gamma^2)) of the lines fitted: inside
    ``band_hz``, above 0 Hz, with coherence of at least :data:`MIN_COHERENCE`."""
    band = (f >= band_hz[0]) & (f <= band_hz[1]) & (f > 0) & (coh >= MIN_COHERENCE)
    if band.sum() < 3:
        raise ValueError(f"{source}: fewer than 3 FRF lines with coherence >= {MIN_COHERENCE} "
                         f"in {band_hz} Hz")
    gamma2 = np.minimum(coh[band], MAX_COHERENCE)
    return f[band], h[band], gamma2 / (1.0 - gamma2)


def _refine_log_frf(fb: NDArray, hb: NDArray, weight: NDArray, kinds: RecordingKinds,
                    hold_k: float | None, hold_c: float | None
                    ) -> tuple[float, float, float, float]:
    """(k, M, c, weighted RMS log-FRF residual): step (3) of the module docstring, started
    from the linear least squares of step (2). ``hold_k``/``hold_c``: values held (None:
    fitted). For a base input k, M, c are ratios to m."""
    g = dynamic_stiffness_factor(fb, kinds)
    start = _linear_start(fb, g / hb, weight)  # D (force) or D / m (base)
    wb = 2.0 * np.pi * fb
    scale = np.array([max(start[1] * wb.min() ** 2, 1e-12), start[1], start[2]])

    def unpack(x: NDArray) -> tuple[float, float, float]:
        k = x[0] * scale[0] if hold_k is None else float(hold_k)
        c = np.exp(x[2]) * scale[2] if hold_c is None else float(hold_c)
        return k, np.exp(x[1]) * scale[1], c

    def residuals(x: NDArray) -> NDArray:
        k, M, c = unpack(x)
        res = np.log(hb * (k - M * wb**2 + 1j * c * wb) / g)
        return np.concatenate([res.real, res.imag]) * np.sqrt(np.tile(weight, 2))

    x0 = np.array([start[0] / scale[0], 0.0, 0.0])
    sol = optimize.least_squares(residuals, x0, bounds=([0.0, -np.inf, -np.inf], np.inf))
    k, M, c = unpack(sol.x)
    return k, M, c, float(np.sqrt(np.sum(sol.fun**2) / (2.0 * np.sum(weight))))


def _scale_base_ratios(ratios: dict[str, float], known: Mapping[str, float],
                       kinds: RecordingKinds, source: str, check_units: bool,
                       linearity=None, notes: list[str] | None = None
                       ) -> tuple[dict[str, float], tuple[str, ...]]:
    """(values, fitted) of a base input's fit, whose M, k, c_m are ratios to m: scaled by the
    first known of M, m, k, c_m; with ``check_units``, an m/M above 1.2 (or none at all: no
    mass line) is an error and one off the known m/M by a factor g is reported, unless the
    recording is visibly nonlinear (``linearity``, a zero-argument function giving
    ``checks.Nonlinearity``): a linear fit to a friction-dominated device means nothing, so
    what it gives is a warning (appended to ``notes``) with that evidence."""
    anchor = next((p for p in ("M", "m", "k", "c_m") if p in known and ratios[p] > 0), None)
    if anchor is None:
        raise ValueError(f"{source}: with a base_acc input the FRF gives only ratios to m: "
                         "give M, m, k or c_m as known")
    s = float(known[anchor]) / ratios[anchor]
    values = {p: v * s for p, v in ratios.items()}
    fitted = tuple(p for p in ("M", "m", "k", "c_m") if p != anchor)
    if check_units:
        m_over_M = 1.0 / ratios["M"] if ratios["M"] > 0 else float("inf")
        if not m_over_M <= 1.2:
            found = (f"the linear FRF fit gives m/M = {m_over_M:.3g}" if np.isfinite(m_over_M)
                     else "the linear FRF fit finds no mass line (M/m = 0)")
            nl = linearity() if linearity is not None else None
            if nl is not None and nl.visible:
                note = (f"{source}: {found}, which no linear device gives (M = m + J (2 pi / "
                        f"l)^2 >= m); but the recording is visibly nonlinear ({nl.evidence()}),"
                        " so its FRF does not measure m/M: no unit is inferred from it, and "
                        "the linear fit's values are only a start")
                log.warning("%s", note)
                (notes if notes is not None else []).append(note)
                return values, fitted
            raise DataError(source, f"{found} > 1, impossible for a device (M = m + J (2 pi / "
                            f"l)^2 >= m) whose response looks linear"
                            + (f" ({nl.evidence()})" if nl is not None else "")
                            + f": are {kinds.input_kind} and {kinds.output_kind} in the units "
                            f"of the format ({kinds.input_unit}, {kinds.output_unit})? A column "
                            "in g is 9.81 times too small, one in mm 1000 times too large")
        if "M" in known and "m" in known:
            check_scale({"m_over_M": m_over_M}, {"m_over_M": known["m"] / known["M"]}, kinds,
                        source)
    return values, fitted


def fit_linear_frf(recording: pd.DataFrame, known: Mapping[str, float],
                   band_hz: tuple[float, float], segment_s: float = SEGMENT_S,
                   reference: str | ArrayLike | None = None,
                   source: str = "<recording>", check_units: bool = True) -> FrfFit:
    """Fit the linear eq. (1) to the recording's FRF over ``band_hz``.

    ``known``: the sidecar's values (M, m, k, c_m). For a force input a known k or c_m is
    held and M is always fitted, so that a known M can be checked against the data for a unit
    slip (:func:`harvester.data.recording.check_scale`: a ratio of g or 1000). For a base input
    the fit gives M/m, k/m, c/m; a known parameter sets the scale (M first, then m, k, c_m),
    and an m/M above 1 (impossible) or off the known m/M by a factor g is reported.
    ``reference``: an instrument column name or array, for a record taken in closed loop.
    """
    kinds, u, y, dt = input_output(recording)
    r = recording[reference].to_numpy(float) if isinstance(reference, str) else reference
    f, h, coh = measured_frf(u, y, 1.0 / dt, segment_s, r)
    fb, hb, weight = _fit_band(f, h, coh, band_hz, source)
    # a force input's known k and c_m are held (M is always fitted: the unit check needs it)
    hold_k = known.get("k") if kinds.input_kind == "force" else None
    hold_c = known.get("c_m") if kinds.input_kind == "force" else None
    k, M, c, resid = _refine_log_frf(fb, hb, weight, kinds, hold_k, hold_c)
    notes: list[str] = []

    def linearity():
        from dataclasses import replace

        from harvester.data.checks import nonlinearity
        return replace(nonlinearity(u, y, 1.0 / dt, band_hz[1]), frf_misfit=resid)

    if kinds.input_kind == "base_acc":
        values, fitted = _scale_base_ratios({"M": M, "m": 1.0, "k": k, "c_m": c}, known, kinds,
                                            source, check_units, linearity, notes)
    else:
        values = {"M": M, "m": np.nan, "k": k, "c_m": c}
        fitted = ("M",) + (("k",) if hold_k is None else ()) + (("c_m",) if hold_c is None else ())
        if check_units:
            try:
                check_scale({"M": M, "k": k, "c_m": c},
                            {p: known[p] for p in ("M",) if p in known}, kinds, source)
            except DataError as err:
                nl = linearity()
                if not nl.visible:
                    raise
                notes.append(f"{err}; but the recording is visibly nonlinear "
                             f"({nl.evidence()}), so its FRF does not measure M: no unit is "
                             "inferred from it")
                log.warning("%s", notes[-1])
    h_model = linear_frf(f, values["M"], values["m"] if kinds.input_kind == "base_acc" else 1.0,
                         values["k"], values["c_m"], kinds)
    return FrfFit(values={p: float(v) for p, v in values.items()}, fitted=fitted,
                  residual=resid, kinds=kinds, band_hz=(float(band_hz[0]), float(band_hz[1])),
                  freqs_hz=f, h_measured=h, h_model=h_model, coherence=coh, notes=notes)


def frf_prior_specs(fit: FrfFit, free: tuple[str, ...],
                    rel_sd: Mapping[str, float] | None = None) -> dict[str, PriorSpec]:
    """Gaussian priors (truncated at 0) for the ``free`` base parameters from an FRF fit.

    Mean: the fitted value; sd: ``rel_sd[name]`` x the value (default :data:`REL_SD`). A
    stiffness fitted at ~0 (a free mass) gets sd = M (2 pi f_low)^2, the smallest stiffness the
    band could have shown.
    """
    rel = {**REL_SD, **(rel_sd or {})}
    units = {"M": "kg", "m": "kg", "k": "N/m", "c_m": "N s/m"}
    specs = {}
    for name in free:
        if name not in units:
            continue
        value = fit.values[name]
        if not np.isfinite(value):
            raise ValueError(f"the FRF fit gives no value for {name} "
                             f"(input {fit.kinds.input_kind})")
        sd = rel[name] * value
        if name == "k":
            floor = fit.values["M"] * (2.0 * np.pi * fit.band_hz[0]) ** 2
            sd = max(sd, floor)
        specs[name] = PriorSpec(name=name, mean=float(value), sd=float(sd), unit=units[name])
    return specs


def sigma_prior(recording: pd.DataFrame, fraction: float = SIGMA_FRACTION) -> PriorSpec:
    """Prior of sigma: mean = sd = ``fraction`` x the output's standard deviation."""
    kinds, _, y, _ = input_output(recording)
    s = fraction * float(np.std(y))
    return PriorSpec(name="sigma", mean=s, sd=s, unit=kinds.output_unit)


def initial_priors(recording: pd.DataFrame, known: Mapping[str, float], free: tuple[str, ...],
                   band_hz: tuple[float, float], segment_s: float = SEGMENT_S,
                   reference: str | ArrayLike | None = None,
                   rel_sd: Mapping[str, float] | None = None,
                   sigma_fraction: float = SIGMA_FRACTION,
                   source: str = "<recording>") -> tuple[FrfFit, dict[str, PriorSpec]]:
    """FRF fit and the priors of the ``free`` base parameters and of sigma.

    ``free`` is usually :func:`harvester.inference.problems.free_base_parameters` of the
    structure; the returned priors go to :func:`harvester.inference.identify.identify` together
    with the friction terms' priors (config or library defaults).
    """
    fit = fit_linear_frf(recording, known, band_hz, segment_s, reference, source)
    specs = frf_prior_specs(fit, free, rel_sd)
    specs["sigma"] = sigma_prior(recording, sigma_fraction)
    return fit, specs
