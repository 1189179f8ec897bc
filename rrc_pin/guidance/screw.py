"""The screw of a finite rigid displacement (Nadkarni, chapter III), vectorised.

A displacement ``X2 = Q X1 + q`` (Nadkarni eq. (3-12)) is a rotation by ``theta`` about an axis
``u`` through the point ``rho`` (the foot of the normal from the origin, ``rho . u = 0``)
combined with a translation ``d`` along the same axis; its pitch is ``h = d / theta``.

Conventions (the thesis's): ``theta`` in (-pi, pi] [rad], right-handed about ``u``; the sign
of ``u`` is fixed as eq. (3-28) fixes it, ``u3 > 0`` (``u1 > 0`` where ``u3 = 0``, ``u2 > 0``
where ``u3 = u1 = 0``, eqs (3-33), (3-36)). A pure translation (``theta`` below
:data:`PURE_TRANSLATION`) has ``u`` along the motion, ``d = |q| >= 0``, ``theta = 0``,
``h = inf`` and ``rho = 0`` (eq. (3-29)); the identity has ``u = z``, ``d = theta = h = 0``.

Where the thesis solves eqs (3-27) and (3-41) with a free constant beta, this module takes the
axis from the skew part of ``Q`` (its symmetric part near a half turn, where the skew part
vanishes) and the foot of the normal in closed form,
``rho = (q_perp + cot(theta / 2) u x q) / 2``: the same numbers (tests/test_screw.py proves
it against eqs (3-41), (3-50)-(3-54) and ``pinocchio.log6``), without the special cases of
eqs (3-30)-(3-35).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.errors import InvalidInput
from rrc_pin.solvers.checks import finite_array, real_array, within_length

Array = npt.NDArray[np.float64]

PURE_TRANSLATION = 1e-12
"""Rotation angle [rad] below which a displacement is taken as a pure translation."""
SIGN_TOL = 1e-12
"""An axis component below this is taken as zero when the sign of ``u`` is fixed."""


class Screw(NamedTuple):
    """The screw of a displacement; every field batched over the leading shape ``(...)``.

    Attributes:
        u: (..., 3) unit vector along the screw axis, base frame.
        rho: (..., 3) foot of the normal from the origin to the axis [m or the input's unit].
        d: (...) translation along ``u``.
        theta: (...) rotation about ``u`` [rad], in (-pi, pi].
        h: (...) pitch ``d / theta`` [length/rad]; ``inf`` for a pure translation, 0 for none.
    """

    u: Array
    rho: Array
    d: Array
    theta: Array
    h: Array


def frames_from_points(points: npt.ArrayLike, name: str = "points") -> Array:
    """Poses of the body frames given by three points each (Nadkarni eqs (3-1)-(3-3), (4-20)).

    Args:
        points: (..., 3, 3) rows: the origin (point 1), a point on +z (point 2), a point in
            the x-z plane on the +x side (point 3).
        name: Argument name for errors.

    Returns:
        (..., 4, 4) poses in the points' frame and unit.

    Raises:
        InvalidInput: Wrong shape, a non-finite coordinate, coincident or collinear points.
    """
    P = real_array(points, name, "expected points of shape (..., 3, 3)")
    if P.ndim < 2 or P.shape[-2:] != (3, 3):
        raise InvalidInput(name, f"expected shape (..., 3, 3), got {P.shape}")
    if not np.isfinite(P).all():
        raise InvalidInput(name, "non-finite coordinate")
    within_length(P, name)
    a, b, c = P[..., 0, :], P[..., 1, :], P[..., 2, :]
    ab, ac = b - a, c - a
    n_ab = np.linalg.norm(ab, axis=-1)
    y = np.cross(ab, ac)
    n_y = np.linalg.norm(y, axis=-1)
    scale = np.maximum(n_ab, np.linalg.norm(ac, axis=-1))
    if np.any(n_ab <= 1e-12 * np.maximum(scale, 1.0)) or np.any(n_y <= 1e-9 * scale**2):
        raise InvalidInput(name, "the three points of a body must be distinct and not collinear")
    z = ab / n_ab[..., None]
    y = y / n_y[..., None]
    T = np.zeros((*P.shape[:-2], 4, 4))
    T[..., :3, 0] = np.cross(y, z)
    T[..., :3, 1] = y
    T[..., :3, 2] = z
    T[..., :3, 3] = a
    T[..., 3, 3] = 1.0
    return T


def screw_from_points(points_1: npt.ArrayLike, points_2: npt.ArrayLike) -> Screw:
    """Screw taking a body from its first to its second position, each given by three points.

    Args:
        points_1: (..., 3, 3) the body's three points in the first position (see
            :func:`frames_from_points`).
        points_2: (..., 3, 3) the same in the second position.

    Raises:
        InvalidInput: Naming ``points_1`` or ``points_2``: bad shape, non-finite, coincident
            or collinear points.
    """
    T1 = frames_from_points(points_1, "points_1")
    T2 = frames_from_points(points_2, "points_2")
    return screw_from_poses(T1, T2)


def screw_from_poses(T1: npt.ArrayLike | pin.SE3, T2: npt.ArrayLike | pin.SE3) -> Screw:
    """Screw taking a body from pose ``T1`` to pose ``T2`` (both (..., 4, 4) or ``pin.SE3``).

    The displacement is ``T2 T1^-1``: ``Q = Q2 Q1^T``, ``q = q2 - Q q1`` (Nadkarni eq. (3-13)).

    Raises:
        InvalidInput: Naming ``T1`` or ``T2``: bad shape, non-finite, not rigid transforms.
    """
    A = _poses(T1.homogeneous if isinstance(T1, pin.SE3) else T1, "T1")
    B = _poses(T2.homogeneous if isinstance(T2, pin.SE3) else T2, "T2")
    Q = B[..., :3, :3] @ np.swapaxes(A[..., :3, :3], -1, -2)
    q = B[..., :3, 3] - (Q @ A[..., :3, 3, None])[..., 0]
    return screw_of_displacement(Q, q)


def screw_of_displacement(Q: npt.ArrayLike, q: npt.ArrayLike) -> Screw:
    """Screw of the displacement ``x -> Q x + q`` (Nadkarni eq. (3-12)).

    Args:
        Q: (..., 3, 3) rotation matrices.
        q: (..., 3) translations.

    Raises:
        InvalidInput: Bad shapes, non-finite entries, or ``Q`` not a rotation.
    """
    Q = _rotations(Q, "Q")
    q = finite_array(q, "q")
    within_length(q, "q")
    if q.shape != Q.shape[:-1]:
        raise InvalidInput("q", f"expected translations of shape {Q.shape[:-1]} (Q's), got "
                           f"{q.shape}")  # fmt: skip
    u, theta = axis_angle(Q)
    pure = np.abs(theta) < PURE_TRANSLATION
    shift = np.linalg.norm(q, axis=-1)
    moves = pure & (shift > 0.0)
    u = np.where(moves[..., None], q / np.where(moves, shift, 1.0)[..., None], u)  # eq. (3-29)
    theta = np.where(pure, 0.0, theta)
    d = np.where(pure, shift, np.sum(u * q, axis=-1))
    q_perp = q - d[..., None] * u
    half = np.where(pure, 1.0, theta / 2.0)
    rho = 0.5 * (q_perp + (np.cos(half) / np.sin(half))[..., None] * np.cross(u, q))
    rho = np.where(pure[..., None], 0.0, rho)
    h = np.where(pure, np.where(moves, np.inf, 0.0), d / np.where(pure, 1.0, theta))
    return Screw(u=u, rho=rho, d=d, theta=theta, h=h)


def displacement(screw: Screw) -> Array:
    """The displacement (..., 4, 4) of a screw: rotation by ``theta`` about the axis, then ``d``.

    ``Q`` by Rodrigues' formula and ``q = (I - Q) rho + d u`` (Nadkarni eq. (3-39)).

    Raises:
        InvalidInput: ``screw`` is not a :class:`Screw` of finite arrays (:func:`check_screw`).
    """
    screw = check_screw(screw)
    u, theta = screw.u, screw.theta
    K = _skew(u)
    s, c = np.sin(theta)[..., None, None], np.cos(theta)[..., None, None]
    Q = np.eye(3) + s * K + (1.0 - c) * (K @ K)
    rho = np.asarray(screw.rho)
    q = rho - (Q @ rho[..., None])[..., 0] + np.asarray(screw.d)[..., None] * u
    T = np.zeros((*theta.shape, 4, 4))
    T[..., :3, :3] = Q
    T[..., :3, 3] = q
    T[..., 3, 3] = 1.0
    return T


def screw_twist(screw: Screw) -> Array:
    """The twist (..., 6), rows [v; w], whose exponential is the screw's displacement.

    ``w = theta u`` and ``v = d u - theta u x rho``: the velocity of the base origin, base axes
    (Pinocchio's WORLD frame; Nadkarni's vector B of eq. (4-19a) for ``theta / k``, rows
    reordered). ``pinocchio.log6`` of the displacement returns the same.

    Raises:
        InvalidInput: ``screw`` is not a :class:`Screw` of finite arrays (:func:`check_screw`).
    """
    screw = check_screw(screw)
    u, theta = screw.u, screw.theta[..., None]
    v = np.asarray(screw.d)[..., None] * u - theta * np.cross(u, np.asarray(screw.rho))
    out: Array = np.concatenate([v, theta * u], axis=-1)
    return out


def check_screw(screw: Screw, name: str = "screw") -> Screw:
    """``screw`` with its fields as finite float arrays of matching shapes (its pitch as given).

    Raises:
        InvalidInput: Not a :class:`Screw`, a field not finite (or beyond ``MAX_LENGTH``), or
            shapes that do not match (``u``, ``rho`` (..., 3); ``d``, ``theta`` (...)), naming
            ``name``.
    """
    if not isinstance(screw, Screw):
        raise InvalidInput(name, f"expected a guidance.Screw, got {type(screw).__name__}")
    u, rho, d, theta = (finite_array(v, name) for v in screw[:4])
    for value in (rho, d, theta):
        within_length(value, name)
    if u.shape[-1:] != (3,) or rho.shape != u.shape or not d.shape == theta.shape == u.shape[:-1]:
        raise InvalidInput(name, f"fields of shapes u {u.shape}, rho {rho.shape}, d {d.shape}, "
                           f"theta {theta.shape}: expected (..., 3), (..., 3), (...), (...)")
    return Screw(u, rho, d, theta, screw.h)


def axis_angle(Q: Array) -> tuple[Array, Array]:
    """Unit axis (..., 3) with the thesis's sign and angle (...) in (-pi, pi] of rotations Q.

    Well defined up to and including a half turn: there the skew part of ``Q`` vanishes and
    the axis comes from its symmetric part, ``u u^T = (Q + Q^T - 2 cos(theta) I) / (2 (1 -
    cos(theta)))``; the thesis's sign (``u3 > 0``, else ``u1 > 0``, else ``u2 > 0``) makes
    the choice between ``u`` and ``-u`` of a half turn (``theta = pi``) the same every time.
    """
    vee = np.stack(
        [Q[..., 2, 1] - Q[..., 1, 2], Q[..., 0, 2] - Q[..., 2, 0], Q[..., 1, 0] - Q[..., 0, 1]],
        axis=-1,
    )  # 2 sin(theta) u
    c = np.clip((np.trace(Q, axis1=-2, axis2=-1) - 1.0) / 2.0, -1.0, 1.0)
    n_vee = np.linalg.norm(vee, axis=-1)
    # Near a half turn the skew part vanishes: take u from Q + Q^T - (tr Q - 1) I = 2(1 - c) u u^T,
    # its column of largest diagonal, signed by the skew part.
    S = Q + np.swapaxes(Q, -1, -2) - (2.0 * c)[..., None, None] * np.eye(3)
    j = np.argmax(np.diagonal(S, axis1=-2, axis2=-1), axis=-1)
    col = np.take_along_axis(S, j[..., None, None], axis=-1)[..., 0]
    col = col / np.maximum(np.linalg.norm(col, axis=-1), 1e-300)[..., None]
    col = col * np.where(np.sum(col * vee, axis=-1) < 0.0, -1.0, 1.0)[..., None]
    use_skew = (c > -0.5) & (n_vee > 0.0)
    u = np.where(use_skew[..., None], vee / np.where(n_vee > 0, n_vee, 1.0)[..., None], col)
    u = np.where((n_vee == 0.0)[..., None] & (c > 0.0)[..., None], (0.0, 0.0, 1.0), u)
    theta = np.arctan2(np.sum(u * vee, axis=-1) / 2.0, c)
    flip = _sign_of_axis(u) < 0.0
    u = np.where(flip[..., None], -u, u)
    theta = np.where(flip, -theta, theta)
    theta = np.where(theta <= -np.pi, np.pi, theta)
    return u, theta


def _sign_of_axis(u: Array) -> Array:
    """+1 where ``u`` has the thesis's sign (u3 > 0, else u1 > 0, else u2 > 0), else -1."""
    first = np.where(
        np.abs(u[..., 2]) > SIGN_TOL,
        u[..., 2],
        np.where(np.abs(u[..., 0]) > SIGN_TOL, u[..., 0], u[..., 1]),
    )
    return np.where(first < 0.0, -1.0, 1.0)


def _skew(u: Array) -> Array:
    K = np.zeros((*u.shape[:-1], 3, 3))
    K[..., 0, 1], K[..., 0, 2] = -u[..., 2], u[..., 1]
    K[..., 1, 0], K[..., 1, 2] = u[..., 2], -u[..., 0]
    K[..., 2, 0], K[..., 2, 1] = -u[..., 1], u[..., 0]
    return K


def _rotations(Q: npt.ArrayLike, name: str) -> Array:
    R = real_array(Q, name, "expected rotations of shape (..., 3, 3)")
    if R.ndim < 2 or R.shape[-2:] != (3, 3):
        raise InvalidInput(name, f"expected shape (..., 3, 3), got {R.shape}")
    if not np.isfinite(R).all():
        raise InvalidInput(name, "non-finite entry")
    with np.errstate(over="ignore", invalid="ignore"):  # huge entries: not a rotation
        error = np.abs(R @ np.swapaxes(R, -1, -2) - np.eye(3)).max(initial=0.0)
        determinant = np.linalg.det(R)
    if not error <= 1e-9 or np.any(~(determinant > 0.0)):
        raise InvalidInput(name, f"not a rotation (|Q Q^T - I| = {error:.2e} or det <= 0)")
    return R


def _poses(T: npt.ArrayLike, name: str) -> Array:
    A = real_array(T, name, "expected poses of shape (..., 4, 4)")
    if A.ndim < 2 or A.shape[-2:] != (4, 4):
        raise InvalidInput(name, f"expected shape (..., 4, 4), got {A.shape}")
    if not np.isfinite(A).all():
        raise InvalidInput(name, "non-finite entry")
    if np.abs(A[..., 3, :] - (0.0, 0.0, 0.0, 1.0)).max(initial=0.0) > 1e-9:
        raise InvalidInput(name, "the last row of a pose must be (0, 0, 0, 1)")
    _rotations(A[..., :3, :3], name)
    within_length(A[..., :3, 3], name)
    return A

