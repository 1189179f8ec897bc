r"""ComTask: the centre of mass's velocity, optionally toward a target position.

.. math:: J_c\,\dot q \approx \dot c^* + k\,(c^* - c)

on the selected axes of the base frame (:mod:`rrc_pin.center_of_mass`: Pinocchio's
``jacobianCenterOfMass``, on the tick's own kinematics). ``axes="xy"`` moves the centre of
mass over the ground and leaves its height free (a body's balance); ``"xyz"`` all of it.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from rrc_pin.center_of_mass import center_of_mass
from rrc_pin.errors import InvalidInput
from rrc_pin.kinematics import Kinematics, Layout
from rrc_pin.solvers.checks import as_vector, positive
from rrc_pin.solvers.tick.problem import TaskRows
from rrc_pin.tasks.task import Task, check_weight, task_name

Array = npt.NDArray[np.float64]

AXES = {"x": 0, "y": 1, "z": 2}


class ComTask(Task):
    """The centre of mass's velocity on ``axes`` (module docstring).

    Args:
        velocity: Commanded velocity [m/s], one per axis (default zero).
        target: Position [m] to hold or reach, one per axis, or None (velocity only).
        axes: Base-frame axes controlled: a string of distinct ``x``, ``y``, ``z``.
        gain: k > 0 [1/s], the fraction of the position error corrected per second.
        weight: Cost > 0 of the squared residual.
        name: Name in the report.

    Raises:
        InvalidInput: Bad axes, velocity, target, gain, weight or name.
    """

    def __init__(
        self,
        velocity: npt.ArrayLike | None = None,
        *,
        target: npt.ArrayLike | None = None,
        axes: str = "xyz",
        gain: float = 5.0,
        weight: float = 1.0,
        name: str = "com",
    ) -> None:
        if (
            not isinstance(axes, str)
            or not axes
            or len(set(axes)) != len(axes)
            or not set(axes) <= set(AXES)
        ):
            raise InvalidInput("axes", f"expected distinct letters of 'xyz', got {axes!r}")
        self.axes = [AXES[a] for a in axes]
        m = len(self.axes)
        self.velocity = np.zeros(m) if velocity is None else as_vector(velocity, "velocity", m)
        self.target = None if target is None else as_vector(target, "target", m).copy()
        self.gain = positive(gain, "gain")
        self.weight = check_weight(weight)
        self.name = task_name(name)
        self._unit: Array | None = None

    def set_target(
        self, target: npt.ArrayLike | None, velocity: npt.ArrayLike | None = None
    ) -> None:
        """Hold or reach ``target`` [m] from now on (None: none), with a feed-forward velocity.

        Raises:
            InvalidInput: Not one finite number per axis; the task is then unchanged.
        """
        m = len(self.axes)
        target_ = None if target is None else as_vector(target, "target", m).copy()
        velocity_ = np.zeros(m) if velocity is None else as_vector(velocity, "velocity", m)
        self.target, self.velocity = target_, velocity_

    def frames(self) -> tuple[str, ...]:
        """None."""
        return ()

    def check(self, layout: Layout) -> None:
        """Keep the rows' unit: the robot's largest reach [m] (its linear rows' metric)."""
        self._unit = np.full(len(self.axes), max(layout.reach.values()))

    def rows(self, kin: Kinematics) -> TaskRows:
        """The centre of mass's Jacobian rows and the commanded velocity (plus the feedback)."""
        com = center_of_mass(kin)
        b = self.velocity.copy()
        if self.target is not None:
            b += self.gain * (self.target - com.position[self.axes])
        return TaskRows(com.jacobian[self.axes], b, self._row_weights(len(self.axes)),
                        self.name, self._unit)  # fmt: skip
