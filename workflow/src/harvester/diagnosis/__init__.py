"""Diagnosis of missing physics: detect and locate a mismatch between a recording and a
baseline model, name it from the physics library, confirm it by evidence, size it, and show
the fit improve.

Entry points: :func:`diagnose_recording` (a recording's file, with its sidecar: the one call
of ``harvester diagnose`` and of ``harvester.diagnose``), :func:`diagnose` (a recording
already read), :func:`diagnose_study` (the study's rule), :func:`quick_detect` (detection and
location only, MAP baseline, seconds), :class:`DiagnosisSettings` (``DiagnosisSettings.fast()``
for grids). ``run`` is the table of contents; the stages are subpackages, each with its map:

``prepare``  settings, the recording's file to the diagnosis's input, the friction's contact,
             the windows and the baseline's start
``detect``   calibrated tests of the baseline against the recording, where the mismatch lies,
             the noise floor
``name``     candidates ranked, screened, confirmed by TMCMC and evidence, in rounds; the
             verdict
``size``     the missing force (latent force, shapes, the periodic shape as a term) and each
             named effect's size and relevance
``report``   the fit on unseen data, diagnosis.json (versioned, with its schema), figures,
             the summary page

Generic inference the stages use lives below them: ``inference.map_fit`` (MAP, Laplace, the
likelihood through the measurement chain), ``inference.state_space`` (Kalman smoother),
``inference.tail`` (p-values against replicates), ``model.term_forces``.
"""

__all__ = ["Diagnosis", "DiagnosisSettings", "check_recording", "diagnose",
           "diagnose_recording", "diagnose_study", "quick_detect", "write"]


def __getattr__(name: str):  # noqa: ANN202 - PEP 562: the entry points load on first use
    """The entry points above, imported from ``run`` when first asked for, so that a module of
    the package (``harvester.diagnosis.size.shapes``, say) loads without the orchestrator's
    imports (ArviZ, PyMC: seconds for every rule that needs one helper)."""
    if name in __all__:
        from harvester.diagnosis import run
        return getattr(run, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
