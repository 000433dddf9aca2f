"""Priors for one recording of a device whose M, m, k are known (the command line's
initial modelling).
"""

from __future__ import annotations

import logging
from collections.abc import Mapping

import numpy as np
import pandas as pd

from harvester.data.errors import DataError
from harvester.initial.damping import DampingFit, fit_viscous_damping
from harvester.inference.priors import PriorSpec, prior_spec

log = logging.getLogger("harvester.initial")

DAMPING_FIT_BAND_HZ = (0.3, 10.0)


def beta_prior(sigma_v: float) -> PriorSpec:
    """The tanh term's prior of beta on a device moving at an RMS velocity sigma_v (m/s)."""
    from dataclasses import replace

    from harvester.model.priors import REFERENCE_DEVICE
    from harvester.model.terms import term
    beta = next(p for p in term("tanh_friction").parameters if p.name == "beta")
    return beta.prior_on(replace(REFERENCE_DEVICE, v=float(sigma_v)))


def recording_priors(df: pd.DataFrame, known: Mapping[str, float],
                     given: Mapping[str, Mapping[str, float]] | None = None,
                     source: str = "<recording>", lowpass_hz: float | None = None
                     ) -> dict[str, PriorSpec]:
    """Priors for one recording of a device whose M, m, k are ``known``: c_m (and F_c) from the
    recording's FRF (:func:`fit_viscous_damping`) as in the initial modelling, beta from its
    RMS velocity (any kind of recording: read as the paper's base_acc -> rel_acc case by
    ``harvester.data.kinds.paper_case``, band-limited at ``lowpass_hz``; a force input's m
    is then 1 kg), then the priors ``given`` (name -> entry as in config ``priors``: mean
    or from: table1, sd, optional lower; e.g. a sidecar's). sigma's prior is left to the
    diagnosis (scaled to the recording's residual, ``diagnosis.run.default_priors``) unless
    given: Table 4's is the paper's rig's noise.

    With a measured static friction (``given["F_c"]``, as the paper's static tests give) c_m's
    mean is the FRF fit with that friction, sd Table 4's, as in the paper (a measured friction
    that alone damps more than the recording shows drives c_m's posterior to zero, and that
    conflict is evidence). Without one, the recording's damping cannot be split
    between viscous damping and friction, and an assumed split must not make a prior conflict:
    c_m is only known to lie between 0 and the purely viscous fit c_v, and F_c between 0 and
    the friction that alone gives that damping, sqrt(pi/2) c_v sigma_v (equivalent
    linearisation, c_eq = sqrt(2/pi) F_c / sigma_v): each prior is N(0, bound) truncated at 0.

    beta sets the velocity 1/beta over which the friction force reverses; Table 4's 100 +- 100
    s/m is beta sigma_v = 1.1 +- 1.1 on the paper's rig, but a friction law close to a sign law
    (beta sigma_v of 75 on a test device) would sit 25 sd in its tail. So beta's prior is the
    tanh term's own (``model/terms/tanh_friction.py``: log-uniform, beta sigma_v from 1/3 to
    100) read at the recording's RMS velocity.
    """
    from harvester.inference.priors import default_prior
    from harvester.study.paper import TABLE4

    unit = {n: default_prior(n).unit for n in ("c_m", "F_c", "beta")}
    specs = {n: PriorSpec(n, m_, s_, unit[n]) for n, (m_, s_) in TABLE4.items() if n in unit}
    stated = _stated_priors(given or {}, specs)
    try:
        from harvester.data.kinds import paper_case
        balance = dissipation(df, known, lowpass_hz, source)
        df, known = paper_case(df, known, lowpass_hz, source)
        _set_damping_priors(specs, df, known, stated.get("F_c"), unit, source, balance)
    except (DataError, ValueError, np.linalg.LinAlgError) as err:
        log.warning("FRF damping fit failed (%s); c_m, F_c and beta priors are Table 4's", err)
    return {**specs, **stated}


#: Unit and bound of a stated noise sd prior (the library's terms have no sigma).
NOISE_PRIOR_BASE = PriorSpec("sigma", 1.0, 1.0, "m/s^2", 0.0)


def _stated_priors(given: Mapping[str, Mapping[str, float]],
                   specs: Mapping[str, PriorSpec]) -> dict[str, PriorSpec]:
    """The priors ``given`` (config ``priors`` entries), with the unit and lower bound of
    ``specs``' (or the library's default) prior of the same name where they give none."""
    from harvester.inference.priors import default_prior
    from harvester.study.paper import TABLE1

    stated = {}
    for name, entry in given.items():
        base = specs.get(name) or (NOISE_PRIOR_BASE if name == "sigma" else default_prior(name))
        stated[name] = prior_spec(name, {"unit": base.unit, "lower": base.lower, **entry},
                                  TABLE1)
    return stated


#: The power balance's damping force replaces the FRF fit's bound on c_m and F_c when it is
#: this many times larger (the linear FRF fit of a friction-dominated device can find no
#: damping at all: 0 N s/m on the frame of Marino and Cicirello).
BALANCE_FACTOR = 2.0


def dissipation(df: pd.DataFrame, known: Mapping[str, float], lowpass_hz: float | None,
                source: str = "<recording>", lead_in_s: float = 1.0
                ) -> tuple[float, float] | None:
    """(damping force c_eq sigma_v in N, RMS relative velocity sigma_v in m/s) the recording
    shows by the power balance of eq. (1), <F_d z'> = -g <u z'> (the input kind's
    ``dissipative_force``, ``harvester.data.kinds``), with the measured z' (the output
    kind's ``velocity``), after ``lead_in_s``; None where it cannot tell (no drive gain,
    no motion)."""
    from harvester.data.kinds import input_kind, model_recording, output_kind
    from harvester.data.recording import recording_kinds
    from harvester.data.signals import uniform_step
    df, _ = model_recording(df, lowpass_hz, source)
    kinds = recording_kinds(df, source)
    inp, out = input_kind(kinds.input_kind), output_kind(kinds.output_kind)
    dt = uniform_step(df["time"].to_numpy(dtype=float), source)
    v = out.velocity(df[out.name].to_numpy(dtype=float), dt, lowpass_hz)
    cut = slice(int(round(lead_in_s / dt)), len(df) - int(round(0.5 / dt)))
    force = inp.dissipative_force(df[inp.name].to_numpy(dtype=float)[cut], v[cut], known)
    return None if force is None else (force, float(np.std(v[cut])))


def _set_damping_priors(specs: dict[str, PriorSpec], df: pd.DataFrame,
                        known: Mapping[str, float], measured_friction: PriorSpec | None,
                        unit: Mapping[str, str], source: str,
                        balance: tuple[float, float] | None = None) -> None:
    """Set ``specs``' c_m (and, without a ``measured_friction``, F_c) from the recording's
    FRF and beta from its RMS velocity (m/s), as :func:`recording_priors` describes; where
    the power balance's damping force (``balance``, :func:`dissipation`) is BALANCE_FACTOR
    times the FRF fit's, its bounds are the balance's. Raises what the FRF fit raises;
    priors set before the failure stay set."""
    lead_in = min(256, len(df) // 4)

    def fit(friction: float) -> DampingFit:
        return fit_viscous_damping(df, known["M"], known["m"], known["k"], friction,
                                   DAMPING_FIT_BAND_HZ, lead_in=lead_in, source=source)

    if measured_friction is not None:
        f_c = measured_friction.mean
        measured = fit(f_c)
        c_m, sigma_v = measured.c_m, measured.sigma_v
        log.info("initial modelling: c_m = %.1f N s/m from the recording's FRF with the "
                 "measured friction %.1f N", c_m, f_c)
        specs["c_m"] = PriorSpec("c_m", c_m, specs["c_m"].sd, unit["c_m"])
    else:
        viscous = fit(0.0)
        floor = 1e-6 * np.sqrt(known["k"] * known["M"])
        c_v, sigma_v = max(viscous.c_m, floor), viscous.sigma_v
        f_max = max(np.sqrt(np.pi / 2.0) * c_v * viscous.sigma_v, 1e-3)
        log.info("initial modelling: the recording's FRF gives c_m = %.1f N s/m without "
                 "friction (RMS velocity %.3g m/s); no measured friction, so c_m lies in "
                 "0-%.1f N s/m and F_c in 0-%.2f N", c_v, viscous.sigma_v, c_v, f_max)
        if balance is not None and balance[0] > BALANCE_FACTOR * c_v * viscous.sigma_v:
            force, sigma_v = balance
            c_v, f_max = force / sigma_v, float(np.sqrt(np.pi / 2.0) * force)
            log.warning("initial modelling: the power the drive puts in says the motion is "
                        "damped by %.3g N (RMS velocity %.3g m/s measured), more than %g "
                        "times what the linear FRF fit shows (a friction-dominated device): "
                        "c_m lies in 0-%.3g N s/m and F_c in 0-%.3g N", force, sigma_v,
                        BALANCE_FACTOR, c_v, f_max)
        specs["c_m"] = PriorSpec("c_m", 0.0, c_v, unit["c_m"])
        specs["F_c"] = PriorSpec("F_c", 0.0, float(f_max), unit["F_c"])
    if sigma_v > 0.0:
        specs["beta"] = beta_prior(sigma_v)
        log.info("initial modelling: beta %s (the tanh term's prior at the RMS velocity "
                 "%.3g m/s)", specs["beta"].describe(), sigma_v)


#: Lowest frequency (Hz) of the FRF fit that sets the priors of unknown M, m, k, c_m, and the
#: top of its band as a fraction of the recording's low-pass (or Nyquist) frequency.
FRF_BAND_LOW_HZ = 0.3
FRF_BAND_TOP = 0.8


def identification_priors(df: pd.DataFrame, free: tuple[str, ...],
                          known: Mapping[str, float],
                          given: Mapping[str, Mapping[str, float]] | None = None,
                          lowpass_hz: float | None = None, source: str = "<recording>"
                          ) -> tuple[dict[str, PriorSpec], list[str]]:
    """Priors of the ``free`` parameters (and sigma) of one recording, and where each came from.

    * M, m, k known (M, k for a force input), any kind of recording: c_m, F_c, beta from the
      recording's FRF and its power balance (:func:`recording_priors`, as ``harvester
      diagnose`` does);
    * otherwise the free base parameters (M, m, k, c_m) from a linear FRF fit over
      FRF_BAND_LOW_HZ to FRF_BAND_TOP x the low-pass (``harvester.initial.frf.initial_priors``);
    * sigma: a tenth of the output's sd (``frf.sigma_prior``); the terms' other parameters:
      the library's defaults (set for the paper's rig);
    * ``given`` (the sidecar's ``priors``) replace any of these.
    """
    from harvester.data.recording import recording_kinds
    from harvester.data.signals import sampling_rate
    from harvester.inference.priors import default_prior
    from harvester.initial.frf import initial_priors, sigma_prior
    from harvester.study.paper import TABLE1

    from harvester.data.kinds import model_recording
    df, _ = model_recording(df, lowpass_hz, source)  # a base_disp: its base_acc
    kinds = recording_kinds(df, source)
    specs: dict[str, PriorSpec] = {}
    notes: list[str] = []
    from harvester.data.kinds import input_kind
    scale = {"M", "k"} if input_kind(kinds.input_kind).force_input else {"M", "m", "k"}
    if scale <= set(known):  # any kind: recording_priors reads it as the paper's case
        specs.update({k: v for k, v in recording_priors(df, known, {}, source,
                                                        lowpass_hz).items() if k in free})
        notes.append(f"priors of {', '.join(specs)}: from the recording's FRF with the known "
                     f"{', '.join(sorted(scale))} (as harvester diagnose)")
    base = tuple(p for p in ("M", "m", "k", "c_m") if p in free and p not in specs)
    values = dict(known)
    if base:
        top = FRF_BAND_TOP * (lowpass_hz or 0.5 * sampling_rate(df, source))
        fit, frf = initial_priors(df, known, base, (FRF_BAND_LOW_HZ, top), source=source)
        specs.update({p: frf[p] for p in base})
        values.update({p: fit.values[p] for p in base})
        notes += fit.notes
        notes.append(f"priors of {', '.join(base)}: a linear FRF fit over "
                     f"{FRF_BAND_LOW_HZ:g}-{top:.3g} Hz (" + ", ".join(
                         f"{p} = {fit.values[p]:.4g}" for p in base) + ")")
    specs["sigma"] = sigma_prior(df)
    rest = [p for p in free if p not in specs]
    if rest:
        defaults, note = _term_defaults(df, rest, values, lowpass_hz, source)
        specs.update(defaults)
        notes.append(note)
    for name, entry in (given or {}).items():
        unit = specs[name].unit if name in specs else default_prior(name).unit
        specs[name] = prior_spec(name, {"unit": unit, **entry}, TABLE1)
    if given:
        notes.append(f"priors of {', '.join(given)}: given in the sidecar")
    return specs, notes


def _term_defaults(df: pd.DataFrame, names: list[str], values: Mapping[str, float],
                   lowpass_hz: float | None, source: str) -> tuple[dict[str, PriorSpec], str]:
    """(priors, note) of the terms' parameters ``names``: the library's, read on the
    recording's own scale where its output is a displacement (``recording_scale``; ``values``:
    M, m, k known or fitted), else on the paper's rig."""
    from harvester.inference.priors import default_prior, recording_scale
    device = recording_scale(df, values, lowpass_hz, source=source)
    specs = {p: default_prior(p) if device is None else default_prior(p, device) for p in names}
    return specs, f"priors of {', '.join(names)}: the library's, " + (
        "on the paper's rig (an acceleration output gives no trusted z)" if device is None
        else f"on the recording's scale (RMS z {device.z:.3g} m, v {device.v:.3g} m/s; "
             f"k {device.k:.3g} N/m)")


def diagnosis_priors(df: pd.DataFrame, baseline: str, known: Mapping[str, float],
                     given: Mapping[str, Mapping[str, float]] | None = None,
                     lowpass_hz: float | None = None, source: str = "<recording>"
                     ) -> tuple[dict[str, PriorSpec], list[str]]:
    """(priors, notes) of ``harvester diagnose`` for any kind of recording: with M, m, k
    known (M, k for a force input) :func:`recording_priors`; otherwise the missing base
    parameters are identified, their priors from a linear FRF fit of the recording
    (:func:`identification_priors`, stated in the notes and in diagnosis.json's priors; a
    device known only through its recordings, e.g. a circuit in volts). sigma's prior is
    left to the diagnosis unless ``given``. ValueError where eq. (1) cannot fix the scale (a
    base input with none of M, m, k, c_m known)."""
    from harvester.data.kinds import input_kind, model_recording
    from harvester.data.recording import recording_kinds
    from harvester.inference.problems import check_identifiable, free_base_parameters
    from harvester.model.structures import structure

    kinds = recording_kinds(model_recording(df, lowpass_hz, source)[0], source)
    scale = {"M", "k"} if input_kind(kinds.input_kind).force_input else {"M", "m", "k"}
    if scale <= set(known):
        return recording_priors(df, known, given, source, lowpass_hz), []
    s = structure(baseline)
    base = free_base_parameters(s, known, kinds.input_kind)
    check_identifiable(base, kinds.input_kind)
    free = tuple(dict.fromkeys(base + s.free_parameters))
    specs, notes = identification_priors(df, free, known, given, lowpass_hz, source)
    if "sigma" not in (given or {}):
        specs.pop("sigma", None)
    missing = sorted(scale - set(known))
    notes.insert(0, f"{', '.join(missing)} not given: identified with the baseline, their "
                 "priors from the recording (below)")
    for line in notes:
        log.info("%s", line)
    return specs, notes
