"""Nadkarni's guidance Type III: one point of the hand on a straight line (chapter IV).

The three points of the hand (its origin, a point on its z axis and one on its x axis, each
``spacing`` from the origin, eq. (4-20)) are carried from their start to their goal positions
along straight lines divided into k equal parts; each step is the screw displacement (Type II,
one step) from the hand reached to the next triangle of divided points. The origin keeps to its
line within the first-order error of a step, while the orientation changes gradually.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from rrc_pin.errors import InvalidInput
from rrc_pin.guidance.screw import frames_from_points, screw_from_poses, screw_twist
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
)
from solvers.validation import finite_number, rigid_transform


def hand_points(T: Array, spacing: float) -> Array:
    """The hand's three points (3, 3): origin, origin + spacing z, origin + spacing x."""
    p = T[:3, 3]
    return np.stack([p, p + spacing * T[:3, 2], p + spacing * T[:3, 0]])


def straight_line(
    arm: Kinematics,
    q0: npt.ArrayLike,
    goal: npt.ArrayLike,
    steps: int,
    *,
    spacing: float = 0.0254,
    solver: Solver = "thesis",
    correction: Correction = "none",
) -> GuidancePath:
    """Type III: the hand origin on the straight line to the goal's, in ``steps`` steps.

    Args:
        arm: A :class:`rrc_pin.Robot` or :class:`rrc_pin.dh.DHChain`.
        q0: Start configuration (nq,).
        goal: (4, 4) goal pose of the hand, base frame.
        steps: Number of divisions k >= 1.
        spacing: Distance [m] of the z and x points from the origin (the thesis's a_7 = 1
            unit, default one inch): it sets how the orientation is shared among the steps.
        solver: ``"thesis"``, a :class:`ThesisSolver` or a :class:`rrc_pin.Resolver`.
        correction: ``"newton"`` for the second-order correction (eq. (5-5)).

    Raises:
        InvalidInput: A bad ``goal``, ``q0``, ``steps`` or ``spacing``, named.
    """
    target = rigid_transform(goal, "goal", InvalidInput)
    k = check_steps(steps)
    gap = finite_number(spacing, "spacing", lower=0.0, inclusive=False, error=InvalidInput)
    start = hand_points(arm.fk(check_q0(arm, q0)), gap)
    end = hand_points(target, gap)

    def twist(i: int, T: Array) -> Step:
        planned = frames_from_points(start + (i + 1) / k * (end - start))
        return Step(screw_twist(screw_from_poses(T, planned)), planned)

    return run_steps(arm, q0, twist, k, solver=solver, correction=correction)
