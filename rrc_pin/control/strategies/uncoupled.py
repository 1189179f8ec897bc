"""Uncoupled arm and wrist: Barker's way around the wrist singularity (text after eq. (63)).

"(1) position the wrist with thetadot_1, thetadot_2 and thetadot_3 (eq. 23); and (2)
individually command the joint velocities thetadot_4, thetadot_5 and thetadot_6 at the wrist."
The command's linear part is the wrist centre's velocity (base axes after the controller's
frame change), solved by the arm block of the closed form (eqs (25)-(36), damped in its
band); its angular part *as the operator gave it* is read as the three wrist joint rates
[rad/s], so no wrist singularity can arise.
"""

from __future__ import annotations

import numpy as np

from rrc_pin.control.strategies.barker_arm import barker_closed_form
from rrc_pin.control.strategies.base import Decision, Situation, Strategy
from rrc_pin.robot import Robot
from rrc_pin.solvers.closed_form.barker import BarkerClosedForm


class Uncoupled(Strategy):
    """Arm by eq. (23), wrist joints commanded one by one (module docstring)."""

    name = "uncoupled"
    chooses_rates = True

    def __init__(self) -> None:
        self.closed_form: BarkerClosedForm | None = None

    def check(self, robot: Robot) -> None:
        """Refuse an arm without Barker's closed form."""
        self.closed_form = barker_closed_form(robot, self.name)

    def decide(self, situation: Situation) -> Decision:
        """thetadot_1..3 from the wrist-centre velocity, thetadot_4..6 from the command."""
        cf = self.closed_form or barker_closed_form(situation.robot, self.name)
        arm = cf.arm_rates(situation.q, situation.twist[:3])
        return Decision(rates=np.concatenate([arm, situation.command[3:]]), note="uncoupled")
