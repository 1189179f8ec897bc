r"""Damped least squares with adaptive damping, and Nguyen's weighted pseudo-inverse.

Two kernels for any Jacobian ``J`` (m, n), rows [v; w] or any subset of them:

- :func:`damped_least_squares`: :math:`\dot q = \arg\min \|J\dot q - \dot x\|^2_W +
  \lambda^2\|\dot q\|^2`, with a damping :math:`\lambda` that is zero away from singularities
  and grows smoothly as the smallest singular value (Maciejewski & Klein 1988; Chiaverini,
  Siciliano & Egeland 1994) or the manipulability (Nakamura & Hanafusa 1986) falls.
- :func:`weighted_pseudo_inverse` and :func:`weighted_rates`: Nguyen eqs. (21)-(22),
  :math:`\dot q = J_W^+\dot x + (I - J_W^+ J) z`, :math:`J_W^+ = W J^T (J W J^T)^{-1}`,
  computed by an SVD so that they stay finite when :math:`J W J^T` is singular.

Both go through :class:`TaskSVD`, the singular value decomposition of the task-weighted
Jacobian that the QP builder (:mod:`solvers.qp_problem`) reuses for its null-space terms
(the resolver takes it where :mod:`solvers.task_factor` cannot avoid it: near
singularities).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal, NamedTuple

import numpy as np
import numpy.typing as npt
from scipy.linalg.lapack import dgesvd as _gesvd

from solvers.errors import InputError
from solvers.validation import as_array, as_vector

Array = npt.NDArray[np.float64]

RANK_TOL = 1e-9
"""Singular values below ``RANK_TOL * sigma_max`` count as zero (null-space directions)."""


@dataclass(frozen=True)
class Damping:
    r"""An adaptive damping schedule :math:`\lambda^2(J)`.

    ``measure="sigma"`` (default; Maciejewski & Klein 1988, Chiaverini et al. 1994):

    .. math::

        \lambda^2 = \lambda_{min}^2 + \begin{cases} 0 & \sigma_{min} \ge \epsilon \\
        \left(1 - (\sigma_{min}/\epsilon)^2\right) \lambda_{max}^2 & \sigma_{min} < \epsilon
        \end{cases}

    ``measure="manipulability"`` (Nakamura & Hanafusa 1986), with
    :math:`w = \prod_i \sigma_i = \sqrt{\det J J^T}`:

    .. math::

        \lambda = \lambda_{max} (1 - w/w_0)^2 \quad (w < w_0), \quad 0 \text{ otherwise}

    (then :math:`\lambda^2 + \lambda_{min}^2`). The default values are chosen here for arms
    of about a metre (singular values in [m/rad] for linear rows, [1] for angular rows).

    Attributes:
        lambda_max: Damping reached at an exact singularity [task units], >= 0.
        threshold: Width of the singular region: :math:`\epsilon` (sigma) or :math:`w_0`
            (manipulability), > 0.
        floor: Constant damping :math:`\lambda_{min}` applied everywhere, >= 0.
        measure: ``"sigma"`` or ``"manipulability"``.

    Raises:
        InputError: A negative or non-finite value, a non-positive threshold, or an unknown
            measure (at construction).
    """

    lambda_max: float = 0.05
    threshold: float = 0.05
    floor: float = 0.0
    measure: Literal["sigma", "manipulability"] = "sigma"

    def __post_init__(self) -> None:
        for name in ("lambda_max", "floor"):
            value = getattr(self, name)
            if not np.isfinite(value) or value < 0.0:
                raise InputError(name, f"expected a finite number >= 0, got {value!r}")
        if not np.isfinite(self.threshold) or self.threshold <= 0.0:
            raise InputError("threshold", f"expected a finite number > 0, got {self.threshold!r}")
        if self.measure not in ("sigma", "manipulability"):
            raise InputError(
                "measure", f"expected 'sigma' or 'manipulability', got {self.measure!r}"
            )

    def lambda_sq(self, sigma: Array) -> float:
        """Squared damping for the singular values ``sigma`` (k,), sorted descending."""
        extra = 0.0
        if self.measure == "sigma":
            s_min = float(sigma[-1]) if sigma.size else 0.0
            if s_min < self.threshold:
                extra = (1.0 - (s_min / self.threshold) ** 2) * self.lambda_max**2
        else:
            w = float(np.prod(sigma)) if sigma.size else 0.0
            if w < self.threshold:
                extra = (self.lambda_max * (1.0 - w / self.threshold) ** 2) ** 2
        return self.floor**2 + extra


class TaskSVD(NamedTuple):
    r"""SVD of the weighted task Jacobian :math:`\tilde J = L^T J` (:math:`W = L L^T`).

    Attributes:
        J: The weighted Jacobian :math:`\tilde J`, (m, n).
        U: Left singular vectors, (m, k), k = min(m, n).
        sigma: Singular values (k,), descending.
        Vt: Right singular vectors (n, n): rows ``0..rank-1`` span the row space, the other
            rows the (numerical) null space.
        rank: Number of singular values above ``RANK_TOL * sigma_max``.
        lambda_sq: Squared damping of the schedule at this Jacobian.
    """

    J: Array
    U: Array
    sigma: Array
    Vt: Array
    rank: int
    lambda_sq: float

    @property
    def n(self) -> int:
        """Number of joints."""
        return int(self.Vt.shape[0])

    @property
    def row_space(self) -> Array:
        """Orthonormal rows (rank, n) spanning the row space of the Jacobian."""
        return self.Vt[: self.rank]

    def null_projector(self) -> Array:
        r"""Orthogonal projector (n, n) onto the null space, :math:`I - V_r V_r^T`."""
        N = self.Vt[self.rank :]
        return N.T @ N

    def null_basis(self) -> Array:
        """Orthonormal rows (n - rank, n) spanning the (numerical) null space, :math:`V_n^T`."""
        return self.Vt[self.rank :]

    def null_project(self, z: Array) -> Array:
        r"""Null-space part (n,) of ``z`` (n,): :math:`V_n V_n^T z`."""
        N = self.Vt[self.rank :]
        return N.T @ (N @ z)

    def row_project(self, v: Array) -> Array:
        r"""Row-space part (n,) of ``v`` (n,): :math:`V_r V_r^T v`."""
        Vr = self.Vt[: self.rank]
        return Vr.T @ (Vr @ v)

    def svd(self) -> TaskSVD:
        """Itself (the interface of :data:`solvers.task_factor.Task`)."""
        return self

    def dls(self, xw: Array) -> Array:
        r"""Damped least-squares rates (n,) for the weighted task velocity ``xw`` (m,).

        :math:`\dot q = \sum_i v_i \sigma_i/(\sigma_i^2 + \lambda^2)\, u_i^T \tilde x`, the
        minimiser of :math:`\|\tilde J\dot q - \tilde x\|^2 + \lambda^2\|\dot q\|^2` of
        least norm. Undamped, singular values below the rank cut-off are dropped; damped,
        every gain is at most :math:`1/(2\lambda)`.
        """
        k = self.sigma.size
        denom = self.sigma**2 + self.lambda_sq
        gain = np.divide(self.sigma, denom, out=np.zeros(k), where=denom > 0.0)
        if self.lambda_sq == 0.0:
            gain[self.rank :] = 0.0  # undamped: numerically zero sigma_i are null directions
        return np.dot(gain * np.dot(xw, self.U), self.Vt[:k])


def weight_factor(weights: npt.ArrayLike | None, m: int, name: str = "weights") -> Array | None:
    r"""Factor :math:`L` (m, m) with :math:`W = L L^T` of a task or joint weight.

    Args:
        weights: None (identity), a positive vector (m,) (diagonal W) or an SPD matrix (m, m).
        m: Size of W.
        name: Argument name for errors.

    Returns:
        None for the identity, else the lower-triangular factor (m, m).

    Raises:
        InputError: Wrong shape, non-finite, non-positive diagonal, or not positive definite.
    """
    if weights is None:
        return None
    w = np.asarray(weights, dtype=np.float64)
    if w.ndim == 1:
        w = as_vector(w, name, m)
        if np.any(w <= 0.0):
            raise InputError(name, f"expected weights > 0, got {w}")
        return np.diag(np.sqrt(w))
    w = as_array(w, name, (m, m))
    if not np.allclose(w, w.T, rtol=1e-12, atol=1e-12 * np.abs(w).max()):
        raise InputError(name, "expected a symmetric matrix")
    try:
        return np.linalg.cholesky(w)
    except np.linalg.LinAlgError as exc:
        raise InputError(name, "expected a positive definite matrix") from exc


def _svd(A: Array) -> tuple[Array, Array, Array]:
    """Full SVD ``U (m, m), sigma (k,), Vt (n, n)`` by LAPACK's dgesvd.

    Through scipy's binding: half of numpy's per-call overhead on these small matrices.

    Raises:
        numpy.linalg.LinAlgError: The SVD did not converge.
    """
    if A.size == 0:
        return np.linalg.svd(A, full_matrices=True)
    U, sigma, Vt, info = _gesvd(A, compute_uv=1, full_matrices=1)
    if info != 0:
        raise np.linalg.LinAlgError(f"dgesvd did not converge (info={info})")
    return U, sigma, Vt


def task_svd(J: Array, factor: Array | None = None, damping: Damping | None = None) -> TaskSVD:
    r"""SVD of :math:`L^T J` with the damping of ``damping`` (no input checks: hot path).

    Args:
        J: Jacobian (m, n), finite.
        factor: :math:`L` (m, m) from :func:`weight_factor`, or None for W = I.
        damping: Damping schedule; None for no damping.

    Returns:
        The :class:`TaskSVD`.

    Raises:
        numpy.linalg.LinAlgError: The SVD did not converge (only for pathological input).
    """
    Jw = J if factor is None else factor.T @ J
    U, sigma, Vt = _svd(Jw)
    k = sigma.size
    if U.shape[1] != k:
        U = U[:, :k]
    values = sigma.tolist()  # a handful of scalars: Python is faster than numpy here
    cut = RANK_TOL * values[0] if k else 0.0
    rank = sum(1 for v in values if v > cut) if cut > 0.0 else 0
    lam = damping.lambda_sq(sigma) if damping is not None else 0.0
    return TaskSVD(J=Jw, U=U, sigma=sigma, Vt=Vt, rank=rank, lambda_sq=lam)


def damped_least_squares(
    J: npt.ArrayLike,
    xdot: npt.ArrayLike,
    damping: Damping | None = None,
    weights: npt.ArrayLike | None = None,
) -> Array:
    r"""Joint rates of damped least squares with adaptive damping.

    .. math::

        \dot q = \arg\min_{\dot q} \|J\dot q - \dot x\|_W^2 + \lambda^2(J)\|\dot q\|^2
              = (J^T W J + \lambda^2 I)^{-1} J^T W \dot x

    computed by the SVD (finite at every configuration, minimum norm where
    :math:`\lambda = 0` and J is rank deficient).

    Args:
        J: Jacobian (m, n), [m/rad] rows then [1] rows.
        xdot: Task velocity (m,), [m/s] then [rad/s], same frame as J.
        damping: Schedule; default :class:`Damping()`.
        weights: Task weights W: (m,) positive or (m, m) SPD; None for identity.

    Returns:
        Joint rates (n,) [rad/s].

    Raises:
        InputError: Wrong shapes, non-finite entries, or invalid weights.
    """
    J = as_array(J, "J", (None, None))
    m, _ = J.shape
    xdot = as_vector(xdot, "xdot", m)
    factor = weight_factor(weights, m, "weights")
    svd = task_svd(J, factor, Damping() if damping is None else damping)
    return svd.dls(xdot if factor is None else factor.T @ xdot)


def _joint_factor(J: Array, W: npt.ArrayLike | None) -> Array | None:
    return weight_factor(W, J.shape[1], "W")


def weighted_pseudo_inverse(
    J: npt.ArrayLike, W: npt.ArrayLike | None = None, rcond: float = RANK_TOL
) -> Array:
    r"""Nguyen eq. (22): :math:`J_W^+ = W J^T (J W J^T)^{-1}`, robust to singular :math:`J W J^T`.

    With :math:`W = L L^T` and :math:`B = J L`, :math:`J_W^+ = L B^+`; :math:`B^+` is taken by
    a truncated SVD (singular values below ``rcond * sigma_max`` dropped), which equals
    eq. (22) wherever :math:`J W J^T` is invertible and stays finite where it is not. It
    minimises :math:`\dot q^T W^{-1} \dot q` among the least-squares solutions of
    :math:`J\dot q = \dot x` (Nguyen eq. (20)). ``W = I`` gives Nguyen eq. (23), the
    Moore-Penrose pseudo-inverse.

    Args:
        J: Jacobian (m, n).
        W: Joint weighting matrix: (n,) positive (diagonal) or (n, n) SPD; None for I.
        rcond: Relative cut-off of the singular values, in [0, 1).

    Returns:
        :math:`J_W^+`, shape (n, m).

    Raises:
        InputError: Wrong shapes, non-finite entries, invalid W or rcond.
    """
    J = as_array(J, "J", (None, None))
    if not 0.0 <= rcond < 1.0:
        raise InputError("rcond", f"expected a number in [0, 1), got {rcond!r}")
    L = _joint_factor(J, W)
    B = J if L is None else J @ L
    B_pinv = np.linalg.pinv(B, rcond=rcond) if B.size else B.T
    return B_pinv if L is None else L @ B_pinv


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
        xdot: Task velocity (m,).
        W: Joint weighting matrix, see :func:`weighted_pseudo_inverse`.
        z: Arbitrary joint velocity (n,) projected into the null space of J; None for 0.
        rcond: Relative cut-off of the singular values.

    Returns:
        Joint rates (n,).

    Raises:
        InputError: Wrong shapes or non-finite entries.
    """
    J = as_array(J, "J", (None, None))
    m, n = J.shape
    xdot = as_vector(xdot, "xdot", m)
    pinv = weighted_pseudo_inverse(J, W, rcond)
    qdot = pinv @ xdot
    if z is not None:
        z = as_vector(z, "z", n)
        qdot = qdot + z - pinv @ (J @ z)
    return qdot


def null_space_projector(
    J: npt.ArrayLike, W: npt.ArrayLike | None = None, rcond: float = RANK_TOL
) -> Array:
    r"""The projector of Nguyen eq. (21), :math:`I - J_W^+ J` (n, n).

    Orthogonal for ``W = I``, W-oblique otherwise; :math:`J (I - J_W^+ J) = 0` where J has full
    row rank, and for the rank-deficient J it removes the components :math:`J_W^+` reaches.

    Raises:
        InputError: Wrong shapes or non-finite entries.
    """
    J = as_array(J, "J", (None, None))
    return np.eye(J.shape[1]) - weighted_pseudo_inverse(J, W, rcond) @ J
