r"""Dense linear algebra of small matrices, compiled: QR, SVD, Cholesky.

Shared by the resolver's tick (:mod:`rrc_pin.solvers.tick`), the closed forms, the active-set
QP and the cells' closure.

The Householder QR of a level's transposed rows and its least-norm rates, the one-sided Jacobi
SVD (of the QR's triangle, or of any small matrix: the closed forms'), the damped
least-squares rates of an SVD, the normal equations of weighted rows and their Cholesky
solve. Each kernel is compiled by numba (``@njit(cache=True)``, through
:func:`~rrc_pin.solvers.compiled.kernel`), written as the textbook writes the math, and runs
as plain Python under ``NUMBA_DISABLE_JIT=1``; tests/test_linalg.py compares each with a plain
numpy reference.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.compiled import inlined, kernel

Array = npt.NDArray[np.float64]

Index = Any
"""An unsigned index (``np.uint64``): numba leaves out the wrap of a negative index where it
indexes an array (its sums with Python ints are not typed as integers by numpy's stubs)."""

SWEEPS = 60
"""Most sweeps of the one-sided Jacobi SVD (:func:`jacobi_svd`); it converges quadratically and
takes five to eight on a 6 x 6 factor, so this cap is only a guard."""


# -- products and norms -----------------------------------------------------------------------


@kernel
def row_values(A: Array, x: Array) -> Array:
    """``A x`` (m,) for rows A (m, n)."""
    m, n = A.shape
    y = np.empty(m)
    for i in range(m):
        s = 0.0
        for j in range(n):
            s += A[i, j] * x[j]
        y[i] = s
    return y


@kernel
def max_abs(x: Array) -> float:
    """The largest ``|x_i|`` (0 for none)."""
    top = 0.0
    for i in range(x.size):
        top = max(top, abs(x[i]))
    return top


# -- QR and least-norm rates ------------------------------------------------------------------


@kernel
def householder_vectors(At: Array, R: Array, V: Array, beta: Array) -> None:
    r"""Householder QR of ``At`` (n, m) in factored form (Golub & Van Loan, Algorithm 5.2.1).

    :math:`At = H_0 H_1 \cdots H_{k-1} R` with :math:`H_j = I - \beta_j v_j v_j^T`,
    k = min(n - 1, m).

    Args:
        At: The transposed task rows (n, m).
        R: Out: upper triangular (n, m).
        V: Out: (k, n) the Householder vectors :math:`v_j` (rows: zero before j, one at j).
        beta: Out: (k,) their factors (0 where the column is zero below j already:
            :math:`H_j = I`, its row of V not set).
    """
    n, m = At.shape
    for i in range(n):  # element by element: an array copy compiles numba's shape error too
        for j in range(m):
            R[i, j] = At[i, j]
    s = np.empty(m)
    for j in range(min(n - 1, m)):
        sigma = 0.0  # the Householder vector of R[j:, j] (Golub & Van Loan, Algorithm 5.1.1)
        for i in range(j + 1, n):
            sigma += R[i, j] * R[i, j]
        beta[j] = 0.0
        if sigma == 0.0:
            continue
        x0 = R[j, j]
        mu = math.sqrt(x0 * x0 + sigma)
        v0 = x0 - mu if x0 <= 0.0 else -sigma / (x0 + mu)
        beta[j] = 2.0 * v0 * v0 / (sigma + v0 * v0)
        v = V[j]
        v[:j] = 0.0
        v[j] = 1.0
        for i in range(j + 1, n):
            v[i] = R[i, j] / v0
        _reflect_columns(R, v, beta[j], np.uint64(j), np.uint64(n), np.uint64(m), s)
        for i in range(j + 1, n):
            R[i, j] = 0.0


@inlined
def _reflect_columns(R: Array, v: Array, b: float, j: Index, n: Index, m: Index,
                     s: Array) -> None:  # fmt: skip
    """``R[j:, j:] = (I - b v v^T) R[j:, j:]``: each column's :math:`v^T R_c` summed in row
    order, the columns side by side (``s`` (m,) their sums)."""  # noqa: D205, D209
    for c in range(j, m):
        s[c] = 0.0
    for i in range(j, n):
        vi = v[i]
        for c in range(j, m):
            s[c] += vi * R[i, c]
    for c in range(j, m):
        s[c] *= b
    for i in range(j, n):
        vi = v[i]
        for c in range(j, m):
            R[i, c] -= s[c] * vi


@inlined
def _reflect_rows(A: Array, v: Array, b: float, j: Index, n: Index, rows: Index,
                  s: Array) -> None:  # fmt: skip
    """``A[:, j:] = A[:, j:] (I - b v v^T)`` for A's first ``rows`` rows: each row's
    :math:`A_r v` summed in order (``s`` (rows,) their sums)."""  # noqa: D205, D209
    for r in range(rows):
        t = 0.0
        for i in range(j, n):
            t += A[r, i] * v[i]
        s[r] = t * b
    for r in range(rows):
        for i in range(j, n):
            A[r, i] -= s[r] * v[i]


@kernel
def householder_qr(At: Array, Q: Array, R: Array) -> None:
    r"""Householder QR of ``At`` (n, m): ``At = Q R`` (Golub & Van Loan, Algorithm 5.2.1).

    :func:`householder_vectors`, then Q accumulated from the left,
    :math:`Q = H_0 H_1 \cdots H_{k-1}`.

    Args:
        At: The transposed task rows (n, m).
        Q: Out: orthogonal (n, n).
        R: Out: upper triangular (n, m).
    """
    n, m = At.shape
    k = max(min(n - 1, m), 0)
    V, beta, s = np.empty((k, n)), np.empty(k), np.empty(n)
    householder_vectors(At, R, V, beta)
    Q[:, :] = 0.0
    for i in range(n):
        Q[i, i] = 1.0
    for j in range(k):
        if beta[j] != 0.0:
            _reflect_rows(Q, V[j], beta[j], np.uint64(j), np.uint64(n), np.uint64(n), s)


@kernel
def householder_null(V: Array, beta: Array, m: int, N: Array) -> None:
    r"""The trailing columns of :math:`Q = H_0 \cdots H_{k-1}` (:func:`householder_vectors`),
    as rows: ``N = Q[:, m:].T`` (n - m, n), an orthonormal basis of the complement of the
    span of ``At``'s m columns (the null space of the rows ``At.T``).

    Accumulated from the right, :math:`H_0(H_1(\cdots H_{k-1}[0; I]))` (Golub & Van Loan,
    5.1.6: backward accumulation, each :math:`H_j` on entries j: only).
    """  # noqa: D205
    n = N.shape[1]
    p = n - m
    N[:, :] = 0.0
    for c in range(p):
        N[c, m + c] = 1.0
    s = np.empty(p)
    for j in range(beta.size - 1, -1, -1):
        if beta[j] != 0.0:
            _reflect_rows(N, V[j], beta[j], np.uint64(j), np.uint64(n), np.uint64(p), s)


@kernel
def least_norm_rates(Q: Array, R: Array, b: Array, x: Array) -> bool:
    r"""The least-norm solution of ``J x = b`` from the QR of :math:`J^T = QR` (m <= n).

    :math:`J = R_1^T Q_1^T`, so :math:`x = Q_1 y` with :math:`R_1^T y = b` by forward
    substitution (Golub & Van Loan, 5.7.2: the minimum-norm solution of an underdetermined
    system).

    Args:
        Q: Orthogonal factor (n, n).
        R: Triangular factor (n, m), m <= n.
        b: Right-hand side (m,).
        x: Out: the rates (n,).

    Returns:
        False where a pivot of :math:`R_1` is not above ``1e-12`` times the largest (the rows
        are numerically dependent, or all zero: the SVD answers instead); ``x`` is then not
        set.
    """
    n, m = R.shape
    largest = 0.0
    for i in range(m):
        largest = max(largest, abs(R[i, i]))
    for i in range(m):
        if abs(R[i, i]) <= 1e-12 * largest:
            return False
    y = np.empty(m)
    for i in range(m):
        s = b[i]
        for k in range(i):
            s -= R[k, i] * y[k]
        y[i] = s / R[i, i]
    for r in range(n):
        s = 0.0
        for i in range(m):
            s += Q[r, i] * y[i]
        x[r] = s
    return True


# -- SVD --------------------------------------------------------------------------------------


@kernel
def jacobi_svd(A: Array, V: Array, sigma: Array) -> None:
    r"""One-sided Jacobi SVD of a small ``A`` (m, k): ``A V = U diag(sigma)`` (Hestenes 1958).

    Plane rotations of pairs of columns until all are orthogonal (Demmel & Veselic 1992,
    Algorithm 4.1: the rotation that zeroes :math:`a_p^T a_q`), accumulated in V; the column
    norms are then the singular values. Columns are sorted by decreasing norm at the end.

    Each column's squared norm is kept from the rotation that last changed it (the same sum,
    in the same order, as from the column). The rotation is Golub & Van Loan 2013's
    (Algorithm 8.5.1, the tangent :math:`t = \mathrm{sign}(\tau)\gamma/d`) in terms of
    :math:`\tau = (\beta - \alpha)/2`, :math:`r = \sqrt{\tau^2 + \gamma^2}` and
    :math:`d = |\tau| + r`: as :math:`d^2 + \gamma^2 = 2rd`, its cosine and sine are
    :math:`c = d/h` and :math:`s = \mathrm{sign}(\tau)\gamma/h` with :math:`h = \sqrt{2rd}`
    (where a square or :math:`2rd` would leave the range of normal floats, of
    :math:`\tau/r` and :math:`\gamma/r`, r by :func:`math.hypot`).

    A block diagonal ``A`` (columns ``c0:c1`` nonzero in rows ``r0:r1`` only, as the
    triangle of two arms' tasks on joints of their own) is rotated block by block, over the
    block's rows: a pair of columns of two blocks is orthogonal already, and a row outside a
    block is zero in both columns of its pairs, so the rotations, norms and order are those of
    the whole matrix.

    Args:
        A: The matrix (m, k); out: its columns rotated, ``U diag(sigma)``.
        V: Out: orthogonal (k, k), the right singular vectors (columns).
        sigma: Out: the singular values (k,), descending.
    """
    m, k = A.shape
    V[:, :] = 0.0
    for i in range(k):
        V[i, i] = 1.0
    norms = np.empty(k)  # each column's squared norm
    for j in range(k):
        s = 0.0
        for i in range(m):
            s += A[i, j] * A[i, j]
        norms[j] = s
    first = np.empty(k + 1, np.int64)  # the first row nonzero in a column from j on
    first[k] = m
    for j in range(k - 1, -1, -1):
        i = 0
        while i < m and A[i, j] == 0.0:
            i += 1
        first[j] = min(i, first[j + 1])
    c0, r0, last = 0, 0, -1  # the block's first column and row, its last nonzero row so far
    for c1 in range(1, k + 1):
        i = m - 1
        while i >= 0 and A[i, c1 - 1] == 0.0:
            i -= 1
        last = max(last, i)
        if c1 < k and last >= first[c1]:  # the columns from c1 on reach into these rows
            continue
        r1 = m if c1 == k else first[c1]
        # unsigned indices: numba leaves out the wrap of a negative index at every access
        _rotate_block(A, V, norms, np.uint64(r0), np.uint64(r1), np.uint64(c0), np.uint64(c1),
                      np.uint64(1))  # fmt: skip
        c0, r0, last = c1, r1, -1
    for j in range(k):
        sigma[j] = math.sqrt(norms[j])
    for j in range(k):  # selection sort, descending, columns of A and V alike
        best = j
        for i in range(j + 1, k):
            if sigma[i] > sigma[best]:
                best = i
        if best != j:
            sigma[j], sigma[best] = sigma[best], sigma[j]
            for i in range(m):
                A[i, j], A[i, best] = A[i, best], A[i, j]
            for i in range(k):
                V[i, j], V[i, best] = V[i, best], V[i, j]


@inlined
def _rotate_block(A: Array, V: Array, norms: Array, r0: Index, r1: Index, c0: Index, c1: Index,
                  one: Index) -> None:  # fmt: skip
    """:func:`jacobi_svd`'s sweeps over the columns ``c0:c1`` of ``A``, nonzero in rows
    ``r0:r1`` only, until they are orthogonal; their rotations accumulated in V's."""  # noqa: D205, D209
    for _ in range(SWEEPS):
        rotated = False
        for p in range(c0, c1 - one):
            for q in range(p + one, c1):
                alpha, beta, gamma = norms[p], norms[q], 0.0
                for i in range(r0, r1):
                    gamma += A[i, p] * A[i, q]
                if gamma == 0.0 or abs(gamma) <= 1e-15 * math.sqrt(alpha * beta):
                    continue
                rotated = True
                tau = 0.5 * (beta - alpha)
                r = math.sqrt(tau * tau + gamma * gamma)
                if not 1e-150 < r < 1e150:  # the same rotation of tau / r, gamma / r
                    r = math.hypot(tau, gamma)
                    tau, gamma, r = tau / r, gamma / r, 1.0
                d = abs(tau) + r
                h = math.sqrt(2.0 * r * d)
                c, s = d / h, math.copysign(1.0, tau) * gamma / h
                alpha = beta = 0.0
                for i in range(r0, r1):
                    ap, aq = A[i, p], A[i, q]
                    A[i, p], A[i, q] = c * ap - s * aq, s * ap + c * aq
                    alpha += A[i, p] * A[i, p]
                    beta += A[i, q] * A[i, q]
                norms[p], norms[q] = alpha, beta
                for i in range(c0, c1):
                    vp, vq = V[i, p], V[i, q]
                    V[i, p], V[i, q] = c * vp - s * vq, s * vp + c * vq
        if not rotated:
            return


@inlined
def triangle_svd(Q: Array, R: Array, tol: float, US: Array, W: Array, sigma: Array,
                 right: Array) -> int:  # fmt: skip
    r"""The SVD of J from the QR of its transpose, :math:`J^T = QR` (k = min(m, n)).

    :math:`R_1^T V = U\Sigma` (:func:`jacobi_svd` of the small triangle's transpose, m x k)
    gives :math:`J = U\Sigma (Q_1 V)^T` (Golub & Van Loan 2013, section 8.6.3: the
    R-bidiagonalisation route to the SVD of a wide or tall matrix).

    Args:
        Q: Orthogonal factor (n, n) of :math:`J^T`.
        R: Triangular factor (n, m).
        tol: Singular values at most ``tol * sigma_max`` count as zero.
        US: Out: :math:`U\Sigma` (m, k).
        W: Out: the triangle's right singular vectors (k, k).
        sigma: Out: singular values (k,), descending.
        right: Out: the right singular vectors of J, :math:`Q_1 W` (n, k).

    Returns:
        The rank (0 when k is 0 or sigma_max is 0).
    """
    n, m = R.shape
    k = min(m, n)
    for i in range(m):
        for j in range(k):
            US[i, j] = R[j, i]
    jacobi_svd(US, W, sigma)
    for i in range(n):
        for j in range(k):
            s = 0.0
            for p in range(k):
                s += Q[i, p] * W[p, j]
            right[i, j] = s
    if k == 0 or not sigma[0] > 0.0:
        return 0
    rank = 0
    for j in range(k):
        if sigma[j] > tol * sigma[0]:
            rank += 1
    return rank


@kernel
def svd_rates(
    US: Array, sigma: Array, right: Array, b: Array, lambda_sq: Array, rank: int, x: Array
) -> None:
    r"""Damped least-squares rates :math:`\sum_{i<r}\sigma_i/(\sigma_i^2+\lambda_i^2)(u_i^Tb)v_i`.

    With ``US`` the columns :math:`\sigma_i u_i`, the coefficient is
    :math:`(\sigma_i u_i)^T b/(\sigma_i^2 + \lambda_i^2)` (Wampler 1986; exact least-norm
    rates for :math:`\lambda = 0`).

    Args:
        US: Left singular vectors times their singular values (m, k).
        sigma: Singular values (k,), descending.
        right: Right singular vectors (n, k) (columns).
        b: Task rates (m,).
        lambda_sq: Squared damping per singular direction (k,).
        rank: Number of directions used (those of nonzero singular value).
        x: Out: rates (n,).
    """
    n = right.shape[0]
    m = US.shape[0]
    x[:] = 0.0
    for i in range(rank):
        c = 0.0
        for r in range(m):
            c += US[r, i] * b[r]
        c /= sigma[i] * sigma[i] + lambda_sq[i]
        for r in range(n):
            x[r] += c * right[r, i]


# -- least squares of a stack -----------------------------------------------------------------


@kernel
def weighted_rows(
    A: Array,
    b: Array,
    weight: Array,
    top: float,
    unit: Array,
    scale: float,
    A_out: Array,
    b_out: Array,
) -> float:
    r"""Rows and rates in a level's metric: each row times :math:`\sqrt{w_i/w_{top}}/u_i`.

    Args:
        A: Task rows (m, n).
        b: Their rates (m,).
        weight: Row weights (m,) > 0.
        top: The level's largest weight.
        unit: Each row's unit (m,) (the arm's reach for linear rows, else 1).
        scale: A factor on the rates, applied first (a command near the float range is
            divided by its largest entry before the rows' factors).
        A_out: Out (m, n).
        b_out: Out (m,).

    Returns:
        The largest magnitude of ``b_out``.
    """
    m, n = A.shape
    peak = 0.0
    for i in range(m):
        f = math.sqrt(weight[i] / top) / unit[i]
        for j in range(n):
            A_out[i, j] = A[i, j] * f
        b_out[i] = (b[i] * scale) * f
        peak = max(peak, abs(b_out[i]))
    return peak


@kernel
def normal_equations(A: Array, b: Array, weight: Array, H: Array, g: Array) -> None:
    r"""The normal equations of weighted rows: :math:`H = A^T W A`, :math:`g = A^T W b`.

    Args:
        A: Rows (m, n).
        b: Their rates (m,).
        weight: Row weights W (m,) > 0.
        H: Out (n, n).
        g: Out (n,).
    """
    m, n = A.shape
    H[:, :] = 0.0
    g[:] = 0.0
    for r in range(m):  # each row's outer product added, the entries' sums in row order
        for i in range(n):
            a = A[r, i] * weight[r]
            if a == 0.0:  # its terms are zero: a joint the row's task does not move
                continue
            g[i] += a * b[r]
            for j in range(i, n):
                H[i, j] += a * A[r, j]
    for i in range(n):
        for j in range(i + 1, n):
            H[j, i] = H[i, j]


@kernel
def cholesky(H: Array, relative: float, L: Array, floor: float = 0.0) -> bool:
    r"""``L`` (n, n) lower triangular with :math:`H = LL^T`, H symmetric (n, n).

    Golub & Van Loan, Algorithm 4.2.1. Reads H's lower triangle only, so ``L`` may be H
    itself (factorised in place).

    Returns:
        False where H is not numerically definite: a pivot at or below ``relative`` times
        the largest diagonal entry or ``floor``, or not a number (``L`` is then not set).
    """
    n = H.shape[0]
    largest = 0.0
    for i in range(n):
        largest = max(largest, H[i, i])
    if not largest > 0.0:
        return False
    least = max(relative * largest, floor)
    for j in range(n):
        s = H[j, j]
        for k in range(j):
            s -= L[j, k] * L[j, k]
        if not s > least:
            return False
        L[j, j] = math.sqrt(s)
        for i in range(j + 1, n):
            s = H[i, j]
            for k in range(j):
                s -= L[i, k] * L[j, k]
            L[i, j] = s / L[j, j]
    return True


@kernel
def solve_factored(L: Array, g: Array, x: Array) -> None:
    r"""``x`` solving :math:`LL^Tx = g`, L (n, n) lower triangular (:func:`cholesky`'s; its
    upper triangle is not read): two triangular solves.
    """  # noqa: D205
    n = g.size
    y = np.empty(n)
    for i in range(n):
        s = g[i]
        for k in range(i):
            s -= L[i, k] * y[k]
        y[i] = s / L[i, i]
    for i in range(n - 1, -1, -1):
        s = y[i]
        for k in range(i + 1, n):
            s -= L[k, i] * x[k]
        x[i] = s / L[i, i]


DEFINITE = 1e-12
"""Relative pivot at or below which :func:`cholesky_solve` finds a matrix not definite."""


@kernel
def cholesky_solve(H: Array, g: Array, x: Array) -> bool:
    r"""``x`` solving :math:`Hx = g` for a symmetric positive definite H: :func:`cholesky`,
    then :func:`solve_factored`.

    Returns:
        False where H is not numerically definite (a pivot at or below :data:`DEFINITE`
        times the largest diagonal entry); ``x`` is then not set.
    """  # noqa: D205
    n = g.size
    L = np.zeros((n, n))
    if not cholesky(H, DEFINITE, L):
        return False
    solve_factored(L, g, x)
    return True
