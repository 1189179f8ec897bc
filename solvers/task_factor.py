r"""Per-step factorisation of the task Jacobian: a Cholesky solve where it settles the damping.

Every step of the resolver needs the damping :math:`\lambda^2` of the weighted Jacobian
:math:`\tilde J = L^T J` (m, n), its damped least-squares rates and, when a bound is
active, the QP terms. The SVD (:class:`solvers.dls.TaskSVD`) gives all of them at any
configuration, but it is the most expensive call of a step. Away from singularities one
Cholesky solve suffices:

.. math::

    A = \tilde J\tilde J^T, \qquad C = A^{-1}\tilde J \ (m, n), \qquad
    \|C\|_F^2 = \operatorname{tr}(C C^T) = \operatorname{tr}(A^{-1})
    = \sum_i \sigma_i^{-2} \ \ge\ \sigma_{min}^{-2}

(:math:`C^T` is the pseudo-inverse of :math:`\tilde J` and :math:`CC^T = A^{-1}`), so
:math:`\|C\|_F^2 \le 1/\epsilon^2` certifies :math:`\sigma_{min}(\tilde J) \ge \epsilon`
(the bound is within a factor :math:`\sqrt m` of :math:`\sigma_{min}`). Then the damping
schedule of :class:`solvers.dls.Damping` (``measure="sigma"``, no floor) is zero,
:math:`\tilde J` has full row rank, and, with :math:`N N^T = I - \tilde J^T C` the
projector onto its null space:

.. math::

    \dot q_{dls} = C^T\tilde x, \qquad
    P = \tilde J^T\tilde J + \mu N N^T = \tilde J^T (\tilde J - \mu C) + \mu I

(:class:`TaskInverse`). Otherwise (inside the damping region, rank deficient, a floor or
the manipulability measure) :func:`factor_task` returns the SVD. Both answer the same
questions (:data:`Task`), to rounding.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt
from scipy.linalg.lapack import dposv

from solvers.dls import Damping, TaskSVD, task_svd

Array = npt.NDArray[np.float64]

# The products below use np.dot, not the @ operator: the same BLAS call for these 1-D and 2-D
# operands, with half the per-call overhead on these small arrays (about 1 us against 2).


class TaskInverse:
    r"""A weighted task Jacobian of full row rank outside the damping region, by :math:`C`.

    Built by :func:`factor_task` only when the certificate of the module docstring holds;
    the damping is then zero and the rank is m.

    Attributes:
        J: The weighted Jacobian :math:`\tilde J` (m, n).
        C: :math:`(\tilde J\tilde J^T)^{-1}\tilde J` (m, n); :math:`C^T` is the
            pseudo-inverse of :math:`\tilde J`.
        n: Number of joints.
        rank: m.
        lambda_sq: 0.0.
    """

    __slots__ = ("C", "J", "_svd", "lambda_sq", "n", "rank")

    def __init__(self, J: Array, C: Array) -> None:
        self.J = J
        self.C = C
        self.rank, self.n = J.shape
        self.lambda_sq = 0.0
        self._svd: TaskSVD | None = None

    def dls(self, xw: Array) -> Array:
        r"""Least-squares rates (n,) of least norm, :math:`C^T\tilde x`."""
        return np.dot(xw, self.C)

    def null_project(self, z: Array) -> Array:
        r"""Null-space part (n,) of ``z`` (n,): :math:`(I - C^T\tilde J) z`."""
        return z - np.dot(np.dot(self.J, z), self.C)

    def row_project(self, v: Array) -> Array:
        r"""Row-space part (n,) of ``v`` (n,): :math:`C^T\tilde J v`."""
        return np.dot(np.dot(self.J, v), self.C)

    def hessian(self, mu: float) -> Array:
        r"""Tracking cost matrix (n, n): :math:`\tilde J^T (\tilde J - \mu C) + \mu I`."""
        M = self.C * -mu
        M += self.J
        P = np.dot(self.J.T, M)
        _diagonal(P)[:] += mu
        return P

    def null_basis(self) -> Array:
        r"""Orthonormal rows (n - m, n) spanning the null space.

        One direction (n = m + 1): the column of the projector :math:`N N^T = I - \tilde J^T C`
        with the largest diagonal, :math:`a\,a_k`, normalised by :math:`|a_k|` (at least
        :math:`1/\sqrt n` for the largest entry of a unit vector, so well away from zero).
        More: from the SVD (computed once).
        """
        if self.n - self.rank != 1:
            svd = self.svd()
            return svd.Vt[svd.rank :]
        rows = np.dot(self.J.T, self.C).tolist()  # I minus this is N N^T; Python floats from here
        diagonal = [row[i] for i, row in enumerate(rows)]
        k = diagonal.index(min(diagonal))
        scale = -1.0 / math.sqrt(1.0 - diagonal[k])
        a = [row[k] * scale for row in rows]
        a[k] -= scale
        return np.array([a])

    def svd(self) -> TaskSVD:
        """The SVD of the same Jacobian (computed on first call; damping zero as here)."""
        if self._svd is None:
            self._svd = task_svd(self.J, None, None)
        return self._svd


Task = TaskInverse | TaskSVD
"""Either factorisation: both have ``J``, ``n``, ``rank``, ``lambda_sq``, ``dls``,
``null_project``, ``row_project``, ``null_basis`` and ``svd``."""


def factor_task(J: Array, factor: Array | None = None, damping: Damping | None = None) -> Task:
    r"""The cheapest factorisation of :math:`L^T J` that settles the damping (no input checks).

    Args:
        J: Jacobian (m, n), finite.
        factor: :math:`L` (m, m) from :func:`solvers.dls.weight_factor`, or None for W = I.
        damping: Damping schedule; None for no damping.

    Returns:
        A :class:`TaskInverse` where the certificate (module docstring) shows that the
        damping is zero and the rank full, else the :class:`~solvers.dls.TaskSVD`.

    Raises:
        numpy.linalg.LinAlgError: The SVD did not converge (only for pathological input).
    """
    Jw = J if factor is None else factor.T @ J
    m, n = Jw.shape
    if m <= n and damping is not None and damping.floor == 0.0 and damping.measure == "sigma":
        # C = A^-1 J by LAPACK's Cholesky solve (info > 0: A not numerically definite)
        _, C, info = posv(np.dot(Jw, Jw.T), Jw)
        # |C|_F eps <= 1 certifies sigma_min >= eps. NaN fails the comparisons, and so does
        # C = 0: A overflowed to inf (J beyond 1e154), where LAPACK returns zeros
        if info == 0 and 0.0 < math.hypot(*C.ravel(order="K").tolist()) * damping.threshold <= 1.0:
            return TaskInverse(Jw, C)
    return task_svd(Jw, None, damping)


def _diagonal(M: Array) -> Array:
    """Writable view of the diagonal of a square C- or Fortran-contiguous ``M`` (LAPACK's)."""
    return M.ravel(order="K")[:: M.shape[0] + 1]


posv = dposv
"""``(factor, X, info)`` of LAPACK dposv for ``A X = B``, A symmetric positive definite:
scipy's binding, a quarter of ``numpy.linalg.solve``'s time on these small matrices."""
