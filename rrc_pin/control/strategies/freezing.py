"""Freezing: Barker's variables held constant near a singular point (his text before eq. (45)).

"A variable is held constant until a new value for the variable is computed outside the
specified region." Each tick the closed form (:class:`GeneralizedInverse`'s rates) proposes
new joint values ``q + qdot dt``; where they fall inside an arm region (eq. (32) or (33)
within ``region * L``) theta2 and theta3 keep their values, inside the wrist region
(``|sin theta5| < region``) theta4 and theta6 keep theirs, and the other joints move. As
Barker warns, this excludes positions near the singular sets and may jerk the arm when the
joints are released.
"""

from __future__ import annotations

from rrc_pin.control.strategies.barker_arm import barker_closed_form, nearness
from rrc_pin.control.strategies.base import Decision, Situation, Strategy
from rrc_pin.robot import Robot
from rrc_pin.solvers.checks import finite_number
from rrc_pin.solvers.closed_form.barker import BarkerClosedForm

ARM_JOINTS = (1, 2)
"""theta2, theta3 (indices): frozen near conditions (32) and (33)."""
WRIST_JOINTS = (3, 5)
"""theta4, theta6: frozen near theta5 = 0."""


class Freezing(Strategy):
    """Barker's frozen variables (module docstring).

    Args:
        region: Relative width of the singular regions, in (0, 0.5).

    Raises:
        InvalidInput: A bad ``region``.
    """

    name = "freezing"
    chooses_rates = True

    def __init__(self, region: float = 0.02) -> None:
        self.region = finite_number(region, "region", 0.0, False, 0.5)
        self.closed_form: BarkerClosedForm | None = None

    def check(self, robot: Robot) -> None:
        """Refuse an arm without Barker's closed form."""
        self.closed_form = barker_closed_form(robot, self.name)

    def decide(self, situation: Situation) -> Decision:
        """The closed form's rates with the frozen joints' rates zero."""
        cf = self.closed_form or barker_closed_form(situation.robot, self.name)
        rates = cf.joint_rates(situation.q, situation.twist)
        new = nearness(cf, situation.q + rates * situation.dt)
        frozen: list[int] = []
        if min(new.shoulder, new.elbow) < self.region:
            frozen += ARM_JOINTS
        if new.wrist < self.region:
            frozen += WRIST_JOINTS
        rates[frozen] = 0.0
        note = "frozen " + ", ".join(f"theta{j + 1}" for j in frozen) if frozen else ""
        return Decision(rates=rates, note=note)
