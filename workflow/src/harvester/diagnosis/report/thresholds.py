"""Every threshold that shapes a diagnosis, as diagnosis.json records it: the module-level
numeric constants (UPPER_CASE names; a number, or a tuple of numbers) of the diagnosis's
stages and of the inference modules it decides with, read from the modules themselves so that
a threshold added to a stage is recorded without a list to keep up to date. Settings a user
may change are recorded apart (diagnosis.json's ``settings``)."""

from __future__ import annotations

import importlib
import pkgutil
import re
from numbers import Real

#: The packages and modules whose constants are recorded.
SOURCES = ("harvester.diagnosis", "harvester.inference.map_fit", "harvester.inference.tail",
           "harvester.inference.reference", "harvester.inference.state_space")

_NAME = re.compile(r"^[A-Z][A-Z0-9_]*$")


def _number(value) -> bool:
    return isinstance(value, Real) and not isinstance(value, bool)


def _constants(module) -> dict[str, float | list[float]]:
    """The module's own numeric constants (not those it imports)."""
    out: dict[str, float | list[float]] = {}
    for name, value in vars(module).items():
        if not _NAME.match(name):
            continue
        if _number(value):
            out[name] = float(value) if isinstance(value, float) else int(value)
        elif isinstance(value, tuple) and value and all(_number(v) for v in value):
            out[name] = [float(v) for v in value]
    return out


def _modules(name: str):
    """``name`` and, for a package, every module under it."""
    module = importlib.import_module(name)
    yield module
    for info in pkgutil.walk_packages(getattr(module, "__path__", []), name + "."):
        yield importlib.import_module(info.name)


def thresholds() -> dict[str, dict[str, float | list[float]]]:
    """{module: {constant: value}} for every module of :data:`SOURCES` that holds any; a
    constant one module imports from another is recorded once, under its own module."""
    out: dict[str, dict] = {}
    for source in SOURCES:
        for module in _modules(source):
            own = {k: v for k, v in _constants(module).items()
                   if not _imported(module, k)}
            if own:
                out[module.__name__] = own
    return dict(sorted(out.items()))


def _imported(module, name: str) -> bool:
    """Whether ``name`` in ``module`` was imported from elsewhere (its source does not assign
    it at the top level)."""
    import inspect
    try:
        text = inspect.getsource(module)
    except (OSError, TypeError):
        return False
    return re.search(rf"^{name}\s*(:[^=\n]*)?=", text, re.M) is None
