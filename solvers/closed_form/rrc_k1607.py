"""Closed-form kinematics and joint rates of the 7-DOF RRC K-1607 (Nguyen & Zhou, NAG 5-1124).

The arm of Nguyen Table 1 in Craig's modified DH (Nguyen eq. (2)), twists fixed at
``alpha_{i-1} = (0, -90, 90, -90, 90, -90, 90)`` deg. The hand frame is frame 7. The
equations are compiled kernels of :mod:`rrc_pin.solvers.closed_form.rrc_k1607_equations`:

- Forward kinematics: Nguyen eqs. (4)-(11), with the typos of eqs. (5), (8) and (9)
  corrected (docs/errata.md). Every ``a_{i-1}`` and ``d_i`` is honoured; for Table 1 (``a0
  = a1 = d1 = d2 = d4 = d6 = d7 = 0``) the position reduces to Nguyen's ``p``.
- Jacobian: the cross-product method, Nguyen eqs. (12)-(17), all seven columns
  ``J_i = [z_i x (p - o_i); z_i]``. Rows ``[v; w]``: velocity of frame 7's origin and
  angular velocity, base axes (``world_aligned``, Pinocchio's LOCAL_WORLD_ALIGNED).
- Joint rates: the weighted pseudo-inverse with null-space term, Nguyen eqs. (21)-(22),
  evaluated as ``qdot = J_W^+ (xdot - J z) + z`` (the same vector, one solve). With
  ``W = L L^T`` and ``B = J L``: ``B B^T y = xdot - J z`` by Cholesky's method, then
  ``qdot = L B^T y + z`` (eq. (22) as printed). With ``W = I`` and ``z = 0`` it is the
  minimum-norm solution of eq. (23). Forming ``B B^T`` squares the condition number: the
  rates are accurate to about ``eps kappa(B)^2`` (1e-13 at kappa = 40, 1e-8 at kappa = 1e4).

Singularities: with ``tau = rcond^2 trace(B B^T)``, the rates come from the truncated
pseudo-inverse (``L B^+ (xdot - J z) + z``, singular values below ``rcond sigma_max``
dropped: the least-squares rates of least ``(qdot - z)^T W^-1 (qdot - z)``, finite for any
finite input, never NaN) where the solve proves ``lambda_min(B B^T) < tau``: a Cholesky
pivot not above 1e-12 times the largest diagonal entry, or ``|b| < tau |y|`` for the
solution ``y`` of ``B B^T y = b`` (``|b| >= lambda_min |y|`` always). Damping is the QP
resolver's business, not this module's. Elsewhere the exact rates are returned, however
large.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.checks import as_array, as_vector, finite_number
from rrc_pin.solvers.closed_form import rrc_k1607_equations as eqs
from rrc_pin.solvers.closed_form.base import Array, ClosedForm, finite_rates, vector
from rrc_pin.solvers.closed_form.rrc_k1607_equations import NQ, TASK_DIM
from rrc_pin.solvers.closed_form.weighted import weight_factor

ALPHA_DEG = (0.0, -90.0, 90.0, -90.0, 90.0, -90.0, 90.0)
"""Nguyen Table 1 twists alpha_{i-1} [deg]; the closed form is derived for these."""
DEFAULT_RCOND = 1e-6
"""Relative singular-value threshold of ``J W^1/2`` below which the SVD form answers."""


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
        InvalidInput: ``a`` or ``d`` not seven finite numbers, or ``rcond`` not in (0, 1).
    """

    nq = NQ
    task_dim = TASK_DIM

    def __init__(
        self, *, a: npt.ArrayLike, d: npt.ArrayLike, rcond: float = DEFAULT_RCOND
    ) -> None:
        self.a = tuple(as_vector(a, "a", NQ).tolist())
        self.d = tuple(as_vector(d, "d", NQ).tolist())
        self._p = np.array(self.a + self.d)  # the kernels' parameters
        self.rcond = finite_number(rcond, "rcond", 0.0, inclusive=False, upper=1.0)

    def __repr__(self) -> str:
        return f"RrcK1607ClosedForm(a={self.a}, d={self.d})"

    def fk(self, q: npt.ArrayLike) -> Array:
        """Pose (4, 4) of frame 7 in frame 0, translation [m], Nguyen eqs. (4)-(11).

        ``q``: joint angles theta_1..theta_7 (7,) [rad].

        Raises:
            InvalidInput: ``q`` is not a finite (7,) vector.
        """
        T: Array = self.fk_batch(as_vector(q, "q", NQ)[None])[0]
        return T

    def fk_batch(self, Q: npt.ArrayLike) -> Array:
        """Poses of frame 7 at N configurations ``Q`` (N, 7) [rad]: (N, 4, 4).

        Raises:
            InvalidInput: ``Q`` is not a finite (N, 7) array.
        """
        Q = as_array(Q, "Q", (None, NQ))
        out = np.empty((Q.shape[0], 4, 4))
        eqs.pose_batch(self._p, Q, out)
        return out

    def jacobian(self, q: npt.ArrayLike) -> Array:
        """Jacobian (6, 7) of frame 7 at ``q`` (7,) [rad], Nguyen eqs. (12)-(17), all columns.

        Rows [v; w], ``world_aligned`` ([m/rad] then [1]).

        Raises:
            InvalidInput: ``q`` is not a finite (7,) vector.
        """
        qv = vector(q, "q", NQ)
        J = np.empty((TASK_DIM, NQ))
        if not eqs.jacobian_at(self._p, qv, J):
            as_vector(q, "q", NQ)  # raises, naming the entry
        return J

    def jacobian_batch(self, Q: npt.ArrayLike) -> Array:
        """Jacobians of frame 7 at ``Q`` (N, 7) [rad]: (N, 6, 7), rows [v; w], ``world_aligned``.

        Raises:
            InvalidInput: ``Q`` is not a finite (N, 7) array.
        """
        Q = as_array(Q, "Q", (None, NQ))
        out = np.empty((Q.shape[0], TASK_DIM, NQ))
        eqs.jacobian_batch(self._p, Q, out)
        return out

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
            InvalidInput: Wrong shape or non-finite entries in any argument (named), or ``W``
                not symmetric positive definite.
        """
        qv, xv = vector(q, "q", NQ), vector(xdot, "xdot", TASK_DIM)
        L = weight_factor(W, NQ)
        zv = None if z is None else as_vector(z, "z", NQ)
        out = np.empty(NQ)
        if not eqs.joint_rates_at(self._p, qv, xv, L, zv, self.rcond, out):
            as_vector(q, "q", NQ)  # one of the two raises, naming the entry
            as_vector(xdot, "xdot", TASK_DIM)
        return finite_rates(out, "xdot")

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
        Zm = None if Z is None else as_array(Z, "Z", (Q.shape[0], NQ))
        out = np.empty((Q.shape[0], NQ))
        eqs.joint_rates_batch(self._p, Q, X, L, Zm, self.rcond, out)
        return finite_rates(out, "X")

