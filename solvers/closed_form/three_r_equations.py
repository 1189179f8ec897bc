r"""The equations of the 3R arm of the Robotics I exam (2012), as compiled kernels.

Standard DH (exam Table 1): ``alpha = (90, 0, 0)`` deg, ``a = (a1, a2, a3)``, ``d = 0``;
``p = (a1, a2, a3, a1 + a2 + a3)`` [m] holds the lengths and the reach. Each equation is one
small kernel (:func:`~rrc_pin.solvers.compiled.kernel`) on one configuration; the loops over N
configurations at the end call the same kernels. The derivation of the inverse is in
:mod:`rrc_pin.solvers.closed_form.three_r`.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.closed_form.base import finite
from rrc_pin.solvers.compiled import kernel

Array = npt.NDArray[np.float64]
Terms = tuple[float, float, float, float, float, float, float]
"""``(c1, s1, r, h, c23, s23, s3)`` of one configuration."""


@kernel
def terms(p: Array, q: Array) -> Terms:
    """The terms ``(c1, s1, r, h, c23, s23, s3)`` of one configuration ``q`` (3,) [rad].

    ``r = a1 + a2 c2 + a3 c23`` [m] is the distance of O3 from axis 1, ``h = a2 s2 + a3 s23``
    [m] the height of O3.
    """
    c23, s23 = math.cos(q[1] + q[2]), math.sin(q[1] + q[2])
    r = p[0] + p[1] * math.cos(q[1]) + p[2] * c23
    h = p[1] * math.sin(q[1]) + p[2] * s23
    return math.cos(q[0]), math.sin(q[0]), r, h, c23, s23, math.sin(q[2])


@kernel
def linear_jacobian(p: Array, t: Terms, J: Array) -> None:
    """``J_L`` (exam, above eq. (1)) into ``J`` (3, 3) [m/rad], base axes."""
    c1, s1, r, h, c23, s23, _ = t
    a3s23 = p[2] * s23
    J[0, 0], J[0, 1], J[0, 2] = -r * s1, -h * c1, -a3s23 * c1
    J[1, 0], J[1, 1], J[1, 2] = r * c1, -h * s1, -a3s23 * s1
    J[2, 0], J[2, 1], J[2, 2] = 0.0, r - p[0], p[2] * c23


@kernel
def angular_jacobian(t: Terms, J: Array) -> None:
    """``J_A = (z0 z1 z2)`` (exam eq. (1)) into ``J`` (3, 3), base axes."""
    c1, s1 = t[0], t[1]
    J[0, 0], J[0, 1], J[0, 2] = 0.0, s1, s1
    J[1, 0], J[1, 1], J[1, 2] = 0.0, -c1, -c1
    J[2, 0], J[2, 1], J[2, 2] = 1.0, 0.0, 0.0


@kernel
def linear_rates(
    p: Array, rcond: float, t: Terms, v0: float, v1: float, v2: float
) -> tuple[float, float, float]:
    """``J_L^-1 v`` [rad/s] for ``v`` [m/s]; the pseudo-inverse answer at singularities.

    ``theta1dot = (t . v) / r`` with the tangential ``t = (-s1, c1, 0)``, dropped where
    ``|r| <= rcond (a1 + a2 + a3)``; the rest ``M^-1 (u . v, v_z)`` with the radial
    ``u = (c1, s1, 0)`` and ``M = [[-h, -a3 s23], [a2 c2 + a3 c23, a3 c23]]``
    (``det M = a2 a3 s3``), or ``M^T / ||M||_F^2`` (the pseudo-inverse of the rank-one M)
    where ``|det M| <= rcond ||M||_F^2``.
    """
    c1, s1, r, h, c23, s23, s3 = t
    vt = c1 * v1 - s1 * v0  # tangential
    vu = c1 * v0 + s1 * v1  # radial
    m00, m01, m10, m11 = -h, -p[2] * s23, r - p[0], p[2] * c23
    det = p[1] * p[2] * s3
    frob = m00 * m00 + m01 * m01 + m10 * m10 + m11 * m11
    th1 = 0.0 if abs(r) <= rcond * p[3] else vt / r
    if abs(det) <= rcond * frob:  # rank one: M^+ = M^T / ||M||_F^2
        return th1, (m00 * vu + m10 * v2) / frob, (m01 * vu + m11 * v2) / frob
    return th1, (m11 * vu - m01 * v2) / det, (m00 * v2 - m10 * vu) / det


@kernel
def angular_split(q0: float, wx: float, wy: float) -> tuple[float, float]:
    """``beta = s1 omega_x - c1 omega_y`` [rad/s] and ``|c1 omega_x + s1 omega_y|`` (step 5).

    ``omega = alpha z0 + beta (s1, -c1, 0)`` with ``alpha = omega_z = thetadot_1`` and
    ``beta = thetadot_2 + thetadot_3`` (exam step 6, corrected); the second value is the
    part of ``omega`` outside R(J_A).
    """
    c1, s1 = math.cos(q0), math.sin(q0)
    return s1 * wx - c1 * wy, abs(c1 * wx + s1 * wy)


# -- entry points: one configuration, and compiled loops over N ----------------------------


@kernel
def jacobian_at(p: Array, q: Array, J: Array) -> bool:
    """:func:`linear_jacobian` at ``q`` (3,) into ``J`` (3, 3).

    False (J unset) unless ``q`` has that many entries, all finite.
    """
    if not finite(q, 3):
        return False
    linear_jacobian(p, terms(p, q), J)
    return True


@kernel
def joint_rates_at(p: Array, rcond: float, q: Array, v: Array, out: Array) -> bool:
    """:func:`linear_rates` at ``q`` (3,) for ``v`` (3,).

    False (``out`` unset) unless both have that many entries, all finite.
    """
    if not (finite(q, 3) and finite(v, 3)):
        return False
    out[0], out[1], out[2] = linear_rates(p, rcond, terms(p, q), v[0], v[1], v[2])
    return True


@kernel
def jacobian_batch(p: Array, Q: Array, out: Array) -> None:
    """:func:`linear_jacobian` at each row of ``Q`` (N, 3) into ``out`` (N, 3, 3)."""
    for k in range(Q.shape[0]):
        linear_jacobian(p, terms(p, Q[k]), out[k])


@kernel
def angular_jacobian_batch(p: Array, Q: Array, out: Array) -> None:
    """:func:`angular_jacobian` at each row of ``Q`` (N, 3) into ``out`` (N, 3, 3)."""
    for k in range(Q.shape[0]):
        angular_jacobian(terms(p, Q[k]), out[k])


@kernel
def joint_rates_batch(p: Array, rcond: float, Q: Array, V: Array, out: Array) -> None:
    """:func:`linear_rates` at each row of ``Q`` (N, 3) for ``V`` (N, 3) into ``out`` (N, 3)."""
    for k in range(Q.shape[0]):
        out[k, 0], out[k, 1], out[k, 2] = linear_rates(p, rcond, terms(p, Q[k]), V[k, 0],
                                                       V[k, 1], V[k, 2])  # fmt: skip
