"""The controller's own model of the arm: the URDF plus the known drive armature, no payload."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.dynamics.drives import Drives, drives_of
from rrc_pin.robot import Robot

Array = npt.NDArray[np.float64]


class NominalModel:
    """Inverse dynamics and gravity of the nominal arm (what a controller may know).

    Args:
        robot: The arm.
        drives: Its drives (armature); default :func:`~rrc_pin.dynamics.drives.drives_of`.
    """

    def __init__(self, robot: Robot, drives: Drives | None = None) -> None:
        drives = drives_of(robot.name, robot.nq) if drives is None else drives
        self.model = robot.model.copy()
        self.model.armature[:] = drives.armature
        self.data = self.model.createData()

    def inverse_dynamics(self, q: Array, v: Array, a: Array) -> Array:
        """``M(q) a + C(q, v) v + g(q)`` (nq,) [N m] by Pinocchio's RNEA."""
        tau: Array = np.array(pin.rnea(self.model, self.data, q, v, a), dtype=float)
        return tau

    def gravity(self, q: Array) -> Array:
        """``g(q)`` (nq,) [N m]."""
        g: Array = np.array(pin.computeGeneralizedGravity(self.model, self.data, q), dtype=float)
        return g
