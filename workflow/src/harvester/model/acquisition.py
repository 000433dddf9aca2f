"""The acquisition of a simulated population, compiled: what a data acquisition and the
preprocessing do to the model's output, for many particles at once.

Each block of particles that the structure's kernel integrates (``harvester.model.codegen``)
is passed, while its samples are still in cache, through

1. the anti-alias decimation of an oversampled simulation (``decimate``): the zero-phase
   Butterworth low-pass of ``harvester.data.signals.antialias_decimate`` and every q-th sample;
2. the output's own zero-phase low-pass (``zero_phase_inplace``), the filter the recording went
   through (``Problem.output_filter``) or the diagnosis's measurement chain;
3. the sum of squared residuals against the observed samples of the likelihood's window
   (``finish_block``), which is all eq. (10) needs, so a likelihood evaluation never builds
   the (particles x samples) arrays.

The zero-phase filter is scipy's ``sosfiltfilt`` (odd extension of ``pad`` samples, the
steady-state initial conditions of ``sosfilt_zi`` scaled by the first sample, a forward and a
backward pass of the transposed direct form II sections), with the particles innermost;
``tests/test_acquisition.py`` checks it against scipy's to 1e-13.

A filter is passed as an array of its sections, each row (b0, b1, b2, a0, a1, a2, zi0, zi1)
with zi from ``scipy.signal.sosfilt_zi`` (:func:`filter_rows`); zero rows mean no filter.
"""

from __future__ import annotations

import numba as nb
import numpy as np
from scipy import signal

__all__ = ["NO_FILTER", "decimate", "filter_rows", "finish_block", "zero_phase_inplace"]

#: No filter (zero sections).
NO_FILTER = np.zeros((0, 8))


def filter_rows(sos: np.ndarray) -> tuple[np.ndarray, int]:
    """(rows, pad) of a filter in second-order sections for :func:`zero_phase_inplace`: the
    sections with their ``sosfilt_zi`` and scipy's default pad length for ``sosfiltfilt``."""
    sos = np.atleast_2d(np.asarray(sos, dtype=np.float64))
    ntaps = 2 * sos.shape[0] + 1 - min(int((sos[:, 2] == 0).sum()), int((sos[:, 5] == 0).sum()))
    return np.ascontiguousarray(np.hstack([sos, signal.sosfilt_zi(sos)])), 3 * ntaps


@nb.njit(error_model="numpy", cache=True, nogil=True)
def _odd_extension(y, pad):
    """[2 y_0 - y_pad..1, y, 2 y_-1 - y_-2..-pad-1] along axis 0 (scipy's odd_ext)."""
    n, C = y.shape
    ext = np.empty((n + 2 * pad, C))
    for t in range(pad):
        for c in range(C):
            ext[t, c] = 2.0 * y[0, c] - y[pad - t, c]
            ext[pad + n + t, c] = 2.0 * y[n - 1, c] - y[n - 2 - t, c]
    for t in range(n):
        for c in range(C):
            ext[pad + t, c] = y[t, c]
    return ext


@nb.njit(error_model="numpy", cache=True, nogil=True)
def _sosfilt_pass(filt, x, forward):
    """One pass of the sections over x (m, C) in place, forward or backward in time, from the
    steady state of the first sample it meets (scipy's ``sosfilt`` with ``zi * x_0``)."""
    ns = filt.shape[0]
    m, C = x.shape
    z0 = np.empty((ns, C))
    z1 = np.empty((ns, C))
    cur = np.empty(C)
    first = 0 if forward else m - 1
    for s in range(ns):
        for c in range(C):
            z0[s, c] = filt[s, 6] * x[first, c]
            z1[s, c] = filt[s, 7] * x[first, c]
    for step in range(m):
        t = step if forward else m - 1 - step
        for c in range(C):
            cur[c] = x[t, c]
        for s in range(ns):
            b0, b1, b2 = filt[s, 0], filt[s, 1], filt[s, 2]
            a1, a2 = filt[s, 4], filt[s, 5]
            for c in range(C):
                xc = cur[c]
                xn = b0 * xc + z0[s, c]
                z0[s, c] = b1 * xc - a1 * xn + z1[s, c]
                z1[s, c] = b2 * xc - a2 * xn
                cur[c] = xn
        for c in range(C):
            x[t, c] = cur[c]


@nb.njit(error_model="numpy", cache=True, nogil=True)
def zero_phase_inplace(y, filt, pad):
    """scipy's ``sosfiltfilt(sos, y, axis=0)`` on a block y (samples, particles), in place.

    ``filt``/``pad`` from :func:`filter_rows`; no sections: y is left as it is.
    """
    n = y.shape[0]
    if filt.shape[0] == 0 or y.shape[1] == 0 or n == 0:
        return
    if n <= pad:
        raise ValueError("the record is too short for the zero-phase filter's padding")
    ext = _odd_extension(y, pad)
    _sosfilt_pass(filt, ext, True)
    _sosfilt_pass(filt, ext, False)
    for t in range(n):
        for c in range(y.shape[1]):
            y[t, c] = ext[pad + t, c]


@nb.njit(error_model="numpy", cache=True, nogil=True)
def decimate(y, q, filt, pad):
    """Every q-th sample of y (samples, particles) after the anti-alias low-pass (in place on
    y); q = 1: y itself."""
    if q == 1:
        return y
    zero_phase_inplace(y, filt, pad)
    return y[::q]


@nb.njit(error_model="numpy", cache=True, nogil=True)
def write_rows(out, block, rows):
    """out[rows[c], t] = block[t, c] (out is particles x samples; nothing if out is empty)."""
    if out.shape[0] == 0:
        return
    for c in range(block.shape[1]):
        r = rows[c]
        for t in range(block.shape[0]):
            out[r, t] = block[t, c]


@nb.njit(error_model="numpy", cache=True, nogil=True)
def finish_block(y, rows, window, stride, observed, sse, ok, ok_block, out_z, zq, out_v, vq,
                 out_acc, acc):
    """Per particle of a block: the ok flag (integration ok and output finite), the sum of
    squared residuals of y against ``observed`` at samples window[0]:window[1]:stride (if
    observed is not empty), and the requested outputs written as rows."""
    C = y.shape[1]
    n_obs = observed.shape[0]
    total = np.zeros(C)
    finite = np.ones(C, dtype=np.bool_)
    if n_obs > 0:
        for k in range(n_obs):
            t = window[0] + k * stride
            for c in range(C):
                r = observed[k] - y[t, c]
                total[c] += r * r
        for c in range(C):
            finite[c] = np.isfinite(total[c])
    else:
        for t in range(y.shape[0]):
            for c in range(C):
                if not np.isfinite(y[t, c]):
                    finite[c] = False
    for c in range(C):
        r = rows[c]
        ok[r] = ok_block[c] and finite[c]
        sse[r] = total[c] if ok[r] else np.inf
    write_rows(out_z, zq, rows)
    write_rows(out_v, vq, rows)
    write_rows(out_acc, acc, rows)


@nb.njit(error_model="numpy", cache=True, nogil=True)
def columns(P, a, b):
    """A contiguous copy of the columns [a, b) of P (parameters x particles)."""
    out = np.empty((P.shape[0], b - a))
    for j in range(P.shape[0]):
        for c in range(b - a):
            out[j, c] = P[j, a + c]
    return out


@nb.njit(error_model="numpy", cache=True, nogil=True)
def acquire(acc_fine, z_fine, v_fine, rows, q, aa_filt, aa_pad, out_filt, out_pad, output_kind,
            stride, window, observed, out_z, out_v, out_acc, sse, ok, ok_block):
    """A block integrated at q x the record's rate, as it is recorded: z'' anti-aliased and
    decimated, z and z' taken at every q-th sample; the output of ``output_kind`` (0: z'',
    1: z) through the output filter; ``finish_block``."""
    acc = decimate(acc_fine, q, aa_filt, aa_pad)
    zq = z_fine[::q]
    vq = v_fine[::q]
    y = np.empty((acc.shape[0] if output_kind == 0 else zq.shape[0], acc_fine.shape[1]))
    src = acc if output_kind == 0 else zq
    for t in range(y.shape[0]):
        for c in range(y.shape[1]):
            y[t, c] = src[t, c]
    zero_phase_inplace(y, out_filt, out_pad)
    finish_block(y, rows, window, stride, observed, sse, ok, ok_block, out_z, zq, out_v, vq,
                 out_acc, acc)
