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

The equations are compiled kernels of :mod:`rrc_pin.solvers.closed_form.three_r_equations`; a batch
method loops over its rows inside the kernel.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.checks import as_array, as_vector, finite_number
from rrc_pin.solvers.closed_form import three_r_equations as eqs
from rrc_pin.solvers.closed_form.base import Array, ClosedForm, finite_rates, first, vector
from rrc_pin.solvers.errors import InvalidInput

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

    Frames: :attr:`frame` is the generated URDF's ``"tool"`` frame, the exam's O3 (the origin
    of frame 3 with its axes); velocities in base axes (``world_aligned``).

    Args:
        a1: Link length a1 [m], >= 0.
        a2: Link length a2 [m], > 0.
        a3: Link length a3 [m], > 0.
        rcond: Relative singularity threshold in (0, 1) (module docstring).

    Raises:
        InvalidInput: A length not finite, ``a1 < 0``, ``a2 <= 0``, ``a3 <= 0``, or ``rcond``
            outside (0, 1), naming it.
    """

    nq = 3
    task_dim = 3

    def __init__(self, *, a1: float, a2: float, a3: float, rcond: float = DEFAULT_RCOND) -> None:
        self.a1 = finite_number(a1, "a1", 0.0)
        self.a2 = finite_number(a2, "a2", 0.0, inclusive=False)
        self.a3 = finite_number(a3, "a3", 0.0, inclusive=False)
        self.rcond = finite_number(rcond, "rcond", 0.0, inclusive=False, upper=1.0)
        self._p = np.array([self.a1, self.a2, self.a3, self.a1 + self.a2 + self.a3])

    def __repr__(self) -> str:
        return f"ThreeRClosedForm(a1={self.a1}, a2={self.a2}, a3={self.a3})"

    def jacobian(self, q: npt.ArrayLike) -> Array:
        """Linear Jacobian ``J_L`` (3, 3) [m/rad] of O3 at ``q`` (3,) [rad] (exam, above eq. (1)).

        ``world_aligned``: the first three rows of Pinocchio's Jacobian.

        Raises:
            InvalidInput: ``q`` is not a finite (3,) vector.
        """
        qv = vector(q, "q", 3)
        J = np.empty((3, 3))
        if not eqs.jacobian_at(self._p, qv, J):
            as_vector(q, "q", 3)  # raises, naming the entry
        return J

    def angular_jacobian(self, q: npt.ArrayLike) -> Array:
        """Angular Jacobian ``J_A = (z0 z1 z2)`` (exam eq. (1)), (3, 3), base axes.

        Raises:
            InvalidInput: ``q`` is not a finite (3,) vector.
        """
        return first(self.angular_jacobian_batch(as_vector(q, "q", 3)[None]))

    def twist_jacobian(self, q: npt.ArrayLike) -> Array:
        """``[J_L; J_A]``, (6, 3), rows [v; w], ``world_aligned`` (Pinocchio's full Jacobian).

        Raises:
            InvalidInput: ``q`` is not a finite (3,) vector.
        """
        return np.vstack([self.jacobian(q), self.angular_jacobian(q)])

    def joint_rates(self, q: npt.ArrayLike, xdot: npt.ArrayLike) -> Array:
        """Joint rates ``J_L^-1 v`` (3,) [rad/s] realising the velocity of O3 (exam, step 3).

        ``q`` (3,) [rad]; ``xdot`` (3,) [m/s], base axes. Near a singularity the pseudo-inverse
        answer of the module docstring.

        Raises:
            InvalidInput: ``q`` or ``xdot`` not a finite (3,) vector.
        """
        qv, xv = vector(q, "q", 3), vector(xdot, "xdot", 3)
        out = np.empty(3)
        if not eqs.joint_rates_at(self._p, self.rcond, qv, xv, out):
            as_vector(q, "q", 3)  # one of the two raises, naming the entry
            as_vector(xdot, "xdot", 3)
        return finite_rates(out, "xdot")

    def angular_velocity(self, q: npt.ArrayLike, qdot: npt.ArrayLike) -> Array:
        """Angular velocity ``omega = J_A thetadot`` (3,) [rad/s] of frame 3, base axes.

        ``q`` (3,) [rad], ``qdot`` (3,) [rad/s] (exam eq. (1), step 4).

        Raises:
            InvalidInput: ``q`` or ``qdot`` not a finite (3,) vector.
        """
        return self.angular_jacobian(q) @ as_vector(qdot, "qdot", 3)

    def angular_null_space(self, q: npt.ArrayLike) -> Array:
        """Unit vector (3,) spanning N(J_A): ``(0, 1, -1) / sqrt(2)`` at every ``q`` (step 5).

        Raises:
            InvalidInput: ``q`` is not a finite (3,) vector.
        """
        as_vector(q, "q", 3)
        return np.array(_NULL)

    def rates_for_angular_velocity(self, q: npt.ArrayLike, omega: npt.ArrayLike) -> AngularRates:
        """Every thetadot with ``J_A thetadot = omega`` (exam, step 5).

        ``omega = alpha z0 + beta (s1, -c1, 0)`` with ``alpha = thetadot_1`` and
        ``beta = thetadot_2 + thetadot_3``; all solutions are
        ``particular + gamma * null_direction``.

        ``q`` (3,) [rad]; ``omega`` (3,) [rad/s], base axes.

        Raises:
            InvalidInput: ``q`` or ``omega`` not a finite (3,) vector.
        """
        qv, w = as_vector(q, "q", 3), as_vector(omega, "omega", 3)
        beta, residual = eqs.angular_split(qv[0], w[0], w[1])
        return AngularRates(
            particular=np.array([w[2], beta, 0.0]),
            null_direction=np.array(_NULL),
            minimum_norm=np.array([w[2], 0.5 * beta, 0.5 * beta]),
            residual=float(residual),
        )

    def jacobian_batch(self, Q: npt.ArrayLike) -> Array:
        """``J_L`` at N configurations: ``Q`` (N, 3) -> (N, 3, 3); see :meth:`jacobian`.

        Raises:
            InvalidInput: ``Q`` is not a finite (N, 3) array.
        """
        Q = as_array(Q, "Q", (None, 3))
        out = np.empty((Q.shape[0], 3, 3))
        eqs.jacobian_batch(self._p, Q, out)
        return out

    def angular_jacobian_batch(self, Q: npt.ArrayLike) -> Array:
        """``J_A`` at N configurations: ``Q`` (N, 3) -> (N, 3, 3).

        Raises:
            InvalidInput: ``Q`` is not a finite (N, 3) array.
        """
        Q = as_array(Q, "Q", (None, 3))
        out = np.empty((Q.shape[0], 3, 3))
        eqs.angular_jacobian_batch(self._p, Q, out)
        return out

    def joint_rates_batch(self, Q: npt.ArrayLike, X: npt.ArrayLike) -> Array:
        """``J_L^-1 v`` at N configurations: ``Q``, ``X`` (N, 3) -> (N, 3) [rad/s].

        Raises:
            InvalidInput: ``Q`` or ``X`` not a finite (N, 3) array.
        """
        Q, X = self._check_batch(Q, X)
        out = np.empty((Q.shape[0], 3))
        eqs.joint_rates_batch(self._p, self.rcond, Q, X, out)
        return finite_rates(out, "X")


def minimum_norm_shift(qdot: npt.ArrayLike, direction: npt.ArrayLike) -> float:
    r"""The ``gamma`` making ``qdot + gamma * direction`` shortest (exam, step 5).

    .. math:: \gamma = -\frac{\dot\theta^T \dot\theta_0}{\dot\theta_0^T \dot\theta_0}

    ``qdot`` (n,), ``direction`` (n,) nonzero (e.g. a null-space vector); gamma is in units of
    ``qdot`` per unit of ``direction``.

    Raises:
        InvalidInput: Non-finite or mismatched vectors, or a zero ``direction``.
    """
    d = as_array(direction, "direction", (None,))
    v = as_vector(qdot, "qdot", d.shape[0])
    dd = float(d @ d)
    if dd == 0.0:
        raise InvalidInput("direction", "expected a nonzero vector")
    return -float(v @ d) / dd

