"""Logging for Snakemake scripts and the CLI: progress to the rule's log file, errors recorded."""

from __future__ import annotations

import contextlib
import logging
import math
import os
import re
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
    handler.addFilter(TimeLeft())
    root.addHandler(handler)
    root.propagate = False
    return root


class TimeLeft(logging.Filter):
    """Adds an estimate of the time left to the TMCMC progress lines.

    Reads the lines ``inference.identify`` and the TMCMC kernel log (a run's chain count, each
    chain's start, each stage's tempering exponent beta) and appends to each stage's line the
    time left of the run: a chain's progress is taken as log(beta / beta_1) / log(1 / beta_1),
    beta_1 its first stage's exponent (stages step about evenly in log beta), and the chains
    still to come as long as this one. Other lines pass unchanged.
    """

    RUN = re.compile(r"TMCMC for (\S+): .* x (\d+) chains")
    CHAIN = re.compile(r"TMCMC chain \d+: \d+ particles")
    STAGE = re.compile(r"TMCMC chain \d+ stage (\d+): beta=([0-9.eE+-]+)")

    def __init__(self) -> None:
        super().__init__()
        self.chains, self.chain, self.started, self.beta_1 = 1, -1, None, None

    def filter(self, record: logging.LogRecord) -> bool:
        message = record.getMessage()
        if (run := self.RUN.search(message)) is not None:
            self.chains, self.chain = int(run[2]), -1
        elif self.CHAIN.match(message):
            self.chain, self.started, self.beta_1 = self.chain + 1, record.created, None
        elif (stage := self.STAGE.match(message)) is not None and self.started is not None:
            left = self._left(float(stage[2]), record.created - self.started)
            if left is not None:
                record.msg, record.args = f"{message}; {left}", ()
        return True

    def _left(self, beta: float, elapsed: float) -> str | None:
        if self.beta_1 is None:
            self.beta_1 = beta
            return None
        if not 0.0 < self.beta_1 < 1.0:
            return None
        done = min(1.0, math.log(beta / self.beta_1) / math.log(1.0 / self.beta_1))
        if done <= 0.0:
            return None
        chain_total = elapsed / done
        later = max(self.chains - self.chain - 1, 0)
        left = chain_total - elapsed + later * chain_total
        where = f"chain {self.chain + 1} of {self.chains}"
        return f"{where}, about {left:.0f} s left" if done < 1.0 or later else \
            f"{where} done"


def use_threads(n: int) -> int:
    """Integrate on at most ``n`` threads (a rule's ``threads``, which Snakemake scales to its
    cores): Numba's thread count when Numba is loaded, else ``NUMBA_NUM_THREADS`` for when it
    is. The number set."""
    n = max(1, int(n))
    if "numba" in sys.modules:
        numba = sys.modules["numba"]
        n = min(n, numba.config.NUMBA_NUM_THREADS)
        numba.set_num_threads(n)
    else:
        os.environ["NUMBA_NUM_THREADS"] = str(n)
    return n


@contextlib.contextmanager
def rule_log(snakemake) -> Iterator[logging.Logger]:  # noqa: ANN001 - the Snakemake object
    """Log a Snakemake script's run (start, wall time, any error with traceback) to its log;
    the integrators run on the rule's threads (:func:`use_threads`)."""
    log_file = snakemake.log[0] if len(snakemake.log) else None
    logger = setup(log_file)
    start = time.perf_counter()
    logger.info("rule %s started on %d thread(s)", snakemake.rule, use_threads(snakemake.threads))
    try:
        yield logger
    except Exception:
        logger.exception("rule %s failed", snakemake.rule)
        raise
    logger.info("rule %s done in %.1f s", snakemake.rule, time.perf_counter() - start)
