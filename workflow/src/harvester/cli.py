"""Command line: ``harvester diagnose RECORDING.csv --baseline tanh --out DIR``.

RECORDING.csv has a header and the columns time (s, uniform), base_acc and rel_acc (m/s^2).
An optional RECORDING.yaml beside it gives the known parameters ``M``, ``m``, ``k`` (default:
the study's Table 1), and may give ``priors`` (``{name: {mean, sd}}``) and ``filtered_at_hz``
(the cut-off of a zero-phase low-pass the recording already went through). The priors of
c_m and F_c come from the recording's frequency response (``initial.recording_priors``: centred
on its FRF fit when a static friction is given in ``priors``, else spanning the damping's split
between the two), and beta's from the RMS velocity (smooth to sign-law friction). Progress
goes to stderr, or to ``--log FILE``.
"""

from __future__ import annotations

import argparse
import logging
import sys
from pathlib import Path

from harvester.data.errors import DataError

log = logging.getLogger("harvester.cli")


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="harvester",
                                description="Bayesian identification tools for the harvester.")
    sub = p.add_subparsers(dest="command", required=True)
    d = sub.add_parser("diagnose", help="diagnose missing physics in one recording",
                       description="Detect, locate and name physics missing from a baseline "
                                   "model of a recording; writes DIR/diagnosis.json and figures.")
    d.add_argument("recording", type=Path, help="CSV with time, base_acc, rel_acc")
    d.add_argument("--baseline", choices=["linear", "tanh"], required=True,
                   help="the model to diagnose (the paper's M1 or M2)")
    d.add_argument("--out", type=Path, required=True, help="output directory")
    d.add_argument("--validation", type=Path, help="unseen recording (same format) for the "
                   "before/after comparison; default: the recording's last quarter is held out")
    filt = d.add_mutually_exclusive_group()
    filt.add_argument("--no-filter", action="store_true",
                      help="use the recording as given (default); a low-pass it already went "
                           "through is found from its spectrum")
    filt.add_argument("--lowpass", type=float, metavar="HZ",
                      help="low-pass both channels at HZ (zero-phase Butterworth) first")
    d.add_argument("--filtered-at", type=float, metavar="HZ",
                   help="the recording was already low-passed (zero-phase) at HZ")
    d.add_argument("--filter-order", type=int, default=8, help="order of that low-pass (8)")
    d.add_argument("--seed", type=int, default=0)
    d.add_argument("--particles", type=int, help="TMCMC particles per chain (300; fast: 150)")
    d.add_argument("--chains", type=int, default=2, help="TMCMC chains (2)")
    d.add_argument("--rounds", type=int, help="most effects added in turn (2; fast: 1)")
    d.add_argument("--top", type=int, help="candidates sampled per round (3; fast: 2)")
    d.add_argument("--fast", action="store_true", help="cheaper settings (for grids)")
    d.add_argument("--no-figures", action="store_true", help="write diagnosis.json only")
    d.add_argument("--log", type=Path, metavar="FILE", help="progress to FILE, not stderr")
    return p


def _metadata(recording: Path) -> dict:
    path = recording.with_suffix(".yaml")
    if not path.exists():
        return {}
    import yaml
    try:
        meta = yaml.safe_load(path.read_text())
    except yaml.YAMLError as err:
        raise DataError(path, f"invalid YAML: {err}") from None
    if meta is None:
        return {}
    if not isinstance(meta, dict):
        raise DataError(path, "expected a mapping with keys M, m, k (and optionally priors, "
                              "filtered_at_hz)")
    allowed = {"M", "m", "k", "priors", "filtered_at_hz"}
    unknown = sorted(set(meta) - allowed)
    if unknown:
        raise DataError(path, f"unknown key(s) {unknown}; allowed: {sorted(allowed)}")
    for key in ("M", "m", "k", "filtered_at_hz"):
        if key in meta and (not isinstance(meta[key], (int, float)) or isinstance(meta[key], bool)
                            or not meta[key] > 0):
            raise DataError(path, f"'{key}' must be a positive number, got {meta[key]!r}")
    priors = meta.get("priors", {})
    if not isinstance(priors, dict):
        raise DataError(path, "'priors' must map parameter names to {mean, sd}")
    for name, spec in priors.items():
        if not isinstance(spec, dict) or not {"mean", "sd"} <= set(spec) or \
                not all(isinstance(spec[k], (int, float)) for k in ("mean", "sd")) or \
                not spec["sd"] > 0:
            raise DataError(path, f"priors.{name} must be {{mean: number, sd: positive number}}")
    return meta


def diagnose_command(args: argparse.Namespace) -> int:
    from harvester.data.daq import read_recording
    from harvester.diagnosis import DiagnosisSettings, check_recording, diagnose
    from harvester.initial.recording import recording_priors
    from harvester.study.paper import TABLE1_KNOWN
    from harvester.data.signals import filter_recording, sampling_rate

    logging.getLogger("pymc").setLevel(logging.ERROR)  # pymc sets INFO when imported
    df = read_recording(args.recording)
    meta = _metadata(args.recording)
    known = {k: float(meta.get(k, v)) for k, v in TABLE1_KNOWN.items()}
    lowpass = args.filtered_at or meta.get("filtered_at_hz")
    if args.lowpass is not None:
        fs = sampling_rate(df, str(args.recording))
        if not 0 < args.lowpass < fs / 2:
            raise DataError(args.recording, f"--lowpass {args.lowpass} Hz must lie in (0, "
                                            f"{fs / 2:g}) Hz")
        df = filter_recording(df, args.lowpass, args.filter_order, str(args.recording))
        lowpass = args.lowpass
    validation = None
    if args.validation is not None:
        validation = read_recording(args.validation)
        if args.lowpass is not None:
            validation = filter_recording(validation, args.lowpass, args.filter_order,
                                          str(args.validation))
    overrides = {k: v for k, v in {"particles": args.particles, "rounds": args.rounds,
                                   "top": args.top}.items() if v is not None}
    overrides.update(chains=args.chains, seed=args.seed, lowpass_hz=lowpass,
                     filter_order=args.filter_order, figures=not args.no_figures)
    settings = DiagnosisSettings.fast(**overrides) if args.fast else \
        DiagnosisSettings(**overrides)
    check_recording(df, str(args.recording), settings.lead_in_s,
                    0.0 if validation is not None else settings.holdout_fraction)
    try:
        priors = recording_priors(df, known, meta.get("priors", {}), str(args.recording))
    except KeyError as err:  # a prior in the sidecar for a parameter the library lacks
        raise DataError(args.recording.with_suffix(".yaml"), str(err.args[0])) from None
    diag = diagnose(df, args.baseline, known, priors, validation=validation,
                    settings=settings, out_dir=args.out, source=str(args.recording))
    print(f"{diag.verdict}" + (f": {', '.join(diag.missing)}" if diag.missing else "")
          + f" -> {args.out / 'diagnosis.json'}")
    return 0


def main(argv: list[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    from harvester.runlog import setup
    setup(args.log)
    try:
        if args.command == "diagnose":
            return diagnose_command(args)
    except DataError as err:
        log.error("%s", err)
        print(f"harvester: error: {err}", file=sys.stderr)
        return 2
    except Exception:
        log.exception("diagnosis failed")
        raise
    return 1


if __name__ == "__main__":
    sys.exit(main())
