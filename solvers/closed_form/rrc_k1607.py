"""Closed-form kinematics and joint rates of the 7-DOF RRC K-1607 (Nguyen & Zhou, NAG 5-1124).

The arm of Nguyen Table 1 in Craig's modified DH (Nguyen eq. (2)), twists fixed at
``alpha_{i-1} = (0, -90, 90, -90, 90, -90, 90)`` deg. The hand frame is frame 7.

- Forward kinematics: Nguyen eqs. (4)-(11), with the typos of eqs. (5), (8) and (9)
  corrected (docs/errata.md). The auxiliaries are the axes of the DH frames:
  ``x3 = (f2, f4, -s2 c3)``, ``z4 = (f1, f3, s2 s3)``, ``x4 = (g1, g3, f5)``,
  ``z5 = (g2, g4, f6)``, ``x5 = (h2, h4, g6)``, ``z6 = (h1, h3, g5)``, ``x6 = (j1, j2, h5)``.
  Every ``a_{i-1}`` and ``d_i`` is honoured; for Table 1 (``a0 = a1 = d1 = d2 = d4 = d6 =
  d7 = 0``) the position reduces to Nguyen's ``p``.
- Jacobian: the cross-product method, Nguyen eqs. (12)-(17), all seven columns
  ``J_i = [z_i x (p - o_i); z_i]`` from the same auxiliaries (the report prints only
  columns 1-3, eqs. (18)-(19)). Rows ``[v; w]``: velocity of frame 7's origin and angular
  velocity, base axes (``world_aligned``, Pinocchio's LOCAL_WORLD_ALIGNED).
- Joint rates: the weighted pseudo-inverse with null-space term, Nguyen eqs. (21)-(22),
  evaluated as ``qdot = J_W^+ (xdot - J z) + z`` (the same vector, one solve). With
  ``W = L L^T`` and ``B = J L``: ``B B^T y = xdot - J z`` by block elimination with 3x3
  blocks (:func:`_solve_spd6`), then ``qdot = L B^T y + z`` (eq. (22) as printed). With
  ``W = I`` and ``z = 0`` it is the minimum-norm solution of eq. (23). Forming ``B B^T``
  squares the condition number: the rates are accurate to about ``eps kappa(B)^2`` (1e-13 at
  kappa = 40, 1e-8 at kappa = 1e4).

Singularities: with ``tau = rcond^2 trace(B B^T)``, the rates come from the SVD form of
:mod:`solvers.closed_form.weighted` (``L B^+ (xdot - J z) + z``, singular values below
``rcond sigma_max`` dropped: the least-squares rates of least ``(qdot - z)^T W^-1
(qdot - z)``, finite for any finite input, never NaN) where the solve proves
``lambda_min(B B^T) < tau``: a 3x3 block determinant <= 0, or ``|b| < tau |y|`` for the
solution ``y`` of ``B B^T y = b`` (``|b| >= lambda_min |y|`` always). Damping is the QP
resolver's business, not this module's. Elsewhere the exact rates are returned, however
large.

Every formula is written once, for Python floats (one configuration) and (N,) arrays (a
batch, in blocks of :data:`~solvers.closed_form._batch.CHUNK` configurations) alike.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

from solvers.closed_form._batch import blocks, cos_sin
from solvers.closed_form.base import Array, ClosedForm, Entry, dot, stack_entries
from solvers.closed_form.weighted import pseudo_inverse, weight_factor
from solvers.validation import as_array, as_vector, finite_number

NQ = 7
TASK_DIM = 6
ALPHA_DEG = (0.0, -90.0, 90.0, -90.0, 90.0, -90.0, 90.0)
"""Nguyen Table 1 twists alpha_{i-1} [deg]; the closed form is derived for these."""
DEFAULT_RCOND = 1e-6
"""Relative singular-value threshold of ``J W^1/2`` below which the SVD form answers."""


def _kinematics(
    c: Sequence[Entry],
    s: Sequence[Entry],
    a: Sequence[float],
    d: Sequence[float],
    pose: bool = True,
) -> tuple[list[list[Entry]], list[Entry], list[Any]]:
    """Hand pose and Jacobian from the joint cosines ``c`` and sines ``s`` (7 each).

    Works element-wise: every entry is a float, or an (N,) array for N configurations.

    Returns:
        ``(R, p, J_cols)``: ``R`` 3 rows of 3 entries (Nguyen eq. (4): columns n, s, a),
        empty unless ``pose`` (the Jacobian does not need it, nor theta_7), ``p`` 3 entries
        [m], ``J_cols`` the 7 columns of J, 6 entries each (rows [v; w], ``world_aligned``).
    """
    c1, c2, c3, c4, c5, c6, c7 = c
    s1, s2, s3, s4, s5, s6, s7 = s
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
    # Nguyen eqs. (5)-(7): the columns n = x7, s = y7 and a = z7 of the hand orientation.
    z7 = (s6 * h2 + c6 * g2, s6 * h4 + c6 * g4, s6 * g6 + c6 * f6)
    R: list[list[Entry]] = []
    if pose:
        R = [
            [s7 * h1 + c7 * j1, c7 * h1 - s7 * j1, z7[0]],
            [s7 * h3 + c7 * j2, c7 * h3 - s7 * j2, z7[1]],
            [s7 * g5 + c7 * h5, c7 * g5 - s7 * h5, z7[2]],
        ]
    # Joint axes b_i = z_i (Nguyen eq. (14)) and the x axes of frames 0-6.
    z: tuple[Any, ...] = (None, (-s1, c1, 0.0), (c1s2, s1s2, c2), (f1, f3, s2s3), (g2, g4, f6),
                          (h1, h3, g5), z7)  # fmt: skip
    x: tuple[Any, ...] = (None, (c1, s1, 0.0), (c1c2, s1c2, -s2), (f2, f4, -s2c3), (g1, g3, f5),
                          (h2, h4, g6), (j1, j2, h5))  # fmt: skip
    # Nguyen eqs. (12)-(13), (16): J_i = [b_i x r_i; b_i] with r_i = p - o_i, from the hand
    # back: r_7 = 0 (so J_7 = [0; z_7]), r_{i-1} = r_i + a_{i-1} x_{i-1} + d_i z_i (Nguyen
    # eq. (2), column 4).
    cols: list[Any] = [None] * NQ
    cols[6] = (0.0, 0.0, 0.0, *z7)
    rx, ry, rz = _step(0.0, 0.0, 0.0, a[6], x[6], d[6], z7)
    for k in range(NQ - 2, 1, -1):
        bx, by, bz = z[k]
        cols[k] = (by * rz - bz * ry, bz * rx - bx * rz, bx * ry - by * rx, bx, by, bz)
        rx, ry, rz = _step(rx, ry, rz, a[k], x[k], d[k], z[k])
    # b_2 = (-s1, c1, 0): Nguyen eq. (18), second column, with r_2 in place of p.
    cols[1] = (c1 * rz, s1 * rz, -s1 * ry - c1 * rx, -s1, c1, 0.0)
    rx, ry, rz = _step(rx, ry, rz, a[1], x[1], d[1], z[1])
    # b_1 = (0, 0, 1): Nguyen eq. (18), first column (sign of its second entry corrected).
    cols[0] = (-ry, rx, 0.0, 0.0, 0.0, 1.0)
    # p = r_1 + o_1 with o_1 = a_0 x_0 + d_1 z_1, x_0 = (1, 0, 0), z_1 = (0, 0, 1).
    p = [rx + a[0], ry, rz + d[0]]
    return R, p, cols


def _step(
    rx: Entry, ry: Entry, rz: Entry, a: float, x: Sequence[Entry], d: float, z: Sequence[Entry]
) -> tuple[Entry, Entry, Entry]:
    """``r + a x + d z`` for 3-vectors, skipping the terms whose length is zero."""
    if d:
        rx, ry, rz = rx + d * z[0], ry + d * z[1], rz + d * z[2]
    if a:
        rx, ry, rz = rx + a * x[0], ry + a * x[1], rz + a * x[2]
    return rx, ry, rz


class RrcK1607ClosedForm(ClosedForm):
    """Nguyen's closed forms for the RRC K-1607 (7 revolute joints, 6-D task).

    Frames: :attr:`frame` is the generated URDF's ``"tool"`` frame, Nguyen's frame 7; twists
    are its origin's velocity and its angular velocity in base axes (``world_aligned``).

    Args:
        a: The seven ``a_{i-1}`` of Nguyen Table 1 [m] (``a_0`` first).
        d: The seven ``d_i`` of Nguyen Table 1 [m] (``d_1`` first).
        rcond: Relative singular-value threshold of ``J W^1/2`` for the SVD form
            (module docstring).

    Raises:
        InputError: ``a`` or ``d`` not seven finite numbers, or ``rcond`` not in (0, 1).
    """

    nq = NQ
    task_dim = TASK_DIM

    def __init__(
        self, *, a: npt.ArrayLike, d: npt.ArrayLike, rcond: float = DEFAULT_RCOND
    ) -> None:
        self.a = tuple(as_vector(a, "a", NQ).tolist())
        self.d = tuple(as_vector(d, "d", NQ).tolist())
        self.rcond = finite_number(rcond, "rcond", 0.0, inclusive=False, upper=1.0)

    def __repr__(self) -> str:
        return f"RrcK1607ClosedForm(a={self.a}, d={self.d})"

    def _columns(self, q: Array, pose: bool = False) -> tuple[Any, Any, list[Any]]:
        """:func:`_kinematics` of one configuration (7,), on Python floats."""
        qs = q.tolist()
        return _kinematics([math.cos(v) for v in qs], [math.sin(v) for v in qs], self.a, self.d,
                           pose)  # fmt: skip

    def fk(self, q: npt.ArrayLike) -> Array:
        """Pose (4, 4) of frame 7 in frame 0, translation [m], Nguyen eqs. (4)-(11).

        ``q``: joint angles theta_1..theta_7 (7,) [rad].

        Raises:
            InputError: ``q`` is not a finite (7,) vector.
        """
        R, p, _ = self._columns(as_vector(q, "q", NQ), pose=True)
        return np.array([R[0] + [p[0]], R[1] + [p[1]], R[2] + [p[2]], [0.0, 0.0, 0.0, 1.0]])

    def fk_batch(self, Q: npt.ArrayLike) -> Array:
        """Poses of frame 7 at N configurations ``Q`` (N, 7) [rad]: (N, 4, 4).

        Raises:
            InputError: ``Q`` is not a finite (N, 7) array.
        """
        Q = as_array(Q, "Q", (None, NQ))
        C, S = cos_sin(np.ascontiguousarray(Q.T))
        R, p, _ = _kinematics(list(C), list(S), self.a, self.d)
        return stack_entries([R[0] + [p[0]], R[1] + [p[1]], R[2] + [p[2]],
                              [0.0, 0.0, 0.0, 1.0]], Q.shape[0])  # fmt: skip

    def jacobian(self, q: npt.ArrayLike) -> Array:
        """Jacobian (6, 7) of frame 7 at ``q`` (7,) [rad], Nguyen eqs. (12)-(17), all columns.

        Rows [v; w], ``world_aligned`` ([m/rad] then [1]).

        Raises:
            InputError: ``q`` is not a finite (7,) vector.
        """
        return np.ascontiguousarray(np.array(self._columns(as_vector(q, "q", NQ))[2]).T)

    def jacobian_batch(self, Q: npt.ArrayLike) -> Array:
        """Jacobians of frame 7 at ``Q`` (N, 7) [rad]: (N, 6, 7), rows [v; w], ``world_aligned``.

        Raises:
            InputError: ``Q`` is not a finite (N, 7) array.
        """
        Q = as_array(Q, "Q", (None, NQ))
        C, S = cos_sin(np.ascontiguousarray(Q.T[: NQ - 1]))  # theta_7 does not move J
        cols = _kinematics([*C, None], [*S, None], self.a, self.d, pose=False)[2]
        return stack_entries(list(zip(*cols, strict=True)), Q.shape[0])

    def joint_rates(
        self,
        q: npt.ArrayLike,
        xdot: npt.ArrayLike,
        W: npt.ArrayLike | None = None,
        z: npt.ArrayLike | None = None,
    ) -> Array:
        r"""Joint rates by the weighted pseudo-inverse, Nguyen eqs. (21)-(22).

        .. math::
            \dot q = J_W^\dagger \dot x + (I_7 - J_W^\dagger J) z,
            \quad J_W^\dagger = W J^T (J W J^T)^{-1}

        Among all ``qdot`` with ``J qdot = xdot`` it minimises
        ``(qdot - z)^T W^-1 (qdot - z)``; ``W = I``, ``z = 0`` give the minimum-norm rates of
        eq. (23). Near a singularity: the SVD form of the module docstring, never NaN.

        Args:
            q: Joint angles (7,) [rad].
            xdot: Hand twist (6,), [m/s] then [rad/s], ``world_aligned``.
            W: Weighting matrix: (7, 7) symmetric positive definite or (7,) positive
                (diagonal); None for identity.
            z: Joint-rate vector (7,) [rad/s] whose null-space part is added; None for zero.

        Returns:
            Joint rates (7,) [rad/s].

        Raises:
            InputError: Wrong shape or non-finite entries in any argument (named), or ``W``
                not symmetric positive definite.
        """
        qv, b = as_vector(q, "q", NQ), as_vector(xdot, "xdot", TASK_DIM)
        L = weight_factor(W, NQ)
        zv = None if z is None else as_vector(z, "z", NQ)
        J = np.array(self._columns(qv)[2]).T  # one configuration: a numpy (6, 7) matrix
        return _weighted_rates(J, b, zv, L, self.rcond)

    def joint_rates_batch(
        self, Q: npt.ArrayLike, X: npt.ArrayLike, W: npt.ArrayLike | None = None,
        Z: npt.ArrayLike | None = None,
    ) -> Array:  # fmt: skip
        """Batch :meth:`joint_rates`: ``Q`` (N, 7) [rad], ``X`` (N, 6) -> (N, 7) [rad/s].

        ``X``: hand twists, ``world_aligned``; ``W``: one weighting matrix for all N; ``Z``:
        (N, 7) [rad/s] or None. Raises as :meth:`joint_rates`.
        """
        Q, X = self._check_batch(Q, X)
        L = weight_factor(W, NQ)
        if Z is not None:
            Z = as_array(Z, "Z", (Q.shape[0], NQ))
        out = np.empty((Q.shape[0], NQ))
        C, S = cos_sin(np.ascontiguousarray(Q.T[: NQ - 1]))
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            for rows in blocks(Q.shape[0]):
                c, s = [v[rows] for v in C], [v[rows] for v in S]
                J = list(zip(*_kinematics([*c, None], [*s, None], self.a, self.d, False)[2],
                             strict=True))  # fmt: skip
                z = None if Z is None else np.ascontiguousarray(Z[rows].T)
                out[rows] = _weighted_rates(J, np.ascontiguousarray(X[rows].T), z, L, self.rcond)
        return out


def _weighted_rates(J: Any, b: Array, z: Array | None, L: Array | None, rcond: float) -> Array:
    r"""Nguyen eq. (22) as ``qdot = L B^T y + z`` with ``B = J L``, ``B B^T y = xdot - J z``.

    ``y`` by :func:`_solve_spd6`, or the SVD form where it fails (module docstring).

    Each step is written once; only the products are spelled two ways. One configuration:
    ``J`` a numpy (6, 7), ``b`` = xdot (6,), ``z`` (7,) or None -> (7,); the products by
    numpy, the solve on floats (16 us a call against 38 us with :func:`dot` on floats, 250 us
    for a block of one, measured). A block of M: ``J`` 6 rows of 7 entries ((M,) arrays or
    constant floats), ``b`` (6, M), ``z`` (7, M) or None -> (M, 7); the products by
    :func:`dot`, which skips the constant entries.
    """
    one = isinstance(J, np.ndarray)
    if z is not None:
        b = b - (J.dot(z) if one else np.array([dot(r, list(z)) for r in J]))
    B = J
    if L is not None:
        B = J.dot(L) if one else [[dot(r, c) for c in L.T.tolist()] for r in J]
    if one:  # A = B B^T
        A = B.dot(B.T).tolist()
    else:  # its upper triangle, all that _solve_spd6 reads
        A = [[dot(B[i], B[j]) if j >= i else None for j in range(TASK_DIM)]
             for i in range(TASK_DIM)]  # fmt: skip
    tau = rcond**2 * sum(A[i][i] for i in range(TASK_DIM))
    e = b.tolist() if one else list(b)  # the entries of b: floats, or (M,) rows
    y = _solve_spd6(A, e)
    ok = dot(e, e) >= tau * tau * dot(y, y)  # False for NaN: not positive definite
    v: Any = B.T.dot(y) if one else [dot(col, y) for col in zip(*B, strict=True)]  # B^T y
    if L is not None:
        v = L.dot(v) if one else [dot(r, v) for r in L.tolist()]
    qdot: Array = v if one else np.stack(v, axis=1)  # a new array: rows below are views
    if not (ok if one else np.all(ok)):  # one configuration: a bool (np.all costs 2 us)
        bad = np.flatnonzero(~np.atleast_1d(ok))
        Js = J[None] if one else stack_entries(J, len(qdot))
        rhs = b.T.reshape(-1, TASK_DIM, 1)[bad]
        qdot.reshape(-1, NQ)[bad] = (pseudo_inverse(Js[bad], L, rcond) @ rhs)[..., 0]
    return qdot if z is None else qdot + z.T


def _positive(det: Entry) -> Entry:
    """``det`` where > 0, else NaN: a solve that is not positive definite fails visibly."""
    if isinstance(det, np.ndarray):
        return np.where(det > 0.0, det, np.nan)
    return det if det > 0.0 else math.nan


def _inv3(
    a00: Entry, a01: Entry, a02: Entry, a11: Entry, a12: Entry, a22: Entry
) -> tuple[Entry, ...]:
    """Inverse of a symmetric positive-definite 3x3 matrix by cofactors.

    Returns its entries (00, 01, 02, 11, 12, 22); NaN if the determinant is not positive.
    """
    c00 = a11 * a22 - a12 * a12
    c01 = a02 * a12 - a01 * a22
    c02 = a01 * a12 - a02 * a11
    r = 1.0 / _positive(a00 * c00 + a01 * c01 + a02 * c02)
    return (c00 * r, c01 * r, c02 * r, (a00 * a22 - a02 * a02) * r,
            (a01 * a02 - a00 * a12) * r, (a00 * a11 - a01 * a01) * r)  # fmt: skip


def _solve_spd6(A: list[list[Any]], b: Sequence[Entry]) -> list[Entry]:
    """Solve ``A y = b`` for a symmetric positive-definite 6x6 ``A`` (upper triangle read).

    Block elimination with 3x3 blocks ``A = [[P, Q], [Q^T, S]]``: the Schur complement
    ``S' = S - Q^T P^-1 Q`` is positive definite with ``lambda_min(S') >= lambda_min(A)``,
    so no pivoting is needed (as in Cholesky). Element-wise: floats or (N,) arrays; NaN
    where a block is not positive definite.
    """
    (p00, p01, p02, q00, q01, q02), (_, p11, p12, q10, q11, q12) = A[0], A[1]
    (_, _, p22, q20, q21, q22), (_, _, _, s00, s01, s02) = A[2], A[3]
    s11, s12, s22 = A[4][4], A[4][5], A[5][5]
    i00, i01, i02, i11, i12, i22 = _inv3(p00, p01, p02, p11, p12, p22)
    # M = P^-1 Q
    m00 = i00 * q00 + i01 * q10 + i02 * q20
    m01 = i00 * q01 + i01 * q11 + i02 * q21
    m02 = i00 * q02 + i01 * q12 + i02 * q22
    m10 = i01 * q00 + i11 * q10 + i12 * q20
    m11 = i01 * q01 + i11 * q11 + i12 * q21
    m12 = i01 * q02 + i11 * q12 + i12 * q22
    m20 = i02 * q00 + i12 * q10 + i22 * q20
    m21 = i02 * q01 + i12 * q11 + i22 * q21
    m22 = i02 * q02 + i12 * q12 + i22 * q22
    # T = (S - Q^T M)^-1
    t00, t01, t02, t11, t12, t22 = _inv3(
        s00 - (q00 * m00 + q10 * m10 + q20 * m20),
        s01 - (q00 * m01 + q10 * m11 + q20 * m21),
        s02 - (q00 * m02 + q10 * m12 + q20 * m22),
        s11 - (q01 * m01 + q11 * m11 + q21 * m21),
        s12 - (q01 * m02 + q11 * m12 + q21 * m22),
        s22 - (q02 * m02 + q12 * m12 + q22 * m22),
    )
    b0, b1, b2, b3, b4, b5 = b
    # lower half: y_S = T (b_S - M^T b_P)
    e0 = b3 - (m00 * b0 + m10 * b1 + m20 * b2)
    e1 = b4 - (m01 * b0 + m11 * b1 + m21 * b2)
    e2 = b5 - (m02 * b0 + m12 * b1 + m22 * b2)
    y3 = t00 * e0 + t01 * e1 + t02 * e2
    y4 = t01 * e0 + t11 * e1 + t12 * e2
    y5 = t02 * e0 + t12 * e1 + t22 * e2
    # upper half: y_P = P^-1 b_P - M y_S
    y0 = i00 * b0 + i01 * b1 + i02 * b2 - (m00 * y3 + m01 * y4 + m02 * y5)
    y1 = i01 * b0 + i11 * b1 + i12 * b2 - (m10 * y3 + m11 * y4 + m12 * y5)
    y2 = i02 * b0 + i12 * b1 + i22 * b2 - (m20 * y3 + m21 * y4 + m22 * y5)
    return [y0, y1, y2, y3, y4, y5]
