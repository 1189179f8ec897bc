"""Nadkarni's guidance Type III: one point of the hand on a straight line (chapter IV).

The thesis carries the three points of the hand (its origin, a point on its z axis and one on
its x axis, eq. (4-20)) from their start to their goal positions along straight lines divided
into k equal parts; each step is the screw displacement (Type II, one step) from the hand
reached to the next triangle of divided points (:func:`straight_line_points`). The origin keeps
to its line within the first-order error of a step, while the orientation changes gradually,
up to a point: the divided triangles turn fastest at mid-way, 2.7x the uniform rate for a turn
of 150 deg in 20 divisions, 9.5x at 179 deg, and at 180 deg the middle triangle's points are
collinear (no frame at all).

:func:`straight_line`, given the goal as a pose, keeps the origin's division and divides the
turn itself instead: the i-th target is turned by i/k of the rotation's angle about its axis
(:func:`rrc_pin.guidance.screw.axis_angle`, defined from the rotation matrix up to and
including a half turn), so that every division turns the hand by the same angle.

The thesis's program hands each division to its Type II routine (DISPM, Appendix I), which may
take it in several steps along the division's screw, located once: ``substeps`` (a number, or
a rule from the division's screw) says how many; ``b_form="disp"`` is DISPM's vector B and
``closing`` the steps it adds at the end (rrc_pin.guidance.screw_motion; Table A2-9 to every
printed digit with all three, docs/api.md).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Union

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.errors import InvalidInput
from rrc_pin.guidance.screw import Screw, axis_angle, frames_from_points, screw_from_poses
from rrc_pin.guidance.screw_motion import BForm, check_b_form, check_closing, screw_step_b
from rrc_pin.guidance.stepping import (
    MAX_STEPS,
    Array,
    Correction,
    GuidancePath,
    Kinematics,
    Solver,
    Step,
    check_q0,
    check_steps,
    on_frame,
    run_steps,
)
from rrc_pin.solvers.checks import MAX_LENGTH, as_array, finite_number, integer, rigid_transform

Substeps = Union[int, Callable[[Screw], int]]  # noqa: UP007 (a runtime alias on 3.10)
"""Steps per division: a number, or a rule from the division's screw (from the hand reached)."""


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
    frame: str | None = None,
) -> GuidancePath:
    """Type III: the hand origin on the straight line to the goal's, in ``steps`` steps.

    Division i (1..k) aims at the origin i/k of the way along the line, turned i/k of the
    rotation from the start's orientation to the goal's about that rotation's axis: the hand
    turns by theta / k a division (within the first-order error of a step, and the same up
    to and including theta = 180 deg, where the axis is the thesis's sign of the half turn's).

    Args:
        arm: A :class:`rrc_pin.Robot` or :class:`rrc_pin.dh.DHChain`.
        q0: Start configuration (nq,).
        goal: (4, 4) goal pose of the hand, base frame.
        steps: Number of divisions k >= 1.
        solver: ``"thesis"``, a :class:`ThesisSolver` or a :class:`rrc_pin.Resolver`.
        correction: ``"eq5_5"`` or ``"newton"`` for the second-order correction.
        frame: The frame to guide on a robot with several tool frames (a cell, a combined
            robot), or any frame of a :class:`rrc_pin.Robot`; None: its one tool frame.

    Returns:
        The path, one row per step; ``division_ends`` marks the rows that end the divisions.

    Raises:
        InvalidInput: A bad ``goal``, ``q0``, ``steps``, ``solver`` or ``correction``, named.
    """
    arm = on_frame(arm, frame)
    target = rigid_transform(goal, "goal")
    k = check_steps(steps)
    q = check_q0(arm, q0)
    return run_divisions(arm, q, divided_poses(arm.fk(q), target, k), 1, "twist", solver,
                         correction)  # fmt: skip


def divided_poses(start: Array, goal: Array, k: int) -> list[Array]:
    """The k poses (4, 4) that divide the way from ``start`` to ``goal``: origin and turn.

    Pose i (1..k) has the origin ``p0 + i/k (p1 - p0)`` and the orientation
    ``exp(i/k theta u) R0``, where ``theta u`` is the rotation ``R1 R0^T`` (base axes); the
    last is ``goal`` itself.
    """
    u, theta = axis_angle(goal[:3, :3] @ start[:3, :3].T)
    poses = []
    for i in range(1, k + 1):
        T = np.eye(4)
        T[:3, :3] = pin.exp3(i / k * float(theta) * u) @ start[:3, :3]
        T[:3, 3] = start[:3, 3] + i / k * (goal[:3, 3] - start[:3, 3])
        poses.append(T)
    poses[-1] = goal.copy()
    return poses


def straight_line_points(
    arm: Kinematics,
    q0: npt.ArrayLike,
    goal_points: npt.ArrayLike,
    steps: int,
    *,
    spacing: float,
    substeps: Substeps = 1,
    b_form: BForm = "twist",
    closing: int = 0,
    solver: Solver = "thesis",
    correction: Correction = "none",
    frame: str | None = None,
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
        substeps: Steps per division (>= 1), or a rule giving them from the screw from the
            hand reached to the division's triangle; a division's steps share one vector B
            (Type II on the division, its screw located once).
        b_form: ``"twist"`` (eq. (4-19a)) or ``"disp"`` (the thesis's program's B,
            :mod:`rrc_pin.guidance.screw_motion`).
        closing: Steps added after the k divisions, each the screw from the hand reached to the
            goal triangle's frame in one step (DISP took one).
        solver: ``"thesis"``, a :class:`ThesisSolver` or a :class:`rrc_pin.Resolver`.
        correction: ``"eq5_5"`` or ``"newton"`` for the second-order correction.
        frame: The frame to guide on a robot with several tool frames (a cell, a combined
            robot), or any frame of a :class:`rrc_pin.Robot`; None: its one tool frame.

    Returns:
        The path, one row per step; ``division_ends`` marks the rows that end the divisions
        (and the closing steps).

    Raises:
        InvalidInput: Bad ``goal_points`` (collinear, non-finite, or a turn whose divided
            points fall on a line: about 180 deg), ``q0``, ``steps``, ``spacing``,
            ``substeps``, ``b_form`` or ``closing``, named.
    """
    arm = on_frame(arm, frame)
    k = check_steps(steps)
    gap = finite_number(spacing, "spacing", lower=0.0, inclusive=False, upper=MAX_LENGTH)
    end = as_array(goal_points, "goal_points", (3, 3))
    goal = frames_from_points(end, "goal_points")
    extra = check_closing(closing)
    if not callable(substeps):
        check_substeps(substeps)
    q = check_q0(arm, q0)
    start = hand_points(arm.fk(q), gap)
    check_b_form(b_form)
    targets = []
    for i in range(k):
        try:
            targets.append(frames_from_points(start + (i + 1) / k * (end - start)))
        except InvalidInput as exc:
            raise InvalidInput(
                "goal_points",
                f"division {i + 1} of {k}: the divided points fall on a line (a turn of "
                "about 180 deg, which the thesis's division of the points cannot pass); "
                "straight_line(arm, q0, goal_pose, steps) divides the turn itself",
            ) from exc
    return run_divisions(arm, q, targets + [goal] * extra, substeps, b_form, solver, correction,
                         closing=extra)  # fmt: skip


def run_divisions(
    arm: Kinematics,
    q: Array,
    targets: list[Array],
    substeps: Substeps,
    b_form: BForm,
    solver: Solver,
    correction: Correction,
    closing: int = 0,
) -> GuidancePath:
    """One Type II run per target pose (4, 4), each from the hand reached.

    Each target is a division of ``substeps`` steps, but the last ``closing`` ones, which are
    closing steps of one step each.
    """
    pieces = []
    divisions = len(targets) - closing
    for i, target in enumerate(targets):
        screw = screw_from_poses(arm.fk(q), target)
        if i >= divisions:
            n = 1
        else:
            n = check_substeps(_division_steps(substeps, screw))

        def twist(_: int, T: Array, screw: Screw = screw, n: int = n) -> Step:
            return screw_step_b(screw, n, b_form, T)

        piece = run_steps(arm, q, twist, n, solver=solver, correction=correction)
        pieces.append(piece)
        q = piece.q[-1]
    return joined(pieces)


def _division_steps(substeps: Substeps, screw: Screw) -> int:
    """A division's steps: ``substeps``, or what the rule ``substeps(screw)`` gives.

    Raises:
        InvalidInput: The rule raised (its error kept as the cause), naming ``substeps``.
    """
    if not callable(substeps):
        return substeps
    try:
        return substeps(screw)  # checked by the caller
    except Exception as exc:  # the caller's rule: whatever it raises, named as its argument
        raise InvalidInput("substeps", f"the rule raised {type(exc).__name__}: {exc}") from exc


def check_substeps(n: int) -> int:
    """A division's number of steps as an int in [1, MAX_STEPS].

    Raises:
        InvalidInput: Not an integer in [1, MAX_STEPS] (named ``substeps``).
    """
    return integer(n, "substeps", 1, MAX_STEPS)


def joined(pieces: list[GuidancePath]) -> GuidancePath:
    """One path from consecutive runs, each starting where the last ended.

    A run whose first row is an escape (``escapes`` holds 0) replaces the previous run's last
    row, as :func:`run_steps` does within a run.
    """
    q, hand = [pieces[0].q[0]], [pieces[0].hand[0]]
    escapes: list[int] = []
    scale: list[Array] = []
    ends: list[int] = []
    for piece in pieces:
        offset = len(q) - 1
        q[-1], hand[-1] = piece.q[0], piece.hand[0]
        q += list(piece.q[1:])
        hand += list(piece.hand[1:])
        escapes += [offset + i for i in piece.escapes]
        scale.append(piece.scale)
        ends.append(len(q) - 1)
    return GuidancePath(
        np.array(q), np.array(hand), tuple(escapes), np.concatenate(scale), tuple(ends)
    )
