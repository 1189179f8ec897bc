r"""Closed-form Jacobians and joint rates of the 3R arm of the Robotics I exam (2012).

Standard DH (exam Table 1): ``alpha = (90, 0, 0)`` deg, ``a = (a1, a2, a3)``, ``d = 0``; the
task is the linear velocity of O3 in base axes (``world_aligned``, task_dim = 3). With
``r = a1 + a2 c2 + a3 c23`` (distance of O3 from axis 1) and ``h = a2 s2 + a3 s23``:

.. math::
    J_L = \begin{pmatrix} -r s_1 & -h c_1 & -a_3 s_{23} c_1 \\
                           r c_1 & -h s_1 & -a_3 s_{23} s_1 \\
                           0 & a_2 c_2 + a_3 c_{23} & a_3 c_{23} \end{pmatrix},
    \qquad
    J_A = \begin{pmatrix} 0 & s_1 & s_1 \\ 0 & -c_1 & -c_1 \\ 1 & 0 & 0 \end{pmatrix}

(the exam's expression above its eq. (1), and eq. (1)). The first column of ``J_L`` is ``r``
times the tangential direction ``t = (-s1, c1, 0)``; the other two lie in the plane of the
radial direction ``u = (c1, s1, 0)`` and ``z0`` and form the 2x2 block
``M = [[-h, -a3 s23], [a2 c2 + a3 c23, a3 c23]]`` with ``det M = a2 a3 s3``. So
``J_L^T J_L = diag(r^2, M^T M)``: the singular values of ``J_L`` are ``|r|`` and those of
``M``, and the inverse decouples (``theta1dot = (t . v) / r``, the rest by ``M^-1``).

Singularities: ``r = 0`` (O3 on axis 1) and ``s3 = 0`` (arm stretched or folded). Where
``|r| <= rcond (a1 + a2 + a3)`` the tangential part is dropped (``theta1dot = 0``), and where
``|det M| <= rcond ||M||_F^2`` the planar part uses ``M^T / ||M||_F^2``, the pseudo-inverse of
the rank-one ``M`` there: the rates are then the minimum-norm least-squares ones (up to
O(rcond)), finite, never NaN.

``J_A`` has constant rank 2, null space ``span{(0, 1, -1)}`` (exam, step 5).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
import numpy.typing as npt

from solvers.closed_form._batch import blocks, cos_sin
from solvers.closed_form.base import ClosedForm
from solvers.errors import InputError
from solvers.validation import as_array, as_float_list, as_vector, finite_number

Array = npt.NDArray[np.float64]
DEFAULT_RCOND = 1e-9
"""Relative threshold below which ``r`` or ``det M`` counts as singular (module docstring)."""
_NULL = (0.0, math.sqrt(0.5), -math.sqrt(0.5))


class AngularRates(NamedTuple):
    """All joint rates realising an angular velocity: ``particular + gamma * null_direction``.

    Attributes:
        particular: (3,) [rad/s]: ``(omega_z, beta, 0)`` with ``beta = s1 omega_x - c1 omega_y``
            (all of ``thetadot_2 + thetadot_3`` on joint 2).
        null_direction: (3,) unit vector spanning N(J_A): ``(0, 1, -1) / sqrt(2)``.
        minimum_norm: (3,) [rad/s]: ``(omega_z, beta / 2, beta / 2)``, the solution of least
            norm (the exam's thetadot*).
        residual: [rad/s] ``|c1 omega_x + s1 omega_y|``, the part of ``omega`` outside R(J_A)
            (0 when ``omega`` is feasible; otherwise the rates are the least-squares ones).
    """

    particular: Array
    null_direction: Array
    minimum_norm: Array
    residual: float


class ThreeRClosedForm(ClosedForm):
    """The exam's 3R arm: ``J_L``, ``J_A``, ``J_L^-1 v`` and the angular-velocity analysis.

    Args:
        a1: Link length a1 [m], >= 0.
        a2: Link length a2 [m], > 0.
        a3: Link length a3 [m], > 0.
        rcond: Relative singularity threshold in (0, 1) (module docstring).

    Raises:
        InputError: A length not finite, ``a1 < 0``, ``a2 <= 0``, ``a3 <= 0``, or ``rcond``
            outside (0, 1), naming it.
    """

    nq = 3
    task_dim = 3

    def __init__(self, *, a1: float, a2: float, a3: float, rcond: float = DEFAULT_RCOND) -> None:
        self.a1 = finite_number(a1, "a1", 0.0)
        self.a2 = finite_number(a2, "a2", 0.0, inclusive=False)
        self.a3 = finite_number(a3, "a3", 0.0, inclusive=False)
        self.rcond = finite_number(rcond, "rcond", 0.0, inclusive=False, upper=1.0)
        self._reach = self.a1 + self.a2 + self.a3

    def __repr__(self) -> str:
        return f"ThreeRClosedForm(a1={self.a1}, a2={self.a2}, a3={self.a3})"

    # ------------------------------------------------------------------ scalar

    def jacobian(self, q: npt.ArrayLike) -> Array:
        """Linear Jacobian ``J_L`` of O3 (exam, above eq. (1)).

        Args:
            q: Joint angles (3,) [rad].

        Returns:
            (3, 3) [m/rad], ``world_aligned`` (the first three rows of Pinocchio's Jacobian).

        Raises:
            InputError: ``q`` is not a finite (3,) vector.
        """
        c1, s1, r, h, c23, s23, _ = self._terms(as_float_list(q, "q", 3))
        a3 = self.a3
        return np.array(
            [
                [-r * s1, -h * c1, -a3 * s23 * c1],
                [r * c1, -h * s1, -a3 * s23 * s1],
                [0.0, r - self.a1, a3 * c23],
            ]
        )

    def angular_jacobian(self, q: npt.ArrayLike) -> Array:
        """Angular Jacobian ``J_A = (z0 z1 z2)`` (exam eq. (1)), (3, 3), base axes.

        Raises:
            InputError: ``q`` is not a finite (3,) vector.
        """
        q0 = as_float_list(q, "q", 3)[0]
        c1, s1 = math.cos(q0), math.sin(q0)
        return np.array([[0.0, s1, s1], [0.0, -c1, -c1], [1.0, 0.0, 0.0]])

    def twist_jacobian(self, q: npt.ArrayLike) -> Array:
        """``[J_L; J_A]``, (6, 3), rows [v; w], ``world_aligned`` (Pinocchio's full Jacobian).

        Raises:
            InputError: ``q`` is not a finite (3,) vector.
        """
        return np.vstack([self.jacobian(q), self.angular_jacobian(q)])

    def joint_rates(self, q: npt.ArrayLike, xdot: npt.ArrayLike) -> Array:
        """Joint rates ``J_L^-1 v`` realising the velocity ``xdot`` of O3 (exam, step 3).

        Args:
            q: Joint angles (3,) [rad].
            xdot: Linear velocity of O3 (3,) [m/s], base axes.

        Returns:
            thetadot (3,) [rad/s]; near a singularity the pseudo-inverse answer of the module
            docstring.

        Raises:
            InputError: ``q`` or ``xdot`` not a finite (3,) vector.
        """
        qs = as_float_list(q, "q", 3)
        vx, vy, vz = as_float_list(xdot, "xdot", 3)
        c1, s1, r, h, c23, s23, s3 = self._terms(qs)
        vt = c1 * vy - s1 * vx  # tangential
        vu = c1 * vx + s1 * vy  # radial
        rate1 = vt / r if abs(r) > self.rcond * self._reach else 0.0
        a2, a3 = self.a2, self.a3
        m00, m01, m10, m11 = -h, -a3 * s23, r - self.a1, a3 * c23
        det = a2 * a3 * s3
        frob = m00 * m00 + m01 * m01 + m10 * m10 + m11 * m11
        if abs(det) > self.rcond * frob:
            rate2 = (m11 * vu - m01 * vz) / det
            rate3 = (m00 * vz - m10 * vu) / det
        else:  # rank-one M: M^+ = M^T / ||M||_F^2
            rate2 = (m00 * vu + m10 * vz) / frob
            rate3 = (m01 * vu + m11 * vz) / frob
        return np.array([rate1, rate2, rate3])

    def angular_velocity(self, q: npt.ArrayLike, qdot: npt.ArrayLike) -> Array:
        """Angular velocity ``omega = J_A thetadot`` of frame 3 (exam eq. (1), step 4).

        Args:
            q: Joint angles (3,) [rad].
            qdot: Joint rates (3,) [rad/s].

        Returns:
            omega (3,) [rad/s], base axes.

        Raises:
            InputError: ``q`` or ``qdot`` not a finite (3,) vector.
        """
        q0 = as_float_list(q, "q", 3)[0]
        d1, d2, d3 = as_float_list(qdot, "qdot", 3)
        c1, s1 = math.cos(q0), math.sin(q0)
        return np.array([s1 * (d2 + d3), -c1 * (d2 + d3), d1])

    def angular_null_space(self, q: npt.ArrayLike) -> Array:
        """Unit vector (3,) spanning N(J_A): ``(0, 1, -1) / sqrt(2)`` at every ``q`` (step 5).

        Raises:
            InputError: ``q`` is not a finite (3,) vector.
        """
        as_float_list(q, "q", 3)
        return np.array(_NULL)

    def rates_for_angular_velocity(self, q: npt.ArrayLike, omega: npt.ArrayLike) -> AngularRates:
        """Every thetadot with ``J_A thetadot = omega`` (exam, step 5).

        ``omega = alpha z0 + beta (s1, -c1, 0)`` with ``alpha = thetadot_1`` and
        ``beta = thetadot_2 + thetadot_3``; all solutions are
        ``particular + gamma * null_direction``.

        Args:
            q: Joint angles (3,) [rad].
            omega: Angular velocity (3,) [rad/s], base axes.

        Returns:
            :class:`AngularRates`.

        Raises:
            InputError: ``q`` or ``omega`` not a finite (3,) vector.
        """
        q0 = as_float_list(q, "q", 3)[0]
        wx, wy, wz = as_float_list(omega, "omega", 3)
        c1, s1 = math.cos(q0), math.sin(q0)
        beta = s1 * wx - c1 * wy
        return AngularRates(
            particular=np.array([wz, beta, 0.0]),
            null_direction=np.array(_NULL),
            minimum_norm=np.array([wz, 0.5 * beta, 0.5 * beta]),
            residual=abs(c1 * wx + s1 * wy),
        )

    def _terms(self, qs: list[float]) -> tuple[float, ...]:
        """c1, s1, r, h, c23, s23, s3 at ``qs`` (module docstring)."""
        q1, q2, q3 = qs
        c2, s2 = math.cos(q2), math.sin(q2)
        c23, s23 = math.cos(q2 + q3), math.sin(q2 + q3)
        r = self.a1 + self.a2 * c2 + self.a3 * c23
        h = self.a2 * s2 + self.a3 * s23
        return math.cos(q1), math.sin(q1), r, h, c23, s23, math.sin(q3)

    # ------------------------------------------------------------------- batch

    def jacobian_batch(self, Q: npt.ArrayLike) -> Array:
        """``J_L`` at N configurations: ``Q`` (N, 3) -> (N, 3, 3); see :meth:`jacobian`.

        Raises:
            InputError: ``Q`` is not a finite (N, 3) array.
        """
        Q, _ = self._check_batch(Q)
        c1, s1, r, h, c23, s23, _ = self._terms_batch(Q)
        J = np.zeros((Q.shape[0], 3, 3))
        J[:, 0, 0] = -r * s1
        J[:, 1, 0] = r * c1
        J[:, 0, 1] = -h * c1
        J[:, 1, 1] = -h * s1
        J[:, 2, 1] = r - self.a1
        a3s23 = self.a3 * s23
        J[:, 0, 2] = -a3s23 * c1
        J[:, 1, 2] = -a3s23 * s1
        J[:, 2, 2] = self.a3 * c23
        return J

    def angular_jacobian_batch(self, Q: npt.ArrayLike) -> Array:
        """``J_A`` at N configurations: ``Q`` (N, 3) -> (N, 3, 3).

        Raises:
            InputError: ``Q`` is not a finite (N, 3) array.
        """
        Q, _ = self._check_batch(Q)
        c1, s1 = np.cos(Q[:, 0]), np.sin(Q[:, 0])
        J = np.zeros((Q.shape[0], 3, 3))
        J[:, 0, 1] = J[:, 0, 2] = s1
        J[:, 1, 1] = J[:, 1, 2] = -c1
        J[:, 2, 0] = 1.0
        return J

    def joint_rates_batch(self, Q: npt.ArrayLike, X: npt.ArrayLike) -> Array:
        """``J_L^-1 v`` at N configurations: ``Q``, ``X`` (N, 3) -> (N, 3) [rad/s].

        Same arithmetic and singularity handling as :meth:`joint_rates`, in blocks of
        :data:`~solvers.closed_form._batch.CHUNK` configurations (cache-sized intermediates).

        Raises:
            InputError: ``Q`` or ``X`` not a finite (N, 3) array.
        """
        Q, X = self._check_batch(Q, X)
        out = np.empty((Q.shape[0], 3))
        with np.errstate(divide="ignore", invalid="ignore"):
            for rows in blocks(Q.shape[0]):
                out[rows] = self._rates_block(Q[rows], X[rows])
        return out

    def _rates_block(self, Q: Array, X: Array) -> Array:
        """:meth:`joint_rates_batch` on one block: ``Q``, ``X`` (M, 3) -> (M, 3)."""
        c1, s1, r, h, c23, s23, s3 = self._terms_batch(Q)
        vx, vy, vz = np.ascontiguousarray(X.T)
        vt = c1 * vy - s1 * vx
        vu = c1 * vx + s1 * vy
        m00, m01, m10, m11 = -h, -self.a3 * s23, r - self.a1, self.a3 * c23
        det = (self.a2 * self.a3) * s3
        out = np.stack([vt / r, (m11 * vu - m01 * vz) / det, (m00 * vz - m10 * vu) / det], 1)
        on_axis = np.abs(r) <= self.rcond * self._reach
        if np.any(on_axis):
            out[on_axis, 0] = 0.0
        frob = m00 * m00 + m01 * m01 + m10 * m10 + m11 * m11
        rank_one = np.abs(det) <= self.rcond * frob
        if np.any(rank_one):  # M^+ = M^T / ||M||_F^2
            k, f = rank_one, frob[rank_one]
            out[k, 1] = (m00[k] * vu[k] + m10[k] * vz[k]) / f
            out[k, 2] = (m01[k] * vu[k] + m11[k] * vz[k]) / f
        return out

    def _terms_batch(self, Q: Array) -> tuple[Array, ...]:
        """:meth:`_terms` over N configurations, (N,) arrays.

        Cosines and sines by :func:`~solvers.closed_form._batch.cos_sin`, ``c23``, ``s23``
        by the angle-addition formulas.
        """
        (c1, c2, c3), (s1, s2, s3) = cos_sin(np.ascontiguousarray(Q.T))
        c23 = c2 * c3 - s2 * s3
        s23 = s2 * c3 + c2 * s3
        r = self.a1 + self.a2 * c2 + self.a3 * c23
        h = self.a2 * s2 + self.a3 * s23
        return c1, s1, r, h, c23, s23, s3


def minimum_norm_shift(qdot: npt.ArrayLike, direction: npt.ArrayLike) -> float:
    r"""The ``gamma`` making ``qdot + gamma * direction`` shortest (exam, step 5).

    .. math:: \gamma = -\frac{\dot\theta^T \dot\theta_0}{\dot\theta_0^T \dot\theta_0}

    Args:
        qdot: A joint-rate vector (n,).
        direction: A nonzero direction (n,), e.g. a null-space vector.

    Returns:
        gamma [same units as ``qdot`` per unit of ``direction``].

    Raises:
        InputError: Non-finite or mismatched vectors, or a zero ``direction``.
    """
    d = as_array(direction, "direction", (None,))
    v = as_vector(qdot, "qdot", d.shape[0])
    dd = float(d @ d)
    if dd == 0.0:
        raise InputError("direction", "expected a nonzero vector")
    return -float(v @ d) / dd

