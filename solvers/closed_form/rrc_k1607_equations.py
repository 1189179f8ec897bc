r"""The equations of Nguyen & Zhou's closed forms for the RRC K-1607 (NAG 5-1124), compiled.

Craig's modified DH (Nguyen eq. (2)), twists fixed at ``alpha_{i-1} = (0, -90, 90, -90, 90,
-90, 90)`` deg (Table 1); ``a`` holds ``a_0..a_6`` and ``d`` holds ``d_1..d_7`` [m]. Each
equation is one small kernel (:func:`~rrc_pin.solvers.compiled.kernel`) on one configuration,
cited
once; the loops over N configurations at the end call the same kernels.

- :func:`frame_axes`: the axes of the DH frames in base coordinates, Nguyen's auxiliaries of
  eqs. (8)-(11) with the typos of eqs. (8), (9) corrected (docs/errata.md):
  ``x3 = (f2, f4, -s2 c3)``, ``z4 = (f1, f3, s2 s3)``, ``x4 = (g1, g3, f5)``,
  ``z5 = (g2, g4, f6)``, ``x5 = (h2, h4, g6)``, ``z6 = (h1, h3, g5)``, ``x6 = (j1, j2, h5)``.
- :func:`pose`: Nguyen eqs. (4)-(7), the position by the chain of eq. (2) (every ``a_{i-1}``
  and ``d_i`` honoured; for Table 1 it reduces to Nguyen's ``p``, eq. (5) corrected).
- :func:`jacobian`: the cross-product method, Nguyen eqs. (12)-(17), all seven columns
  ``J_i = [z_i x (p - o_i); z_i]`` (the report prints only columns 1-3, eqs. (18)-(19)).
- :func:`weighted_rates`: Nguyen eqs. (21)-(22) by their normal equations, the SVD where
  the rows are numerically dependent.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.closed_form.base import finite
from rrc_pin.solvers.compiled import kernel
from rrc_pin.solvers.linalg import cholesky_solve, jacobi_svd, svd_rates

Array = npt.NDArray[np.float64]
Vector3 = tuple[float, float, float]
Axes = tuple[Vector3, Vector3, Vector3, Vector3, Vector3, Vector3, Vector3]
NQ = 7
TASK_DIM = 6


@kernel
def frame_axes(q: Array) -> tuple[Axes, Axes]:
    """Axes of the DH frames in base coordinates at ``q`` (7,) [rad] (theta_7 not used).

    Returns:
        ``(x, z)``: ``x[k]`` the x axis of frame k (k = 0..6), ``z[k]`` the z axis of frame
        k + 1, the axis of joint k + 1 (Nguyen's ``b_{k+1}``, eq. (14)).
    """
    c1, c2, c3, c4, c5, c6 = (math.cos(q[0]), math.cos(q[1]), math.cos(q[2]), math.cos(q[3]),
                              math.cos(q[4]), math.cos(q[5]))  # fmt: skip
    s1, s2, s3, s4, s5, s6 = (math.sin(q[0]), math.sin(q[1]), math.sin(q[2]), math.sin(q[3]),
                              math.sin(q[4]), math.sin(q[5]))  # fmt: skip
    c1c2, s1c2, c1s2, s1s2 = c1 * c2, s1 * c2, c1 * s2, s1 * s2
    s2c3, s2s3 = s2 * c3, s2 * s3
    # Nguyen eq. (8); f3 and f6 corrected (errata).
    f1 = -c1c2 * s3 - s1 * c3
    f2 = c1c2 * c3 - s1 * s3
    f3 = c1 * c3 - s1c2 * s3
    f4 = s1c2 * c3 + c1 * s3
    f5 = -s2c3 * c4 - c2 * s4
    f6 = c2 * c4 - s2c3 * s4
    # Nguyen eq. (9); g1 corrected (errata).
    g1 = c4 * f2 - c1s2 * s4
    g2 = c1s2 * c4 + s4 * f2
    g3 = c4 * f4 - s1s2 * s4
    g4 = s1s2 * c4 + s4 * f4
    g5 = s2s3 * c5 - s5 * f5
    g6 = s2s3 * s5 + c5 * f5
    # Nguyen eq. (10).
    h1 = c5 * f1 - s5 * g1
    h2 = s5 * f1 + c5 * g1
    h3 = c5 * f3 - s5 * g3
    h4 = s5 * f3 + c5 * g3
    h5 = c6 * g6 - s6 * f6
    # Nguyen eq. (11).
    j1 = c6 * h2 - s6 * g2
    j2 = c6 * h4 - s6 * g4
    # z7 = a, the third column of the hand orientation (Nguyen eqs. (5)-(7)).
    z7 = (s6 * h2 + c6 * g2, s6 * h4 + c6 * g4, s6 * g6 + c6 * f6)
    x = ((1.0, 0.0, 0.0), (c1, s1, 0.0), (c1c2, s1c2, -s2), (f2, f4, -s2c3), (g1, g3, f5),
         (h2, h4, g6), (j1, j2, h5))  # fmt: skip
    z = ((0.0, 0.0, 1.0), (-s1, c1, 0.0), (c1s2, s1s2, c2), (f1, f3, s2s3), (g2, g4, f6),
         (h1, h3, g5), z7)  # fmt: skip
    return x, z


@kernel
def pose(a: Array, d: Array, q: Array, T: Array) -> None:
    """Pose of frame 7 in frame 0 into ``T`` (4, 4), translation [m], Nguyen eqs. (4)-(11).

    The columns ``n = c7 x6 + s7 z6``, ``s = c7 z6 - s7 x6``, ``a = z7`` of eqs. (5)-(7); the
    origin ``p = sum_i a_{i-1} x_{i-1} + d_i z_i``, the fourth column of eq. (2) chained.
    """
    x, z = frame_axes(q)
    c7, s7 = math.cos(q[6]), math.sin(q[6])
    for i in range(3):
        T[i, 0] = c7 * x[6][i] + s7 * z[5][i]
        T[i, 1] = c7 * z[5][i] - s7 * x[6][i]
        T[i, 2] = z[6][i]
        T[i, 3] = 0.0
        for k in range(NQ):
            T[i, 3] += a[k] * x[k][i] + d[k] * z[k][i]
        T[3, i] = 0.0
    T[3, 3] = 1.0


@kernel
def jacobian(a: Array, d: Array, q: Array, J: Array) -> None:
    """Jacobian of frame 7 into ``J`` (6, 7), Nguyen eqs. (12)-(17): rows [v; w], base axes.

    ``J_i = [b_i x p_i; b_i]`` (eqs. (12), (13)) with ``b_i = z_i`` (eq. (14)) and ``p_i``
    the vector from the origin of frame i to that of frame 7 (eq. (16) corrected), from the
    hand back: ``p_7 = 0``, ``p_{i-1} = p_i + a_{i-1} x_{i-1} + d_i z_i`` (eq. (2)). For
    ``z_1 = (0, 0, 1)`` the first column is ``[-p_y, p_x, 0, 0, 0, 1]`` (eq. (18), sign of
    its second entry corrected).
    """
    x, z = frame_axes(q)
    px = py = pz = 0.0
    for k in range(NQ - 1, -1, -1):
        bx, by, bz = z[k]
        J[0, k] = by * pz - bz * py
        J[1, k] = bz * px - bx * pz
        J[2, k] = bx * py - by * px
        J[3, k], J[4, k], J[5, k] = bx, by, bz
        px += a[k] * x[k][0] + d[k] * bx
        py += a[k] * x[k][1] + d[k] * by
        pz += a[k] * x[k][2] + d[k] * bz


@kernel
def weighted_rates(
    J: Array, L: Array | None, xdot: Array, z: Array | None, rcond: float, qdot: Array
) -> None:
    r"""Nguyen eqs. (21)-(22): ``qdot`` (n,) from J (m, n), ``W = L L^T``, ``xdot`` (m,), z (n,).

    .. math::
        \dot q = J_W^\dagger \dot x + (I - J_W^\dagger J) z
               = W J^T (J W J^T)^{-1} (\dot x - J z) + z

    (the same vector, one solve), with ``B = J L``: ``B B^T y = xdot - J z`` by Cholesky's
    method (:func:`~rrc_pin.solvers.linalg.cholesky_solve`), then ``qdot = L B^T y + z``.
    ``L``
    lower triangular, None for ``W = I``; ``z`` None for zero (eq. (23): the minimum-norm
    rates). Forming ``B B^T`` squares the condition number: accurate to about eps kappa(B)^2
    (1e-13 at kappa = 40, 1e-8 at kappa = 1e4).

    Where the solve proves :math:`\lambda_{min}(B B^T) < \tau = \text{rcond}^2\,
    \text{trace}(B B^T)` (a pivot of the Cholesky factor not above 1e-12 times the largest
    diagonal entry, or :math:`|r| < \tau |y|`, since :math:`|r| \ge \lambda_{min} |y|`),
    the rates are ``L B^+ (xdot - J z) + z`` instead, the truncated pseudo-inverse (singular
    values ``<= rcond sigma_max`` dropped; one-sided Jacobi SVD): the least-squares rates of
    least :math:`(\dot q - z)^T W^{-1} (\dot q - z)`, finite.
    """
    m, n = J.shape
    r = xdot.copy()  # r = xdot - J z
    if z is not None:
        for i in range(m):
            for j in range(n):
                r[i] -= J[i, j] * z[j]
    B = J
    if L is not None:
        B = np.zeros((m, n))  # B = J L
        for i in range(m):
            for j in range(n):
                for k in range(j, n):
                    B[i, j] += J[i, k] * L[k, j]
    A = np.empty((m, m))  # A = B B^T = J W J^T
    trace = 0.0
    for i in range(m):
        for j in range(i, m):
            s = 0.0
            for k in range(n):
                s += B[i, k] * B[j, k]
            A[i, j] = A[j, i] = s
        trace += A[i, i]
    y, v = np.empty(m), np.empty(n)
    solved = cholesky_solve(A, r, y)
    if solved:
        size_r = size_y = 0.0
        for i in range(m):
            size_r += r[i] * r[i]
            size_y += y[i] * y[i]
        tau = rcond * rcond * trace
        solved = size_r >= tau * tau * size_y
    if solved:
        for j in range(n):  # v = B^T y
            v[j] = 0.0
            for i in range(m):
                v[j] += B[i, j] * y[i]
    else:
        US, V, sigma = B.copy(), np.empty((n, n)), np.empty(n)
        jacobi_svd(US, V, sigma)
        rank = 0
        for i in range(n):
            if sigma[i] > rcond * sigma[0]:
                rank += 1
        svd_rates(US, sigma, V, r, np.zeros(n), rank, v)  # v = B^+ r
    for i in range(n):  # qdot = L v + z
        if L is None:
            qdot[i] = v[i]
        else:
            qdot[i] = 0.0
            for k in range(i + 1):
                qdot[i] += L[i, k] * v[k]
        if z is not None:
            qdot[i] += z[i]


# -- entry points: one configuration, and compiled loops over N ----------------------------
# ``p`` (14,) holds a (the first seven) and d.


@kernel
def jacobian_at(p: Array, q: Array, J: Array) -> bool:
    """:func:`jacobian` at ``q`` (7,) into ``J`` (6, 7).

    False (J unset) unless ``q`` has that many entries, all finite.
    """
    if not finite(q, NQ):
        return False
    jacobian(p[:NQ], p[NQ:], q, J)
    return True


@kernel
def joint_rates_at(
    p: Array, q: Array, xdot: Array, L: Array | None, z: Array | None, rcond: float, qdot: Array
) -> bool:
    """:func:`weighted_rates` at ``q`` (7,) for ``xdot`` (6,) into ``qdot`` (7,).

    False (``qdot`` unset) unless ``q`` and ``xdot`` have that many entries, all finite.
    """
    if not (finite(q, NQ) and finite(xdot, TASK_DIM)):
        return False
    J = np.empty((TASK_DIM, NQ))
    jacobian(p[:NQ], p[NQ:], q, J)
    weighted_rates(J, L, xdot, z, rcond, qdot)
    return True


@kernel
def pose_batch(p: Array, Q: Array, out: Array) -> None:
    """:func:`pose` at each row of ``Q`` (N, 7) into ``out`` (N, 4, 4)."""
    for k in range(Q.shape[0]):
        pose(p[:NQ], p[NQ:], Q[k], out[k])


@kernel
def jacobian_batch(p: Array, Q: Array, out: Array) -> None:
    """:func:`jacobian` at each row of ``Q`` (N, 7) into ``out`` (N, 6, 7)."""
    for k in range(Q.shape[0]):
        jacobian(p[:NQ], p[NQ:], Q[k], out[k])


@kernel
def joint_rates_batch(
    p: Array, Q: Array, X: Array, L: Array | None, Z: Array | None, rcond: float, out: Array
) -> None:
    """:func:`weighted_rates` at each row of ``Q`` (N, 7), ``X`` (N, 6) into ``out`` (N, 7).

    ``Z``: (N, 7), or None.
    """
    J = np.empty((TASK_DIM, NQ))
    for k in range(Q.shape[0]):
        jacobian(p[:NQ], p[NQ:], Q[k], J)
        weighted_rates(J, L, X[k], None if Z is None else Z[k], rcond, out[k])
