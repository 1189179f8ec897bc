r"""Hybrid position/force control (Nguyen & Zhou Fig. 13, after Raibert and Craig), adaptive gains.

M. H. Raibert and J. J. Craig, "Hybrid position/force control of manipulators", ASME J.
Dynamic Systems, Measurement and Control 103(2):126-133, 1981 (the report's reference [12]
prints volume 102). In a task frame with axes
``R`` (base axes of its x, y, z), a compliance selection matrix ``S = diag(s)``, ``s_i = 1``
for a force-controlled axis and 0 for a position-controlled one, splits the three
translational axes; orientation is always position-controlled (the plane senses no moment).
With ``e = [p_d - p; delta]`` (quaternion orientation error, Nguyen eqs. (32)-(37)) and
``edot = twist_d - J qdot``:

.. math::
    u_p &= \mathrm{Seraji}_p\big([(I - S) R^T e_{1:3};\ e_{4:6}],
                               [(I - S) R^T \dot e_{1:3};\ \dot e_{4:6}]\big) \\
    u_f &= \mathrm{Seraji}_f\big(S R^T (f_d - f),\ -S R^T \dot p\big) \\
    F &= \big[R\,((I - S)\, u_{p,1:3} + S\,(R^T f_d + u_f));\ u_{p,4:6}\big] \\
    \tau &= J^T F + (I - J^+ J)^T (K_n (q_d - q) + D_n (\dot q_d - \dot q))

``f`` is the measured force the tool exerts, ``f_d`` the desired one (base axes). The force
loop is a feedforward of ``f_d`` plus Seraji's adapted law on the force error, whose rate
term is the (negated) tool speed along the force axis: an adapted damping. Errors on the
axes a loop does not own are zero, so its adaptation there stands still.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from rrc_pin.dynamics.adaptation import SerajiGains, SerajiLaw
from rrc_pin.dynamics.cartesian_adaptive import null_space_pd
from rrc_pin.dynamics.controller import Array, Controller, gains
from rrc_pin.dynamics.pose_error import pose_error
from rrc_pin.dynamics.state import Reference, State
from rrc_pin.errors import InvalidInput
from rrc_pin.robot import Robot
from rrc_pin.solvers.checks import as_array, real_array


class HybridForcePosition(Controller):
    """Raibert-Craig hybrid control with Seraji-adapted position and force loops.

    Args:
        robot: The arm.
        position: Seraji gains of the six position axes ``[x, y, z, rx, ry, rz]`` (task
            frame for x, y, z).
        force: Seraji gains of the three force axes (``kp0`` [N/N], ``kv0`` [N s/m]...).
        selection: ``s`` (3,), each 0 (position) or 1 (force), task-frame x, y, z.
        task_frame: Rotation (3, 3) whose columns are the task axes in base axes.
        null_kp: Null-space joint stiffness [N m/rad], >= 0.
        null_kv: Null-space joint damping [N m s/rad], >= 0.
        f0: Initial auxiliary wrench (6,) [N, N m], e.g. the holding wrench at rest: the
            position loop starts from it, the force loop from its force-axis components.
        dt: Control period [s].
        torque_limit: Motor limits (nq,) [N m]; default the URDF's.

    Raises:
        InvalidInput: A bad gain, selection (not 0/1, wrong shape) or task frame (not a
            rotation), named.
    """

    name = "hybrid_force_position"

    def __init__(
        self,
        robot: Robot,
        position: SerajiGains,
        force: SerajiGains,
        selection: npt.ArrayLike,
        *,
        task_frame: npt.ArrayLike | None = None,
        null_kp: npt.ArrayLike = 0.0,
        null_kv: npt.ArrayLike = 0.0,
        f0: npt.ArrayLike = 0.0,
        dt: float = 1e-3,
        torque_limit: npt.ArrayLike | None = None,
    ) -> None:
        super().__init__(robot, dt, torque_limit)
        self.selection = check_selection(selection)
        self.task_frame = check_rotation(np.eye(3) if task_frame is None else task_frame)
        self.position = SerajiLaw(position, 6, self.dt, f0)
        held = self.selection * (self.task_frame.T @ self.position.f0[:3])
        self.force = SerajiLaw(force, 3, self.dt, held)
        self.null_kp = gains(null_kp, "null_kp", robot.nq, sign="nonnegative")
        self.null_kv = gains(null_kv, "null_kv", robot.nq, sign="nonnegative")

    def reset(self) -> None:
        """Back to the initial gains of both loops."""
        super().reset()
        self.position.reset()
        self.force.reset()

    def law(self, state: State, ref: Reference) -> Array:
        """Position loop on ``I - S``, force loop on ``S``, ``J^T`` to torques."""
        R, s = self.task_frame, self.selection
        J = self.robot.jacobian(state.q)
        e = pose_error(self.robot.fk(state.q), ref.pose)
        tool_twist = J @ state.v
        edot = ref.twist - tool_twist
        free = 1.0 - s
        u_p = self.position.update(
            np.concatenate([free * (R.T @ e[:3]), e[3:]]),
            np.concatenate([free * (R.T @ edot[:3]), edot[3:]]),
        )
        f_d = R.T @ ref.force
        u_f = self.force.update(s * (f_d - R.T @ state.force), -s * (R.T @ tool_twist[:3]))
        wrench = np.concatenate([R @ (free * u_p[:3] + s * (f_d + u_f)), u_p[3:]])
        hold = null_space_pd(self.null_kp, self.null_kv, J, state, ref)
        return np.asarray(J.T @ wrench + hold, dtype=float)


def check_selection(selection: npt.ArrayLike) -> Array:
    """``s`` as a (3,) float array of zeros and ones.

    Raises:
        InvalidInput: Not three entries, or an entry other than 0 or 1 (names ``selection``).
    """
    s = real_array(selection, "selection", "expected three 0/1 entries")
    if s.shape != (3,) or not np.all((s == 0.0) | (s == 1.0)):
        raise InvalidInput(
            "selection", f"expected three entries, each 0 (position) or 1 (force), got {s}"
        )
    return s.astype(float)


def check_rotation(R: npt.ArrayLike) -> Array:
    """``R`` as a (3, 3) rotation (orthonormal, det +1, within 1e-6).

    Raises:
        InvalidInput: Wrong shape, non-finite, or not a rotation (names ``task_frame``).
    """
    m = as_array(R, "task_frame", (3, 3))
    if np.abs(m.T @ m - np.eye(3)).max() > 1e-6 or abs(np.linalg.det(m) - 1.0) > 1e-6:
        raise InvalidInput("task_frame", "expected a rotation matrix (orthonormal, det +1)")
    return m
