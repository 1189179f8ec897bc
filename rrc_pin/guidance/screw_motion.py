"""Nadkarni's guidance Type II: the hand on the screw of its displacement (chapter IV).

A modified form of Pieper's iterative velocity method (the thesis's footnote): the screw of the
displacement is located once (chapter III) and each of the k steps is the same twist, a turn
``theta / k`` about the axis with the advance ``h theta / k`` along it (eqs (4-18), (4-19a));
a pure translation moves ``d / k`` along it (eq. (4-19b)).
"""

from __future__ import annotations

import numpy.typing as npt

from rrc_pin.errors import InvalidInput
from rrc_pin.guidance.screw import screw_from_poses, screw_twist
from rrc_pin.guidance.stepping import (
    Array,
    Correction,
    GuidancePath,
    Kinematics,
    Solver,
    Step,
    check_q0,
    check_steps,
    run_steps,
    screw_step,
)
from solvers.validation import rigid_transform


def screw_motion(
    arm: Kinematics,
    q0: npt.ArrayLike,
    goal: npt.ArrayLike,
    steps: int,
    *,
    relocate: bool = False,
    solver: Solver = "thesis",
    correction: Correction = "none",
) -> GuidancePath:
    """Type II: from the hand's pose at ``q0`` to ``goal`` along their screw, in ``steps`` steps.

    Args:
        arm: A :class:`rrc_pin.Robot` or :class:`rrc_pin.dh.DHChain`.
        q0: Start configuration (nq,).
        goal: (4, 4) goal pose of the hand, base frame.
        steps: Number of steps k >= 1.
        relocate: False (the thesis): one screw, the same twist at every step, so the
            first-order errors add up (``correction="newton"`` removes them). True: the screw is
            located again from the hand reached, each step a ``1 / (k - i)`` share of it (the
            hand then ends on the goal, near the first screw).
        solver: ``"thesis"``, a :class:`ThesisSolver` or a :class:`rrc_pin.Resolver`.
        correction: ``"newton"`` for the second-order correction (eq. (5-5)).

    Raises:
        InvalidInput: A bad ``goal``, ``q0`` or ``steps``, named.
    """
    target = rigid_transform(goal, "goal", InvalidInput)
    k = check_steps(steps)
    fixed = screw_twist(screw_from_poses(arm.fk(check_q0(arm, q0)), target)) / k

    def twist(i: int, T: Array) -> Step:
        if not relocate:
            return screw_step(fixed, T)
        return screw_step(screw_twist(screw_from_poses(T, target)) / (k - i), T)

    return run_steps(arm, q0, twist, k, solver=solver, correction=correction)
