"""What every singularity strategy is: one tick's state in, an adjusted command or rates out."""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import NamedTuple

import numpy as np
import numpy.typing as npt

from rrc_pin.robot import Robot

Array = npt.NDArray[np.float64]


class Situation(NamedTuple):
    """What a strategy sees at one tick.

    Attributes:
        robot: The robot.
        q: Joint positions (nq,) [rad or m].
        twist: The command to serve this tick (6,) [m/s, rad/s], ``world_aligned`` (speed
            override, deadman and drift correction applied).
        jacobian: The task rows of the tool Jacobian at ``q``, ``world_aligned`` (m, nq)
            (all six rows, or the three linear ones for an arm of fewer than six joints).
        singular_values: Singular values of ``jacobian``, descending (min(m, nq),).
        dt: Control period [s].
        command: The operator's twist (6,) as given, in its frame (speed override and
            deadman applied, no drift correction).
    """

    robot: Robot
    q: Array
    twist: Array
    jacobian: Array
    singular_values: Array
    dt: float
    command: Array


class Decision(NamedTuple):
    """What a strategy decided.

    Attributes:
        factor: Speed factor in [0, 1] applied to the command (1: unchanged).
        rates: Joint rates (nq,) [rad/s] chosen by the strategy, or None to let the resolver
            resolve the (scaled) command. The controller keeps them inside the joint limits
            (scaled uniformly into them when they do not fit).
        note: What the strategy did, for the log ("" when nothing).
    """

    factor: float = 1.0
    rates: Array | None = None
    note: str = ""


class Strategy(ABC):
    """A way of working near singularities, chosen per controller.

    Subclasses set :attr:`name` and implement :meth:`decide`; those that need a particular
    arm refuse others in :meth:`check`. A strategy may keep state across ticks (hysteresis,
    frozen joints, the sign of K3); :meth:`reset` forgets it.
    """

    name: str = "strategy"

    def check(self, robot: Robot) -> None:  # noqa: B027 - a hook: most strategies take any arm
        """Refuse a robot this strategy cannot work on.

        Raises:
            InvalidInput: Naming ``strategy``, saying what the strategy needs.
        """

    @abstractmethod
    def decide(self, situation: Situation) -> Decision:
        """The adjusted command (a speed factor) or the joint rates for this tick."""

    def reset(self) -> None:  # noqa: B027 - stateless strategies have nothing to forget
        """Forget the state carried across ticks."""
