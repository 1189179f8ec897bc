"""DampingTask: the least-norm regularisation of a weighted resolution."""

from __future__ import annotations

import numpy as np

from rrc_pin.kinematics import Kinematics
from rrc_pin.solvers.tick.problem import TaskRows
from rrc_pin.tasks.task import Task, check_weight, identity, task_name


class DampingTask(Task):
    r"""Small joint rates: :math:`\dot q \approx 0` with cost ``weight`` (pink's DampingTask).

    In a weighted resolution it trades speed for smaller rates everywhere (constant damping,
    as in Levenberg-Marquardt); near singularities the resolver's own adaptive damping acts
    on the top level already.

    Args:
        weight: Cost > 0 [task units^2 per (rad/s)^2].
        name: Name in the report.

    Raises:
        InvalidInput: A weight not > 0.
    """

    joint_rows = True

    def __init__(self, weight: float = 1e-3, *, name: str = "damping") -> None:
        self.weight = check_weight(weight)
        self.name = task_name(name)

    def frames(self) -> tuple[str, ...]:
        """None."""
        return ()

    def rows(self, kin: Kinematics) -> TaskRows:
        """Identity rows, zero rates."""
        n = kin.q.size
        return TaskRows(identity(n), np.zeros(n), self._row_weights(n), self.name)
