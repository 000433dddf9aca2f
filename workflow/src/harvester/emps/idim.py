"""Inverse-dynamics least squares on an EMPS record: the benchmark authors' own method.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import signal

from harvester.emps.data import EmpsRecord


@dataclass(frozen=True)
class IdimFit:
    """Inverse-dynamics least squares (the benchmark's method): values, standard errors."""

    values: dict[str, float]
    se: dict[str, float]
    rel_error: float  # ||F - X beta|| / ||F|| (%)


def idim_ls(record: EmpsRecord, cutoff_hz: float = 100.0, order: int = 4,
            decimate_to_hz: float = 40.0, border: int = 50) -> IdimFit:
    """M, Fv, Fc, offset by least squares on F = M q'' + Fv q' + Fc sgn(q') + OF.

    As the benchmark authors' script: qm low-passed (Butterworth, zero phase, ``cutoff_hz``),
    differentiated twice by central differences, ``border`` samples dropped at each end,
    columns and force decimated (``scipy.signal.decimate``, factor round(0.8 fs/2 /
    decimate_to_hz)).
    """
    fs = 1.0 / record.dt
    b, a = signal.butter(order, cutoff_hz / (fs / 2.0))
    q = signal.filtfilt(b, a, record.qm)
    dq = np.gradient(q, record.dt)
    ddq = np.gradient(dq, record.dt)
    s = slice(border, len(q) - border)
    x = np.column_stack([ddq, dq, np.sign(dq), np.ones_like(dq)])[s]
    y = record.force[s]
    factor = int(round(0.8 * fs / 2.0 / decimate_to_hz))
    xd = np.column_stack([signal.decimate(x[:, j], factor) for j in range(4)])
    yd = signal.decimate(y, factor)
    beta, *_ = np.linalg.lstsq(xd, yd, rcond=None)
    err = yd - xd @ beta
    se = np.std(err) * np.sqrt(np.diag(np.linalg.inv(xd.T @ xd)))
    names = ("M", "Fv", "Fc", "offset")
    return IdimFit(dict(zip(names, map(float, beta))), dict(zip(names, map(float, se))),
                   float(100 * np.linalg.norm(err) / np.linalg.norm(yd)))


