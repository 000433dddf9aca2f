"""Proof on concealed effects: how often the diagnosis names an effect it cannot see.

For every scenario of ``harvester.synthetic.scenarios`` (effect x contribution-to-noise ratio x seed) the
diagnosis runs on the recording through :func:`run_diagnosis`; this module turns the results
into the detection table, the confusion matrix and the false-alarm rate.

Scoring one scenario whose true effect is e. The correct names are the truth's own
``correct_names`` where the generator states them (the literature generator), else e and the
names :data:`ACCEPTED` declares equivalent; with each, the library's terms of the same physics in
another form (``Term.alike``). Each scenario has one ``outcome``:
``named`` (the first effect named alone is correct), ``tied`` (nothing named alone, and a tie
the diagnosis reported, effects it could not tell apart, holds a correct name), ``wrong`` (the
first effect named alone is not correct, or every tie lacks a correct name: the diagnosis said
something false), ``missed`` (adequate, or a mismatch without a name or tie). Also reported:
``top2`` (a correct name among the first two) and ``flagged`` (verdict "missing_physics" or
"inadequate").
On an effect-free scenario, a false alarm is a flagged verdict.

Size (``named_size``). Where the truth gives the force the nominal device misses along the
true path (``missing_force_rms_N``, the literature generator's), the first term named alone
is checked against it: the RMS of its own force over its posterior, each sample along its
own simulated path (median and 95 % interval; ``diagnosis.size.relevance.term_force_rms``), and
whether that interval holds the truth; where the diagnosis says an acceleration record
leaves the force's mean to the term's form, both about their means
(``missing_force_varying_rms_N``); where several terms are named from one fit, their own
forces summed (``diagnosis.size.missing_force.together_force``). The two are one quantity for an effect added to the
device (a stop, a spring, a damper, a mass error); for a friction law with memory the truth
is the law's departure from the sliding one, which a term beside a refitted sliding law need
not equal.

Rates carry Wilson score intervals (95 %). The goals of the issue: named correctly in at least
90 % of seeds at a contribution of half the noise RMS, and at most 5 % false alarms.

Information in a scenario (``information_nats``). What the baseline's parameters cannot
absorb of the contribution, u x the noise RMS (``unabsorbed_to_noise``, linearised least
squares in ``harvester.synthetic.scenarios``), is all that any added term can explain; at the true
parameters it raises the diagnosis's tempered log-likelihood by lambda n u^2 / 2 nats on
average (n samples fitted by TMCMC, lambda the tempering of the diagnosis's likelihood). The
log evidence gain of the effect is that minus the Occam factor of its parameters, so a
scenario holding less than log(1/alpha) nats (the acceptance threshold before its Monte Carlo
margin: 3.0 at alpha = 0.05) cannot be named by an evidence test that keeps its false-alarm
rate at alpha, whatever the method; it is counted as not ``nameable`` and the table gives the
rate named among the nameable scenarios beside the plain rate. The diagnosis itself asks for
log(N/alpha) (``diagnosis.name.confirm``: 5.4 nats among the tanh model's 11 candidates), so a
scenario holding 3-5.4 nats counts as nameable and is missed: the rate is conservative. The
bound is approximate: the
nonlinear refit absorbs a little more than the linearised one (an inertia error of the medium
grid: 2.45 nats by the formula, 1.84 from the likelihood itself at the true parameters).
Where the truth gives ``refit_unabsorbed_to_noise`` (the literature generator's records:
the baseline's MAP refitted to the record with and without the effect as a model driven by
the recorded input makes it, ``harvester.grid.information``), u is that instead: a
linearised fit misses what a large move of the baseline's parameters absorbs, and a
contribution made from the true excitation holds parts that no model driven by the recording
can reproduce.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

log = logging.getLogger("harvester.grid.scoring")

#: Names that count as naming the effect correctly, besides the effect's own. A tanh law is a
#: Coulomb friction with a finite slope at reversal: on the linear baseline either names it.
ACCEPTED: dict[str, tuple[str, ...]] = {"coulomb_friction": ("tanh_friction",)}
#: Label of the confusion matrix's column for scenarios the diagnosis passed.
ADEQUATE = "adequate"
#: Verdicts that say the baseline misses something (``diagnosis.name.verdict.decide_verdict``).
FLAGGED = ("missing_physics", "inadequate")
#: Label for "missing physics" without a named effect.
UNNAMED = "unnamed"
#: Goals of the issue.
GOAL_RATIO = 0.5
GOAL_NAMED_RATE = 0.9
GOAL_FALSE_ALARM_RATE = 0.05
GOAL_WRONG_RATE = 0.05


# --------------------------------------------------------------------------- the diagnosis


def run_diagnosis(recording: pd.DataFrame, baseline: str, known: Mapping[str, float],
                  seed: int = 0, fast: bool = False, *, lead_in: int = 256,
                  lowpass_hz: float | None = 20.0, filter_order: int = 8,
                  priors: Mapping[str, Any] | None = None,
                  candidates: Sequence[str] | None = None) -> dict[str, Any]:
    """The diagnosis of one recording as a plain dict, like the CLI's diagnosis.json.

    Keys: ``verdict`` ("adequate" | "missing_physics" | "inadequate"), ``missing`` (effect
    names, most probable first), ``candidates`` (per effect: p_value, z, statistic, strength, ...),
    ``locations``, ``fit`` (the baseline's parameters), ``p_value``, ``runtime_s``,
    ``implementation``.

    THE ONE PLACE THAT KNOWS THE DIAGNOSIS'S API: it runs ``harvester.diagnosis.diagnose``
    (TMCMC confirmation included; ``fast``: ``DiagnosisSettings.fast`` with 15 s fitted, for
    the grid). ``implementation`` in the result says which ran.
    """
    from harvester.diagnosis.run import DiagnosisSettings, diagnose
    from harvester.inference.priors import PriorSpec
    from harvester.initial.recording import recording_priors
    from harvester.data.signals import uniform_step

    start = time.perf_counter()
    dt = uniform_step(recording["time"].to_numpy())
    common = dict(seed=seed, lead_in_s=lead_in * dt, lowpass_hz=lowpass_hz,
                  filter_order=filter_order, figures=False,
                  candidates=tuple(candidates) if candidates else None)
    settings = DiagnosisSettings.fast(fit_seconds=15.0, **common) if fast \
        else DiagnosisSettings(**common)
    given = {"sigma": SIGMA_PRIOR, **(priors or {})}
    stated = {n: p for n, p in given.items() if isinstance(p, PriorSpec)}
    entries = {n: p for n, p in given.items() if not isinstance(p, PriorSpec)}
    # as `harvester diagnose` does: the baseline's priors from the recording's FRF
    specs = {**recording_priors(recording, known, entries, "<scenario>"), **stated}
    out = diagnose(recording, baseline, known, specs, settings=settings).to_dict()
    out["runtime_s"] = time.perf_counter() - start
    out["implementation"] = "harvester.diagnosis.diagnose" + (" (fast)" if fast else "")
    return out


#: Prior of the noise sd when none is given: the study's (config ``priors.sigma``).
SIGMA_PRIOR = {"mean": 0.07, "sd": 0.03, "unit": "m/s^2"}


def wilson_interval(k: int | np.ndarray, n: int | np.ndarray, level: float = 0.95
                    ) -> tuple[np.ndarray, np.ndarray]:
    """Wilson score interval of a binomial proportion k / n (NaN where n = 0)."""
    from scipy.stats import norm

    k = np.asarray(k, dtype=float)
    n = np.asarray(n, dtype=float)
    zq = norm.ppf(0.5 + level / 2.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        p = k / n
        denom = 1.0 + zq**2 / n
        centre = (p + zq**2 / (2 * n)) / denom
        half = zq * np.sqrt(p * (1 - p) / n + zq**2 / (4 * n**2)) / denom
    return centre - half, centre + half


def accepted_names(effect: str, accepted: Mapping[str, Iterable[str]] | None = None,
                   truth: Mapping[str, Any] | None = None) -> set[str]:
    """The names that count as naming ``effect``: the truth's ``correct_names`` if it states
    them, else the effect and its :data:`ACCEPTED` equivalents; by default (``accepted``
    None) with every library term that describes the same physics in another form
    (``Term.alike``, ``model.terms.same_physics``: Dahl's hysteresis and the hysteretic
    spring, a sliding law and its sticking form)."""
    if truth is not None and truth.get("correct_names"):
        names = set(truth["correct_names"])
    else:
        names = {effect, *(ACCEPTED if accepted is None else accepted).get(effect, ())}
    if accepted is not None:
        return names
    from harvester.model.terms import TERMS, same_physics
    known = [n for n in names if n in TERMS]
    return names | {t for t in TERMS for n in known if same_physics(t, n)}


def outcome(diagnosis: Mapping[str, Any], correct: set[str]) -> str:
    """named | tied | wrong | missed of one diagnosis of a scenario with an effect (module
    docstring)."""
    if diagnosis["verdict"] not in FLAGGED:
        return "missed"
    missing = list(diagnosis.get("missing") or [])
    if missing:
        return "named" if missing[0] in correct else "wrong"
    ties = [set(t.get("effects") or []) for t in diagnosis.get("ties") or []]
    if not ties:
        return "missed"
    return "tied" if any(t & correct for t in ties) else "wrong"


def information_nats(truth: Mapping[str, Any], diagnosis: Mapping[str, Any]) -> float:
    """Expected tempered log-likelihood gain (nats) of the true effect at its true parameters
    over the refitted baseline: lambda n u^2 / 2, u the refit's where the truth has it
    (module docstring). NaN where the diagnosis
    does not give lambda, its analysis rate and TMCMC window, or the truth no ``u``."""
    chain = diagnosis.get("measurement_chain") or {}
    lam, rate = chain.get("tempering_lambda"), chain.get("analysis_rate_hz")
    window = diagnosis.get("tmcmc_window_s")
    u = truth.get("refit_unabsorbed_to_noise", truth.get("unabsorbed_to_noise"))
    if lam is None or rate is None or not window or u is None:
        return float("nan")
    n = round((float(window[1]) - float(window[0])) * float(rate)) + 1
    return 0.5 * float(lam) * n * float(u) ** 2


def acceptance_nats(diagnosis: Mapping[str, Any]) -> float:
    """log(1/alpha): the evidence gain an effect needs before its Monte Carlo margin."""
    alpha = float((diagnosis.get("settings") or {}).get("evidence_alpha", 0.05))
    return float(np.log(1.0 / alpha))


def score(truth: Mapping[str, Any], diagnosis: Mapping[str, Any],
          accepted: Mapping[str, Iterable[str]] | None = None) -> dict[str, Any]:
    """One row of the results: the scenario's truth beside what the diagnosis said."""
    effect = truth["effect"]
    missing = list(diagnosis.get("missing") or [])
    flagged = diagnosis["verdict"] in FLAGGED
    named = (missing[0] if missing else _tie_label(diagnosis)) if flagged else ADEQUATE
    ok = accepted_names(effect, accepted, truth)
    effect_free = float(truth["ratio"]) == 0.0
    result = "false_alarm" if effect_free and flagged else "quiet" if effect_free \
        else outcome(diagnosis, ok)
    screen = diagnosis.get("detection") or {}
    p_value = float(screen.get("p_value", np.nan))
    info = information_nats(truth, diagnosis)
    return {
        "effect": effect, "ratio": float(truth["ratio"]), "seed": int(truth["seed"]),
        "baseline": truth.get("baseline", ""), "effect_free": effect_free,
        "contribution_ratio": float(truth.get("contribution_ratio", 0.0)),
        "unabsorbed_to_noise": float(truth.get("unabsorbed_to_noise", 0.0)),
        "peak_to_noise": float(truth.get("peak_to_noise", 0.0)),
        "invisible": bool(truth.get("invisible", True)),
        "information_nats": info,
        # NaN information (not known) counts as nameable: the plain rate then applies
        "nameable": (not effect_free) and not info < acceptance_nats(diagnosis),
        "verdict": diagnosis["verdict"], "flagged": flagged, "named_effect": named,
        "outcome": result, "named": result == "named",
        "tied": result in ("named", "tied"), "wrong": result == "wrong",
        "missed": result == "missed",
        "top2": (not effect_free) and flagged and bool(ok & set(missing[:2])),
        "p_value": p_value,
        # the detection screen alone (before any evidence), at its own alpha
        "screen_flagged": bool(p_value < float(screen.get("alpha", 0.05))),
        "runtime_s": float(diagnosis.get("runtime_s", np.nan)),
        **named_size(truth, diagnosis),
    }


def named_size(truth: Mapping[str, Any], diagnosis: Mapping[str, Any]) -> dict[str, Any]:
    """The first named term's own force RMS (N: median, 95 % interval; several named terms'
    summed force where the diagnosis gives it, ``together``) beside the truth's missing
    force RMS, whether the interval holds it (1.0 / 0.0; NaN where either is not given:
    nothing named, a diagnosis without sizes, a generator without the truth), and the
    baseline parameter its strength lies on a ridge with ("" for none). Where the diagnosis
    says the record leaves the force's mean to the form (``mean_unfixed``), both are the
    RMS about the mean (``size_part`` "varying", else "whole")."""
    lit = truth.get("literature") or truth
    missing = list(diagnosis.get("missing") or [])
    mf = diagnosis.get("missing_force") or {}
    sizes = {e.get("term"): e for e in mf.get("named_effects") or []}
    size = sizes.get(missing[0]) if missing else None
    both = mf.get("together") if len(missing) > 1 else None
    own = ({k.removeprefix("term_force_"): v for k, v in size.items()}
           if both is None and size is not None else both)
    varying = bool(own and own.get("mean_unfixed"))
    key = "varying_rms" if varying else "rms"
    true = lit.get(f"missing_force_{key}_N")
    nan = float("nan")
    out = {"size_true_N": nan if true is None else float(true), "size_N": nan,
           "size_lo_N": nan, "size_hi_N": nan, "size_covered": nan, "size_ridge": "",
           "size_part": ("varying" if varying else "whole") + (" together" if both else "")}
    if own is None or own.get(f"{key}_interval_N") is None:
        return out
    lo, hi = (float(x) for x in own[f"{key}_interval_N"])
    return {**out, "size_N": float(own[f"{key}_N"]), "size_lo_N": lo, "size_hi_N": hi,
            "size_covered": nan if true is None else float(lo <= float(true) <= hi),
            "size_ridge": ((size or {}).get("ridge") or {}).get("parameter", "")}


def _tie_label(diagnosis: Mapping[str, Any]) -> str:
    """The first tie as "a | b", or "unnamed" when the diagnosis named nothing."""
    ties = diagnosis.get("ties") or []
    return " | ".join(ties[0].get("effects") or []) if ties else UNNAMED


def results_table(pairs: Iterable[tuple[Mapping[str, Any], Mapping[str, Any]]],
                  accepted: Mapping[str, Iterable[str]] | None = None) -> pd.DataFrame:
    """(truth, diagnosis) pairs -> one scored row per scenario."""
    rows = [score(t, d, accepted) for t, d in pairs]
    if not rows:
        raise ValueError("no scenario results to aggregate")
    return pd.DataFrame(rows).sort_values(["effect", "ratio", "seed"], ignore_index=True)


def detection_table(results: pd.DataFrame, goal_ratio: float = GOAL_RATIO,
                    goal_rate: float = GOAL_NAMED_RATE) -> pd.DataFrame:
    """Per effect and ratio: seeds, rate named correctly (Wilson 95 %), in top 2, flagged.

    ``meets_goal`` (at ``goal_ratio`` only): the rate reaches ``goal_rate``; ``goal_certain``:
    the interval's lower end does. ``nameable``: seeds whose information reaches the acceptance
    threshold (module docstring), ``named_nameable`` how many of them were named first.
    ``sized``: seeds named alone with a size and a truth (``named_size``),
    ``size_covered_rate`` the share of them whose 95 % interval holds the truth.
    """
    res = results[~results["effect_free"]]
    rows = []
    for (effect, ratio), g in res.groupby(["effect", "ratio"], sort=True):
        n = len(g)
        k = int(g["named"].sum())
        lo, hi = wilson_interval(k, n)
        at_goal = bool(np.isclose(ratio, goal_ratio))
        rows.append({
            "effect": effect, "ratio": ratio, "baseline": g["baseline"].iloc[0], "seeds": n,
            "named": k, "named_rate": k / n, "named_lo": float(lo), "named_hi": float(hi),
            "tied_rate": float(g["tied"].mean()), "wrong_rate": float(g["wrong"].mean()),
            "missed_rate": float(g["missed"].mean()),
            "top2_rate": float(g["top2"].mean()), "flagged_rate": float(g["flagged"].mean()),
            "contribution_ratio_mean": float(g["contribution_ratio"].mean()),
            "unabsorbed_to_noise_mean": float(g["unabsorbed_to_noise"].mean()),
            "information_nats_mean": float(g["information_nats"].mean()),
            "nameable": int(g["nameable"].sum()),
            "named_nameable": int((g["named"] & g["nameable"]).sum()),
            "invisible_share": float(g["invisible"].mean()),
            "most_named_instead": _most_common(g.loc[~g["named"], "named_effect"]),
            # named alone with a size and a truth to hold it against (``named_size``)
            "sized": int(g["size_covered"].notna().sum()),
            "size_covered_rate": float(g["size_covered"].mean()),
            "meets_goal": (k / n >= goal_rate) if at_goal else None,
            "goal_certain": (float(lo) >= goal_rate) if at_goal else None,
        })
    return pd.DataFrame(rows)


def goal_summary(results: pd.DataFrame, goal_rate: float = GOAL_NAMED_RATE) -> pd.DataFrame:
    """Per ratio, all effects pooled: rate named first and named or tied (Wilson 95 %), and
    the same among the scenarios that hold enough information to be named (module docstring).
    """
    res = results[~results["effect_free"]]
    rows = []
    for ratio, g in res.groupby("ratio", sort=True):
        n, k = len(g), int(g["named"].sum())
        able = g[g["nameable"]]
        na, ka = len(able), int(able["named"].sum())
        lo, hi = wilson_interval(k, n)
        alo, ahi = wilson_interval(ka, na) if na else (np.nan, np.nan)
        wa = int(able["wrong"].sum())
        wlo, whi = wilson_interval(wa, na) if na else (np.nan, np.nan)
        rows.append({
            "ratio": ratio, "scenarios": n, "named": k, "named_rate": k / n,
            "named_lo": float(lo), "named_hi": float(hi), "tied": int(g["tied"].sum()),
            "tied_rate": float(g["tied"].mean()), "nameable": na, "named_nameable": ka,
            "named_rate_nameable": ka / na if na else np.nan,
            "named_nameable_lo": float(alo), "named_nameable_hi": float(ahi),
            "tied_nameable": int(able["tied"].sum()),
            "wrong": int(g["wrong"].sum()), "wrong_rate": float(g["wrong"].mean()),
            "wrong_nameable": wa, "wrong_rate_nameable": wa / na if na else np.nan,
            "wrong_nameable_hi": float(whi),
            "missed_nameable": int(able["missed"].sum()),
            "not_nameable": ", ".join(sorted(set(g.loc[~g["nameable"], "effect"]))),
            "meets_goal": bool(k / n >= goal_rate),
            "meets_goal_nameable": bool(na and ka / na >= goal_rate),
            "meets_wrong_goal_nameable": bool(na and wa / na <= GOAL_WRONG_RATE),
        })
    return pd.DataFrame(rows)


def _most_common(values: pd.Series) -> str:
    return "" if values.empty else str(values.value_counts().index[0])


def confusion_matrix(results: pd.DataFrame) -> pd.DataFrame:
    """Counts of (true effect, named effect), per ratio and pooled ("all").

    Columns: ``ratio``, ``true_effect``, then one per name given first (``adequate`` when the
    diagnosis passed the scenario, ``unnamed`` when it flagged it but named nothing).
    """
    res = results.assign(ratio=results["ratio"].map(lambda r: f"{r:g}"))
    pooled = res[~res["effect_free"]].assign(ratio="all")
    both = pd.concat([res, pooled], ignore_index=True)
    names = sorted(set(both["named_effect"]) - {ADEQUATE, UNNAMED})
    columns = [ADEQUATE, UNNAMED, *names]
    table = (both.groupby(["ratio", "effect", "named_effect"])
             .size().unstack("named_effect", fill_value=0)
             .reindex(columns=columns, fill_value=0).reset_index()
             .rename(columns={"effect": "true_effect"}))
    table.columns.name = None
    return table


def wrong_name_rates(table: pd.DataFrame) -> dict[str, tuple[int, int]]:
    """Issue 63's catch-all count, per term: (records whose flagging verdict names or ties it
    where it is not a right name, records where it is not a right name), the most often
    wrong first. ``table``: a row per record with ``said`` (the set of names a flagging
    verdict gives, named or tied; empty otherwise) and ``right`` (the set of its right
    names, :func:`accepted_names`: a term alike to a right one is right)."""
    terms = sorted(set().union(*table["said"])) if len(table) else []
    out = {}
    for t in terms:
        absent = table[[t not in r for r in table["right"]]]
        out[t] = (int(sum(t in s for s in absent["said"])), len(absent))
    return dict(sorted(out.items(), key=lambda kv: -kv[1][0] / max(kv[1][1], 1)))


def false_alarms(results: pd.DataFrame, goal: float = GOAL_FALSE_ALARM_RATE) -> pd.DataFrame:
    """False-alarm rate on the effect-free scenarios, per baseline and overall (Wilson 95 %).

    ``false_alarms`` counts verdicts of missing physics; ``screen_alarms`` the recordings on
    which the detection screen alone (before the evidence) fired.
    """
    free = results[results["effect_free"]]
    rows = []
    groups = [(b, g) for b, g in free.groupby("baseline", sort=True)] + [("all", free)]
    for baseline, g in groups:
        n = len(g)
        k = int(g["flagged"].sum())
        lo, hi = wilson_interval(k, n)
        rows.append({"baseline": baseline, "scenarios": n, "false_alarms": k,
                     "screen_alarms": int(g["screen_flagged"].sum()),
                     "rate": k / n if n else np.nan, "rate_lo": float(lo), "rate_hi": float(hi),
                     "meets_goal": bool(n and k / n <= goal),
                     "goal_certain": bool(n and float(hi) <= goal),
                     "named_on_false_alarm": _most_common(g.loc[g["flagged"], "named_effect"])})
    return pd.DataFrame(rows)


# --------------------------------------------------------------------------- figure


def detection_figure(table: pd.DataFrame, alarms: pd.DataFrame, path: str | Path,
                     goal_ratio: float = GOAL_RATIO, goal_rate: float = GOAL_NAMED_RATE,
                     goal_alarm: float = GOAL_FALSE_ALARM_RATE,
                     results: pd.DataFrame | None = None,
                     threshold_nats: float = float(np.log(1.0 / 0.05))) -> None:
    """Rate named correctly against the contribution-to-noise ratio, one line per effect,
    Wilson 95 % bars; the goal (90 % at 0.5) dashed; the false-alarm rate in the title. With
    ``results``, a second panel: each scenario's outcome against its information (nats), the
    acceptance threshold log(1/alpha) dotted."""
    import matplotlib
    import matplotlib.ticker

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from harvester.plots.style import save_figure

    panels = 2 if results is not None else 1
    fig, axes = plt.subplots(1, panels, figsize=(10 + 5 * (panels - 1), 5), squeeze=False)
    ax = axes[0, 0]
    effects = sorted(table["effect"].unique())
    colours = {e: plt.get_cmap("tab10")(i % 10) for i, e in enumerate(effects)}
    for i, effect in enumerate(effects):
        g = table[table["effect"] == effect].sort_values("ratio")
        x = g["ratio"].to_numpy() * (1 + 0.015 * (i - len(effects) / 2))  # dodge the bars
        y = g["named_rate"].to_numpy()
        err = np.vstack([y - g["named_lo"].to_numpy(), g["named_hi"].to_numpy() - y])
        ax.errorbar(x, y, yerr=err, marker="o", ms=4, lw=1, capsize=2, color=colours[effect],
                    label=f"{effect} ({g['baseline'].iloc[0]})")
    ax.axhline(goal_rate, color="k", ls="--", lw=0.8)
    ax.axvline(goal_ratio, color="k", ls=":", lw=0.8)
    ax.set_xscale("log")
    ratios = sorted(table["ratio"].unique())
    ax.set_xlim(min(ratios + [goal_ratio]) / 1.5, max(ratios + [goal_ratio]) * 1.5)
    ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    ax.set_xticks(ratios, [f"{r:g}" for r in ratios])
    ax.set_ylim(-0.03, 1.03)
    ax.set_xlabel("contribution RMS / noise RMS of the recorded z'' (after the 20 Hz filter)")
    ax.set_ylabel("rate named correctly (first in 'missing')")
    overall = alarms[alarms["baseline"] == "all"]
    fa = (f"false alarms {int(overall['false_alarms'].iloc[0])}/"
          f"{int(overall['scenarios'].iloc[0])} = {overall['rate'].iloc[0]:.0%} "
          f"[{overall['rate_lo'].iloc[0]:.0%}, {overall['rate_hi'].iloc[0]:.0%}]"
          if len(overall) and overall["scenarios"].iloc[0] else "no effect-free scenarios")
    ax.set_title(f"Concealed effects named by the diagnosis (SIMULATED scenarios)\n{fa}; "
                 f"goal {goal_rate:.0%} named at {goal_ratio:g}, false alarms <= "
                 f"{goal_alarm:.0%}", fontsize=9)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    ax.grid(alpha=0.3)
    if results is not None:
        _information_panel(axes[0, 1], results, colours, threshold_nats)
    save_figure(fig, path)


#: Outcomes of a scenario on the information panel, bottom to top.
OUTCOMES = ("missed", "named wrong", "tied (truth among them)", "named first")


def _information_panel(ax, results: pd.DataFrame, colours: Mapping[str, Any],
                       threshold_nats: float) -> None:
    """Each effect scenario's outcome against lambda n u^2 / 2 (nats), log scale."""
    res = results[~results["effect_free"] & np.isfinite(results["information_nats"])]
    level = np.select([res["named"], res["tied"], res["wrong"]], [3, 2, 1], 0)
    rng = np.random.default_rng(0)  # vertical jitter only, so coincident points show
    for effect, g in res.groupby("effect"):
        idx = res.index.get_indexer(g.index)
        ax.scatter(np.maximum(g["information_nats"], 1e-2), level[idx] +
                   rng.uniform(-0.15, 0.15, len(g)), s=22, color=colours.get(effect, "grey"))
    ax.axvline(threshold_nats, color="k", ls=":", lw=0.8)
    ax.set_xscale("log")
    ax.set_yticks(range(len(OUTCOMES)), OUTCOMES)
    ax.set_ylim(-0.5, len(OUTCOMES) - 0.5)
    ax.set_xlabel("information: lambda n u^2 / 2 (nats); u = unabsorbed RMS / noise RMS")
    ax.set_title(f"What each scenario held; left of the dotted line (log(1/alpha) = "
                 f"{threshold_nats:.1f} nats)\nno evidence test at that alpha can name it",
                 fontsize=9)
    ax.grid(alpha=0.3)


# --------------------------------------------------------------------------- the grid


def scenario_grid(det_cfg: Mapping[str, Any]) -> list[tuple[str, str, int]]:
    """(effect, ratio label, seed) of every scenario of the selected grid of config ``detection``.

    Ratios are labelled with ``:g`` (0.5 -> "0.5"); effect-free scenarios have ratio "0".
    """
    grid = det_cfg["grids"][det_cfg["grid"]]
    effects = grid.get("effects") or det_cfg["effects"]
    out = [(e, f"{float(r):g}", s) for e in effects for r in grid["ratios"]
           for s in range(int(grid["seeds"]))]
    out += [(e, "0", s) for e in grid.get("effect_free", ["none_tanh"])
            for s in range(int(grid["false_alarm_seeds"]))]
    return out
