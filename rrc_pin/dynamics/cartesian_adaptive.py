r"""Cartesian-space adaptive PD (Nguyen & Zhou Fig. 12): Seraji's law on the six tool axes.

Forward kinematics gives the tool pose; the error is ``e = [p_d - p; delta]`` with the
quaternion orientation error of Nguyen eqs. (32)-(37) (:mod:`rrc_pin.dynamics.pose_error`),
``edot = twist_d - J(q) qdot`` (base axes); the adapted wrench ``F`` of
:mod:`rrc_pin.dynamics.adaptation` becomes torques by the Jacobian transpose:

.. math:: \tau = J^T F + (I - J^+ J)^T \left(K_n (q_d - q) + D_n (\dot q_d - \dot q)\right)

The second term, a joint PD projected onto the null space of ``J``, holds the self-motion
of a redundant arm (the K-1607's elbow), which the wrench cannot see; on an arm of six joints
or fewer it is zero away from singularities and is not computed.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from rrc_pin.dynamics.adaptation import SerajiGains, SerajiLaw
from rrc_pin.dynamics.controller import Array, Controller, gains
from rrc_pin.dynamics.pose_error import pose_error
from rrc_pin.dynamics.state import Reference, State
from rrc_pin.robot import Robot


class CartesianAdaptivePD(Controller):
    """Decentralised adaptive PD on the tool's six Cartesian axes, torques by ``J^T``.

    Args:
        robot: The arm.
        adaptive: Seraji gains per axis ``[x, y, z, rx, ry, rz]`` (units N/m, N m/rad...).
        null_kp: Null-space joint stiffness (nq,) or scalar [N m/rad], >= 0.
        null_kv: Null-space joint damping (nq,) or scalar [N m s/rad], >= 0.
        f0: Initial auxiliary wrench (6,) [N, N m].
        dt: Control period [s].
        torque_limit: Motor limits (nq,) [N m]; default the URDF's.

    Raises:
        InvalidInput: A bad gain (named).
    """

    name = "cartesian_adaptive_pd"

    def __init__(
        self,
        robot: Robot,
        adaptive: SerajiGains,
        *,
        null_kp: npt.ArrayLike = 0.0,
        null_kv: npt.ArrayLike = 0.0,
        f0: npt.ArrayLike = 0.0,
        dt: float = 1e-3,
        torque_limit: npt.ArrayLike | None = None,
    ) -> None:
        super().__init__(robot, dt, torque_limit)
        self.adaptation = SerajiLaw(adaptive, 6, self.dt, f0)
        self.null_kp = gains(null_kp, "null_kp", robot.nq, sign="nonnegative")
        self.null_kv = gains(null_kv, "null_kv", robot.nq, sign="nonnegative")

    def reset(self) -> None:
        """Back to the initial gains."""
        super().reset()
        self.adaptation.reset()

    def law(self, state: State, ref: Reference) -> Array:
        """``J^T F`` plus the null-space joint PD."""
        J = self.robot.jacobian(state.q)
        e = pose_error(self.robot.fk(state.q), ref.pose)
        wrench = self.adaptation.update(e, ref.twist - J @ state.v)
        hold = null_space_pd(self.null_kp, self.null_kv, J, state, ref)
        return np.asarray(J.T @ wrench + hold, dtype=float)


def null_space_pd(kp: Array, kv: Array, J: Array, state: State, ref: Reference) -> Array:
    """``(I - J^+ J)^T (K_n e + D_n edot)`` (nq,) [N m]: the self-motion hold.

    Zero (not computed) on an arm of six joints or fewer, or with zero gains.
    """
    n = J.shape[1]
    if n <= 6 or not (kp.any() or kv.any()):
        return np.zeros(n)
    N = np.eye(n) - np.linalg.pinv(J) @ J
    joint = kp * (ref.q - state.q) + kv * (ref.v - state.v)
    return np.asarray(N.T @ joint, dtype=float)
