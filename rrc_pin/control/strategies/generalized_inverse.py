"""GeneralizedInverse: Barker's closed-form rates.

Near singularities his 2x2 generalized inverses (eqs (38)-(44), (57)-(60)).
"""

from __future__ import annotations

from rrc_pin.control.strategies.barker_arm import barker_closed_form
from rrc_pin.control.strategies.base import Decision, Situation, Strategy
from rrc_pin.robot import Robot
from rrc_pin.solvers.checks import flag
from rrc_pin.solvers.closed_form.barker import BarkerClosedForm


class GeneralizedInverse(Strategy):
    """Joint rates from Barker's decoupled closed form (``BarkerClosedForm.joint_rates``).

    Outside the singular bands the exact inverse; inside them (default) the damped
    generalized inverse, continuous across the singularity, or (``exact=True``) the truncated
    generalized inverses M*, M1*, M2* of Barker eqs (38), (44), (60). The controller keeps
    the rates inside the joint limits.

    Args:
        exact: Barker's truncated generalized inverses instead of the damped ones.
    """

    name = "generalized_inverse"
    chooses_rates = True

    def __init__(self, exact: bool = False) -> None:
        self.exact = flag(exact, "exact")
        self.closed_form: BarkerClosedForm | None = None

    def check(self, robot: Robot) -> None:
        """Refuse an arm without Barker's closed form."""
        self.closed_form = barker_closed_form(robot, self.name)

    def decide(self, situation: Situation) -> Decision:
        """The closed form's rates for the command."""
        cf = self.closed_form or barker_closed_form(situation.robot, self.name)
        return Decision(rates=cf.joint_rates(situation.q, situation.twist, exact=self.exact))
