"""What Barker's strategies share: his closed form at the robot's tool frame, refused elsewhere."""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
import numpy.typing as npt

from rrc_pin.errors import InvalidInput
from rrc_pin.robot import Robot
from rrc_pin.solvers.closed_form.barker import BarkerClosedForm
from rrc_pin.solvers.closed_form.barker_equations import eq33, f_terms, joint_trig

Array = npt.NDArray[np.float64]


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


class Nearness(NamedTuple):
    """How near Barker's singular sets a configuration is, each in [0, 1]-ish units.

    Attributes:
        shoulder: ``|eq. (32)| / L`` (``L`` the reach from joint 2 to the wrist centre).
        elbow: ``|eq. (33)| / L``.
        wrist: ``|sin theta5|``.
    """

    shoulder: float
    elbow: float
    wrist: float


def nearness(cf: BarkerClosedForm, q: Array) -> Nearness:
    """Barker's singularity conditions (32), (33) and S5 at ``q`` (6,), normalised.

    The values of ``cf.singularity(q)`` on Python floats: 4 us against its 100 us (its batch
    path on one row; measured), for every tick of a controller.
    """
    g = cf.geometry
    t = joint_trig(q)
    return Nearness(abs(f_terms(g, t).f1) / g.reach, abs(eq33(g, t)) / g.reach, abs(t.s5))


def elbow_singular_angle(cf: BarkerClosedForm) -> float:
    """theta3 [rad] nearest 0 where eq. (33) vanishes: ``SAL3 WE S3 + A3 C3 = 0``."""
    g = cf.geometry
    return math.atan2(-g.a3, g.sal3 * g.we)
