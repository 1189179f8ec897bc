r"""Slowdown: approaching a singularity slows the hand; moving away is never slowed.

A velocity damper on a singularity measure ``m`` (the smallest singular value of the task
Jacobian, or the manipulability ``prod sigma_i``): once ``m`` falls below ``start`` the
strategy predicts how fast the full command would decrease ``m`` (a finite difference along
the least-squares joint rates of the command) and scales the command so that

.. math:: -\dot m \le \mathrm{rate}\,(m - \mathrm{stop}),

so ``m`` approaches ``stop`` at most exponentially and never crosses it to first order. A
command that keeps ``m`` or increases it (moving along or away from the singularity) gets
factor 1: an operator who was slowed down can always jog back out (MoveIt Servo's halt does
not let them). Hysteresis: the damper engages below ``start`` and releases only above
``release * start``.
"""

from __future__ import annotations

from typing import Any, Literal

import numpy as np
import numpy.typing as npt

from rrc_pin.control.strategies.base import Decision, Situation, Strategy
from rrc_pin.solvers.checks import choice, finite_number

Measure = Literal["sigma_min", "manipulability"]
STEP = 1e-6
"""[rad] Length of the finite-difference step along the predicted joint motion."""


class Slowdown(Strategy):
    """Velocity damper on a singularity measure, with hysteresis (module docstring).

    Args:
        measure: ``"sigma_min"`` (smallest singular value of the task Jacobian, [m/s] or
            [rad/s] per unit joint rate) or ``"manipulability"`` (product of the singular
            values).
        start: Measure below which the damper engages, > stop.
        stop: Measure the hand does not approach beyond, >= 0.
        rate: Damper rate [1/s], > 0: the largest relative decrease of ``m - stop`` per
            second.
        release: Hysteresis ratio >= 1: the damper releases above ``release * start``.

    Raises:
        InvalidInput: A bad argument, named.
    """

    name = "slowdown"

    def __init__(
        self, measure: Measure = "sigma_min", *, start: float = 0.05, stop: float = 0.005,
        rate: float = 4.0, release: float = 1.2,
    ) -> None:  # fmt: skip
        self.measure: Measure = choice(measure, "measure", ("sigma_min", "manipulability"))  # type: ignore[assignment]
        self.stop = finite_number(stop, "stop", 0.0)
        self.start = finite_number(start, "start", self.stop, inclusive=False)
        self.rate = finite_number(rate, "rate", 0.0, inclusive=False)
        self.release = finite_number(release, "release", 1.0)
        self.engaged = False

    def reset(self) -> None:
        """Release the damper."""
        self.engaged = False

    def value(self, singular_values: npt.NDArray[np.floating[Any]]) -> float:
        """The measure from the singular values of the task Jacobian."""
        if self.measure == "sigma_min":
            return float(singular_values[-1])
        return float(np.prod(singular_values))

    def decide(self, situation: Situation) -> Decision:
        """Factor 1 away from singularities or moving away; the damper's factor approaching."""
        m = self.value(situation.singular_values)
        if self.engaged and m > self.release * self.start:
            self.engaged = False
        elif not self.engaged and m < self.start:
            self.engaged = True
        if not self.engaged or not situation.twist.any():
            return Decision()
        approach = self.approach_rate(situation, m)
        allowed = self.rate * max(m - self.stop, 0.0)
        if approach <= allowed:
            return Decision(note=f"{self.measure} {m:.3g}, leaving" if approach <= 0 else "")
        factor = allowed / approach
        return Decision(factor=factor, note=f"{self.measure} {m:.3g}: speed x{factor:.3f}")

    def approach_rate(self, situation: Situation, m: float) -> float:
        """``-dm/dt`` [measure/s] under the full command (> 0: approaching the singularity).

        Along the least-squares joint rates of the command (singular values below ``stop``
        damped), by a finite difference of :data:`STEP` rad.
        """
        J = situation.jacobian
        U, s, Vt = np.linalg.svd(J, full_matrices=False)
        damp = max(self.stop, 1e-9 * float(s[0]))
        qdot = Vt.T @ ((s / (s * s + damp * damp)) * (U.T @ situation.twist[: J.shape[0]]))
        speed = float(np.linalg.norm(qdot))
        if speed == 0.0:
            return 0.0
        h = STEP / speed
        robot = situation.robot
        J_next = robot.jacobian(situation.q + h * qdot)[: J.shape[0]]
        m_next = self.value(np.linalg.svd(J_next, compute_uv=False))
        return (m - m_next) / h
