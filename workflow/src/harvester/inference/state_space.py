"""Linear Gaussian state space: Matern processes as states, exact discretisation, and the
Kalman filter, Rauch-Tung-Striebel smoother and backward sampler over a record.

A Matern process of smoothness nu = p - 1/2 (p = 2: Matern-3/2, p = 3: Matern-5/2), length
scale l (s) and standard deviation s_f is the stationary output g of the SDE (Hartikainen and
Sarkka 2010)

    d/dt [g, g', ...] = F [g, g', ...] + e_p w(t),   lam = sqrt(2 nu) / l,
    F = companion matrix of (D + lam)^p,            E[w(t) w(t')] = q delta(t - t'),
    q = s_f^2 (2 lam)^(2p - 1) ((p - 1)!)^2 / (2p - 2)!.

A continuous system x' = A x + b d(t) + noise (spectral density W), with the input d linear
between samples (first-order hold), is exact at the samples as

    x_{k+1} = Phi x_k + G0 d_k + G1 d_{k+1} + w_k,     w_k ~ N(0, Q),

Phi, G0, G1 from one matrix exponential, Q by Van Loan's method. Measurements y_k = H x_k +
D d_k + N(0, R) where ``measured[k]``.

Noise through a zero-phase low-pass (``sosfiltfilt``: the filter forward, then backward) is a
stationary process whose spectrum is white x |H|^4; the same filter run twice forward gives
the same spectrum causally (the phase cancels in a spectrum), so the band-limited noise is a
state space of its own (:func:`filtered_noise`), measured at every sample without counting
correlated noise as independent. The marginal likelihood, evaluated a hundred times
per fit, is compiled (Numba, plain loops); the filter that stores the path, the smoother
(its gains solved for all samples at once) and the sampler run once per fit in numpy:
compiling them cost more than running them.
"""

from __future__ import annotations

from dataclasses import dataclass
from math import comb, factorial

import numba as nb
import numpy as np
from scipy import linalg, signal

#: Matern smoothness by name: the number of states p of the process.
MATERN_STATES = {"matern32": 2, "matern52": 3}


def matern(kind: str, length_s: float, sd: float) -> tuple[np.ndarray, float, np.ndarray]:
    """(F, q, P_inf) of a Matern process (module docstring): its drift matrix (p, p), the
    spectral density of its white noise and its stationary covariance."""
    p = MATERN_STATES[kind]
    lam = np.sqrt(2.0 * (p - 0.5)) / length_s
    F = np.diag(np.ones(p - 1), 1)
    F[-1] = [-float(comb(p, j)) * lam ** (p - j) for j in range(p)]
    q = sd**2 * (2.0 * lam) ** (2 * p - 1) * factorial(p - 1) ** 2 / factorial(2 * p - 2)
    W = np.zeros((p, p))
    W[-1, -1] = q
    P_inf = linalg.solve_continuous_lyapunov(F, -W)
    return F, q, 0.5 * (P_inf + P_inf.T)


def filtered_noise(sos: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unit-variance white noise through the digital filter ``sos`` applied forward and
    backward, as a causal state space with the same spectrum (module docstring):
    (A, c, P) with e_k = c x_k, x_{k+1} = A x_k + e_n w_{k+1}, w unit white, the last state
    the current white sample (so that e has no feedthrough); c scaled so that e has unit
    variance; P the stationary covariance of x."""
    A, B = np.zeros((0, 0)), np.zeros((0, 1))
    C, D = np.zeros((1, 0)), np.ones((1, 1))
    for section in np.concatenate([sos, sos]):
        a, b, c, d = signal.tf2ss(section[:3], section[3:])
        n0, n1 = len(A), len(a)
        A = np.block([[A, np.zeros((n0, n1))], [b @ C, a]])
        B = np.vstack([B, b @ D])
        C, D = np.hstack([d @ C, c]), d @ D
    n = len(A)
    Aw = np.zeros((n + 1, n + 1))
    Aw[:n, :n], Aw[:n, n] = A, B[:, 0]
    cw = np.concatenate([C[0], D[0]])
    W = np.zeros((n + 1, n + 1))
    W[n, n] = 1.0
    P = linalg.solve_discrete_lyapunov(Aw, W)
    return Aw, cw / np.sqrt(float(cw @ P @ cw)), 0.5 * (P + P.T)


@dataclass(frozen=True)
class Discrete:
    """x_{k+1} = Phi x_k + G0 d_k + G1 d_{k+1} + N(0, Q) (module docstring)."""

    Phi: np.ndarray
    G0: np.ndarray
    G1: np.ndarray
    Q: np.ndarray


def discretise(A: np.ndarray, b: np.ndarray, W: np.ndarray, h: float) -> Discrete:
    """Exact discretisation over a step h (s) of x' = A x + b d(t) + w, d linear in the step,
    w white with spectral density W."""
    n = len(A)
    big = np.zeros((n + 2, n + 2))
    big[:n, :n], big[:n, n], big[n, n + 1] = A, b, 1.0
    E = linalg.expm(big * h)
    Phi, g_level, g_slope = E[:n, :n], E[:n, n], E[:n, n + 1] / h
    vl = np.zeros((2 * n, 2 * n))
    vl[:n, :n], vl[:n, n:], vl[n:, n:] = -A, W, A.T
    V = linalg.expm(vl * h)
    Q = V[n:, n:].T @ V[:n, n:]
    return Discrete(Phi, g_level - g_slope, g_slope, 0.5 * (Q + Q.T))


def kalman_filter(Phi, G0, G1, Q, H, D, R, d, y, measured, m0, P0):
    """Filtered and predicted means (N, n) and covariances (N, n, n) and the log marginal
    likelihood of the measurements (nats). Joseph-form updates keep P symmetric and
    positive. The covariances do not depend on the data: once the gain repeats from one
    measurement to the next they repeat with it and are copied, not recomputed."""
    N, n = d.size, m0.size
    mf, mp = np.empty((N, n)), np.empty((N, n))
    Pf, Pp = np.empty((N, n, n)), np.empty((N, n, n))
    m, P = m0.copy(), P0.copy()
    K, loglik, eye = np.zeros(n), 0.0, np.eye(n)
    drive = np.outer(d[:-1], G0) + np.outer(d[1:], G1)
    period = None  # (first sample of a repeating measurement cycle, its length)
    last, S_steady, K_steady = None, 1.0, K
    for k in range(N):
        if k > 0:
            m = Phi @ m + drive[k - 1]
            P = Pp[k - period[1]] if period else Phi @ P @ Phi.T + Q
        mp[k], Pp[k] = m, P
        if measured[k]:
            if period:
                P_up, S, K = Pf[k - period[1]], S_steady, K_steady
            else:
                S = H @ P @ H + R
                K_new = P @ H / S
                IKH = eye - np.outer(K_new, H)
                P_up = IKH @ P @ IKH.T + R * np.outer(K_new, K_new)
                if last is not None and np.max(np.abs(K_new - K)) < 1e-12 * np.max(np.abs(K_new)):
                    period, S_steady, K_steady = (last, k - last), S, K_new
                K, last = K_new, k
            v = y[k] - H @ m - D * d[k]
            m = m + K * v
            P = P_up
            loglik += -0.5 * (np.log(2.0 * np.pi * S) + v * v / S)
        mf[k], Pf[k] = m, P
    return mf, Pf, mp, Pp, loglik


def rts_smoother(Phi, mf, Pf, mp, Pp):
    """Smoothed means (N, n), the backward gains J_k = P_k Phi^T P_{k+1|k}^-1 and the
    covariance of x_k given x_{k+1} and the data, C_k = P_k - J_k Phi P_k (for
    :func:`backward_sample`). The gains do not depend on the recursion and are solved for all
    samples at once; only the means run backwards (the smoothed covariances are not formed:
    the draws give the spread)."""
    N, n = mf.shape
    A = Pp[1:] + 1e-12 * np.trace(Pp[1:], axis1=1, axis2=2)[:, None, None] / n * np.eye(n)
    PhiPf = Phi[None, :, :] @ Pf[:-1]
    J = np.zeros((N, n, n))
    J[:-1] = np.swapaxes(np.linalg.solve(A, PhiPf), 1, 2)
    C = Pf.copy()
    C[:-1] = Pf[:-1] - J[:-1] @ PhiPf
    ms = mf.copy()
    for k in range(N - 2, -1, -1):
        ms[k] = mf[k] + J[k] @ (ms[k + 1] - mp[k + 1])
    return ms, J, C


def _roots(C):
    """Square roots S_k of symmetric positive semi-definite C_k (S S^T = C), negative
    eigenvalues from round-off set to 0; all samples at once."""
    w, V = np.linalg.eigh(0.5 * (C + np.swapaxes(C, 1, 2)))
    return V * np.sqrt(np.maximum(w, 0.0))[:, None, :]


def backward_sample(mf, mp, J, C, noise):
    """Joint draws of the state path given the data (forward filtering, backward sampling):
    ``noise`` (draws, N, n) standard normal; returns (draws, N, n)."""
    S = _roots(C)
    N = mf.shape[0]
    out = np.empty_like(noise)
    out[:, N - 1] = mf[N - 1] + noise[:, N - 1] @ S[N - 1].T
    for k in range(N - 2, -1, -1):
        out[:, k] = mf[k] + (out[:, k + 1] - mp[k + 1]) @ J[k].T + noise[:, k] @ S[k].T
    return out


@nb.njit(cache=True)
def _predict_cov(Phi, P, Q, tmp):
    """P <- Phi P Phi^T + Q in place (``tmp`` scratch, n x n)."""
    n = P.shape[0]
    for i in range(n):
        for j in range(n):
            acc = 0.0
            for a in range(n):
                acc += Phi[i, a] * P[a, j]
            tmp[i, j] = acc
    for i in range(n):
        for j in range(n):
            acc = Q[i, j]
            for a in range(n):
                acc += tmp[i, a] * Phi[j, a]
            P[i, j] = acc


@nb.njit(cache=True)
def _update_cov(P, H, R, K):
    """The gain K (in place) and S = H P H^T + R; P <- P - K S K^T (in place)."""
    n = P.shape[0]
    S = R
    for i in range(n):
        acc = 0.0
        for j in range(n):
            acc += P[i, j] * H[j]
        K[i] = acc
        S += H[i] * acc
    for i in range(n):
        K[i] /= S
    for i in range(n):
        for j in range(n):
            P[i, j] -= K[i] * K[j] * S
    for i in range(n):  # keep P symmetric against round-off
        for j in range(i + 1, n):
            avg = 0.5 * (P[i, j] + P[j, i])
            P[i, j] = avg
            P[j, i] = avg
    return S


@nb.njit(cache=True)
def kalman_loglik(Phi, G0, G1, Q, H, D, R, d, y, stride, m0, P0):
    """The log marginal likelihood (nats) of measurements at every ``stride``-th sample (from
    the first), as :func:`kalman_filter`'s but without storing the path: the covariances do
    not depend on the data, so once the gain repeats from one measurement to the next
    (relative change < 1e-10) it is frozen and only the means are propagated. Plain loops:
    2-10 ms for 10^4 samples and five states, and a short compilation."""
    N, n = d.size, m0.size
    m, P = m0.copy(), P0.copy()
    tmp, scratch = np.empty(n), np.empty((n, n))
    K, K_old = np.zeros(n), np.zeros(n)
    S = 1.0
    frozen = False
    loglik = 0.0
    for k in range(N):
        if k > 0:
            for i in range(n):
                acc = G0[i] * d[k - 1] + G1[i] * d[k]
                for j in range(n):
                    acc += Phi[i, j] * m[j]
                tmp[i] = acc
            m[:] = tmp
            if not frozen:
                _predict_cov(Phi, P, Q, scratch)
        if k % stride == 0:
            if not frozen:
                K_old[:] = K
                S = _update_cov(P, H, R, K)
                change, size = 0.0, 0.0
                for i in range(n):
                    change = max(change, abs(K[i] - K_old[i]))
                    size = max(size, abs(K[i]))
                frozen = k > 0 and change < 1e-10 * size
            v = y[k] - D * d[k]
            for j in range(n):
                v -= H[j] * m[j]
            for j in range(n):
                m[j] += K[j] * v
            loglik += -0.5 * (np.log(2.0 * np.pi * S) + v * v / S)
    return loglik
