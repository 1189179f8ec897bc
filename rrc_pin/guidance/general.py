"""Nadkarni's guidance Type I: a general displacement in k steps (chapter IV, Examples 1-4)."""

from __future__ import annotations

import numpy.typing as npt

from rrc_pin.errors import InvalidInput
from rrc_pin.guidance.screw import screw_from_poses
from rrc_pin.guidance.stepping import (
    Array,
    Correction,
    GuidancePath,
    Kinematics,
    Solver,
    Step,
    check_q0,
    check_steps,
    hand_step,
    on_frame,
    run_steps,
    unit_axis,
)
from rrc_pin.solvers.checks import MAX_LENGTH, finite_number, flag, rigid_transform


def general(
    arm: Kinematics,
    q0: npt.ArrayLike,
    goal: npt.ArrayLike,
    steps: int,
    *,
    relocate: bool = True,
    solver: Solver = "thesis",
    correction: Correction = "none",
    frame: str | None = None,
) -> GuidancePath:
    """Type I, Example 4: from the hand's pose at ``q0`` to ``goal`` in ``steps`` steps.

    Each step turns the hand by ``theta / k`` about the direction ``U`` of the screw axis of the
    displacement, through the hand point, and moves the hand point by ``R / k`` along the line
    joining the two origins (eqs (4-16), (4-17)): rotation and translation axes may differ.

    With ``relocate`` (the reading that reproduces Table A2-13 to its printed digits; DISP
    "uses the actual position of the manipulator hand ... for any intermediate stage"), the
    screw and ``R`` are located again at every step from the hand reached to ``goal`` and
    divided by the steps left, ``k - i``. Without it they are located once (eq. (4-17) as
    printed) and the first-order errors of the steps add up.

    Args:
        arm: A :class:`rrc_pin.Robot` or :class:`rrc_pin.dh.DHChain`.
        q0: Start configuration (nq,).
        goal: (4, 4) goal pose of the hand, base frame.
        steps: Number of steps k >= 1.
        relocate: Locate the screw again at every step (default) or once.
        solver: ``"thesis"``, a :class:`ThesisSolver` (eq. (4-11b)) or a
            :class:`rrc_pin.Resolver` (joint limits hold).
        correction: ``"newton"`` for the second-order correction (eq. (5-5)).
        frame: The frame to guide on a robot with several tool frames (a cell, a combined
            robot), or any frame of a :class:`rrc_pin.Robot`; None: its one tool frame.

    Raises:
        InvalidInput: A bad ``goal``, ``q0`` or ``steps``, named.
    """
    arm = on_frame(arm, frame)
    target = rigid_transform(goal, "goal")
    k = check_steps(steps)
    start = None if flag(relocate, "relocate") else arm.fk(check_q0(arm, q0))

    def twist(i: int, T: Array) -> Step:
        frm, left = (T, k - i) if start is None else (start, k)
        s = screw_from_poses(frm, target)
        R = target[:3, 3] - frm[:3, 3]
        return hand_step(s.u, float(s.theta) / left, R / left, T)

    return run_steps(arm, q0, twist, k, solver=solver, correction=correction)


def general_axes(
    arm: Kinematics,
    q0: npt.ArrayLike,
    rotation: tuple[npt.ArrayLike, float],
    translation: tuple[npt.ArrayLike, float],
    steps: int,
    *,
    solver: Solver = "thesis",
    correction: Correction = "none",
    frame: str | None = None,
) -> GuidancePath:
    """Type I, Examples 1-3: a turn and a translation about and along fixed axes, k steps.

    The hand turns ``theta`` about ``u_w`` through the hand point and its point moves ``r``
    along ``u_v``, both axes fixed in the base frame, in ``steps`` equal steps.

    Args:
        arm: A :class:`rrc_pin.Robot` or :class:`rrc_pin.dh.DHChain`.
        q0: Start configuration (nq,).
        rotation: ``(u_w, theta)``: axis (3,) (any length, not zero) and angle [rad].
        translation: ``(u_v, r)``: direction (3,) and distance [m].
        steps: Number of steps k >= 1.
        solver: ``"thesis"``, a :class:`ThesisSolver` or a :class:`rrc_pin.Resolver`.
        correction: ``"newton"`` for the second-order correction (eq. (5-5)).
        frame: The frame to guide on a robot with several tool frames (a cell, a combined
            robot), or any frame of a :class:`rrc_pin.Robot`; None: its one tool frame.

    Raises:
        InvalidInput: Not ``(axis, amount)`` pairs, a zero or non-finite axis, an angle or
            distance not finite (or beyond ``MAX_LENGTH``), bad steps.
    """
    arm = on_frame(arm, frame)
    u_w, theta = _axis_and_amount(rotation, "rotation")
    u_v, r = _axis_and_amount(translation, "translation")
    k = check_steps(steps)

    def twist(i: int, T: Array) -> Step:
        return hand_step(u_w, theta / k, r / k * u_v, T)

    return run_steps(arm, q0, twist, k, solver=solver, correction=correction)


def _axis_and_amount(pair: tuple[npt.ArrayLike, float], name: str) -> tuple[Array, float]:
    """``(axis, amount)``: the unit axis (3,) and the angle [rad] or distance [m].

    Raises:
        InvalidInput: Not such a pair, naming ``name``.
    """
    if not isinstance(pair, (tuple, list)) or len(pair) != 2:
        raise InvalidInput(name, f"expected (axis (3,), amount), got {pair!r}")
    amount = finite_number(pair[1], name, -MAX_LENGTH, upper=MAX_LENGTH)
    return unit_axis(pair[0], name), amount
