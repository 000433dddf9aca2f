"""Whether two runs diagnosed alike: every diagnosis.json under BEFORE and AFTER (the study's
``results/``, or the folders of ``harvester diagnose`` runs) compared in what it concludes:
the verdict, the names, the ties and the names withheld. Prints one row per diagnosis and
exits 1 where any differs (or is missing from one side).

    python benchmarks/bench_same_verdicts.py BEFORE/results AFTER/results

A restructuring of the code (no change of method) must leave every row "same".
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

#: What a diagnosis concludes, compared key by key.
CONCLUSION = ("verdict", "missing", "indistinguishable", "withheld")


def conclusions(root: Path) -> dict[str, dict]:
    """{path of diagnosis.json relative to ``root``: its conclusion}."""
    out = {}
    for path in sorted(root.rglob("diagnosis.json")):
        doc = json.loads(path.read_text())
        out[str(path.relative_to(root))] = {k: doc.get(k) for k in CONCLUSION}
    return out


def compare(before: Path, after: Path) -> list[tuple[str, str, str]]:
    """(diagnosis, "same" or what differs, the conclusion after) for every diagnosis of
    either side."""
    a, b = conclusions(before), conclusions(after)
    rows = []
    for key in sorted(set(a) | set(b)):
        if key not in a or key not in b:
            rows.append((key, "only " + ("after" if key in b else "before"), ""))
            continue
        diff = [k for k in CONCLUSION if a[key][k] != b[key][k]]
        words = f"{b[key]['verdict']}: {', '.join(b[key]['missing']) or 'no name'}"
        rows.append((key, "same" if not diff else "differs in " + ", ".join(
            f"{k} ({a[key][k]} -> {b[key][k]})" for k in diff), words))
    return rows


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("before", type=Path)
    p.add_argument("after", type=Path)
    args = p.parse_args(argv)
    rows = compare(args.before, args.after)
    if not rows:
        print(f"no diagnosis.json under {args.before} or {args.after}")
        return 1
    width = max(len(r[0]) for r in rows)
    for key, status, words in rows:
        print(f"{key:<{width}}  {status:<10}  {words}")
    same = sum(r[1] == "same" for r in rows)
    print(f"{same} of {len(rows)} diagnoses conclude the same")
    return 0 if same == len(rows) else 1


if __name__ == "__main__":
    sys.exit(main())
