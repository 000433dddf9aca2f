"""Bayesian system identification of friction-dominated mechanical devices.

From Python (the README's section "From Python" runs them on a bundled recording)::

    from harvester import load_recording, identify, diagnose

    rec = load_recording("run.csv")            # read and checked, with its sidecar run.yaml
    fit = identify(rec, "tanh", particles=200)  # TMCMC: posterior, priors, log evidence (nats)

* :func:`load_recording`: ``harvester.data.daq.read_checked_recording``, what ``harvester
  check`` does (a :class:`~harvester.data.daq.CheckedRecording`: table, kinds, time step,
  sidecar, the checks' warnings);
* :func:`identify`: ``harvester.api.identify``, what ``harvester identify`` does (an
  :class:`~harvester.inference.recording_fit.Fit`; files only where ``out`` is given);
* :func:`diagnose`: ``harvester.diagnosis.diagnose_recording``, what ``harvester diagnose``
  does: the diagnosis of missing physics of a recording's file, the same call as the
  command's (a :class:`~harvester.diagnosis.run.Diagnosis`; ``out_dir`` writes
  diagnosis.json, its figures and summary.html).

They are imported on first use (PEP 562), so that ``import harvester`` and ``harvester
--help`` do not wait for PyMC. ``__version__`` is the installed distribution's (the version
in pyproject.toml).
"""

from __future__ import annotations

__all__ = ["__version__", "diagnose", "identify", "load_recording"]

#: Each public name and the module that holds it, imported when first asked for.
_PUBLIC = {"load_recording": ("harvester.data.daq", "read_checked_recording"),
           "identify": ("harvester.api", "identify"),
           "diagnose": ("harvester.diagnosis", "diagnose_recording")}


def _version() -> str:
    """The installed distribution's version; from a source tree that was not installed, the
    one pyproject.toml states; "0+unknown" where neither can be read."""
    from importlib.metadata import PackageNotFoundError, version
    try:
        return version("harvester")
    except PackageNotFoundError:
        import re
        from pathlib import Path
        pyproject = Path(__file__).resolve().parents[3] / "pyproject.toml"
        found = re.search(r'(?m)^version\s*=\s*"([^"]+)"',
                          pyproject.read_text() if pyproject.is_file() else "")
        return found.group(1) if found else "0+unknown"


def __getattr__(name: str):  # noqa: ANN202 - PEP 562: the public API loads on first use
    if name == "__version__":
        value = _version()
    elif name in _PUBLIC:
        from importlib import import_module
        module, attribute = _PUBLIC[name]
        value = getattr(import_module(module), attribute)
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    globals()[name] = value  # asked once
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
