"""Deadman: a command older than a timeout fades smoothly to zero."""

from __future__ import annotations

import math
from dataclasses import dataclass

from rrc_pin.solvers.checks import finite_number


@dataclass(frozen=True)
class Deadman:
    """How long an operator's command stays valid without a new one.

    The command is held at full strength while its age is at most ``timeout``, then
    multiplied by a raised-cosine ramp from 1 to 0 over ``fade`` (continuous with a continuous
    first derivative: no jerk of the hand), and is zero afterwards.

    Attributes:
        timeout: Age [s] up to which a command is used as given, >= 0.
        fade: Duration [s] of the fade to zero, > 0.

    Raises:
        InvalidInput: ``timeout`` < 0 or ``fade`` <= 0, or not finite.
    """

    timeout: float = 0.2
    fade: float = 0.3

    def __post_init__(self) -> None:
        finite_number(self.timeout, "timeout", 0.0)
        finite_number(self.fade, "fade", 0.0, inclusive=False)

    def factor(self, age: float) -> float:
        """Weight in [0, 1] of a command ``age`` seconds old."""
        x = (age - self.timeout) / self.fade
        if x <= 0.0:
            return 1.0
        if x >= 1.0:
            return 0.0
        return 0.5 * (1.0 + math.cos(math.pi * x))
