"""How the paper's session of the virtual rig was calibrated (issue 44; docs/design.md, the
virtual rig): what the session does to the statistics the paper reports, in seconds, without
TMCMC.

For a rig config (the config's, with ``--set`` overrides of the session), the training and
validation records are simulated, converted and low-passed as the workflow does (20 Hz, order
8; 2000 samples after the 1 s lead-in), and the linear and tanh models are fitted by least
squares with the study's likelihood (``recording_problem``; M, m, k known). Printed, one JSON
line per setting:

* ``sigma_v_mm_s``: the rig's RMS screw speed over the fitted samples; ``stuck_pct`` the share
  of them at which the rig sticks;
* ``linear_c_m``, ``linear_sigma``, ``tanh`` (c_m, F_c, beta), ``tanh_sigma``: the least-squares
  estimates (sigma = RMS residual: the posterior means of Tables 3 and 5 up to the priors);
* ``sticks``, ``longest_stick_ms``, ``near_stick_pct`` (within 20 ms of a stick) and, per
  model, ``*_rms_near_over_elsewhere``: its RMS residual near the sticks over elsewhere, and
  ``*_nrmse_near_over_elsewhere`` the same of the residual relative to the measured output's
  RMS there (``study.sticking``), and ``*_nrmse_stuck`` / ``*_nrmse_moving``: its RMS
  residual over the record's RMS while the rig is stuck / moves;
* ``tanh_sd``: their posterior sds by Laplace (Gauss-Newton Hessian), ``tanh_z``: (estimate -
  truth) / sd, the truth being the rig's Table 5 values; ``tanh_z_adj`` the same with the sds
  adjusted for correlated residuals (``inference.correlated_residuals``, flat priors);
* ``log_bf_laplace``: eq. (12) by the Laplace approximation of both evidences under the
  config's priors (the c_m and F_c prior means given by ``--prior-c-m``, ``--prior-f-c``: our
  Table 1's); ``n_log_sigma_ratio``: its likelihood part, N ln(sigma_linear / sigma_tanh);
* with ``--unseen``: on the validation record, the tanh model's predictive ensemble (200 draws
  of the Laplace posterior), the share of the unseen samples outside +-3 sd of the parameter
  samples alone (the paper's bounds) and of the full predictive (parameters + sigma), and the
  parameter sd over sigma.

``--realizations K``: K draws of the mass channel's extra error (the session's other streams
fixed), the tanh estimates' z per draw and their RMS, with eq. (10)'s sds and with the sds
adjusted for correlated residuals: how far eq. (10)'s independent residuals fall short of the
estimates' scatter, and whether the adjustment closes the gap.

Run: ``python benchmarks/bench_rig_session.py`` (the config's session, with ``--unseen``),
``python benchmarks/bench_rig_session.py --set excitation.peak_m_s2=4,5,6,7,8`` (a scan),
``python benchmarks/bench_rig_session.py --realizations 10``.
"""

from __future__ import annotations

import argparse
import copy
import itertools
import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import yaml
from scipy import optimize

from harvester.data import daq
from harvester.inference.correlated_residuals import (adjustment_matrix, lag_window,
                                                      likelihood_curvature, sandwich)
from harvester.data.signals import filter_recording
from harvester.inference.recording_fit import FitWindow, recording_problem
from harvester.study.sticking import stick_misfit
from harvester.synthetic import rig

ROOT = Path(__file__).resolve().parents[1]
RECORDS = ("training", "validation")


def session_config(cfg: dict, overrides: dict[str, float]) -> dict:
    """The rig config with ``section.key`` overrides put in the paper records' session."""
    rc = copy.deepcopy(cfg["rig"])
    for name in RECORDS:
        session = copy.deepcopy(rc["records"][name].get("session") or {})
        for key, value in overrides.items():
            section, field = key.split(".")
            session.setdefault(section, {})[field] = value
        rc["records"][name]["session"] = session
    return rc


def filtered_record(rc: dict, name: str, pre: dict) -> tuple[rig.RecordSimulation, pd.DataFrame]:
    sim = rig.simulate_record(rc, name)
    frame = pd.DataFrame({"time": sim.time, "ai0": sim.ai0, "ai1": sim.ai1})
    acc = daq.to_accelerations(frame, daq.record_metadata(rc, name, len(frame), sim.seed))
    return sim, filter_recording(acc, pre["lowpass_hz"], pre["filter_order"], name, ("rel_acc",))


def normal_logpdf(x: float, mean: float, sd: float) -> float:
    return -0.5 * ((x - mean) / sd) ** 2 - math.log(sd * math.sqrt(2.0 * math.pi))


def fit(problem, model: str) -> dict:
    """Least squares with sigma profiled; Laplace covariance of the physical parameters."""
    n = problem.n_data

    def sse(x):
        s, ok = problem.residual_sums(np.atleast_2d(np.r_[x, 1.0]))
        return float(s[0]) if ok[0] else 1e12

    if model == "linear":
        x = np.array([optimize.minimize_scalar(lambda c: sse([c]), bounds=(1.0, 5000.0),
                                               method="bounded").x])
    else:
        x = optimize.minimize(sse, [109.5, 11.86, 88.35], method="Nelder-Mead",
                              options={"xatol": 1e-4, "fatol": 1e-10, "maxiter": 800}).x
    sigma = math.sqrt(sse(x) / n)

    def pred(v):
        return problem.predict(np.atleast_2d(np.r_[v, sigma]))[0][problem.samples]

    y0, jac = pred(x), []
    for j in range(x.size):
        h = 1e-4 * max(abs(x[j]), 1.0)
        xp = x.copy()
        xp[j] += h
        jac.append((pred(xp) - y0) / h)
    jac = np.array(jac).T
    hess = jac.T @ jac / sigma ** 2
    cov = np.linalg.inv(hess)
    r = problem.observed - y0
    _, lag = lag_window(r)
    gauss_newton, meat = sandwich(jac, r, lag)
    bread = likelihood_curvature(problem, x, np.sqrt(np.diag(cov)), sigma, gauss_newton,
                                 float(np.mean(r * r)))
    mat = adjustment_matrix(cov, bread, meat)
    return {"x": x, "sigma": sigma, "cov": cov, "hess": hess, "n": n,
            "residual": problem.observed - y0,
            "cov_adj": mat @ cov @ mat.T,
            "names": problem.structure.free_parameters, "problem": problem}


def laplace_log_evidence(f: dict, priors: dict) -> float:
    """log L(theta_hat) + log prior(theta_hat) + d/2 log 2 pi - 1/2 log det H (sigma included,
    its curvature 2N / sigma^2 at the maximum)."""
    n, sigma = f["n"], f["sigma"]
    log_l = -0.5 * n * math.log(2.0 * math.pi * sigma ** 2) - 0.5 * n
    log_p = sum(normal_logpdf(v, *priors[name]) for name, v in zip(f["names"], f["x"]))
    log_p += normal_logpdf(sigma, *priors["sigma"])
    d = f["x"].size + 1
    log_det = np.linalg.slogdet(f["hess"])[1] + math.log(2.0 * n / sigma ** 2)
    return log_l + log_p + 0.5 * d * math.log(2.0 * math.pi) - 0.5 * log_det


def stick_statistics(stuck: np.ndarray, speed: np.ndarray, fits: dict,
                     fs: float = 256.0) -> dict:
    """Figure 7's question (``study.sticking``): the rig's sticks over the fitted samples and
    each model's misfit near them over elsewhere, absolute and relative to the record, and its
    share of the record while the rig is stuck and while it moves."""
    y = next(iter(fits.values()))["problem"].observed
    rig_keys = ("sticks", "longest_stick_ms", "stuck_pct", "near_stick_pct")
    out = {}
    for model, f in fits.items():
        m = stick_misfit(f["residual"], y, stuck, speed, fs).to_dict()
        out.update({k: v for k, v in m.items() if k in rig_keys})
        out.update({f"{model}_{k}": v for k, v in m.items() if k not in rig_keys})
    return out


def analyse(cfg: dict, rc: dict, args, unseen: bool) -> dict:
    pre = cfg["preprocess"]
    lead, n_fit = pre["training_lead_in"], pre["training_samples"]
    sim, train = filtered_record(rc, "training", pre)
    known = {"M": rc["M"], "m": rc["m"], "k": rc["k"]}
    window = FitWindow(lead / 256.0, pre["lowpass_hz"], pre["filter_order"], n_fit / 256.0)
    fits = {m: fit(recording_problem(train, m, known, window), m) for m in ("linear", "tanh")}
    pc = cfg["priors"]
    priors = {"c_m": (args.prior_c_m, pc["c_m"]["sd"]), "F_c": (args.prior_f_c, pc["F_c"]["sd"]),
              "beta": (pc["beta"]["mean"], pc["beta"]["sd"]),
              "sigma": (pc["sigma"]["mean"], pc["sigma"]["sd"])}
    truth = np.array([rc["c_m"], rc["friction"]["F_c"], rc["friction"]["beta"]])
    t = fits["tanh"]
    sd = np.sqrt(np.diag(t["cov"]))
    v = sim.truth["v"][lead:lead + n_fit]
    out = {"sigma_v_mm_s": round(1e3 * float(np.sqrt(np.mean(v ** 2))), 2),
           "stuck_pct": round(100.0 * float(sim.truth["stuck"][lead:lead + n_fit].mean()), 2),
           "base_peak_m_s2": round(float(np.abs(sim.truth["base_acc"]).max()), 3),
           "linear_c_m": round(float(fits["linear"]["x"][0]), 1),
           "linear_sigma": round(fits["linear"]["sigma"], 4),
           "tanh": [round(float(x), 3) for x in t["x"]], "tanh_sd": [round(float(s), 3) for s in sd],
           "tanh_z": [round(float(z), 2) for z in (t["x"] - truth) / sd],
           "tanh_z_adj": [round(float(z), 2) for z in
                          (t["x"] - truth) / np.sqrt(np.diag(t["cov_adj"]))],
           "tanh_sigma": round(t["sigma"], 4),
           "log_bf_laplace": round(laplace_log_evidence(t, priors)
                                   - laplace_log_evidence(fits["linear"], priors), 1),
           "n_log_sigma_ratio": round(t["n"] * math.log(fits["linear"]["sigma"] / t["sigma"]), 1),
           **stick_statistics(sim.truth["stuck"][lead:lead + n_fit],
                              sim.truth["v"][lead:lead + n_fit], fits)}
    if unseen:
        simv, val = filtered_record(rc, "validation", pre)
        rng = np.random.default_rng(11)
        theta = rng.multivariate_normal(t["x"], t["cov"], size=200)
        theta = np.c_[theta, np.full(len(theta), t["sigma"])]
        pv = t["problem"].replace(input=val["base_acc"].to_numpy(float),
                                  output=val["rel_acc"].to_numpy(float), window=None)
        ens = pv.predict(theta)
        y = pv.acquired_output
        sec = slice(pre["validation_lead_in"], y.size - 256)  # the filter's end effects left out
        mean, sd_p = ens[:, sec].mean(0), ens[:, sec].std(0, ddof=1)
        err = np.abs(y[sec] - mean)
        out.update({
            "unseen_outside_3sd_parameter_pct": round(100.0 * float(np.mean(err > 3 * sd_p)), 2),
            "unseen_outside_3sd_predictive_pct": round(100.0 * float(np.mean(
                err > 3 * np.sqrt(sd_p ** 2 + t["sigma"] ** 2))), 2),
            "unseen_parameter_sd_over_sigma": round(float(np.sqrt(np.mean(sd_p ** 2))
                                                          / t["sigma"]), 4),
            "unseen_stuck_pct": round(100.0 * float(simv.truth["stuck"].mean()), 2)})
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--config", default=str(ROOT / "config/config.yaml"))
    ap.add_argument("--set", action="append", default=[],
                    help="section.key=v1,v2,...: session overrides (all combinations scanned)")
    ap.add_argument("--unseen", action="store_true", help="also the unseen record's bounds")
    ap.add_argument("--realizations", type=int, default=0,
                    help="draws of the mass channel's extra error (tanh z per draw)")
    ap.add_argument("--prior-c-m", type=float, default=111.3, help="our Table 1's c_m (N s/m)")
    ap.add_argument("--prior-f-c", type=float, default=8.31, help="our Table 1's F_c (N)")
    args = ap.parse_args()
    cfg = yaml.safe_load(Path(args.config).read_text())
    keys, values = [], []
    for item in args.set:
        key, vals = item.split("=")
        keys.append(key)
        values.append([float(v) for v in vals.split(",")])
    for combo in itertools.product(*values) if keys else [()]:
        over = dict(zip(keys, combo))
        rc = session_config(cfg, over)
        if args.realizations:
            streams, zs = rig.record_streams, []
            for j in range(args.realizations):
                def draw(seed, n=4, j=j):
                    s = streams(seed, n)
                    if n >= 5:  # the mass channel's extra error: its own draw j
                        s[4] = np.random.default_rng([seed, 1000 + j])
                    return s
                rig.record_streams = draw
                try:
                    out = analyse(cfg, rc, args, False)
                finally:
                    rig.record_streams = streams
                zs.append([out["tanh_z"], out["tanh_z_adj"]])
                print(json.dumps({"set": over, "draw": j, **out}), flush=True)
            for label, z in zip(("eq10", "adjusted"), np.array(zs).transpose(1, 0, 2)):
                print(json.dumps({"set": over, "draws": len(z), "intervals": label,
                                  "rms_z": np.round(np.sqrt((z ** 2).mean(0)), 2).tolist(),
                                  "mean_z": np.round(z.mean(0), 2).tolist(),
                                  "within_1.96": np.mean(np.abs(z) < 1.96, 0).tolist(),
                                  "all_within_1.96": float(np.mean((np.abs(z) < 1.96).all(1)))}),
                      flush=True)
        else:
            print(json.dumps({"set": over, **analyse(cfg, rc, args, args.unseen or not keys)}),
                  flush=True)


if __name__ == "__main__":
    main()
