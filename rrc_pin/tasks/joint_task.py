"""JointTask: one joint's rate (a torso joint held still, a wrist turned at a given rate)."""

from __future__ import annotations

import numpy as np

from rrc_pin.errors import InvalidInput
from rrc_pin.kinematics import Kinematics, Layout
from rrc_pin.solvers.checks import finite_number
from rrc_pin.solvers.tick.problem import TaskRows
from rrc_pin.tasks.task import Task, check_weight, task_name


class JointTask(Task):
    """Joint ``joint`` at the rate ``rate``.

    Args:
        joint: Joint name.
        rate: Desired rate [rad/s or m/s]; default 0 (held still).
        weight: Cost > 0.
        name: Name in the report (default ``"joint:<name>"``).

    Raises:
        InvalidInput: A bad joint name type, rate or weight.
    """

    joint_rows = True

    def __init__(
        self, joint: str, rate: float = 0.0, *, weight: float = 1.0, name: str | None = None
    ) -> None:
        if not isinstance(joint, str):
            raise InvalidInput("joint", f"expected a joint name, got {joint!r}")
        self.joint = joint
        self.rate = finite_number(rate, "rate")
        self.weight = check_weight(weight)
        self.name = f"joint:{joint}" if name is None else task_name(name)

    def frames(self) -> tuple[str, ...]:
        """None."""
        return ()

    def check(self, layout: Layout) -> None:
        """Refuse a joint the robot does not have.

        Raises:
            InvalidInput: Unknown joint (the error lists the robot's joints).
        """
        if self.joint not in layout.joints:
            joints = ", ".join(layout.joints)
            raise InvalidInput("joint", f"no joint {self.joint!r}; joints: {joints}")

    def rows(self, kin: Kinematics) -> TaskRows:
        """One row selecting the joint."""
        A = np.zeros((1, kin.q.size))
        A[0, kin.joint_index(self.joint)] = 1.0
        return TaskRows(A, np.array([self.rate]), self._row_weights(1), self.name)
