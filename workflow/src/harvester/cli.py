"""Command line: the whole method on one recording, each command a thin front on the library.

    harvester check    REC                                 the instrument checks alone
    harvester identify REC --model tanh+cubic_stiffness --out DIR
    harvester compare  REC --models linear tanh --out DIR
    harvester predict  REC --posterior DIR/posterior.nc --out DIR2
    harvester diagnose REC --baseline tanh --out DIR
    harvester terms                                        the physics library
    harvester power    EXC.csv --electrical results/electrical --out DIR   power vs load

A recording is read and checked once (``harvester.data.daq.read_checked_recording``, the
checks of ``harvester.data.checks``, the sidecar of ``harvester.data.sidecar``), ``--out`` is
checked before any work, results appear in ``--out`` only when complete
(``harvester.data.fileio.atomic_directory``: a killed run resumes from its staging
directory), and every warning goes to the log and to the output (``run.json`` or
``diagnosis.json``'s ``notes``). Exit status: 0 done, 2 bad input (the message names the
file, the line or column, what was found and what was expected), 1 a bug (traceback).

Each command imports the library it needs inside its function, so that ``harvester --help``
and a bad argument answer at once instead of after PyMC's import.
"""

from __future__ import annotations

import argparse
import logging
import sys
from dataclasses import asdict
from pathlib import Path

from harvester.data.errors import DataError
from harvester.inference import TMCMC_STARTS

log = logging.getLogger("harvester.cli")

RECORDING_HELP = """\
recording: a CSV file, comma-separated, '.' as the decimal point, with a header:
  time      s       uniform steps
  base_acc  m/s^2   input: base acceleration (gravity removed), or
  base_disp m       input: base displacement (laser, LVDT; differentiated twice into
                    base_acc by the library, band-limited at filtered_at_hz), or
  force     N       input: force on the mass, base fixed
  rel_acc   m/s^2   output: acceleration of the mass relative to the base, or
  rel_disp  m       output: displacement of the mass relative to the base
  (other columns are carried along unused).
sidecar RECORDING.yaml beside it (optional): M (kg), m (kg), k (N/m), priors
  ({name: {mean, sd}}), filtered_at_hz (Hz), friction_on (base or ground: what the
  friction acts on; ground: diagnose rewrites base_disp -> rel_disp as force k y -> x).
  Device parameters it does not give are identified, or must be given, or assumed with
  --paper-device (the paper's Table 1:
  M 12.8 kg, m 8 kg, k 250 N/m); what was assumed is logged and written to the output.
exit status: 0 done, 2 bad input (named: file, line or column, found, expected)."""

#: Sampler defaults of the command line (the study's config: 1000 particles x 2 chains).
CLI_TMCMC = {"particles": 500, "chains": 2, "mcmc_steps": 3, "target_accept": 0.25}

_log_to_file = False


# --------------------------------------------------------------------------- parser


def _model_expression(text: str) -> str:
    """argparse type: a model expression ``base+term+...`` the library can build."""
    from harvester.model.structures import structure
    try:
        structure(text)
    except (KeyError, ValueError) as err:
        raise argparse.ArgumentTypeError(str(err.args[0] if err.args else err)) from None
    return text


def _term_name(text: str) -> str:
    """argparse type: the name of a physics term of the library."""
    from harvester.model.terms import term
    try:
        term(text)
    except KeyError as err:
        raise argparse.ArgumentTypeError(str(err.args[0])) from None
    return text


#: Each command's help, example and what it writes (its --help).
COMMAND_TEXTS: dict[str, tuple[str, str, str]] = {
    "check": ("check a recording as an instrument would, and nothing else",
              "harvester check rec.csv",
              "prints the recording's kinds, rate, duration, device parameters and every "
              "warning with its evidence"),
    "identify": ("identify one model structure by TMCMC",
                 "harvester identify rec.csv --model tanh+cubic_stiffness --out fit",
                 "writes DIR/posterior.nc, summary.csv (parameter, unit, mean, sd, 2.5 and 97.5 "
                 "%, and the same adjusted for correlated residuals), evidence.json (log "
                 "evidence in nats per chain, pooled, standard error), "
                 "posterior_pairs.png, run.json (known, assumed, priors, warnings)"),
    "compare": ("identify several structures; evidence and Bayes factors",
                "harvester compare rec.csv --models linear tanh --out cmp",
                "writes DIR/evidence.csv (model, log evidence and standard error in nats, log "
                "Bayes factor against the first model and its error), DIR/models/<model>/ "
                "as identify writes, run.json"),
    "predict": ("posterior predictive on an unseen recording",
                "harvester predict unseen.csv --posterior fit/posterior.nc --out pred",
                "writes DIR/predictive.csv (time s, measured, mean, lower_3sd, upper_3sd, "
                "sd_parameter, in the output's unit), validation.json (NRMSE, shares outside "
                "+-1, 2, 3 sd, mean log predictive density in nats), predictive.png, run.json."
                " The device's parameters are the posterior's."),
    "diagnose": ("diagnose physics missing from a baseline model",
                 "harvester diagnose rec.csv --baseline tanh --out diag",
                 "writes DIR/diagnosis.json (verdict, missing effects, candidates' log "
                 "evidence in nats, where the mismatch lies, the fit before and after; "
                 "notes: warnings and assumptions) and figures. Takes every kind of "
                 "recording (input base_acc, base_disp or force, output rel_acc or rel_disp) "
                 "M, m, k not given (sidecar or --paper-device) are identified, with priors "
                 "from the recording's FRF (a base input needs one of them known)."),
    "terms": ("list the physics library: terms, equations, units, priors", "harvester terms",
              "prints the base equation and every term"),
    "power": ("power the harvester would make on your base acceleration, per load, with its "
              "uncertainty",
              "harvester power boat.csv --electrical results/electrical --out power",
              "EXC.csv: columns time (s, uniform) and base_acc (m/s^2). --electrical: the "
              "directory of the study's rules electrical_identify and electrical_evidence "
              "(weights.json, samples_<structure>.csv). Writes DIR/curve.csv (per load in ohm: "
              "mean, median, interval and low quantile of the mean power in W, also with the "
              "friction scaled by --friction-factor; with --record also one record's "
              "interval), energy.csv (J over a record), "
              "design.json (the loads of maximum expected power and of maximum low quantile, "
              "the paired gain of the change), power_vs_load.png, energy.png, run.json"),
}


def _command(sub, name: str) -> argparse.ArgumentParser:
    """The sub-parser of a command, with its texts from :data:`COMMAND_TEXTS`."""
    help_, example, outputs = COMMAND_TEXTS[name]
    return sub.add_parser(name, help=help_, description=help_,
                          formatter_class=argparse.RawDescriptionHelpFormatter,
                          epilog=f"example:\n  {example}\n\n{outputs}\n\n{RECORDING_HELP}")


def _recording_args(p: argparse.ArgumentParser, out: bool = True,
                    paper_device: bool = True) -> None:
    p.add_argument("recording", type=Path, help="the recording (CSV; see below)")
    if out:
        p.add_argument("--out", type=Path, required=True, metavar="DIR",
                       help="output directory (created; replaced as a whole when the run "
                            "completes; a killed run resumes)")
    if paper_device:
        p.add_argument("--paper-device", action="store_true",
                       help="assume the paper's M, m, k (12.8 kg, 8 kg, 250 N/m) where the "
                            "sidecar gives none (logged and written to the output)")
    p.add_argument("--log", type=Path, metavar="FILE", help="progress to FILE, not stderr")


def _fit_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--particles", type=int, default=CLI_TMCMC["particles"],
                   help=f"TMCMC particles per chain ({CLI_TMCMC['particles']})")
    p.add_argument("--chains", type=int, default=CLI_TMCMC["chains"],
                   help=f"TMCMC chains ({CLI_TMCMC['chains']}; >= 2 for an evidence error)")
    p.add_argument("--seed", type=int, default=0, help="random seed (0)")
    p.add_argument("--start", choices=TMCMC_STARTS, default="map",
                   help="where TMCMC's particles start: map (half at the model's MAP; "
                        "default) or prior (all from the prior, as the paper's study)")
    p.add_argument("--lead-in", type=float, default=1.0, metavar="S",
                   help="seconds skipped before the likelihood (1.0; the model starts at rest)")
    p.add_argument("--fit-seconds", type=float, metavar="S",
                   help="most seconds fitted after the lead-in (default: all)")
    p.add_argument("--filtered-at", type=float, metavar="HZ",
                   help="the recording went through a zero-phase low-pass at HZ (default: the "
                        "sidecar's filtered_at_hz, else found from its spectrum; 0: none)")
    p.add_argument("--filter-order", type=int, default=8, help="order of that low-pass (8)")
    p.add_argument("--no-figures", action="store_true", help="write no figures")


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="harvester", description=__doc__.split("\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter,
                                epilog=RECORDING_HELP)
    from harvester import __version__
    p.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")
    _recording_args(_command(sub, "check"), out=False)
    i = _command(sub, "identify")
    _recording_args(i)
    i.add_argument("--model", type=_model_expression, required=True, metavar="EXPR",
                   help="base+term+..., e.g. tanh+cubic_stiffness (harvester terms lists them)")
    _fit_args(i)
    c = _command(sub, "compare")
    _recording_args(c)
    c.add_argument("--models", type=_model_expression, nargs="+", required=True,
                   metavar="EXPR", help="model expressions; Bayes factors against the first")
    _fit_args(c)
    _predict_parser(sub)
    _diagnose_parser(sub)
    _command(sub, "terms")
    _power_parser(sub)
    return p


def _power_parser(sub) -> None:
    w = _command(sub, "power")
    w.add_argument("excitation", type=Path, help="base acceleration CSV (time, base_acc)")
    w.add_argument("--electrical", type=Path, required=True, metavar="DIR",
                   help="weights.json and samples_<structure>.csv of the electrical study")
    w.add_argument("--out", type=Path, required=True, metavar="DIR", help="output directory")
    w.add_argument("--loads", type=float, nargs=3, default=(0.25, 25.0, 13),
                   metavar=("MIN", "MAX", "COUNT"), help="geometric grid of loads, ohm")
    w.add_argument("--draws", type=int, default=150, help="posterior draws (150)")
    w.add_argument("--seed", type=int, default=0, help="random seed of the draws (0)")
    w.add_argument("--lead-in", type=float, default=2.0, metavar="S",
                   help="seconds left out of the mean power (2.0; the model starts at rest)")
    w.add_argument("--record", type=float, default=None, metavar="S",
                   help="cut the excitation into records of S seconds: their spread joins the "
                        "parameters' (default: one record)")
    w.add_argument("--interval", type=float, default=0.9, help="credible interval (0.9)")
    w.add_argument("--low-quantile", type=float, default=0.05, help="cautious quantile (0.05)")
    w.add_argument("--friction-factor", type=float, default=0.5,
                   help="the change whose gain is predicted: F_c times this (0.5)")
    w.add_argument("--no-figures", action="store_true", help="write no figure")
    w.add_argument("--log", type=Path, metavar="FILE", help="progress to FILE, not stderr")


def _predict_parser(sub) -> None:
    d = _command(sub, "predict")
    _recording_args(d, paper_device=False)
    d.add_argument("--posterior", type=Path, required=True, metavar="P.nc",
                   help="posterior.nc written by harvester identify (same device and kinds)")
    d.add_argument("--samples", type=int, default=200, help="posterior samples simulated (200)")
    d.add_argument("--seed", type=int, default=0, help="random seed of the thinning (0)")
    d.add_argument("--lead-in", type=float, default=1.0, metavar="S",
                   help="seconds left out of the metrics (1.0; the model starts at rest)")
    d.add_argument("--no-figures", action="store_true", help="write no figure")


def _diagnose_parser(sub) -> None:
    d = _command(sub, "diagnose")
    _recording_args(d)
    d.add_argument("--baseline", type=_model_expression, required=True, metavar="EXPR",
                   help="model to diagnose: any expression, e.g. linear, tanh, "
                        "tanh+cubic_stiffness")
    d.add_argument("--validation", type=Path, help="unseen recording (same format) for the "
                   "before/after comparison; default: the recording's last quarter is held out")
    filt = d.add_mutually_exclusive_group()
    filt.add_argument("--no-filter", action="store_true",
                      help="use the recording as given (default); a low-pass it already went "
                           "through is found from its spectrum")
    filt.add_argument("--lowpass", type=float, metavar="HZ",
                      help="low-pass the output at HZ (zero-phase Butterworth) first")
    d.add_argument("--filtered-at", type=float, metavar="HZ",
                   help="the recording was already low-passed (zero-phase) at HZ")
    d.add_argument("--filter-order", type=int, default=8, help="order of that low-pass (8)")
    d.add_argument("--seed", type=int, default=0, help="random seed (0)")
    d.add_argument("--particles", type=int, help="TMCMC particles per chain (300; fast: 150)")
    d.add_argument("--chains", type=int, default=2, help="TMCMC chains (2)")
    d.add_argument("--rounds", type=int, help="most effects added in turn (2; fast: 1)")
    d.add_argument("--top", type=int, help="candidates sampled per round (3; fast: 2)")
    d.add_argument("--candidates", nargs="+", metavar="TERM", type=_term_name,
                   help="library terms considered as missing (default: every term; "
                        "`harvester terms` lists them)")
    d.add_argument("--budget", type=_budget, metavar="SECONDS", default=argparse.SUPPRESS,
                   help="the diagnosis's time budget: past it no candidate is sampled further "
                        "and diagnosis.json says what was not decided (default: 120 s + 4 s "
                        "per second of the recording, at least 150; none: no budget)")
    d.add_argument("--fast", action="store_true", help="cheaper settings (for grids)")
    d.add_argument("--no-figures", action="store_true", help="write diagnosis.json only")


def _budget(text: str) -> float | None:
    """--budget's value: seconds (> 0) or "none"."""
    if text.strip().lower() == "none":
        return None
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not value > 0:
        raise argparse.ArgumentTypeError(f"expected seconds > 0 or 'none', got {text!r}")
    return value


# --------------------------------------------------------------------------- shared steps


def _warn(text: str) -> None:
    """A warning: to the log, and to the console once (the log is the console without --log)."""
    log.warning("%s", text)
    if _log_to_file:
        print(f"harvester: warning: {text}", file=sys.stderr)


def _read(path: Path, paper_device: bool, accept=None, known=None, known_from=None,
          for_model: bool = False):
    """(checked recording, known parameters) by the library's one reader
    (``data.device_recording``); its warnings and notes reported here."""
    from harvester.data.device_recording import read_device_recording
    from harvester.study.paper import TABLE1_KNOWN
    dev = read_device_recording(path, TABLE1_KNOWN if paper_device else None,
                                "the paper's Table 1 (--paper-device)", accept=accept,
                                known=known, known_from=known_from, for_model=for_model)
    for w in dev.checked.warnings:
        _warn(str(w))
    for note in dev.notes:
        (_warn if note.startswith("ASSUMED") else log.info)(note)
    for line in dev.rewritten:
        log.info("%s", line)
    return dev.checked, dev.known


def _record(command: str, args: argparse.Namespace, checked, kp) -> dict:
    """What run.json says about the input: recording, kinds, sidecar, known and assumed."""
    from harvester.data.daq import sha256
    df = checked.data
    options = {k: (str(v) if isinstance(v, Path) else v) for k, v in vars(args).items()}
    return {"command": command, "options": options, "recording": str(args.recording),
            "recording_sha256": sha256(args.recording),
            "input": checked.kinds.input_kind, "output": checked.kinds.output_kind,
            "duration_s": float(len(df) * checked.dt), "sampling_rate_hz": 1.0 / checked.dt,
            "sidecar": checked.sidecar.summary(), "known": kp.values,
            "assumed": {"values": kp.assumed, "from": kp.assumed_from},
            "warnings": [str(w) for w in checked.warnings],
            "notes": kp.notes(checked.sidecar)}


def _key(args: argparse.Namespace, *extra) -> str:
    from harvester.data.fileio import run_key
    from harvester.data.sidecar import sidecar_path
    settings = {k: v for k, v in vars(args).items() if k not in ("out", "log", "models")}
    return run_key(args.recording, sidecar_path(args.recording), settings, *extra)


def _quiet_pymc() -> None:
    """PyMC sets its logger to INFO when imported: quiet it once it is."""
    import pymc  # noqa: F401
    logging.getLogger("pymc").setLevel(logging.ERROR)


def _fit_figure(args: argparse.Namespace, note: str):
    """The posterior's pair figure for ``fit_recording``, or None with --no-figures."""
    from harvester.plots.posterior import fit_pair_figure
    return None if args.no_figures else fit_pair_figure(note)


def _settings(args: argparse.Namespace):
    from harvester.inference.identify import TMCMCSettings
    _quiet_pymc()
    if args.particles < 20 or args.chains < 1:
        raise DataError("<command line>", f"--particles {args.particles} and --chains "
                        f"{args.chains}: need at least 20 particles and 1 chain")
    return TMCMCSettings(particles=args.particles, chains=args.chains, seed=args.seed,
                         start=args.start, mcmc_steps=CLI_TMCMC["mcmc_steps"],
                         target_accept=CLI_TMCMC["target_accept"])


# --------------------------------------------------------------------------- commands


def check_command(args: argparse.Namespace) -> int:
    checked, kp = _read(args.recording, args.paper_device)
    df = checked.data
    print(f"{args.recording}: {checked.kinds.input_kind} -> {checked.kinds.output_kind}, "
          f"{len(df)} samples, {len(df) * checked.dt:.4g} s at {1.0 / checked.dt:.6g} Hz; "
          f"{len(checked.warnings)} warning(s)")
    for note in kp.notes(checked.sidecar):
        print(f"  {note}")
    for w in checked.warnings:
        print(f"  warning: {w}")
    return 0


def _prepare_fit(args: argparse.Namespace, model: str, checked, kp):
    """(problem, priors, notes) of one structure on the checked recording (``api.fit_problem``,
    the one preparation of the command line and of ``harvester.identify``)."""
    from harvester.api import fit_problem
    problem, priors, notes = fit_problem(
        checked, model, kp.values, lead_in_s=args.lead_in, lowpass_hz=args.filtered_at,
        filter_order=args.filter_order, fit_seconds=args.fit_seconds,
        source=str(args.recording), hint=f", in {checked.sidecar.path}, or pass --paper-device",
        option="--filtered-at")
    for note in notes:
        log.info("%s", note)
    return problem, priors, notes


def _fit_record(problem, priors, notes, settings) -> dict:
    return {"model": problem.structure.name, "identified": list(problem.parameter_names),
            "held": problem.known, "window_s": [problem.window[0] * problem.dt,
                                                problem.window[1] * problem.dt],
            "output_filter": problem.output_filter, "settings": asdict(settings),
            "priors": {n: asdict(s) for n, s in priors.items()
                       if n in problem.parameter_names}, "prior_notes": notes}


def identify_command(args: argparse.Namespace) -> int:
    from harvester.data.fileio import atomic_directory, check_output_dir, write_json
    from harvester.inference.recording_fit import fit_recording, interval_lines, parameter_table
    check_output_dir(args.out, inputs=(args.recording,))
    settings = _settings(args)
    checked, kp = _read(args.recording, args.paper_device, for_model=True)
    problem, priors, notes = _prepare_fit(args, args.model, checked, kp)
    record = {**_record("identify", args, checked, kp),
              **_fit_record(problem, priors, notes, settings)}
    with atomic_directory(args.out, _key(args)) as stage:
        fit = fit_recording(problem, priors, settings, stage,
                            _fit_figure(args, f"recording: {args.recording.name}"))
        write_json({**record, "evidence": fit.evidence}, stage / "run.json")
    ev = fit.evidence
    print(f"{args.model}: log evidence {ev['log_evidence']:.2f}"
          + (f" +- {ev['standard_error']:.2f}" if ev["standard_error"] else "")
          + f" -> {args.out}")
    print("\n".join(interval_lines(parameter_table(fit.idata, fit.priors))))
    return 0


def compare_command(args: argparse.Namespace) -> int:
    import shutil

    from harvester.data.fileio import atomic_directory, check_output_dir, write_json
    from harvester.inference.compare import evidence_table, verdict
    from harvester.inference.recording_fit import fit_recording
    check_output_dir(args.out, inputs=(args.recording,))
    if len(set(args.models)) != len(args.models):
        raise DataError("<command line>", f"--models repeats a model: {args.models}")
    settings = _settings(args)
    checked, kp = _read(args.recording, args.paper_device, for_model=True)
    prepared = {m: _prepare_fit(args, m, checked, kp) for m in args.models}
    record = _record("compare", args, checked, kp)
    with atomic_directory(args.out, _key(args)) as stage:
        for old in (stage / "models").glob("*") if (stage / "models").exists() else []:
            if old.name not in args.models:
                shutil.rmtree(old)  # left by a killed run with other models
        fits = {m: fit_recording(p, pr, settings, stage / "models" / m,
                                 _fit_figure(args, f"recording: {args.recording.name}"))
                for m, (p, pr, _) in prepared.items()}
        table = evidence_table({m: f.evidence for m, f in fits.items()})
        table.to_csv(stage / "evidence.csv", index=False, float_format="%.6g")
        text = verdict(table)
        write_json({**record, "verdict": text, "models": {
            m: _fit_record(*prepared[m], settings) for m in args.models}}, stage / "run.json")
    print(table.to_string(index=False, float_format=lambda x: f"{x:.2f}"))
    print(f"{text} -> {args.out}")
    return 0


def predict_command(args: argparse.Namespace) -> int:
    from harvester.data.fileio import atomic_directory, check_output_dir, write_json
    from harvester.inference.posterior import read_posterior
    from harvester.inference.unseen import (posterior_structure, predict_unseen,
                                            unseen_problem, write_prediction)
    from harvester.plots.predictive import prediction_figure
    check_output_dir(args.out, inputs=(args.recording, args.posterior))
    if not args.posterior.is_file():
        raise DataError(args.posterior, "posterior not found (expected posterior.nc written by "
                        "harvester identify)")
    try:
        idata = read_posterior(args.posterior)
    except (OSError, ValueError) as err:
        raise DataError(args.posterior, f"cannot read as netCDF: {err}") from None
    _quiet_pymc()
    _, known = posterior_structure(idata, str(args.posterior))
    checked, kp = _read(args.recording, False, for_model=True, known=known,
                        known_from=f"the posterior {args.posterior.name}")
    for name, value in kp.given.items():
        if name in known and abs(known[name] - value) > 1e-9 * abs(value):
            _warn(f"{checked.sidecar.path}: {name} = {value:g}, but the posterior holds "
                  f"{name} = {known[name]:g}: a different device? The posterior's is used")
    problem = unseen_problem(idata, checked.data, str(args.posterior), str(args.recording))
    record = {**_record("predict", args, checked, kp), "posterior": str(args.posterior),
              "model": problem.structure.name, "known": problem.known}
    with atomic_directory(args.out, _key(args, Path(args.posterior))) as stage:
        pred = predict_unseen(problem, idata, args.samples, args.seed, args.lead_in)
        files = write_prediction(pred, stage, None if args.no_figures else
                                 prediction_figure(f"recording: {args.recording.name}"))
        write_json({**record, "metrics": pred.metrics, "files": files}, stage / "run.json")
    m = pred.metrics
    print(f"{m['model']} on {args.recording.name}: NRMSE {m['nrmse']:.3f}, outside +-3 sd "
          f"{m['outside_3sd']:.1%} (nominal {m['nominal_outside_3sd']:.1%}) -> {args.out}")
    return 0


def _diagnosis_settings(args: argparse.Namespace):
    """The command's DiagnosisSettings (the low-pass the recording went through:
    --filtered-at; the sidecar's and the units are the library's, ``diagnosis_input``)."""
    from harvester.diagnosis import DiagnosisSettings
    _quiet_pymc()
    overrides = {k: v for k, v in {"particles": args.particles, "rounds": args.rounds,
                                   "top": args.top}.items() if v is not None}
    if hasattr(args, "budget"):  # else the library's default, from the recording's length
        overrides.update(budget=args.budget is not None, budget_s=args.budget)
    if args.candidates:
        overrides["candidates"] = tuple(args.candidates)
    overrides.update(chains=args.chains, seed=args.seed, lowpass_hz=args.filtered_at,
                     filter_order=args.filter_order, figures=not args.no_figures)
    return DiagnosisSettings.fast(**overrides) if args.fast else DiagnosisSettings(**overrides)


def diagnose_command(args: argparse.Namespace) -> int:
    from harvester.data.fileio import atomic_directory, check_output_dir
    from harvester.diagnosis.prepare.recording import diagnosis_input
    from harvester.diagnosis.run import diagnose_given, write
    from harvester.study.paper import TABLE1_KNOWN

    check_output_dir(args.out, inputs=tuple(p for p in (args.recording, args.validation) if p))
    given = diagnosis_input(  # the library's decisions, as harvester.diagnose makes them
        args.recording, args.baseline, validation=args.validation,
        settings=_diagnosis_settings(args), lowpass_output_hz=args.lowpass,
        defaults=TABLE1_KNOWN if args.paper_device else None,
        defaults_from="the paper's Table 1 (--paper-device)")
    if _log_to_file:  # the library logged them; the console hears them once too
        for w in given.warnings:
            print(f"harvester: warning: {w}", file=sys.stderr)
    key = _key(args, Path(args.validation) if args.validation else None)
    with atomic_directory(args.out, key) as stage:
        diag = diagnose_given(given, args.baseline)
        write(diag, stage)
    print(f"{diag.headline} -> {args.out / 'diagnosis.json'}")
    return 0


def terms_command(args: argparse.Namespace) -> int:
    from harvester.model.terms import TERMS
    from harvester.terms_table import terms_text
    print(terms_text(TERMS))
    return 0


def power_command(args: argparse.Namespace) -> int:
    from harvester.data.fileio import atomic_directory, check_output_dir, run_key, write_json
    from harvester.power.excitations import read_excitation
    from harvester.power.run import load_posteriors, power_study, write_power_study
    check_output_dir(args.out, inputs=(args.excitation,))
    samples = sorted(args.electrical.glob("samples_*.csv"))
    weights = args.electrical / "weights.json"
    if not samples or not weights.is_file():
        raise DataError(args.electrical, "expected weights.json and samples_<structure>.csv "
                        "(rules electrical_identify and electrical_evidence)")
    try:
        exc = read_excitation(args.excitation)
    except ValueError as err:
        raise DataError(args.excitation, str(err)) from None
    cfg = {"seed": args.seed, "draws": args.draws, "lead_in_s": args.lead_in,
           "record_s": args.record,
           "loads": dict(zip(("min_ohm", "max_ohm", "count"), args.loads)),
           "interval": args.interval, "low_quantile": args.low_quantile,
           "change": {"F_c": args.friction_factor}}
    key = run_key(args.excitation, weights, *samples,
                  {k: str(v) for k, v in vars(args).items() if k not in ("out", "log")})
    with atomic_directory(args.out, key) as stage:
        study = power_study(*load_posteriors(samples, weights), exc, cfg)
        files = write_power_study(study, stage, cfg, not args.no_figures)
        write_json({"command": "power", "excitation": str(args.excitation), "settings": cfg,
                    "files": files}, stage / "run.json")
    best = study["design"]["optimum"]
    print(f"{exc.name}: best load {best['expected']['load_ohm']:.3g} ohm "
          f"({1e3 * best['expected']['power_W']:.3g} mW expected); cautious "
          f"{best['low_quantile']['load_ohm']:.3g} ohm -> {args.out}")
    return 0


COMMANDS = {"check": check_command, "identify": identify_command, "compare": compare_command,
            "predict": predict_command, "diagnose": diagnose_command, "terms": terms_command,
            "power": power_command}


def main(argv: list[str] | None = None) -> int:
    global _log_to_file
    args = _parser().parse_args(argv)
    from harvester.runlog import setup
    log_file, out = getattr(args, "log", None), getattr(args, "out", None)
    if log_file and out and Path(out).resolve() in Path(log_file).resolve().parents:
        print(f"harvester: error: {log_file}: --log lies inside --out {out}, which the results "
              "replace as a whole: put the log beside it", file=sys.stderr)
        return 2
    _log_to_file = log_file is not None
    setup(log_file)
    try:
        return COMMANDS[args.command](args)
    except DataError as err:
        if _log_to_file:
            log.error("%s", err)
        print(f"harvester: error: {err}", file=sys.stderr)
        return 2
    except Exception:
        if _log_to_file:  # without --log the traceback below is the log's
            log.exception("%s failed", args.command)
        raise


if __name__ == "__main__":
    sys.exit(main())
