"""What Barker's strategies share: his closed form at the robot's tool frame, refused elsewhere."""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
import numpy.typing as npt

from rrc_pin.errors import InvalidInput
from rrc_pin.robot import Robot
from rrc_pin.solvers.closed_form.barker import BarkerClosedForm
from rrc_pin.solvers.closed_form.barker_equations import (
    eq33,
    f_terms,
    joint_trig,
    turn1,
    wrist_equations,
)

Array = npt.NDArray[np.float64]


def barker_closed_form(robot: Robot, strategy: str) -> BarkerClosedForm:
    """The robot's :class:`BarkerClosedForm` (``barker6`` and its variants), compiled.

    Its kernels compiled or loaded from numba's cache now (:func:`compile_closed_form`).

    Raises:
        InvalidInput: Naming ``strategy``, for an arm without Barker's closed form.
    """
    cf = robot.closed_form
    if not isinstance(cf, BarkerClosedForm):
        raise InvalidInput(
            "strategy", f"{strategy!r} needs Barker's closed form (barker6 and its variants); "
            f"{robot.name} has none: use 'slowdown' or 'resolver'",
        )  # fmt: skip
    compile_closed_form(cf)
    return cf


def compile_closed_form(cf: BarkerClosedForm) -> None:
    """Compile the kernels Barker's strategies call (or load them from numba's cache) now.

    Each called as a controller's tick calls it: its ``q`` read-only, the twist writable and
    its halves views, ``nearness`` also on a writable ``q``; so that no tick compiles.
    """
    q = np.full(6, 0.3)
    q.flags.writeable = False
    twist = np.full(6, 0.1)
    for exact in (False, True):
        cf.joint_rates(q, twist, exact=exact)
    arm = cf.arm_rates(q, twist[:3])
    cf.wrist_rates(q, cf.rvel_tilde(q, arm, twist[3:]))
    cf.tvel_frame2(q, twist[:3])
    for at in (q, q + twist):
        nearness(cf, at)
        t = joint_trig(at)
        turn1(t, 0.1, 0.1)
        wrist_equations(cf.geometry, t, 0.1, 0.1, 0.1)


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

    The values of ``cf.singularity(q)`` on Python floats, for every tick of a controller (its
    batch path costs more on one row).
    """
    g = cf.geometry
    t = joint_trig(q)
    return Nearness(abs(f_terms(g, t).f1) / g.reach, abs(eq33(g, t)) / g.reach, abs(t.s5))


def elbow_singular_angle(cf: BarkerClosedForm) -> float:
    """theta3 [rad] nearest 0 where eq. (33) vanishes: ``SAL3 WE S3 + A3 C3 = 0``."""
    g = cf.geometry
    return math.atan2(-g.a3, g.sal3 * g.we)
