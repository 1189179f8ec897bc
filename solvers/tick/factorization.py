r"""The factorisation of a level's rows: QR for the exact rates, the SVD only when needed.

For rows J (m, n), the Householder QR of the transpose, :math:`J^T = QR`
(:func:`~rrc_pin.solvers.linalg.householder_qr`), gives at once:

- the least-norm rates of a full-row-rank J, :math:`x = Q_1 R_1^{-T} b`
  (:func:`~rrc_pin.solvers.linalg.least_norm_rates`), what most ticks need;
- the null space, the last n - m columns of Q.

The singular values are those of the small triangle :math:`R_1` (k = min(m, n) rows), so
the SVD of J costs a one-sided Jacobi SVD of :math:`R_1^T` (m, k)
(:func:`~rrc_pin.solvers.linalg.jacobi_svd`): :math:`R_1^T V = U\Sigma` gives
:math:`J = U\Sigma (Q_1 V)^T`. It is computed on first use, where the rows are numerically
dependent (a singularity, more rows than joints), and for the condition number and the
damping near singularities.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers import linalg
from rrc_pin.solvers.tick import feasibility
from rrc_pin.solvers.tick.direction import Along, direction_step

Array = npt.NDArray[np.float64]

RANK_TOL = 1e-9
"""Singular values below ``RANK_TOL * sigma_max`` count as zero (null-space directions)."""


class Factorization:
    """QR of rows J (m, n), and their SVD on first use (module docstring).

    Args:
        J: The rows (m, n), in the metric the level is solved in.

    Attributes:
        J: The rows.
        Q: Orthogonal factor (n, n) of :math:`J^T`.
        R: Triangular factor (n, m).
        regular: Whether J has full row rank (m <= n, every pivot of R above 1e-12 times the
            largest), known once :meth:`least_norm` ran: its rates then meet any rates.
    """

    __slots__ = ("J", "Q", "R", "_svd", "regular")

    def __init__(self, J: Array) -> None:
        m, n = J.shape
        self.J = J
        self.Q, self.R = np.empty((n, n)), np.empty((n, m))
        linalg.householder_qr(J.T, self.Q, self.R)
        self.regular = False  # full row rank, known once least_norm's forward solve ran
        self._svd: tuple[Array, Array, Array, int] | None = None

    @classmethod
    def fitted(
        cls, J: Array, b: Array, lb: Array, ub: Array
    ) -> tuple[Factorization, Array, bool, Along | None]:
        """The factorisation of J, the least-norm rates of ``J x ~= b``, whether they fit.

        Where they do not, also the largest scale along them within the box. One kernel call
        where J has full row rank (:func:`~rrc_pin.solvers.tick.direction.direction_step`), the SVD
        otherwise.

        Args:
            J: The rows (m, n).
            b: Their rates (m,).
            lb: Lower bounds (n,) of the rates.
            ub: Upper bounds (n,).

        Returns:
            The factorisation, the rates (n,), whether ``lb <= x <= ub``, and where they do
            not the direction problem's answer within the box alone (exact: at most one null
            direction), else None.
        """
        m, n = J.shape
        factor = cls.__new__(cls)
        factor.J, factor._svd = J, None
        x: Array = np.empty(n)
        qdot: Array = np.empty(n)
        factor.Q, factor.R = np.empty((n, n)), np.empty((n, m))
        fit, u = direction_step(J, b, lb, ub, factor.Q, factor.R, x, qdot)
        factor.regular = fit > 0
        if fit:
            return factor, x, fit == 2, Along(qdot, u) if u >= 0.0 else None
        x = factor.rates(b, None)
        return factor, x, feasibility.inside(x, lb, ub), None

    def least_norm(self, b: Array) -> Array:
        """The least-squares rates of least norm, :math:`J^+ b` (n,), rank by :data:`RANK_TOL`."""
        m, n = self.J.shape
        x = np.empty(n)
        if m <= n and linalg.least_norm_rates(self.Q, self.R, b, x):
            self.regular = True
            return x
        return self.rates(b, None)

    def rates(self, b: Array, lambda_sq: Array | None) -> Array:
        r"""Damped least-squares rates :math:`\sum_i \sigma_i/(\sigma_i^2+\lambda_i^2)(u_i^Tb)v_i`.

        Args:
            b: Rates of the rows (m,).
            lambda_sq: Squared damping per singular direction (k,), or None for none.
        """
        US, sigma, right, rank = self.svd
        x = np.empty(self.J.shape[1])
        lam = np.zeros(sigma.size) if lambda_sq is None else lambda_sq
        linalg.svd_rates(US, sigma, right, b, lam, rank, x)
        return x

    @property
    def svd(self) -> tuple[Array, Array, Array, int]:
        r"""``(US, sigma, V, rank)``: :math:`J = U\Sigma V^T` with ``US`` = :math:`U\Sigma` (m, k),
        sigma (k,) descending, V (n, k) the right singular vectors, rank by :data:`RANK_TOL`."""  # noqa: D205, D209
        if self._svd is None:
            m, n = self.J.shape
            k = min(m, n)
            US, W, sigma, right = np.empty((m, k)), np.empty((k, k)), np.empty(k), np.empty((n, k))
            rank = linalg.triangle_svd(self.Q, self.R, RANK_TOL, US, W, sigma, right)
            self._svd = (US, sigma, right, rank)
        return self._svd

    def null_basis(self) -> Array:
        """Orthonormal rows (n - rank, n) spanning the null space of J."""
        m, n = self.J.shape
        if self.regular:
            null: Array = self.Q[:, m:].T
            return null
        _, _, right, rank = self.svd
        basis: Array = np.vstack([right[:, rank:].T, self.Q[:, min(m, n) :].T])
        return basis

    def condition(self) -> float:
        """The condition number sigma_max / sigma_min of J (inf where it is rank deficient)."""
        _, sigma, _, rank = self.svd
        if rank < min(self.J.shape) or rank == 0:
            return math.inf
        return float(sigma[0] / sigma[rank - 1])
