"""Logging for Snakemake scripts and the CLI: progress to the rule's log file, errors recorded."""

from __future__ import annotations

import contextlib
import logging
import sys
import time
from collections.abc import Iterator
from pathlib import Path

LOGGER_NAME = "harvester"


def setup(log_file: str | Path | None = None, level: int = logging.INFO) -> logging.Logger:
    """Send the ``harvester`` loggers to ``log_file`` (and stderr when it is None)."""
    root = logging.getLogger(LOGGER_NAME)
    root.setLevel(level)
    for h in list(root.handlers):
        root.removeHandler(h)
    if log_file is None:
        handler: logging.Handler = logging.StreamHandler(sys.stderr)
    else:
        Path(log_file).parent.mkdir(parents=True, exist_ok=True)
        handler = logging.FileHandler(log_file, mode="w")
    handler.setFormatter(logging.Formatter("%(asctime)s %(name)s %(levelname)s %(message)s",
                                           "%H:%M:%S"))
    root.addHandler(handler)
    root.propagate = False
    return root


@contextlib.contextmanager
def rule_log(snakemake) -> Iterator[logging.Logger]:  # noqa: ANN001 - the Snakemake object
    """Log a Snakemake script's run (start, wall time, any error with traceback) to its log."""
    log_file = snakemake.log[0] if len(snakemake.log) else None
    logger = setup(log_file)
    start = time.perf_counter()
    logger.info("rule %s started", snakemake.rule)
    try:
        yield logger
    except Exception:
        logger.exception("rule %s failed", snakemake.rule)
        raise
    logger.info("rule %s done in %.1f s", snakemake.rule, time.perf_counter() - start)
