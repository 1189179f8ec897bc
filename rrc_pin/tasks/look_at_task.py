r"""LookAtTask: an axis of a frame aimed at a point of the world.

A camera on its subject, a tool's axis through a target:

:class:`~rrc_pin.tasks.AxisAlignTask` toward the direction :math:`d = (p - o)/\rho` from the
frame's origin :math:`o` to the point :math:`p`, :math:`\rho = |p - o|`. The direction turns
as the frame moves: :math:`\dot d = -(I - d d^T)\,\dot o/\rho`, so its angular velocity
:math:`d \times \dot d = -[d]_\times J_v \dot q/\rho` (:math:`J_v` the frame's linear
rows) enters the rows: a frame that moves sideways keeps aiming at the point.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from rrc_pin.kinematics import Kinematics
from rrc_pin.solvers.checks import as_vector
from rrc_pin.tasks.axis_align_task import AxisAlignTask

Array = npt.NDArray[np.float64]

NEAR = 1e-6
"""[m] A point closer to the frame's origin than this has no direction: the task holds the
axis (its last direction)."""


class LookAtTask(AxisAlignTask):
    """Axis ``axis`` of ``frame`` aimed at ``point`` (module docstring).

    Args:
        frame: A frame of the robot (e.g. a camera's optical frame).
        point: The point (3,) in the base frame [m].
        axis: The aimed axis (3,) in the frame's axes (default its z, a camera's optical
            axis in the ROS convention).
        gain: k > 0 [1/s]: the fraction of the angle turned per second.
        weight: Cost > 0 of the squared residual.
        name: Name in the report (default ``"look:<frame>"``).

    Raises:
        InvalidInput: A bad frame name, point, axis, gain, weight or name.
    """

    def __init__(
        self,
        frame: str,
        point: npt.ArrayLike,
        axis: npt.ArrayLike = (0.0, 0.0, 1.0),
        *,
        gain: float = 5.0,
        weight: float = 1.0,
        name: str | None = None,
    ) -> None:
        super().__init__(frame, axis, gain=gain, weight=weight,
                         name=f"look:{frame}" if name is None else name)  # fmt: skip
        self.point = as_vector(point, "point", 3).copy()

    def set_point(self, point: npt.ArrayLike) -> None:
        """Aim at ``point`` (3,) [m] in the base frame from now on.

        Raises:
            InvalidInput: Not a finite (3,) vector; the task is then unchanged.
        """
        self.point = as_vector(point, "point", 3).copy()

    def aim(self, kin: Kinematics) -> tuple[Array, Array]:
        """The direction to the point (3,) and its angular velocity's Jacobian (3, nv)."""
        pose = kin.pose(self.frame)
        offset = self.point - pose[:3, 3]
        rho = float(np.linalg.norm(offset))
        if rho < NEAR:
            return pose[:3, :3] @ self.axis, np.zeros((3, kin.q.size))
        d = offset / rho
        Jv = kin.jacobian(self.frame, "world_aligned")[:3]
        rows: Array = np.asarray(-np.cross(d[:, None], Jv, axis=0) / rho, np.float64)
        return d, rows

