"""Errors raised on bad input: each names the file, the line or column, and what was expected."""

from __future__ import annotations

from pathlib import Path


class DataError(ValueError):
    """A recording or metadata file does not hold what the study expects."""

    def __init__(self, path: str | Path, what: str, *, line: int | None = None,
                 column: str | None = None) -> None:
        where = str(path)
        if line is not None:
            where += f", line {line}"
        if column is not None:
            where += f", column '{column}'"
        super().__init__(f"{where}: {what}")
        self.path = str(path)
        self.line = line
        self.column = column
