r"""The sliding stage's QP, solved by hand: a projection in a definite metric onto a polytope.

.. math:: \min_{\dot q}\ (\dot q - w)^T M (\dot q - w) \quad \text{s.t.}\quad
   lb \le \dot q \le ub,\ G\dot q \le h

with M symmetric positive definite (n of a few tens at most, a few tens of rows). With
:math:`M = LL^T` and :math:`y = L^T(\dot q - w)` it is the least-distance problem
:math:`\min \|y\|` s.t. :math:`E^T y \ge f` (Lawson & Hanson 1974, chapter 23), whose answer
comes from the non-negative least squares :math:`\min_{u \ge 0} \|[E; f^T] u - e_{n+1}\|`
(their algorithm NNLS, chapter 23.3): with :math:`r` its residual,
:math:`y = -r_{1..n} / r_{n+1}`, and :math:`r = 0` where the constraints admit no point.

Each constraint's column is divided by the norm of its part in y (a constraint times a
positive number is the same constraint), so that NNLS's tolerances read alike for every row.
The caller checks the answer against the constraints (the kernel's only failure mode left is
rounding, which that check catches) and falls back to a QP backend where it is refused.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from solvers.kernels import kernel

Array = npt.NDArray[np.float64]

SOLVED, NOT_DEFINITE, INFEASIBLE, NOT_CONVERGED = 0, 1, 2, 3
"""What :func:`project` returns."""

CHECK = 1e-9
"""Relative violation of a constraint beyond which :func:`project`'s answer is refused
(INFEASIBLE: constraints that admit no point leave a residual of rounding in NNLS)."""


@kernel
def project(M: Array, w: Array, lb: Array, ub: Array, G: Array, h: Array, x: Array) -> int:
    """``x`` the point of the box and rows nearest to ``w`` in the metric M (module docstring).

    Args:
        M: Symmetric positive definite (n, n).
        w: The point projected (n,).
        lb: Lower bounds (n,), -inf allowed.
        ub: Upper bounds (n,), +inf allowed.
        G: Rows (p, n).
        h: Their bounds (p,).
        x: Out (n,), set when SOLVED.

    Returns:
        SOLVED, NOT_DEFINITE (M's Cholesky failed), INFEASIBLE (no point meets the
        constraints, or a row with no entries is broken at w) or NOT_CONVERGED (an iteration
        limit, or a degenerate passive set).
    """
    n = w.size
    p = h.size
    # M = L L^T
    L = np.zeros((n, n))
    largest = 0.0
    for i in range(n):
        largest = max(largest, M[i, i])
    if not largest > 0.0:
        return NOT_DEFINITE
    for j in range(n):
        s = M[j, j]
        for k in range(j):
            s -= L[j, k] * L[j, k]
        if not s > 1e-13 * largest:
            return NOT_DEFINITE
        L[j, j] = math.sqrt(s)
        for i in range(j + 1, n):
            s = M[i, j]
            for k in range(j):
                s -= L[i, k] * L[j, k]
            L[i, j] = s / L[j, j]
    # the constraints c^T qdot <= d as columns [-L^{-1} c; c^T w - d] / |L^{-1} c|
    m_max = 2 * n + p
    E = np.empty((n + 1, m_max))
    a = np.empty(n)
    c = np.empty(n)
    m = 0
    for r in range(m_max):
        if r < 2 * n:
            i = r % n
            sign = 1.0 if r < n else -1.0
            d = ub[i] if r < n else -lb[i]
            if not d < math.inf:
                continue
            for k in range(n):
                c[k] = 0.0
            c[i] = sign
        else:
            d = h[r - 2 * n]
            for k in range(n):
                c[k] = G[r - 2 * n, k]
        # a = L^{-1} c (forward substitution), value = c^T w - d
        norm = 0.0
        value = -d
        for i in range(n):
            s = c[i]
            for k in range(i):
                s -= L[i, k] * a[k]
            a[i] = s / L[i, i]
            norm += a[i] * a[i]
            value += c[i] * w[i]
        norm = math.sqrt(norm)
        if norm == 0.0:
            if value > 0.0:
                return INFEASIBLE
            continue
        for i in range(n):
            E[i, m] = -a[i] / norm
        E[n, m] = value / norm
        m += 1
    # NNLS: min |E u - e_n| over u >= 0 (Lawson & Hanson's algorithm)
    u = np.zeros(m)
    passive = np.zeros(m, dtype=np.bool_)
    resid = np.zeros(n + 1)  # e_n - E u
    resid[n] = 1.0
    gradient = np.empty(m)
    s = np.zeros(m)
    index = np.empty(n + 1, dtype=np.int64)
    H = np.empty((n + 1, n + 1))
    g = np.empty(n + 1)
    z = np.empty(n + 1)
    scale_f = 0.0
    for j in range(m):
        scale_f = max(scale_f, abs(E[n, j]))
    tol = 1e-12 * (1.0 + scale_f)
    for _ in range(3 * (m + n + 1)):
        # the most promising inactive column
        best, entering = tol, -1
        for j in range(m):
            if passive[j]:
                continue
            t = 0.0
            for i in range(n + 1):
                t += E[i, j] * resid[i]
            gradient[j] = t
            if t > best:
                best, entering = t, j
        if entering < 0:
            break
        passive[entering] = True
        converged = False
        for _inner in range(3 * (m + n + 1)):
            k = 0
            for j in range(m):
                if passive[j]:
                    if k == n + 1:
                        return NOT_CONVERGED
                    index[k] = j
                    k += 1
            # least squares on the passive columns: normal equations by Cholesky
            for i in range(k):
                ci = index[i]
                for j in range(i + 1):
                    cj = index[j]
                    t = 0.0
                    for r in range(n + 1):
                        t += E[r, ci] * E[r, cj]
                    H[i, j] = t
                g[i] = E[n, ci]
            ok = True
            for j in range(k):
                t = H[j, j]
                for q in range(j):
                    t -= H[j, q] * H[j, q]
                if not t > 1e-14:
                    ok = False
                    break
                H[j, j] = math.sqrt(t)
                for i in range(j + 1, k):
                    t = H[i, j]
                    for q in range(j):
                        t -= H[i, q] * H[j, q]
                    H[i, j] = t / H[j, j]
            if not ok:
                return NOT_CONVERGED
            for i in range(k):
                t = g[i]
                for q in range(i):
                    t -= H[i, q] * z[q]
                z[i] = t / H[i, i]
            for i in range(k - 1, -1, -1):
                t = z[i]
                for q in range(i + 1, k):
                    t -= H[q, i] * z[q]
                z[i] = t / H[i, i]
            for j in range(m):
                s[j] = 0.0
            positive = True
            for i in range(k):
                s[index[i]] = z[i]
                if not z[i] > 0.0:
                    positive = False
            if positive:
                for j in range(m):
                    u[j] = s[j]
                converged = True
                break
            # step toward s until a passive coefficient reaches zero, and drop it
            alpha = 1.0
            for i in range(k):
                j = index[i]
                if not s[j] > 0.0:
                    t = u[j] / (u[j] - s[j])
                    if t < alpha:
                        alpha = t
            for i in range(k):
                j = index[i]
                u[j] += alpha * (s[j] - u[j])
                if not u[j] > 1e-300 or (not s[j] > 0.0 and u[j] <= 1e-15 * (1.0 + abs(s[j]))):
                    u[j] = 0.0
                    passive[j] = False
        if not converged:
            return NOT_CONVERGED
        for i in range(n + 1):
            t = 1.0 if i == n else 0.0
            for j in range(m):
                t -= E[i, j] * u[j]
            resid[i] = t
    else:
        return NOT_CONVERGED
    # r = E u - e_n = -resid; y = -r[:n] / r[n] = -resid[:n] / resid[n]
    norm_sq = 0.0
    for i in range(n + 1):
        norm_sq += resid[i] * resid[i]
    if not resid[n] > 1e-14 or not norm_sq > 1e-28:
        return INFEASIBLE
    y = np.empty(n)
    for i in range(n):
        y[i] = -resid[i] / resid[n]
    # x = w + L^{-T} y (back substitution)
    for i in range(n - 1, -1, -1):
        t = y[i]
        for k in range(i + 1, n):
            t -= L[k, i] * z[k]
        z[i] = t / L[i, i]
    for i in range(n):
        x[i] = w[i] + z[i]
    # near-infeasible data leave a residual of rounding, not of a point: the answer is checked
    for i in range(n):
        if x[i] > ub[i] + CHECK * (1.0 + abs(ub[i])) or x[i] < lb[i] - CHECK * (1.0 + abs(lb[i])):
            return INFEASIBLE
    for r in range(p):
        t = 0.0
        for i in range(n):
            t += G[r, i] * x[i]
        if not t <= h[r] + CHECK * (1.0 + abs(h[r])):
            return INFEASIBLE
    return SOLVED
