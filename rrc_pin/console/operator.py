r"""The operator at the console: what the controls ask of the hand at this tick.

The loop keeps one :class:`Operator`, applies the page's commands to it and asks it for the
tick's twist. The deadman gates everything: the hold button's heartbeats (each good for
:attr:`OperatorSettings.hold_timeout`) or the latch. While it is released the operator
commands nothing new and the controller's own deadman fades the last command out (Barker's
operator lets go of the hand controller).

Three sources of a twist, in the order they win:

- the target (the gizmo): the hand servoes to a pose,

  .. math:: \xi = \mathrm{clip}(k\, \log_6(T^{-1} T^*)) \quad \text{(hand axes)},

  linear and angular parts clipped to the sliders' largest values;
- the sliders (held until changed) plus the keyboard's jogs (each press good for
  :attr:`OperatorSettings.jog_timeout`, so that a held key's repeats keep it going),
  in hand or base axes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.console.commands import Frame, Hold, Jog, Latch, Target, Velocity
from rrc_pin.errors import InvalidInput
from rrc_pin.solvers.checks import finite_number

Array = npt.NDArray[np.float64]


@dataclass(frozen=True)
class OperatorSettings:
    """The console's limits on what the operator may command.

    Attributes:
        max_linear: Largest slider value of a linear component [m/s], > 0.
        max_angular: Largest slider value of an angular component [rad/s], > 0.
        jog_fraction: A key's jog as a fraction of the largest slider value, in (0, 1].
        jog_timeout: How long one key press commands [s], > 0 (longer than a key's
            auto-repeat interval, about 0.03 to 0.1 s).
        hold_timeout: How long one heartbeat of the hold button keeps the deadman held [s],
            > 0 (longer than the button's heartbeat period, 0.05 s).
        target_gain: Gain of the servo to the target [1/s], > 0.

    Raises:
        InvalidInput: A value out of its range, named.
    """

    max_linear: float = 0.1
    max_angular: float = 0.5
    jog_fraction: float = 0.5
    jog_timeout: float = 0.25
    hold_timeout: float = 0.25
    target_gain: float = 2.0

    def __post_init__(self) -> None:
        for name in ("max_linear", "max_angular", "jog_timeout", "hold_timeout", "target_gain"):
            finite_number(getattr(self, name), name, 0.0, inclusive=False)
        fraction = finite_number(self.jog_fraction, "jog_fraction", 0.0, inclusive=False)
        if fraction > 1.0:
            raise InvalidInput("jog_fraction", f"expected a number in (0, 1], got {fraction}")


class Operator:
    """The state of the console's controls, and the twist they command now.

    Args:
        settings: The limits of the controls.

    Attributes:
        velocity: The sliders' twist (6,) [m/s, rad/s] in :attr:`frame`.
        frame: ``"local"`` or ``"world_aligned"``.
        latched: Whether the deadman is latched on.
        target: The pose (4, 4) the hand servoes to, or None.
        stops: How many times :meth:`stop` was called (the page resets its controls when
            it changes).
    """

    def __init__(self, settings: OperatorSettings | None = None) -> None:
        self.settings = settings or OperatorSettings()
        self.velocity: Array = np.zeros(6)
        self.frame: Frame = "local"
        self.latched = False
        self.target: Array | None = None
        self._jog: Array = np.zeros(6)
        self._jog_until = -math.inf
        self._held_until = -math.inf
        self.stops = 0

    def apply(self, command: Velocity | Jog | Hold | Latch | Target, now: float) -> None:
        """Take one of the controls' commands at time ``now`` [s] (a monotonic clock)."""
        s = self.settings
        if isinstance(command, Velocity):
            self.velocity, self.frame = command.twist.copy(), command.frame
        elif isinstance(command, Jog):
            speed = (s.max_linear if command.axis < 3 else s.max_angular) * s.jog_fraction
            if now > self._jog_until:
                self._jog = np.zeros(6)
            self._jog[command.axis] = command.sign * speed
            self._jog_until = now + s.jog_timeout
        elif isinstance(command, Hold):
            self._held_until = now + s.hold_timeout
        elif isinstance(command, Latch):
            self.latched = command.on
        else:
            self.target = command.pose

    def stop(self) -> None:
        """Release the deadman and drop every command (sliders, jogs, target); counted."""
        self.stops += 1
        self.velocity = np.zeros(6)
        self.latched = False
        self.target = None
        self._jog = np.zeros(6)
        self._jog_until = self._held_until = -math.inf

    def enabled(self, now: float) -> bool:
        """Whether the deadman is held (a recent heartbeat) or latched at ``now``."""
        return self.latched or now <= self._held_until

    def twist(self, now: float, pose: Array | None = None) -> tuple[Array, Frame] | None:
        """The twist to command at ``now``, or None when the deadman is released.

        Args:
            now: Time [s] of the tick (the clock of :meth:`apply`).
            pose: The commanded hand's pose (4, 4) in the base frame, needed when a target is
                set (see :meth:`needs_pose`).

        Returns:
            (twist (6,) [m/s, rad/s], its frame), or None: no new command (the controller's
            deadman fades the last one).
        """
        if not self.enabled(now):
            return None
        if self.target is not None and pose is not None:
            return self._servo(pose, self.target), "local"
        if now <= self._jog_until:
            return self.velocity + self._jog, self.frame
        return self.velocity.copy(), self.frame

    def needs_pose(self) -> bool:
        """Whether :meth:`twist` needs the hand's pose (a target is set)."""
        return self.target is not None

    def _servo(self, pose: Array, target: Array) -> Array:
        """The clipped twist (hand axes) that takes the hand from ``pose`` toward ``target``."""
        s = self.settings
        error = pin.log6(pin.SE3(pose).actInv(pin.SE3(target)))
        twist: Array = s.target_gain * np.concatenate([error.linear, error.angular])
        for part, limit in ((slice(0, 3), s.max_linear), (slice(3, 6), s.max_angular)):
            size = float(np.linalg.norm(twist[part]))
            if size > limit:
                twist[part] *= limit / size
        return twist
