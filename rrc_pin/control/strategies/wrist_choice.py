r"""Wrist choice: which joint takes the roll near theta5 = 0 (Barker eqs (61)-(63)).

At theta5 = 0 eq. (50) is useless and eq. (51) becomes
:math:`\dot\theta_4 + \dot\theta_6 = SAL3\,D3 - CAL3\,D2` (eq. (61)): the generalized inverse
splits the roll equally between theta4 and theta6. Instead, while ``|sin theta5| < region``:
:math:`\dot\theta_4 = 0` and theta6 takes the roll, eq. (62); when theta6 reaches its limit
(the roll would carry it beyond), theta4 continues it, eq. (63), with theta6 still. theta5
follows eq. (49) and the arm the closed form. Outside the region the closed form answers.
"""

from __future__ import annotations

import numpy as np

from rrc_pin.control.strategies.barker_arm import barker_closed_form
from rrc_pin.control.strategies.base import Decision, Situation, Strategy
from rrc_pin.robot import Robot
from rrc_pin.solvers.checks import finite_number
from rrc_pin.solvers.closed_form.barker import BarkerClosedForm
from rrc_pin.solvers.closed_form.barker_equations import joint_trig, wrist_equations


class WristChoice(Strategy):
    """Barker's choice of the rolling joint near theta5 = 0 (module docstring).

    Args:
        region: Width of the wrist region in ``|sin theta5|``, in (0, 0.5).
        margin: Distance [rad] from theta6's limits at which the roll passes to theta4, >= 0.

    Raises:
        InvalidInput: A bad argument, named.
    """

    name = "wrist_choice"
    chooses_rates = True

    def __init__(self, region: float = 0.05, margin: float = 0.0) -> None:
        self.region = finite_number(region, "region", 0.0, False, 0.5)
        self.margin = finite_number(margin, "margin", 0.0)
        self.closed_form: BarkerClosedForm | None = None

    def check(self, robot: Robot) -> None:
        """Refuse an arm without Barker's closed form."""
        self.closed_form = barker_closed_form(robot, self.name)

    def decide(self, situation: Situation) -> Decision:
        """The closed form's rates, with the roll on theta6 (or theta4) in the wrist region."""
        cf = self.closed_form or barker_closed_form(situation.robot, self.name)
        q, twist = situation.q, situation.twist
        t = joint_trig(q)
        if abs(t.s5) >= self.region:
            return Decision(rates=cf.joint_rates(q, twist))
        arm = cf.arm_rates(q, twist[:3])
        rvel = cf.rvel_tilde(q, arm, twist[3:])
        th5, _, roll = wrist_equations(cf.geometry, t, *rvel.tolist())  # eqs (49), (61)
        robot = situation.robot
        next6 = q[5] + roll * situation.dt
        at_limit = not (robot.lower[5] + self.margin <= next6 <= robot.upper[5] - self.margin)
        if at_limit:  # eq. (63): theta4 continues the roll
            wrist, note = [roll, th5, 0.0], "roll on theta4 (theta6 at its limit)"
        else:  # eq. (62)
            wrist, note = [0.0, th5, roll], "roll on theta6"
        return Decision(rates=np.concatenate([arm, wrist]), note=note)
