r"""Quaternions (Euler parameters) and differential rotations, Nguyen & Zhou eqs. (24)-(37).

A quaternion is ``(eta, s)`` with ``s = (beta, gamma, xi)``, stored as a (4,) array
``[eta, beta, gamma, xi]`` (scalar first, as in the report), unit norm, ``eta >= 0``. It is
the active rotation by angle ``theta`` about the unit axis ``k``:
``eta = cos(theta/2)``, ``s = sin(theta/2) k``, and

.. math:: R = (\eta^2 - s^T s) I_3 + 2 s s^T + 2 \eta\, s^\times

(Nguyen eq. (28) corrected: eq. (26) and the skew matrix of eq. (29) fix this sign, and the
identity is 3x3; docs/errata.md). Products follow ``Q{R_a R_b} = Q{R_a} * Q{R_b}`` (Hamilton).

Every function takes one item or a stack: ``R`` (3, 3) or (N, 3, 3), quaternions (4,) or
(N, 4), rotation vectors (3,) or (N, 3); the result has the matching leading shape.

- :func:`quaternion_from_matrix`: ``Q{R}``, Nguyen eqs. (25)-(26). Eq. (26) divides by
  ``4 eta``, which vanishes at 180 deg; this uses Shepperd's method instead (S. W. Shepperd,
  "Quaternion from rotation matrix", J. Guidance and Control 1(3):223-224, 1978): of
  ``4 eta^2 = 1 + tr R`` and ``4 beta^2 = 1 + r11 - r22 - r33`` (and the like for gamma, xi)
  the largest is taken from its square root and the other three from sums or differences
  of off-diagonal pairs divided by it (never less than 1/2), which is eq. (26) itself when
  ``eta`` is the largest. At exactly 180 deg (``eta = 0``) the sign is fixed by the largest
  component of ``s`` being positive.
- :func:`matrix_from_quaternion` (eqs. (27)-(28) corrected), :func:`quaternion_difference`
  (eqs. (32)-(34)), :func:`differential_rotation` (eq. (37)), :func:`small_rotation`
  (eqs. (35)-(36) corrected) and :func:`rotation_vector` (the exact log map).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.checks import as_array
from rrc_pin.solvers.closed_form.base import first
from rrc_pin.solvers.errors import InvalidInput

Array = npt.NDArray[np.float64]
ORTHONORMAL_TOL = 1e-6
"""Largest accepted ``|R^T R - I|`` entry and ``|det R - 1|`` of a rotation matrix."""


def quaternion_from_matrix(R: npt.ArrayLike) -> Array:
    """``Q{R}``: the unit quaternion of a rotation matrix (Nguyen eqs. (24)-(26), Shepperd).

    ``R`` (3, 3) or (N, 3, 3), orthonormal with det +1 -> ``[eta, beta, gamma, xi]`` (4,) or
    (N, 4), ``eta >= 0``.

    Raises:
        InvalidInput: ``R`` has the wrong shape, a non-finite entry, or is not a rotation
            (tolerance :data:`ORTHONORMAL_TOL`).
    """
    Rs, single = _stack(R, "R", (3, 3))
    gram = np.einsum("nki,nkj->nij", Rs, Rs) - np.eye(3)
    det = np.linalg.det(Rs)
    bad = (np.abs(gram).max(axis=(1, 2)) > ORTHONORMAL_TOL) | (np.abs(det - 1.0) > ORTHONORMAL_TOL)
    if np.any(bad):
        i = int(np.argmax(bad))
        raise InvalidInput(
            "R", f"expected a rotation matrix (orthonormal, det +1); item {i} has det {det[i]:.6g}"
        )
    r11, r12, r13 = Rs[:, 0, 0], Rs[:, 0, 1], Rs[:, 0, 2]
    r21, r22, r23 = Rs[:, 1, 0], Rs[:, 1, 1], Rs[:, 1, 2]
    r31, r32, r33 = Rs[:, 2, 0], Rs[:, 2, 1], Rs[:, 2, 2]
    # 4 x (eta^2, beta^2, gamma^2, xi^2): eq. (26) squared, and its siblings.
    squares = np.stack(
        [
            1.0 + r11 + r22 + r33,
            1.0 + r11 - r22 - r33,
            1.0 - r11 + r22 - r33,
            1.0 - r11 - r22 + r33,
        ],
        axis=1,
    )
    # Off-diagonal combinations: 4 eta beta, 4 eta gamma, 4 eta xi, 4 beta gamma, ...
    eb, eg, ex = r32 - r23, r13 - r31, r21 - r12
    bg, bx, gx = r12 + r21, r13 + r31, r23 + r32
    pivot = np.argmax(squares, axis=1)
    big = np.sqrt(np.take_along_axis(squares, pivot[:, None], axis=1)[:, 0])  # 2 x largest
    # Row k: the quaternion times 4 x (its k-th component), for pivot k.
    scaled = np.stack(
        [
            np.stack([squares[:, 0], eb, eg, ex], axis=1),
            np.stack([eb, squares[:, 1], bg, bx], axis=1),
            np.stack([eg, bg, squares[:, 2], gx], axis=1),
            np.stack([ex, bx, gx, squares[:, 3]], axis=1),
        ],
        axis=1,
    )
    q = np.take_along_axis(scaled, pivot[:, None, None], axis=1)[:, 0] / (2.0 * big[:, None])
    q *= np.where(q[:, :1] < 0.0, -1.0, 1.0)
    return first(q) if single else q


def matrix_from_quaternion(q: npt.ArrayLike) -> Array:
    r"""``Q^-1{eta, s}``: the rotation matrix of a quaternion (Nguyen eqs. (27)-(28) corrected).

    .. math:: R = \frac{(\eta^2 - s^T s) I_3 + 2 s s^T + 2 \eta\, s^\times}{\eta^2 + s^T s}

    (the denominator is 1 for a unit quaternion; a non-unit one is normalised). ``q``
    ``[eta, beta, gamma, xi]`` (4,) or (N, 4), nonzero -> rotation matrix (3, 3) or (N, 3, 3).

    Raises:
        InvalidInput: Wrong shape, non-finite entries, or a zero quaternion.
    """
    qs, single = _stack(q, "q", (4,))
    norm2 = np.einsum("ni,ni->n", qs, qs)
    if np.any(norm2 == 0.0):
        raise InvalidInput("q", "expected a nonzero quaternion")
    eta, s = qs[:, 0], qs[:, 1:]
    R = (eta * eta - np.einsum("ni,ni->n", s, s))[:, None, None] * np.eye(3)
    R += 2.0 * s[:, :, None] * s[:, None, :]
    R += 2.0 * eta[:, None, None] * _skew(s)
    R /= norm2[:, None, None]
    return first(R) if single else R


def quaternion_difference(q1: npt.ArrayLike, q2: npt.ArrayLike) -> Array:
    """Quaternion of the orientation difference ``R2 R1^T`` (Nguyen eqs. (32)-(34)).

    ``R2 R1^T`` is the rotation about the base frame that brings frame 1 to frame 2
    (Nguyen eq. (31)); its quaternion is ``q2 * conj(q1)``:

    ``delta eta = eta1 eta2 + s1 . s2``, ``delta s = eta1 s2 - eta2 s1 + s1 x s2``. ``q1``,
    ``q2``: quaternions of ``R1``, ``R2``, (4,) or (N, 4); the result has their shape (not
    sign-normalised: ``delta eta`` may be < 0).

    Raises:
        InvalidInput: Wrong or mismatched shapes, non-finite entries.
    """
    a, single = _stack(q1, "q1", (4,))
    b = as_array(q2, "q2", np.shape(q1))
    b = b.reshape(a.shape)
    eta1, s1 = a[:, 0], a[:, 1:]
    eta2, s2 = b[:, 0], b[:, 1:]
    d_eta = eta1 * eta2 + np.einsum("ni,ni->n", s1, s2)  # eq. (33)
    d_s = eta1[:, None] * s2 - eta2[:, None] * s1 + np.cross(s1, s2)  # eq. (34)
    out = np.concatenate([d_eta[:, None], d_s], axis=1)
    return first(out) if single else out


def differential_rotation(dq: npt.ArrayLike) -> Array:
    """Differential rotations ``(delta_x, delta_y, delta_z) = 2 delta s`` (Nguyen eq. (37)).

    For a small rotation about the base axes (Nguyen eq. (36)); equals the rotation vector
    :func:`rotation_vector` up to ``theta^3 / 24`` (third order in the angle), taking the
    sign of ``delta eta`` into account (``dq`` and ``-dq`` are the same rotation). ``dq``:
    quaternion of the orientation difference, (4,) or (N, 4); returns (3,) or (N, 3) [rad].

    Raises:
        InvalidInput: Wrong shape or non-finite entries.
    """
    qs, single = _stack(dq, "dq", (4,))
    sign = np.where(qs[:, :1] < 0.0, -1.0, 1.0)
    out = 2.0 * sign * qs[:, 1:]
    return first(out) if single else out


def rotation_vector(dq: npt.ArrayLike) -> Array:
    """Exact rotation vector ``theta k`` (3,) or (N, 3) [rad] of a quaternion (the log map).

    ``theta`` in [0, pi]; ``dq`` (4,) or (N, 4), nonzero (normalised here).

    Raises:
        InvalidInput: Wrong shape, non-finite entries, or a zero quaternion.
    """
    qs, single = _stack(dq, "dq", (4,))
    norm = np.linalg.norm(qs, axis=1)
    if np.any(norm == 0.0):
        raise InvalidInput("dq", "expected a nonzero quaternion")
    qs = qs * (np.where(qs[:, :1] < 0.0, -1.0, 1.0) / norm[:, None])
    sin_half = np.linalg.norm(qs[:, 1:], axis=1)
    theta = 2.0 * np.arctan2(sin_half, qs[:, 0])
    # theta / sin(theta/2), continued by its limit 2 at theta = 0.
    scale = np.where(sin_half > 0.0, theta / np.where(sin_half > 0.0, sin_half, 1.0), 2.0)
    out = scale[:, None] * qs[:, 1:]
    return first(out) if single else out


def small_rotation(delta: npt.ArrayLike) -> Array:
    """``I + delta^x``: rotation by small angles about the base axes (Nguyen eq. (36) corrected).

    .. code-block:: text

        [[1, -dz,  dy],
         [dz,  1, -dx],
         [-dy, dx,  1]]

    Equals the exact rotation to first order (error O(|delta|^2)); not orthonormal.
    ``delta``: ``(delta_x, delta_y, delta_z)`` [rad], (3,) or (N, 3); returns (3, 3) or
    (N, 3, 3).

    Raises:
        InvalidInput: Wrong shape or non-finite entries.
    """
    d, single = _stack(delta, "delta", (3,))
    out = np.eye(3) + _skew(d)
    return first(out) if single else out


def _skew(s: Array) -> Array:
    """Skew matrices ``s^x`` of Nguyen eq. (29), (N, 3) -> (N, 3, 3)."""
    S = np.zeros((s.shape[0], 3, 3))
    S[:, 0, 1], S[:, 0, 2] = -s[:, 2], s[:, 1]
    S[:, 1, 0], S[:, 1, 2] = s[:, 2], -s[:, 0]
    S[:, 2, 0], S[:, 2, 1] = -s[:, 1], s[:, 0]
    return S


def _stack(x: npt.ArrayLike, name: str, item: tuple[int, ...]) -> tuple[Array, bool]:
    """``x`` as a stack (N, *item) and whether it was a single item.

    Raises:
        InvalidInput: Neither shape ``item`` nor (N, *item), or non-finite entries.
    """
    try:
        ndim = np.ndim(x)
    except (TypeError, ValueError):
        ndim = -1
    if ndim == len(item):
        return as_array(x, name, item)[None], True
    return as_array(x, name, (None, *item)), False

