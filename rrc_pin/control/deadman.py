"""Deadman: a command older than a timeout fades smoothly to zero."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rrc_pin.errors import InvalidInput
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
        """Weight in [0, 1] of a command ``age`` seconds old (inf: never came, 0).

        Raises:
            InvalidInput: ``age`` is not a number, or NaN.
        """
        if type(age) is not float or math.isnan(age):
            age = _age(age)
        x = (age - self.timeout) / self.fade
        if x <= 0.0:
            return 1.0
        if x >= 1.0:
            return 0.0
        return 0.5 * (1.0 + math.cos(math.pi * x))


def _age(age: object) -> float:
    """``age`` [s] as a float: a real number, infinity included (a command that never came).

    Raises:
        InvalidInput: Not a real number, or NaN.
    """
    if isinstance(age, (int, float, np.integer, np.floating)) and not isinstance(age, bool):
        big = isinstance(age, int) and abs(age) > 10**300  # beyond the float range
        out = (math.inf if age > 0 else -math.inf) if big else float(age)
        if not math.isnan(out):
            return out
    raise InvalidInput("age", f"expected a number [s] (inf: never came), got {age!r}")
