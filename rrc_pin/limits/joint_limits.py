"""JointLimits: the joint limits a resolver keeps, as options, checked against the robot."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from rrc_pin.errors import InvalidInput
from solvers.errors import InputError
from solvers.joint_bounds import JointBounds

if TYPE_CHECKING:
    from rrc_pin.robot import Robot

Array = npt.NDArray[np.float64]


@dataclass(frozen=True)
class JointLimits:
    """Joint limits of a resolver (:mod:`solvers.joint_bounds` for the bounds of a step).

    Every step keeps the velocity limits and the position limits over the step (exactly, in
    floating point); a start outside the position limits only moves back.

    Attributes:
        margin: Distance kept from every position limit [rad or m], >= 0.
        acceleration: Joint acceleration limits [rad/s^2 or m/s^2], a scalar or (nq,), or
            None for none.
        velocity: Velocity limits (nq,) [rad/s or m/s] replacing the robot's, or None.
        position_gain: Fraction in (0, 1] of the distance to a position limit allowed in one
            step (pink's ``config_limit_gain``).
    """

    margin: float = 0.0
    acceleration: float | npt.ArrayLike | None = None
    velocity: npt.ArrayLike | None = None
    position_gain: float = 1.0

    def bounds(self, robot: Robot) -> JointBounds:
        """The robot's limits prepared for the per-step bounds.

        Args:
            robot: The robot (its ``lower``, ``upper``, ``velocity_limit``, ``joint_names``).

        Raises:
            InvalidInput: An invalid field (named), or a joint without a finite velocity
                limit (its URDF gives none) while ``velocity`` is not given.
        """
        velocity = robot.velocity_limit if self.velocity is None else self.velocity
        if self.velocity is None and not np.isfinite(robot.velocity_limit).all():
            missing = [n for n, v in zip(robot.joint_names, robot.velocity_limit, strict=True)
                       if not np.isfinite(v)]  # fmt: skip
            raise InvalidInput(
                "velocity",
                f"the robot gives no velocity limit for joints {missing} (its URDF has "
                "velocity=\"0\" or none); pass JointLimits(velocity=[...]) in rad/s or m/s",
            )
        if np.size(velocity) != robot.nq:
            raise InvalidInput(
                "velocity", f"expected shape ({robot.nq},), got {np.shape(velocity)}"
            )
        try:
            return JointBounds(
                robot.lower, robot.upper, velocity, self.margin, self.acceleration,
                self.position_gain,
            )  # fmt: skip
        except InputError as exc:
            name = {"gain": "position_gain"}.get(exc.argument, exc.argument)
            raise InvalidInput(name, exc.reason) from exc
