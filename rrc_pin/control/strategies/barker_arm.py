"""What Barker's strategies share: his closed form at the robot's tool frame, refused elsewhere."""

from __future__ import annotations

from rrc_pin.errors import InvalidInput
from rrc_pin.robot import Robot
from solvers.closed_form.barker import BarkerClosedForm


def barker_closed_form(robot: Robot, strategy: str) -> BarkerClosedForm:
    """The robot's :class:`BarkerClosedForm` (``barker6`` and its variants).

    Raises:
        InvalidInput: Naming ``strategy``, for an arm without Barker's closed form.
    """
    cf = robot.closed_form
    if not isinstance(cf, BarkerClosedForm):
        raise InvalidInput(
            "strategy", f"{strategy!r} needs Barker's closed form (barker6 and its variants); "
            f"{robot.name} has none: use 'slowdown' or 'resolver'",
        )  # fmt: skip
    return cf
