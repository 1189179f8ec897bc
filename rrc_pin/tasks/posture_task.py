"""PostureTask: joint rates toward a reference configuration."""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

from rrc_pin.errors import InvalidInput
from rrc_pin.kinematics import Kinematics, Layout
from rrc_pin.solvers.checks import as_array, positive
from rrc_pin.solvers.tick.problem import TaskRows
from rrc_pin.tasks.task import Task, check_weight, identity, task_name

Array = npt.NDArray[np.float64]


class PostureTask(Task):
    r"""Every joint toward ``q_ref``: :math:`\dot q \approx k\,(q_{ref} - q)`.

    Continuous joints take the short way round (the difference wrapped into [-pi, pi]).

    The task knows no robot until a resolver meets it: ``q_ref``'s size is checked against the
    robot's joints there (:meth:`check`, from ``Resolver.solve`` and ``Resolver.rows_of``),
    before anything is computed, as every task's frames are.

    Args:
        q_ref: Reference configuration (nq,) [rad or m].
        gain: k > 0 [1/s]: the fraction of the remaining distance asked per second.
        weight: Cost > 0, scalar or one per joint.
        name: Name in the report.

    Raises:
        InvalidInput: A bad q_ref, gain or weight.
    """

    joint_rows = True

    def __init__(
        self,
        q_ref: npt.ArrayLike,
        gain: float = 1.0,
        *,
        weight: float | npt.ArrayLike = 1.0,
        name: str = "posture",
    ) -> None:
        self.q_ref = as_array(q_ref, "q_ref", (None,))
        self.gain = positive(gain, "gain")
        self.weight = check_weight(weight, self.q_ref.size)
        self.name = task_name(name)
        self._constants: tuple[Any, ...] = (None, None, False, None, None)

    def constant_rows(self, continuous: npt.NDArray[np.bool_]) -> tuple[bool, Array, Array | None]:
        """Whether the mask ``continuous`` (a robot's layout's) has a continuous joint, the
        identity rows and the row weights (read only): found once per layout and weight."""  # noqa: D205, D209
        mask, weight, wraps, eye, weights = self._constants
        if mask is not continuous or weight is not self.weight:
            n = self.q_ref.size
            wraps, eye, weights = bool(continuous.any()), identity(n), self._row_weights(n)
            self._constants = (continuous, self.weight, wraps, eye, weights)
        return wraps, eye, weights

    def frames(self) -> tuple[str, ...]:
        """None."""
        return ()

    def check(self, layout: Layout) -> None:
        """Refuse a q_ref (or weights) of another size than the robot's joints.

        Raises:
            InvalidInput: ``q_ref`` has the wrong size.
        """
        if self.q_ref.size != layout.nv:
            names = list(layout.joints)
            shown = ", ".join(names[:3] + (["..."] if len(names) > 4 else []) + names[3:][-1:])
            raise InvalidInput(
                "q_ref", f"the posture task {self.name!r} holds {self.q_ref.size} positions, the "
                f"robot has {layout.nv} joints ({shown}): expected shape ({layout.nv},)",
            )

    def rows(self, kin: Kinematics) -> TaskRows:
        """Identity rows and ``gain (q_ref - q)``."""
        continuous = kin.layout.continuous
        wraps, eye, weights = self.constant_rows(continuous)
        error = self.q_ref - kin.q
        if wraps:
            wrapped = np.remainder(error + np.pi, 2.0 * np.pi) - np.pi
            error = np.where(continuous, wrapped, error)
        error *= self.gain
        return TaskRows(eye, error, weights, self.name)
