r"""A level's rows factorised inside the compiled tick: QR for the exact rates, the SVD on demand.

The compiled twin of :class:`~rrc_pin.solvers.tick.factorization.Factorization` (whose module
docstring gives the math), as an immutable record, :class:`Factor`, and functions of it: the
SVD is computed where a stage first needs it (:func:`with_svd` returns the record with it).
Every function calls the same kernels in the same order as the class, so both give the same
floats.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers import linalg
from rrc_pin.solvers.compiled import kernel
from rrc_pin.solvers.tick import feasibility
from rrc_pin.solvers.tick.direction import direction_step

Array = npt.NDArray[np.float64]

RANK_TOL = 1e-9
"""Singular values below ``RANK_TOL * sigma_max`` count as zero (null-space directions)."""


class Factor(NamedTuple):
    r"""QR of rows J (m, n), :math:`J^T = QR`, and their SVD once computed.

    Attributes:
        J: The rows (m, n).
        Q: Orthogonal factor (n, n).
        R: Triangular factor (n, m).
        regular: Whether J has full row rank (m <= n, every pivot of R above 1e-12 times the
            largest), known once the least-norm rates were asked for.
        US: :math:`U\Sigma` (m, k), k = min(m, n); empty before the SVD.
        sigma: Singular values (k,), descending; empty before the SVD.
        right: Right singular vectors (n, k); empty before the SVD.
        rank: The rank by :data:`RANK_TOL`, -1 before the SVD.
    """

    J: Array
    Q: Array
    R: Array
    regular: bool
    US: Array
    sigma: Array
    right: Array
    rank: int


@kernel
def qr(J: Array) -> Factor:
    """The QR of ``J^T`` (:func:`~rrc_pin.solvers.linalg.householder_qr`), no SVD yet."""
    m, n = J.shape
    Q, R = np.empty((n, n)), np.empty((n, m))
    linalg.householder_qr(J.T, Q, R)
    return Factor(J, Q, R, False, Q[:0], Q[0, :0], Q[:0], -1)


@kernel
def with_svd(f: Factor) -> Factor:
    r"""``f`` with its SVD (:func:`~rrc_pin.solvers.linalg.triangle_svd`)."""
    if f.rank >= 0:
        return f
    m, n = f.J.shape
    k = min(m, n)
    US, W, sigma, right = np.empty((m, k)), np.empty((k, k)), np.empty(k), np.empty((n, k))
    rank = linalg.triangle_svd(f.Q, f.R, RANK_TOL, US, W, sigma, right)
    return Factor(f.J, f.Q, f.R, f.regular, US, sigma, right, rank)


@kernel
def rates(f: Factor, b: Array, lambda_sq: Array) -> Array:
    r"""Damped least-squares rates (n,) :math:`\sum_i \sigma_i/(\sigma_i^2+\lambda_i^2)(u_i^Tb)v_i`
    of a record with its SVD (:func:`~rrc_pin.solvers.linalg.svd_rates`).
    """  # noqa: D205
    x = np.empty(f.J.shape[1])
    linalg.svd_rates(f.US, f.sigma, f.right, b, lambda_sq, f.rank, x)
    return x


@kernel
def least_norm(f: Factor, b: Array) -> tuple[Factor, Array]:
    """The least-squares rates of least norm :math:`J^+ b` (n,), and ``f`` knowing its rank.

    The QR's forward solve where J has full row rank, else the SVD's rates.
    """
    m, n = f.J.shape
    x = np.empty(n)
    if m <= n and linalg.least_norm_rates(f.Q, f.R, b, x):
        return Factor(f.J, f.Q, f.R, True, f.US, f.sigma, f.right, f.rank), x
    f = with_svd(f)
    return f, rates(f, b, np.zeros(f.sigma.size))


@kernel
def fitted(J: Array, b: Array, lb: Array, ub: Array) -> tuple[Factor, Array, bool, Array, float]:
    """The factorisation of J, the least-norm rates w of ``J x ~= b``, whether they fit.

    One kernel call where J has full row rank
    (:func:`~rrc_pin.solvers.tick.direction.direction_step`), the SVD otherwise.

    Returns:
        The record, w (n,), whether ``lb <= w <= ub``, and where they do not fit and J has at
        most one null direction, the direction problem's answer within the box alone and its
        scale u (else u = -1).
    """
    m, n = J.shape
    space = np.empty(n * (n + m + 2))  # one allocation: Q, R, w and the boxed rates
    Q, R = space[: n * n].reshape(n, n), space[n * n : n * (n + m)].reshape(n, m)
    w, boxed = space[n * (n + m) : n * (n + m + 1)], space[n * (n + m + 1) :]
    fit, u = direction_step(J, b, lb, ub, Q, R, w, boxed)
    f = Factor(J, Q, R, fit > 0, Q[:0], w[:0], Q[:0], -1)
    if fit:
        return f, w, fit == 2, boxed, u
    f = with_svd(f)
    w = rates(f, b, np.zeros(f.sigma.size))
    return f, w, feasibility.inside(w, lb, ub), boxed, -1.0


@kernel
def null_basis(f: Factor) -> tuple[Factor, Array]:
    """Orthonormal rows (n - rank, n) spanning the null space of J (and ``f`` with its SVD
    where it was needed).
    """  # noqa: D205
    m, n = f.J.shape
    if f.regular:
        return f, np.ascontiguousarray(f.Q[:, m:].T)
    f = with_svd(f)
    k = min(m, n)
    N = np.empty((k - f.rank + n - k, n))
    for i in range(k - f.rank):
        for j in range(n):
            N[i, j] = f.right[j, f.rank + i]
    for i in range(n - k):
        for j in range(n):
            N[k - f.rank + i, j] = f.Q[j, k + i]
    return f, N


@kernel
def condition(f: Factor) -> float:
    """sigma_max / sigma_min of J (inf where it is rank deficient) from ``f``'s SVD."""
    k = min(f.J.shape[0], f.J.shape[1])
    if f.rank < k or f.rank == 0:
        return np.inf
    return float(f.sigma[0] / f.sigma[f.rank - 1])


@kernel
def surely_conditioned(f: Factor, threshold: float) -> bool:
    r"""Whether J (m <= n) surely has full rank and a condition number at most ``threshold``,
    without the SVD.

    :math:`\kappa_2(J) = \kappa_2(R_1) \le \|R_1\|_F\,\|R_1^{-1}\|_F` (R_1 the leading m x m
    triangle of R; Golub & Van Loan 2013, section 2.3.2: the 2-norm at most the Frobenius
    one): that bound at most ``threshold`` and below ``1 / RANK_TOL`` (less a rounding
    margin), :func:`condition` is at most ``threshold`` and the rank m. False where unsure
    (a singular triangle, or a bound beyond the float range; the SVD decides then).
    """  # noqa: D205
    m, n = f.J.shape
    if m > n:
        return False
    R = f.R
    bound = min(threshold, 1.0 / RANK_TOL) * (1.0 - 1e-9)
    low, high = np.inf, 0.0
    for i in range(m):
        low, high = min(low, abs(R[i, i])), max(high, abs(R[i, i]))
    if not (low > 0.0 and high <= bound * low):  # the pivots' ratio is at most the condition
        return False
    size = 0.0
    pivots = np.empty(m)  # the triangle's inverse diagonal
    for i in range(m):
        pivots[i] = 1.0 / R[i, i]
        for j in range(i, m):
            size += R[i, j] ** 2
    limit = bound**2
    x = np.empty(m)
    inverse = 0.0
    for k in range(m):  # column k of the inverse: R_1 x = e_k by back substitution (x_i = 0, i > k)
        for i in range(k, -1, -1):
            s = 1.0 if i == k else 0.0
            for j in range(i + 1, k + 1):
                s -= R[i, j] * x[j]
            x[i] = s * pivots[i]
            inverse += x[i] ** 2
        if not size * inverse <= limit:  # the bound only grows
            return False
    return True
