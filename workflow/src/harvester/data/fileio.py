"""Atomic file and directory writing (no half-written outputs) and small JSON helpers."""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import shutil
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np


@contextlib.contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; move it into place only if the block succeeds."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=path.suffix, dir=path.parent)
    os.close(fd)
    umask = os.umask(0)
    os.umask(umask)
    try:
        yield Path(tmp)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp makes 0600; give the usual permissions
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)


#: Files that mark a directory as an earlier result of a command (which a rerun replaces).
RESULT_MARKERS: tuple[str, ...] = ("run.json", "diagnosis.json")


def check_output_dir(path: str | Path, option: str = "--out",
                     inputs: tuple[str | Path, ...] = ()) -> Path:
    """Check, before any work, that ``path`` can become an output directory; nothing is made.

    A run's results replace the directory as a whole (:func:`atomic_directory`), so it must be
    new, empty, or an earlier result (holding one of RESULT_MARKERS), and must not hold any of
    the ``inputs``. DataError (``harvester.data.errors``) when it is an existing file, another
    directory, holds an input, or when the nearest existing ancestor is a file or not writable.
    """
    from harvester.data.errors import DataError
    path = Path(path).resolve()
    if path.exists() and not path.is_dir():
        raise DataError(path, f"{option} names an existing file; expected a directory (new or "
                        "an earlier result) for the results")
    for f in inputs:
        if path in Path(f).resolve().parents:
            raise DataError(path, f"{option} holds the input {f}; the results replace the "
                            "directory as a whole: give another directory")
    if path.is_dir():
        entries = sorted(p.name for p in path.iterdir())
        if entries and not any(m in entries for m in RESULT_MARKERS):
            raise DataError(path, f"{option} is a directory holding other files ({len(entries)}"
                            f", e.g. {entries[0]!r}) and no earlier result "
                            f"({' or '.join(RESULT_MARKERS)}); the results replace the directory "
                            "as a whole: give a new or empty directory")
    ancestor = path
    while not ancestor.exists():
        ancestor = ancestor.parent
    if not ancestor.is_dir():
        raise DataError(ancestor, f"{option} {path}: {ancestor} is a file, not a directory")
    if not os.access(ancestor, os.W_OK | os.X_OK):
        raise DataError(ancestor, f"{option} {path}: {ancestor} is not writable")
    return path


def _staging_dir(path: Path) -> Path:
    return path.parent / f".{path.name}.partial"


@contextlib.contextmanager
def atomic_directory(path: str | Path, key: str) -> Iterator[Path]:
    """Yield a staging directory that replaces ``path`` only if the block succeeds.

    The staging directory ``.<name>.partial`` beside ``path`` survives a failed or killed
    run, so that a rerun with the same ``key`` (what the run depends on: inputs and settings)
    resumes from what it holds; a different key starts it afresh. On success the previous
    ``path`` (if any) is replaced as a whole: a reader sees the old results or the new, never
    a mixture.
    """
    path = Path(path).resolve()
    staging = _staging_dir(path)
    stamp = staging / ".run-key"
    if staging.exists() and (not stamp.exists() or stamp.read_text() != key):
        shutil.rmtree(staging)
    staging.mkdir(parents=True, exist_ok=True)
    stamp.write_text(key)
    yield staging
    stamp.unlink()
    old = path.parent / f".{path.name}.old"
    if old.exists():
        shutil.rmtree(old)
    if path.exists():
        os.replace(path, old)
    os.replace(staging, path)
    if old.exists():
        shutil.rmtree(old)


def run_key(*parts: Any) -> str:
    """A short digest of what a run depends on (file contents by path, settings as JSON)."""
    digest = hashlib.sha256()
    for part in parts:
        if isinstance(part, Path) and part.is_file():
            digest.update(part.read_bytes())
        else:
            digest.update(json.dumps(part, sort_keys=True, default=str).encode())
    return digest.hexdigest()[:16]


def _default(obj: Any) -> Any:
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, np.generic):
        return obj.item()
    if hasattr(obj, "__dataclass_fields__"):
        return {k: getattr(obj, k) for k in obj.__dataclass_fields__}
    raise TypeError(f"cannot write {type(obj).__name__} to JSON")


def write_json(obj: Any, path: str | Path) -> None:
    """Write ``obj`` as indented JSON, atomically (numpy values and dataclasses allowed)."""
    with atomic_path(path) as tmp:
        tmp.write_text(json.dumps(obj, indent=2, default=_default) + "\n")


def read_json(path: str | Path) -> Any:
    return json.loads(Path(path).read_text())
