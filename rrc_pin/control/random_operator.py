"""Random operator commands for simulated sessions: piecewise-constant hand-frame twists."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from rrc_pin.errors import InvalidInput
from rrc_pin.solvers.checks import finite_number

Array = npt.NDArray[np.float64]


def random_commands(
    rng: np.random.Generator, seconds: float, dt: float, *, speed: float = 0.05,
    turn: float = 0.2, hold: float = 0.5, pause: float = 0.1,
) -> Array:  # fmt: skip
    """Twists an operator might send at every tick, (round(seconds / dt), 6).

    Every ``hold`` seconds a new twist: linear part normal with standard deviation ``speed``
    [m/s] per axis, angular part ``turn`` [rad/s]; with probability ``pause`` the operator
    lets go (zero twist).

    Raises:
        InvalidInput: A bad argument, named.
    """
    if not isinstance(rng, np.random.Generator):
        raise InvalidInput("rng", f"expected a numpy Generator, got {rng!r}")
    seconds = finite_number(seconds, "seconds", 0.0, inclusive=False)
    dt = finite_number(dt, "dt", 0.0, inclusive=False)
    hold = finite_number(hold, "hold", 0.0, inclusive=False)
    n, per = round(seconds / dt), max(1, round(hold / dt))
    segments = -(-n // per)
    twists = rng.normal(size=(segments, 6)) * np.array([speed] * 3 + [turn] * 3)
    twists[rng.random(segments) < pause] = 0.0
    out: Array = np.repeat(twists, per, axis=0)[:n]
    return out
