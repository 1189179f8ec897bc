"""RatesTask: joint rates chosen by a strategy, kept inside the limits by the resolver."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from rrc_pin.kinematics import Kinematics
from rrc_pin.solvers.tick.problem import TaskRows
from rrc_pin.tasks import Task

Array = npt.NDArray[np.float64]


class RatesTask(Task):
    """Every joint at the given rate: rows ``I qdot = rates``.

    Resolved alone (one level, direction-preserving), the answer is ``rates`` where they fit
    the step's limits, else ``rates`` scaled uniformly (their direction kept) into them.

    Args:
        rates: Joint rates (nq,) [rad/s or m/s], finite (checked by the caller).
        name: Name in the resolution's report.
    """

    joint_rows = True

    def __init__(self, rates: Array, name: str = "rates") -> None:
        self.rates = rates
        self.weight = 1.0
        self.name = name

    def frames(self) -> tuple[str, ...]:
        """None."""
        return ()

    def rows(self, kin: Kinematics) -> TaskRows:
        """The identity rows."""
        return TaskRows(np.eye(kin.q.size), self.rates, None, self.name)
