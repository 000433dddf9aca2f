"""Fit on unseen data before and after, and the diagnosis as a JSON-ready dictionary."""

from __future__ import annotations

from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from harvester.inference.map_fit import ChainProblem
from harvester.diagnosis.name.fits import prior_dict
from harvester.diagnosis.report.thresholds import thresholds
from harvester.inference.predictive import nrmse, outside_fraction, thin


@dataclass
class UnseenFit:
    """A posterior's prediction of a record it was not fitted to.

    ``time``, ``measured`` (through the chain), ``mean`` and ``sd`` (predictive: parameter
    spread and the likelihood's sigma) over the compared samples.
    """

    data: str  # "validation" (a separate record) or "holdout" (the recording's tail)
    time: np.ndarray
    measured: np.ndarray
    mean: np.ndarray
    sd: np.ndarray

    @property
    def nrmse(self) -> float:
        return nrmse(self.measured, self.mean)

    @property
    def outside_3sigma(self) -> float:
        return outside_fraction(self.measured, self.mean, self.sd, 3.0)

    @property
    def coverage_3sigma(self) -> float:
        return 1.0 - self.outside_3sigma

    def to_dict(self) -> dict:
        return {"data": self.data, "seconds": float(self.time[-1] - self.time[0]),
                "nrmse": self.nrmse, "coverage_3sigma": self.coverage_3sigma,
                "outside_3sigma": self.outside_3sigma}


def unseen_fit(problem: ChainProblem, samples: np.ndarray, base_acc: np.ndarray,
               rel_acc: np.ndarray, time: np.ndarray, section: tuple[int, int], data: str,
               count: int = 100, seed: int = 0) -> UnseenFit:
    """Posterior predictive of ``problem``'s structure for a record, over ``section``.

    ``base_acc``, ``rel_acc``: the record's input and output, of ``problem``'s kinds (the
    paper-case names; a force and a displacement too)."""
    theta = thin(samples, count, seed)
    record = ChainProblem(problem.structure, base_acc, rel_acc, problem.dt, dict(problem.known),
                          (section[0], section[1]), input_kind=problem.input_kind,
                          output_kind=problem.output_kind, temper=problem.temper,
                          lowpass_hz=problem.lowpass_hz, filter_order=problem.filter_order,
                          oversample=problem.oversample, band_fraction=problem.band_fraction)
    pred, ok = record.predicted(theta)
    if not ok.any():
        raise RuntimeError(f"no posterior sample of {problem.structure.name} can be simulated")
    a, b = section
    resp = pred[ok, a:b]
    sigma = theta[ok, -1]
    sd = np.sqrt(resp.var(axis=0, ddof=1) + np.mean(sigma**2)) if len(resp) > 1 else \
        np.full(b - a, np.sqrt(np.mean(sigma**2)))
    return UnseenFit(data, time[a:b], record.observed, resp.mean(axis=0), sd)


# --------------------------------------------------------------------------- diagnosis.json


def _locations(det) -> dict:
    w, ws = det.windows, det.window_stats
    w_thr = ws.threshold()
    w_exp = w.expected_share()
    w_share = np.exp(ws.observed)
    w_p = ws.pointwise_p()
    windows = [{"start": a, "stop": b, "energy_share": float(sh), "expected_share": float(ex),
                "ratio": float(sh / ex), "z": float(z), "p_pointwise": float(p),
                "flagged": bool(z >= w_thr and sh > ex)}
               for (a, b), sh, ex, z, p in zip(w.bounds_s, w_share, w_exp, ws.z, w_p)]
    rg, rs = det.regions, det.region_stats
    r_thr = rs.threshold()
    r_time = rg.time_share()
    r_share = rg.energy_share(rs.observed)
    gs = det.region_gain
    g_thr = gs.threshold()
    regions = [{"region": name, "description": rg.descriptions[name],
                "time_share": float(ts), "energy_share": float(sh), "ratio": float(sh / ts),
                "z": float(z), "p_pointwise": float(p), "flagged": bool(z >= r_thr and sh > ts),
                "amplitude_ratio": float(g), "amplitude_z": float(gz),
                "amplitude_flagged": bool(gz >= g_thr and abs(np.log(max(g, 1e-3))) > np.log(1.25))}
               for name, ts, sh, z, p, g, gz in zip(rg.names, r_time, r_share, rs.z,
                                                    rs.pointwise_p(), gs.observed, gs.z)]
    b, bs = det.bands, det.band_explained_stats
    b_thr = bs.threshold()
    total = det.band_energy.sum()
    flat = b.flat_share()
    bands = [{"low": lo, "high": hi, "energy_share": float(e / total),
              "white_noise_share": float(fl), "explained_share": float(x / total),
              "z": float(z), "flagged": bool(z >= b_thr)}
             for (lo, hi), e, fl, x, z in zip(b.bounds_hz, det.band_energy, flat,
                                              det.band_explained, bs.z)]
    return {"time_windows_s": windows, "state_regions": regions, "frequency_bands_hz": bands,
            "flag_rule": "z above the 95 % quantile of the family's largest z over stationary "
                         "noise replicates, with more energy than expected; amplitude_ratio is "
                         "measured / model amplitude in the region (1 + <r, m> / <m, m>, 0 when "
                         "the data stand still where the model moves), amplitude_flagged when "
                         "its departure from 1 is significant in the same way and above 25 %"}


def _detection(det) -> dict:
    return {"p_value": det.p_value, "alpha": det.alpha, "significant": det.significant,
            "test": "score tests of the candidates' signatures (library family); windows and "
                    "regions are locations, reported with their own calibrated p-values",
            "families": {f: {"statistic": float(det.family_statistic[f]), "p_value": float(p),
                             "p_value_from": det.family_tail[f].to_dict()}
                         for f, p in det.family_p.items()},
            "band_hz": [det.frame.f_low, det.frame.f_high], "sigma": det.sigma,
            "prior_conflict": det.conflict,
            "prior_conflicts": [c.to_dict() for c in det.conflicts]}


def _equivalent(terms: tuple[str, ...]) -> str | None:
    from harvester.model.structures import STRUCTURES
    for name, t in STRUCTURES.items():
        if set(t) == set(terms):
            return name
    return None


def _fit_entry(structure, log_ev, source, unseen) -> dict:
    out = {"structure": structure.name, "terms": list(structure.terms),
           "equivalent_to": _equivalent(structure.terms), "log_evidence": log_ev,
           "log_evidence_source": source}
    if unseen is not None:
        out.update({"nrmse": unseen.nrmse, "coverage_3sigma": unseen.coverage_3sigma,
                    "outside_3sigma": unseen.outside_3sigma, "unseen_data": unseen.data,
                    "unseen_seconds": float(unseen.time[-1] - unseen.time[0])})
    else:
        out.update({"nrmse": None, "coverage_3sigma": None, "outside_3sigma": None,
                    "unseen_data": None})
    return out


def _finite(obj):
    """Numbers made JSON-safe: numpy scalars to Python, NaN and infinities to None."""
    if isinstance(obj, dict):
        return {k: _finite(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_finite(v) for v in obj]
    if isinstance(obj, (np.floating, float)):
        return float(obj) if np.isfinite(obj) else None
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, np.bool_):
        return bool(obj)
    return obj


#: The version of diagnosis.json's contract (``diagnosis.schema.json`` beside this module,
#: docs/diagnosis-json.md): the major number changes when a key is removed or changes its
#: meaning, the minor one when a key is added.
SCHEMA_VERSION = "1.4"
#: The JSON Schema diagnosis.json validates against, shipped with the package.
SCHEMA_PATH = Path(__file__).with_name("diagnosis.schema.json")


def validate_document(doc: dict) -> None:
    """Check a diagnosis.json document against its schema (:data:`SCHEMA_PATH`, with the
    ``jsonschema`` package); ValueError naming the first key that breaks it."""
    import json

    import jsonschema
    schema = json.loads(SCHEMA_PATH.read_text())
    error = jsonschema.exceptions.best_match(
        jsonschema.Draft202012Validator(schema).iter_errors(doc))
    if error is not None:
        where = "/".join(map(str, error.absolute_path)) or "(top level)"
        raise ValueError(f"diagnosis.json does not follow schema {SCHEMA_VERSION} at "
                         f"{where}: {error.message}")


def diagnosis_dict(d) -> dict:
    """The JSON document of a :class:`~harvester.diagnosis.run.Diagnosis` (no NaN: None)."""
    return _finite(_diagnosis_dict(d))


def _candidate_entries(d) -> list[dict]:
    """Every candidate sampled in every round, with its gain over the first baseline."""
    out = []
    for i, rnd in enumerate(d.rounds):
        for res in rnd.confirmed:
            entry = res.to_dict()
            entry["round"] = i + 1
            entry["reference"] = rnd.structure
            entry["delta_log_evidence_vs_baseline"] = (res.fit.log_evidence
                                                        - d.baseline_log_evidence)
            out.append(entry)
    return out


def _device_plausibility(d) -> dict:
    """Each named, tied or refused term's implied device against the sidecar
    (``plausibility``): its role, the quantities it implies and whether they agree (None
    where it implies none the sidecar states)."""
    from harvester.diagnosis.name.plausibility import AGREEMENT_SDS
    tied = {e for t in d.ties for e in t.effects}
    terms = []
    for i, rnd in enumerate(d.rounds):
        for r in rnd.confirmed:
            role = ("named" if r.effect in d.missing and r.accepted else
                    "negligible" if r.effect in d.negligible and r.accepted else
                    "tied" if r.effect in tied and (r.accepted or r.indistinguishable_from)
                    else "withheld" if r.effect in d.withheld and r.accepted else
                    "refused" if r.refused_for_device else None)
            if role is None:
                continue
            terms.append({"term": r.effect, "round": i + 1, "role": role,
                          "device": [x.to_dict() for x in r.device],
                          "agrees": None if not r.device else not r.contradicted})
    return {"bar_sd": AGREEMENT_SDS, "default_relative_sd": d.settings.device_relative_sd,
            "stated_sd": dict(d.settings.device_sd), "terms": terms}


def _output_words(d) -> str:
    """The output the likelihood compares, in words: its kind, symbol and unit, and the input
    kind the models are driven by (``harvester.data.kinds``)."""
    if not d.rounds:
        return "z''"
    p = d.rounds[0].state.problem
    out = p.output_type
    return f"{out.symbol} ({out.name}, {out.unit}; models driven by {p.input_kind})"


def _fit_section(d) -> dict:
    """The fit before and after: parameters, evidence, unseen-data errors."""
    improved_ev = d.improved_fit.log_evidence if d.improved_fit else d.baseline_log_evidence
    fit = {"baseline": _fit_entry(d.baseline, d.baseline_log_evidence,
                                  d.baseline_evidence_source, d.unseen_before),
           "improved": _fit_entry(d.improved, improved_ev,
                                  "diagnosis" if d.improved_fit else d.baseline_evidence_source,
                                  d.unseen_after),
           "log_evidence_gain": improved_ev - d.baseline_log_evidence,
           "likelihood": f"eq. (10) on {_output_words(d)} through the measurement chain's "
                         "low-pass, tempered by lambda (effective share of independent samples)"}
    if d.improved_fit is not None:
        from harvester.model.terms import term
        added = [p for t in d.improved.terms if t not in d.baseline.terms
                 for p in term(t).parameter_names]
        summ = d.improved_fit.summary()
        fit["added_parameters"] = {n: summ[n] for n in added if n in summ}
    return fit


def _rounds(d) -> list[dict]:
    return [{"structure": rnd.structure, "p_value": rnd.detection.p_value,
             "significant": rnd.detection.significant,
             "prior_conflict": rnd.detection.conflict,
             # the acceptance shares alpha among these (results.ConfirmSettings.family)
             "candidates_in_family": len(rnd.detection.candidates),
             "sampled": [r.effect for r in rnd.confirmed],
             "screened": ([s.to_dict() for s in rnd.screen.candidates]
                          if rnd.screen is not None else []),
             "importance_check": (None if rnd.screen is None
                                  or rnd.screen.nested_importance is None else {
                                      **rnd.screen.nested_importance.to_dict(),
                                      "trusted": rnd.screen.importance_check}),
             "accepted": rnd.accepted.effect if rnd.accepted else None,
             "named": bool(rnd.accepted and rnd.accepted.named),
             "device_scale": asdict(rnd.scale) if rnd.scale is not None else None,
             "seconds": dict(rnd.seconds),
             # the accepted mode held against the output's sensor (name.sensor)
             "sensor_resonance": (rnd.sensor.to_dict()
                                  if getattr(rnd, "sensor", None) is not None else None)}
            for rnd in d.rounds]


def _diagnosis_dict(d) -> dict:
    first = d.rounds[0]
    s = d.settings
    judged = d.fit_judgement
    return {
        "schema_version": SCHEMA_VERSION,
        "verdict": d.verdict,
        "headline": d.headline,
        "explained_share": None if judged is None else judged.explained,
        "unseen_nrmse": None if judged is None else judged.nrmse,
        "noise_floor": None if judged is None or judged.floor is None else judged.floor.to_dict(),
        "fit_judgement": None if judged is None else judged.to_dict(s.floor_ratio),
        "missing_force": None if d.missing_force is None else d.missing_force.to_dict(),
        "missing": d.missing,
        "withheld": d.withheld,
        "negligible": d.negligible,
        "indistinguishable": d.indistinguishable,
        "ties": [tie.to_dict() for tie in d.ties],
        "device_plausibility": _device_plausibility(d),
        "unexplained_mismatch": d.unexplained,
        "baseline": d.baseline.name,
        "improved": d.improved.name,
        "candidates": _candidate_entries(d),
        "locations": _locations(first.detection),
        "fit": _fit_section(d),
        "detection": _detection(first.detection),
        "ranking": [r.to_dict() for r in first.ranked],
        "rounds": _rounds(d),
        "measurement_chain": {"lowpass_hz": d.lowpass_hz, "filter_order": s.filter_order,
                              "likelihood_lowpass_hz": d.likelihood_lowpass_hz,
                              "tempering_lambda": d.temper,
                              "analysis_rate_hz": float(1.0 / (d.time[1] - d.time[0]))},
        "analysis_window_s": list(d.window_s),
        "tmcmc_window_s": list(d.fit_window_s),
        "traded_away": d.settings.trades(),
        "priors": {k: prior_dict(v) for k, v in d.priors.items()},
        "settings": {k: (list(v) if isinstance(v, tuple) else v)
                     for k, v in s.__dict__.items() if k != "deadline"},
        "budget": d.budget,
        "runtime_s": d.seconds,
        "notes": d.notes,
        "figures": list(getattr(d, "figure_files", [])),
        "thresholds": thresholds(),
    }
