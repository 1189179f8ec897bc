"""JointLimits: velocity, one-step position and acceleration limits of every joint, as a box."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from rrc_pin.errors import InvalidInput
from rrc_pin.limits.limit import Limit
from rrc_pin.solvers.checks import as_vector, finite_number, real_array
from rrc_pin.solvers.tick.joint_box import joint_box
from rrc_pin.solvers.tick.problem import Box, Constraints

if TYPE_CHECKING:
    from rrc_pin.kinematics import Kinematics, Layout

Array = npt.NDArray[np.float64]


@dataclass(frozen=True)
class JointLimits(Limit):
    """The joint limits a resolver keeps: the box of :mod:`rrc_pin.solvers.tick.joint_box`.

    Every step keeps the velocity limits and the position limits over the step exactly (in
    floating point); a start outside the position limits only moves back (``recovering``).

    Attributes:
        margin: Distance kept from every position limit [rad or m], >= 0 and below half of
            every joint's range (checked against the robot when a Resolver is built).
        acceleration: Joint acceleration limits [rad/s^2 or m/s^2] > 0, a scalar or (nq,),
            or None for none.
        velocity: Velocity limits (nv,) [rad/s or m/s] > 0 replacing the robot's, or None
            (those its mimic joints put on the joints they follow are kept either way:
            :attr:`rrc_pin.Robot.mimic_velocity`).
        position_gain: Fraction in (0, 1] of the distance to a position limit allowed in one
            step (pink's ``config_limit_gain``).
        name: Name in the report.

    Raises:
        InvalidInput: A field that is not a finite number in its range, named.
    """

    margin: float = 0.0
    acceleration: float | npt.ArrayLike | None = None
    velocity: npt.ArrayLike | None = None
    position_gain: float = 1.0
    name: str = "joint limits"

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        set_(self, "margin", finite_number(self.margin, "margin", 0.0))
        gain = finite_number(self.position_gain, "position_gain", 0.0, inclusive=False)  # fmt: skip
        if gain > 1.0:
            raise InvalidInput("position_gain", f"expected a number in (0, 1], got {gain}")
        set_(self, "position_gain", gain)
        if self.acceleration is not None:
            a = real_array(self.acceleration, "acceleration").reshape(-1).copy()
            if (
                np.ndim(self.acceleration) > 1
                or not np.isfinite(a).all()
                or (a <= 0.0).any()
                or not a.size
            ):
                raise InvalidInput("acceleration", f"expected finite limits > 0, got {a}")
            a.flags.writeable = False
            set_(self, "acceleration", a)
        if self.velocity is not None:
            v = real_array(self.velocity, "velocity").copy()
            if v.ndim != 1 or not np.isfinite(v).all() or (v <= 0.0).any():
                raise InvalidInput("velocity", f"expected finite limits > 0 (nq,), got {v}")
            v.flags.writeable = False
            set_(self, "velocity", v)
        if not isinstance(self.name, str):
            raise InvalidInput("name", f"expected a string, got {self.name!r}")

    def check(self, layout: Layout) -> None:
        """Refuse limits that do not fit the robot.

        Raises:
            InvalidInput: ``velocity`` or ``acceleration`` of the wrong length, a joint
                without a finite velocity limit while ``velocity`` is not given, or a
                ``margin`` of at least half a joint's range (no room would be left).
        """
        n = layout.nv
        if self.velocity is None and not np.isfinite(layout.velocity).all():
            missing = [name for name, i in layout.joints.items()
                       if not np.isfinite(layout.velocity[i])]  # fmt: skip
            if layout.actuated is not None and not all(layout.actuated[layout.joints[n]]
                                                       for n in missing):  # fmt: skip
                raise InvalidInput(
                    "velocity",
                    f"the floating base's rates {missing} have no velocity limit: give the "
                    "free-flyer's model.velocityLimit (a body speed cap) or JointLimits("
                    "velocity=[...]) (nv,)",
                )
            raise InvalidInput(
                "velocity",
                f"the robot gives no velocity limit for joints {missing} (its URDF has "
                'velocity="0" or none); pass JointLimits(velocity=[...]) in rad/s or m/s',
            )
        if self.velocity is not None:
            as_vector(self.velocity, "velocity", n)
        if self.acceleration is not None and np.size(self.acceleration) not in (1, n):
            raise InvalidInput("acceleration", f"expected a scalar or shape ({n},), got "
                               f"{np.shape(self.acceleration)}")  # fmt: skip
        half = 0.5 * layout.upper - 0.5 * layout.lower  # no overflow at a floating base's 1.8e308
        if self.margin > 0.0 and (self.margin >= half).any():
            narrow = [name for name, i in layout.joints.items() if self.margin >= half[i]]
            raise InvalidInput(
                "margin", f"{self.margin} leaves no range for joints {narrow} (half their "
                f"ranges: {np.round(half[[layout.joints[n] for n in narrow]], 4).tolist()})",
            )  # fmt: skip

    def velocities(self, layout: Layout) -> Array:
        """The velocity limits this box keeps on ``layout``'s joints (nv,) [rad/s or m/s]: the
        robot's, or the override's within what mimic joints put on the joints they follow."""  # noqa: D205, D209
        if self.velocity is None:
            return layout.velocity
        velocity: Array = np.asarray(self.velocity)
        if layout.mimic_velocity is not None:
            velocity = np.minimum(velocity, layout.mimic_velocity)
        return velocity

    def constraints(self, kin: Kinematics, dt: float, previous: Array) -> Constraints:
        """The step's box (:func:`rrc_pin.solvers.tick.joint_box.joint_box`)."""
        layout = kin.layout
        n = layout.nv
        velocity = self.velocities(layout)
        acceleration = _NO_ACCELERATION if self.acceleration is None else np.asarray(
            self.acceleration
        )
        lb, ub, kind = np.empty(n), np.empty(n), np.empty((2, n), np.int8)
        zero, recovering = joint_box(
            kin.q, layout.lower, layout.upper, velocity, self.margin, self.position_gain, dt,
            previous, acceleration, lb, ub, kind,
        )  # fmt: skip
        return Constraints(Box(lb, ub, kind, zero, recovering, velocity))


_NO_ACCELERATION = np.array([np.inf])
