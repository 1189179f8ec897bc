"""Nadkarni's guidance Type III: one point of the hand on a straight line (chapter IV).

The three points of the hand (its origin, a point on its z axis and one on its x axis,
eq. (4-20)) are carried from their start to their goal positions
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
    solver: Solver = "thesis",
    correction: Correction = "none",
) -> GuidancePath:
    """Type III: the hand origin on the straight line to the goal's, in ``steps`` steps.

    The hand's points are taken at the same distance from the origin in both poses, which
    makes the orientation of the divided triangles independent of that distance.

    Args:
        arm: A :class:`rrc_pin.Robot` or :class:`rrc_pin.dh.DHChain`.
        q0: Start configuration (nq,).
        goal: (4, 4) goal pose of the hand, base frame.
        steps: Number of divisions k >= 1.
        solver: ``"thesis"``, a :class:`ThesisSolver` or a :class:`rrc_pin.Resolver`.
        correction: ``"eq5_5"`` or ``"newton"`` for the second-order correction.

    Raises:
        InvalidInput: A bad ``goal``, ``q0`` or ``steps``, named.
    """
    target = rigid_transform(goal, "goal", InvalidInput)
    return straight_line_points(
        arm, q0, hand_points(target, 1.0), steps, spacing=1.0, solver=solver,
        correction=correction,
    )  # fmt: skip


def straight_line_points(
    arm: Kinematics,
    q0: npt.ArrayLike,
    goal_points: npt.ArrayLike,
    steps: int,
    *,
    spacing: float,
    solver: Solver = "thesis",
    correction: Correction = "none",
) -> GuidancePath:
    """Type III as the thesis states it: the goal given by three points of the hand.

    The start triangle is the hand's origin, origin + ``spacing`` z and origin + ``spacing`` x
    (the thesis's hand points at a_7); the goal triangle is ``goal_points``, whose points need
    not be at that distance: the ratio of the two triangles' sides sets how the turn is shared
    among the divisions (Illustration 5's goal has its z point 5 units out, its x point 1).

    Args:
        arm: A :class:`rrc_pin.Robot` or :class:`rrc_pin.dh.DHChain`.
        q0: Start configuration (nq,).
        goal_points: (3, 3) rows: the goal origin, a point on its +z axis, a point in its x-z
            plane on the +x side [m].
        steps: Number of divisions k >= 1.
        spacing: Distance [m] of the start triangle's z and x points from the origin, > 0.
        solver: ``"thesis"``, a :class:`ThesisSolver` or a :class:`rrc_pin.Resolver`.
        correction: ``"eq5_5"`` or ``"newton"`` for the second-order correction.

    Raises:
        InvalidInput: Bad ``goal_points`` (collinear, non-finite), ``q0``, ``steps`` or
            ``spacing``, named.
    """
    k = check_steps(steps)
    gap = finite_number(spacing, "spacing", lower=0.0, inclusive=False, error=InvalidInput)
    frames_from_points(goal_points, "goal_points")
    end = np.asarray(goal_points, dtype=np.float64)
    start = hand_points(arm.fk(check_q0(arm, q0)), gap)

    def twist(i: int, T: Array) -> Step:
        planned = frames_from_points(start + (i + 1) / k * (end - start))
        return Step(screw_twist(screw_from_poses(T, planned)), planned)

    return run_steps(arm, q0, twist, k, solver=solver, correction=correction)
