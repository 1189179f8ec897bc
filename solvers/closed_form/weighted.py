r"""Nguyen's weighted pseudo-inverse with null-space term (NAG 5-1124, eqs. (20)-(23)).

.. math::
    \dot q = J_W^+ \dot x + (I - J_W^+ J) z, \qquad J_W^+ = W J^T (J W J^T)^{-1}

(Nguyen eqs. (21), (22)); ``W = I`` gives the Moore-Penrose pseudo-inverse of eq. (23). With
``W = L L^T`` and ``B = J L``, ``J_W^+ = L B^+``, and ``B^+`` is taken by a truncated SVD
(singular values ``<= rcond sigma_max`` dropped): eq. (22) wherever ``J W J^T`` is
invertible, finite where it is not. Among the least-squares solutions of ``J qdot = xdot``
it minimises ``(qdot - z)^T W^-1 (qdot - z)`` (Nguyen eq. (20)).

These work for any Jacobian (m, n);
:class:`~rrc_pin.solvers.closed_form.rrc_k1607.RrcK1607ClosedForm`
uses them (through :func:`pseudo_inverse`, on stacks) wherever its normal equations are not safe.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.checks import as_array, as_vector, finite_number
from rrc_pin.solvers.closed_form.base import Array
from rrc_pin.solvers.errors import InvalidInput
from rrc_pin.solvers.tick.factorization import RANK_TOL  # the default rcond


def weight_factor(W: npt.ArrayLike | None, n: int, name: str = "W") -> Array | None:
    r"""The factor :math:`L` (n, n) with :math:`W = L L^T` of a weighting matrix.

    Args:
        W: None (identity), a positive vector (n,) (diagonal W) or an SPD matrix (n, n).
        n: Size of W.
        name: Argument name for errors.

    Returns:
        None for the identity, else the lower-triangular factor (n, n).

    Raises:
        InvalidInput: Wrong shape, non-finite, non-positive diagonal, or not symmetric
            positive definite, naming ``name``.
    """
    if W is None:
        return None
    if np.ndim(W) == 1:
        w = as_vector(W, name, n)
        if np.any(w <= 0.0):
            raise InvalidInput(name, f"expected weights > 0, got {w}")
        return np.diag(np.sqrt(w)).astype(np.float64)
    Wm = as_array(W, name, (n, n))
    if not np.allclose(Wm, Wm.T, rtol=1e-12, atol=1e-12 * np.abs(Wm).max()):
        raise InvalidInput(name, "expected a symmetric matrix")
    try:
        L = np.asarray(np.linalg.cholesky(Wm), dtype=np.float64)
    except np.linalg.LinAlgError as exc:
        raise InvalidInput(name, "expected a positive definite matrix") from exc
    return L


def pseudo_inverse(J: Array, L: Array | None, rcond: float) -> Array:
    """``L (J L)^+`` for a stack ``J`` (..., m, n) -> (..., n, m); no checks (callers validate)."""
    B = J if L is None else J @ L
    P = np.linalg.pinv(B, rcond=rcond) if B.size else np.swapaxes(B, -1, -2)
    return np.asarray(P if L is None else L @ P, dtype=np.float64)


def weighted_pseudo_inverse(
    J: npt.ArrayLike, W: npt.ArrayLike | None = None, rcond: float = RANK_TOL
) -> Array:
    r"""Nguyen eq. (22): :math:`J_W^+ = W J^T (J W J^T)^{-1}`, robust to singular :math:`J W J^T`.

    Args:
        J: Jacobian (m, n).
        W: Joint weighting matrix: (n,) positive (diagonal) or (n, n) SPD; None for I.
        rcond: Relative cut-off of the singular values of ``J L``, in [0, 1).

    Returns:
        :math:`J_W^+`, shape (n, m).

    Raises:
        InvalidInput: Wrong shapes, non-finite entries, invalid ``W`` or ``rcond``, naming it.
    """
    J = as_array(J, "J", (None, None))
    rcond = finite_number(rcond, "rcond", 0.0, upper=1.0)
    L = weight_factor(W, J.shape[1])
    return pseudo_inverse(J, L, rcond)


def weighted_rates(
    J: npt.ArrayLike,
    xdot: npt.ArrayLike,
    W: npt.ArrayLike | None = None,
    z: npt.ArrayLike | None = None,
    rcond: float = RANK_TOL,
) -> Array:
    r"""Nguyen eq. (21): :math:`\dot q = J_W^+\dot x + (I - J_W^+ J) z`.

    Args:
        J: Jacobian (m, n).
        xdot: Task velocity (m,), in the units and frame of J's rows.
        W: Joint weighting matrix, see :func:`weighted_pseudo_inverse`.
        z: Joint velocity (n,) whose null-space part is added; None for 0.
        rcond: Relative cut-off of the singular values, in [0, 1).

    Returns:
        Joint rates (n,).

    Raises:
        InvalidInput: Wrong shapes, non-finite entries, invalid ``W`` or ``rcond``, naming it.
    """
    J = as_array(J, "J", (None, None))
    b = as_vector(xdot, "xdot", J.shape[0])
    P = weighted_pseudo_inverse(J, W, rcond)
    if z is None:
        return P @ b
    zv = as_vector(z, "z", J.shape[1])
    return P @ (b - J @ zv) + zv


def null_space_projector(
    J: npt.ArrayLike, W: npt.ArrayLike | None = None, rcond: float = RANK_TOL
) -> Array:
    r"""The projector of Nguyen eq. (21), :math:`I - J_W^+ J` (n, n).

    Orthogonal for ``W = I``, W-oblique otherwise; :math:`J (I - J_W^+ J) = 0` where J has full
    row rank, and for a rank-deficient J it removes the components :math:`J_W^+` reaches.

    Raises:
        InvalidInput: Wrong shapes, non-finite entries, invalid ``W`` or ``rcond``, naming it.
    """
    J = as_array(J, "J", (None, None))
    return np.eye(J.shape[1]) - weighted_pseudo_inverse(J, W, rcond) @ J
