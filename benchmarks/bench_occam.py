"""What the broad priors cost in evidence: the Occam factor of each accepted candidate under
the term files' priors (over the physically plausible decades) against the narrow priors of
commit 878cd79 (set for the paper's rig and scaled).

Where the likelihood is much narrower than both priors, the log evidence of a model differs
between two priors by the log ratio of their densities at the posterior (Laplace):

    log Z_new - log Z_old ~= log p_new(theta_hat) - log p_old(theta_hat),

summed over the candidate's added parameters. For every candidate of the given diagnosis
JSON files (``added_parameters``: posterior means; ``added_priors``: the priors it was fitted
under; the round's ``device_scale``, which holds the device's M, m and k), the old priors are evaluated by the code of the old
commit in a subprocess (``--old-src``: its ``workflow/src``, e.g. after ``git worktree add
/tmp/oldtree 878cd79``) on the same device scales. Printed per candidate: the effect, the
posterior means, both log densities and their difference (negative: the broad prior costs
evidence). Parameters the old term did not have are left out and named.

Run: ``python benchmarks/bench_occam.py --old-src /tmp/oldtree/workflow/src
results/detection/*/diagnoses/*/*.json``.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

import numpy as np

from harvester.inference.priors import PriorSpec

#: Run inside the old commit's package: its candidate priors' log densities at given values.
OLD_SIDE = r"""
import json, sys
import numpy as np
from harvester.diagnosis.name.fits import candidate_priors
from harvester.diagnosis.detect.signatures import MotionScale
out = []
for job in json.load(sys.stdin):
    s = job["scale"]
    scale = MotionScale(z=s["z"], v=s["v"], f_high=s["f_high"], force=s["force"],
                        z_quantiles={float(k): v for k, v in s["z_quantiles"].items()})
    try:
        priors = candidate_priors(job["effect"], scale, job["known"])
    except KeyError as err:
        out.append({"error": str(err)}); continue
    out.append({n: float(priors[n].logpdf(x)) for n, x in job["values"].items() if n in priors})
print(json.dumps(out))
"""


def candidates(paths: list[Path]) -> list[dict]:
    """(effect, device scale, known, posterior means, new log densities) per candidate."""
    jobs = []
    for path in paths:
        d = json.loads(path.read_text())
        scales = {i + 1: r.get("device_scale") for i, r in enumerate(d.get("rounds", []))}
        for c in d.get("candidates", []):
            scale = scales.get(c.get("round"))
            if not scale or not c.get("added_priors"):
                continue
            values = {n: s["mean"] for n, s in c["added_parameters"].items()}
            new = {n: float(_spec(n, p).logpdf(values[n]))
                   for n, p in c["added_priors"].items() if n in values}
            jobs.append({"file": str(path), "effect": c["effect"], "scale": scale,
                         "known": {k: scale[k] for k in ("M", "m", "k")},
                         "values": values, "new": new, "accepted": c.get("accepted")})
    return jobs


def _spec(name: str, p: dict) -> PriorSpec:
    upper = np.inf if p.get("upper") is None else p["upper"]
    lower = -np.inf if p.get("lower") is None else p["lower"]
    return PriorSpec(name=name, mean=p["mean"], sd=p["sd"], unit=p.get("unit", ""),
                     lower=lower, upper=upper, family=p.get("family", "normal"))


def old_log_densities(jobs: list[dict], old_src: Path) -> list[dict]:
    """The old commit's candidate priors' log densities, evaluated by its own code."""
    payload = [{k: j[k] for k in ("effect", "scale", "known", "values")} for j in jobs]
    proc = subprocess.run([sys.executable, "-c", OLD_SIDE], input=json.dumps(payload),
                          capture_output=True, text=True, check=True,
                          env={"PYTHONPATH": str(old_src), "PATH": "/usr/bin:/bin"})
    return json.loads(proc.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--old-src", type=Path, required=True)
    ap.add_argument("files", type=Path, nargs="+")
    args = ap.parse_args()
    jobs = candidates(args.files)
    old = old_log_densities(jobs, args.old_src)
    print(f"{'effect':20s} {'accepted':8s} {'new - old (nats)':>16s}  parameters")
    diffs = []
    for job, o in zip(jobs, old):
        if "error" in o:
            print(f"{job['effect']:20s} (not in the old library: {o['error']})")
            continue
        shared = [n for n in job["new"] if n in o]
        diff = sum(job["new"][n] - o[n] for n in shared)
        diffs.append(diff)
        left = sorted(set(job["new"]) - set(shared))
        print(f"{job['effect']:20s} {str(job['accepted']):8s} {diff:16.2f}  " + ", ".join(
            f"{n}={job['values'][n]:.3g} ({job['new'][n] - o[n]:+.2f})" for n in shared) +
            (f"; new only: {', '.join(left)}" if left else ""))
    if diffs:
        print(f"median {np.median(diffs):+.2f} nats over {len(diffs)} candidates "
              f"(range {min(diffs):+.2f} to {max(diffs):+.2f})")


if __name__ == "__main__":
    main()
