"""The house's layers, counted from the imports (every ``import`` and ``from ... import`` of
the package, inside functions too): no circle between modules, nothing from the data, model
or inference layers importing a higher one, and the diagnosis by stage (subpackages, no flat
module but ``run.py`` and ``__init__.py``)."""

from __future__ import annotations

import ast
from pathlib import Path

from conftest import ROOT

SRC = ROOT / "workflow" / "src"
PACKAGE = SRC / "harvester"
#: What each low layer may import of the package (besides itself).
LOWER = {"data": set(), "model": {"data"}, "inference": {"data", "model"}}
#: The diagnosis's stages.
MAX_STAGES = 6


def _module(path: Path) -> str:
    parts = path.relative_to(SRC).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(path: Path, name: str) -> set[str]:
    """The package's modules ``path`` imports (a ``from X import y`` of a submodule y counts
    as X.y; ``from . import`` is resolved)."""
    out: set[str] = set()
    package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            out |= {a.name for a in node.names if a.name.startswith("harvester")}
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                base = ".".join(package.split(".")[:len(package.split(".")) - node.level + 1]
                                + ([base] if base else []))
            if base.startswith("harvester"):
                out.add(base)
                out |= {f"{base}.{a.name}" for a in node.names}
    return out


def _graph() -> dict[str, set[str]]:
    files = {_module(p): p for p in PACKAGE.rglob("*.py")}
    return {m: {i for i in _imports(p, m) if i in files and i != m} for m, p in files.items()}


def _circles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components of more than one module (Tarjan)."""
    index, low, stack, on, out = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))
    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def _layer(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else ""


def test_no_circle_between_modules():
    assert _circles(_graph()) == []


def test_the_low_layers_import_nothing_above_them():
    wrong = [(m, i) for m, deps in _graph().items() if _layer(m) in LOWER
             for i in deps if _layer(i) not in LOWER[_layer(m)] | {_layer(m)}]
    assert wrong == []


def test_the_diagnosis_is_laid_out_by_stage():
    root = PACKAGE / "diagnosis"
    flat = sorted(p.name for p in root.glob("*.py"))
    stages = sorted(p.name for p in root.iterdir() if (p / "__init__.py").is_file())
    assert flat == ["__init__.py", "run.py"]
    assert 1 < len(stages) <= MAX_STAGES
    for stage in stages:  # each stage's docstring is its map: it names every module
        doc = ast.get_docstring(ast.parse((root / stage / "__init__.py").read_text())) or ""
        modules = [p.stem for p in (root / stage).glob("*.py") if p.stem != "__init__"]
        assert all(f"``{m}``" in doc for m in modules), (stage, modules)


def test_the_checks_see_a_circle_and_a_layer_broken():
    """The checks themselves: a circle and an upward import written here are found."""
    assert _circles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": set()}) == [["a", "b", "c"]]
    assert _layer("harvester.inference.identify") == "inference"
