"""What every singularity strategy is: one tick's state in, an adjusted command or rates out."""

from __future__ import annotations

from abc import ABC, abstractmethod
from functools import cached_property
from typing import NamedTuple

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.kinematics import Kinematics
from rrc_pin.robot import Robot

Array = npt.NDArray[np.float64]


class Situation:
    """What a strategy sees at one tick.

    The base-axes twist, the task Jacobian and its singular values are computed on first
    access: a strategy that does not read them (the resolver's) does not pay for them at
    every tick.

    Args:
        robot: The robot.
        q: Joint positions (nq,) [rad or m].
        twist: The command to serve this tick (6,) [m/s, rad/s] (speed override, deadman
            and drift correction applied), in base axes, or in hand axes with ``hand``.
        dt: Control period [s].
        command: The operator's twist (6,) as given, in its frame (speed override and
            deadman applied, no drift correction).
        rows: The task rows of the tool Jacobian: all six, or the three linear ones for an
            arm of fewer than six joints.
        hand: The tool's pose when ``twist`` is in hand axes, else None.
        kinematics: The tick's kinematics at ``q`` (the controller's, shared), or None: the
            Jacobian is then computed here.

    Attributes:
        robot, q, dt, command, rows: As given.
    """

    def __init__(
        self, robot: Robot, q: Array, twist: Array, dt: float, command: Array,
        rows: tuple[int, ...], hand: pin.SE3 | None = None, kinematics: Kinematics | None = None,
    ) -> None:  # fmt: skip
        self.robot, self.q, self.dt, self.command, self.rows = robot, q, dt, command, rows
        self._twist, self._hand, self._kinematics = twist, hand, kinematics

    @cached_property
    def twist(self) -> Array:
        """The command to serve (6,) [m/s, rad/s], ``world_aligned`` (Barker eq. (20))."""
        if self._hand is None:
            return self._twist
        return to_base_axes(self._hand.rotation, self._twist)

    @cached_property
    def jacobian(self) -> Array:
        """The task rows of the tool Jacobian at ``q``, ``world_aligned`` (m, nq)."""
        kin, frame = self._kinematics, self.robot.tool_frame
        if kin is None or frame is None:
            J = self.robot.jacobian(self.q)
        else:
            J = kin.jacobian(frame, "world_aligned")
        out: Array = J if len(self.rows) == 6 else J[list(self.rows)]
        return out

    @cached_property
    def singular_values(self) -> Array:
        """Singular values of :attr:`jacobian`, descending (min(m, nq),)."""
        out: Array = np.asarray(np.linalg.svd(self.jacobian, compute_uv=False), np.float64)
        return out


def to_base_axes(R: Array, twist: Array) -> Array:
    """``[R v; R w]``: a hand-axes twist (6,) in base axes, ``R`` the hand's orientation.

    Stacked alike: twists (n, 6) with orientations (n, 3, 3).
    """
    out: Array = (twist.reshape(*twist.shape[:-1], 2, 3) @ np.swapaxes(R, -1, -2)).reshape(
        twist.shape)  # fmt: skip
    return out


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


KEEP = Decision()
"""The command unchanged."""


class Strategy(ABC):
    """A way of working near singularities, chosen per controller.

    Subclasses set :attr:`name` and implement :meth:`decide`; those that need a particular
    arm refuse others in :meth:`check`. A strategy may keep state across ticks (hysteresis,
    frozen joints, the sign of K3); :meth:`reset` forgets it.
    """

    name: str = "strategy"
    passive: bool = False
    """Whether :meth:`decide` always keeps the command (:data:`KEEP`): the controller then
    builds no :class:`Situation` for it."""
    chooses_rates: bool = False
    """Whether :meth:`decide` always gives joint rates (Barker's strategies): the controller
    then has no commanded pose to hold, and the log's drift is not measured (it reads 0)."""

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
