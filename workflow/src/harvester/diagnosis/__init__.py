"""Diagnosis of missing physics (issue 5): detect and locate a mismatch between a recording
and a baseline model, name it from the physics library, confirm it by evidence, and show the
fit improve.

Entry points: :func:`diagnose` (one recording), :func:`diagnose_study` (the study's rule),
:func:`quick_detect` (detection and location only, MAP baseline, seconds),
:class:`DiagnosisSettings` (``DiagnosisSettings.fast()`` for grids). Modules, in the order the
diagnosis runs: ``settings``; ``analysis`` (the recording cut into windows, the baseline's
start); ``baseline`` (likelihood through the measurement chain, MAP, sensitivities);
``spectral`` (frame, noise spectrum, replicates); ``signatures`` (candidate effects' output
signatures); ``detect`` (calibrated score tests, prior conflicts); ``locate`` (time windows,
state regions, frequency bands); ``rank``; ``confirm`` (TMCMC, evidence, ties); ``rounds``
(detect -> rank -> confirm, one effect at a time); ``verdict`` (what is named, what is
tied); ``separate`` (experiments that would break a tie); ``report`` (unseen-data fit,
diagnosis.json); ``figures``; ``run`` (the orchestrator).
"""

__all__ = ["Diagnosis", "DiagnosisSettings", "check_recording", "diagnose", "diagnose_study",
           "quick_detect", "write"]


def __getattr__(name: str):  # noqa: ANN202 - PEP 562: the entry points load on first use
    """The entry points above, imported from ``run`` when first asked for, so that a module of
    the package (``harvester.diagnosis.shapes``, say) loads without the orchestrator's
    imports (ArviZ, PyMC: seconds for every rule that needs one helper)."""
    if name in __all__:
        from harvester.diagnosis import run
        return getattr(run, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
