"""Which singularity is near.

By Barker's conditions where his closed form knows the geometry, else by the singular vectors
of the task Jacobian.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from rrc_pin.control.strategies.barker_arm import compile_closed_form, nearness
from rrc_pin.robot import Robot
from rrc_pin.solvers.closed_form.barker import BarkerClosedForm

Array = npt.NDArray[np.float64]
AXES = ("vx", "vy", "vz", "wx", "wy", "wz")


class SingularityLabel:
    """Names the singularity near a configuration.

    For Barker's arm (``robot.closed_form`` a :class:`BarkerClosedForm`): ``"shoulder (eq.
    32)"`` when ``|S2 ES + F5 - F1| < near * L``, ``"elbow (eq. 33)"`` when ``|SAL3 WE S3 + A3
    C3| < near * L`` (``L`` the reach from joint 2 to the wrist centre), ``"wrist (S5 = 0)"``
    when ``|sin theta5| < near``; several joined by ``+``. Any other arm: when the smallest
    singular value of the task Jacobian is below ``near`` (same units), the joint that
    carries most of its right singular vector and the task direction lost (the largest
    component of the left one), e.g. ``"panda_joint5 (wz)"``.

    Args:
        robot: The robot.
        near: Width of the neighbourhood, > 0: relative for Barker's conditions, the smallest
            singular value's otherwise.
    """

    def __init__(self, robot: Robot, near: float = 0.05) -> None:
        self.robot = robot
        self.near = near
        cf = robot.closed_form
        self.barker = cf if isinstance(cf, BarkerClosedForm) else None
        if self.barker is not None:  # its kernels now, not at a tick
            compile_closed_form(self.barker)

    def __call__(self, q: Array, jacobian: Array, singular_values: Array) -> str:
        """The label at ``q`` ("" when no singularity is near).

        Args:
            q: Joint positions (nq,).
            jacobian: Task rows of the tool Jacobian (m, nq), world_aligned.
            singular_values: Its singular values, descending.
        """
        if self.barker is not None:
            near = nearness(self.barker, q)
            names = [name for name, value in (("shoulder (eq. 32)", near.shoulder),
                                              ("elbow (eq. 33)", near.elbow),
                                              ("wrist (S5 = 0)", near.wrist))
                     if value < self.near]  # fmt: skip
            return "+".join(names)
        if singular_values[-1] >= self.near:
            return ""
        U, _, Vt = np.linalg.svd(jacobian, full_matrices=False)
        v, u = np.abs(Vt[-1]), np.abs(U[:, -1])
        return f"{self.robot.joint_names[int(np.argmax(v))]} ({AXES[int(np.argmax(u))]})"
