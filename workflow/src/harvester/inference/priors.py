"""Priors of an identification: the config's (Tables 2 and 4 of the paper), the library's
defaults, and our priors beside the paper's.

The distribution itself (:class:`PriorSpec`, its families) lives in ``harvester.model.priors``.
The config section ``priors`` gives, per parameter, either ``mean`` or ``from: table1`` (the
mean is then our Table 1 estimate, as the paper took its means from its Table 1), plus ``sd``
and ``unit``: a Gaussian truncated at ``lower`` (0 in the paper, 'Linear model' and
'Hyperbolic tangent'); ``family: lognormal`` (mean = median, sd of ln x) or ``family:
loguniform`` (``lower``, ``upper``) for the other families.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd

from harvester.model.priors import REFERENCE_DEVICE, Z_QUANTILES, DeviceScale, PriorSpec
from harvester.model.terms import BASE_PARAMETERS, TERMS

__all__ = ["PriorSpec", "default_prior", "prior_moments", "prior_spec", "priors_for",
           "recording_scale"]

if TYPE_CHECKING:
    from harvester.inference.likelihood import Problem

def _prior_mean(name: str, entry: Mapping[str, Any], table1: Mapping[str, float]) -> float:
    """Mean of one prior: ``entry['mean']`` or, with ``from: table1``, our Table 1 value."""
    source = entry.get("from")
    if source is not None and "mean" in entry:
        raise ValueError(f"priors.{name}: give either 'mean' or 'from', not both")
    if source is None:
        if "mean" not in entry:
            raise ValueError(f"priors.{name}: needs 'mean' or 'from: table1'")
        return float(entry["mean"])
    if source != "table1":
        raise ValueError(f"priors.{name}: 'from' must be 'table1', got {source!r}")
    if name not in table1:
        raise ValueError(f"priors.{name}: 'from: table1' but Table 1 has no {name!r} "
                         f"(has {sorted(table1)})")
    return float(table1[name])


def prior_spec(name: str, entry: Mapping[str, Any], table1: Mapping[str, float]) -> PriorSpec:
    """One :class:`PriorSpec` from its config entry (keys mean|from, sd, unit, optional lower;
    or family: loguniform with lower and upper; or family: lognormal with mean (the median)
    and sd (of ln x))."""
    family = str(entry.get("family", "normal"))
    unit = str(entry.get("unit", ""))
    if family == "loguniform":
        try:
            return PriorSpec.log_uniform(name, float(entry["lower"]), float(entry["upper"]),
                                         unit)
        except (KeyError, TypeError, ValueError) as err:
            raise ValueError(f"priors.{name}: a log-uniform prior needs 0 < lower < upper "
                             f"({err})") from None
    sd = float(entry.get("sd", np.nan))
    if not sd > 0.0:
        raise ValueError(f"priors.{name}: 'sd' must be a positive number, got {entry.get('sd')!r}")
    if family == "lognormal":
        return PriorSpec.log_normal(name, _prior_mean(name, entry, table1), sd, unit)
    return PriorSpec(name=name, mean=_prior_mean(name, entry, table1), sd=sd, unit=unit,
                     lower=float(entry.get("lower", 0.0)))


def prior_moments(config_priors: Mapping[str, Mapping[str, Any]],
                  table1: Mapping[str, float]) -> dict[str, PriorSpec]:
    """Prior of every parameter in config ``priors``; ``table1`` maps parameter -> our value.

    Use :func:`harvester.study.tables.table1_values` to turn our Table 1 DataFrame into ``table1``.
    """
    return {name: prior_spec(name, entry, table1) for name, entry in config_priors.items()}


def default_prior(name: str, device: DeviceScale = REFERENCE_DEVICE) -> PriorSpec:
    """The physics library's prior of a parameter on ``device`` (the paper's rig by default;
    used where the config gives none)."""
    for p in BASE_PARAMETERS + tuple(q for t in TERMS.values() for q in t.parameters):
        if p.name == name:
            return p.prior_on(device)
    raise KeyError(f"no prior for parameter {name!r}")


#: Top of the band a recording's scale names (``DeviceScale.f_high``), as a fraction of its
#: low-pass (or Nyquist) frequency: the diagnosis's detection band ends at 0.9 x it.
SCALE_BAND_TOP = 0.9


def recording_scale(df: pd.DataFrame, values: Mapping[str, float],
                    lowpass_hz: float | None = None, lead_in_s: float = 1.0,
                    source: str = "<recording>") -> DeviceScale | None:
    """The scales (``DeviceScale``) a recorded device's term priors are read on, measured
    from a recording of its displacement after ``lead_in_s`` (s): RMS z (m, about its
    median) and the quantiles of |z|, RMS velocity v (m/s, z differentiated), the damping
    force c_eq v by the power balance (N; the reference rig's where that cannot tell), the
    band's top f_high (Hz, SCALE_BAND_TOP) and M, m, k from ``values`` (known or fitted;
    NaN where absent): what the diagnosis takes from its baseline's simulated motion
    (``harvester.diagnosis.detect.signatures.motion_scale``), here without a model, for
    ``harvester identify`` and ``compare`` on a device unlike the paper's rig (a circuit in
    volts: k_cubic's prior in k / z^2 is 1e5 times narrower than on the rig's scale).

    None for an acceleration output: z integrated twice from z'' is no level to trust (the
    tanh rig's simulated record: 0.47 x its RMS z by a windowed spectrum above 0.3 Hz, up to
    8.6 x by an FFT integral of a sine; measured)."""
    from harvester.data.kinds import derivative, input_kind, model_recording, output_kind
    from harvester.data.recording import recording_kinds
    from harvester.data.signals import uniform_step
    df, _ = model_recording(df, lowpass_hz, source)
    kinds = recording_kinds(df, source)
    inp, out = input_kind(kinds.input_kind), output_kind(kinds.output_kind)
    if out.order != 0:
        return None
    dt = uniform_step(df["time"].to_numpy(dtype=float), source)
    y = df[out.name].to_numpy(dtype=float)
    cut = slice(min(int(round(lead_in_s / dt)), len(y) // 4), None)
    v = derivative(y, dt, 1, lowpass_hz)[cut]
    az = np.abs(y[cut] - np.median(y[cut]))
    force = inp.dissipative_force(df[inp.name].to_numpy(dtype=float)[cut], v, values)
    return DeviceScale(force=force or REFERENCE_DEVICE.force,
                       v=float(np.sqrt(np.mean(v**2))) or 1e-3,
                       z=float(np.sqrt(np.mean(az**2))) or 1e-3,
                       f_high=float(SCALE_BAND_TOP * (lowpass_hz or 0.5 / dt)),
                       **{n: float(values.get(n, np.nan)) for n in ("M", "m", "k")},
                       z_quantiles={q: float(np.quantile(az, q)) for q in Z_QUANTILES})


def priors_for(problem: Problem, priors: Mapping[str, PriorSpec],
               names: Sequence[str] | None = None) -> dict[str, PriorSpec]:
    """Prior of each identified parameter (or of ``names``): from ``priors`` if given, else
    the library default."""
    names = problem.parameter_names if names is None else names
    return {n: priors[n] if n in priors else default_prior(n) for n in names}
