"""Nadkarni's guidance Type IV: operator-commanded motion (chapter IV).

An operator asks for a displacement ``d`` along an axis ``R`` and a turn ``theta`` about the
same axis through a point ``rho_0`` (default: the hand point when the command starts), in the
global frame or in the hand frame (``R = Q R'``). Each command is a screw of pitch
``h = d / theta`` taken in k equal steps of the same twist (eq. (4-21)), as in Type II.
"""

from __future__ import annotations

from typing import Literal, NamedTuple

import numpy.typing as npt

from rrc_pin.errors import InvalidInput
from rrc_pin.guidance.stepping import (
    Array,
    Correction,
    GuidancePath,
    Kinematics,
    Solver,
    Step,
    StepTwist,
    check_q0,
    check_steps,
    hand_twist,
    on_frame,
    run_steps,
    screw_step,
    unit_axis,
)
from rrc_pin.solvers.checks import as_vector, choice, finite_number

Frame = Literal["global", "hand"]


class Command(NamedTuple):
    """One operator command (the thesis's SET THREE card: NTY, DC, DD, THA).

    Attributes:
        axis: (3,) direction R of the motion and of the turn, in ``frame``.
        d: Displacement along the axis [m].
        theta: Turn about the axis [rad], right-handed.
        frame: ``"global"`` (NTY = 0) or ``"hand"`` (NTY = 1).
        point: (3,) a point of the turning axis, base frame [m]; None: the hand point.
    """

    axis: npt.ArrayLike
    d: float
    theta: float
    frame: Frame = "global"
    point: npt.ArrayLike | None = None


def operator(
    arm: Kinematics,
    q0: npt.ArrayLike,
    commands: list[Command],
    steps: int | list[int],
    *,
    solver: Solver = "thesis",
    correction: Correction = "none",
    frame: str | None = None,
) -> list[GuidancePath]:
    """Type IV: the commands one after another, each from where the previous one ended.

    Args:
        arm: A :class:`rrc_pin.Robot` or :class:`rrc_pin.dh.DHChain`.
        q0: Start configuration (nq,).
        commands: The operator's commands, in order.
        steps: Steps per command (one k for all, or one per command).
        solver: ``"thesis"``, a :class:`ThesisSolver` or a :class:`rrc_pin.Resolver`.
        correction: ``"newton"`` for the second-order correction (eq. (5-5)).
        frame: The frame to guide on a robot with several tool frames (a cell, a combined
            robot), or any frame of a :class:`rrc_pin.Robot`; None: its one tool frame.

    Returns:
        One path per command (each starts where the previous one ended).

    Raises:
        InvalidInput: A bad command (named ``commands[i].field``), ``q0`` or ``steps``.
    """
    arm = on_frame(arm, frame)
    q = check_q0(arm, q0)
    if not isinstance(commands, (list, tuple)):
        raise InvalidInput("commands", f"expected a list of guidance.Command, got "
                           f"{type(commands).__name__}")  # fmt: skip
    ks = [steps] * len(commands) if not isinstance(steps, list) else steps
    if len(ks) != len(commands):
        raise InvalidInput("steps", f"expected {len(commands)} step counts, got {len(ks)}")
    ks = [check_steps(k) for k in ks]
    checked = [_check(c, i) for i, c in enumerate(commands)]
    paths = []
    for (axis, d, theta, frame, point), k in zip(checked, ks, strict=True):
        T = arm.fk(q)
        U = T[:3, :3] @ axis if frame == "hand" else axis
        rho = T[:3, 3] if point is None else point
        step = hand_twist(U, theta / k, d / k * U, rho)
        path = run_steps(arm, q, _constant(step), k, solver=solver, correction=correction)
        paths.append(path)
        q = path.q[-1]
    return paths


def _constant(step: Array) -> StepTwist:
    def twist(i: int, T: Array) -> Step:
        return screw_step(step, T)

    return twist


def _check(c: Command, i: int) -> tuple[Array, float, float, Frame, Array | None]:
    name = f"commands[{i}]"
    if not isinstance(c, Command):
        raise InvalidInput(name, f"expected a guidance.Command, got {c!r}")
    axis = unit_axis(c.axis, f"{name}.axis")
    d = finite_number(c.d, f"{name}.d")
    theta = finite_number(c.theta, f"{name}.theta")
    frame = choice(c.frame, f"{name}.frame", ("global", "hand"))
    point = None if c.point is None else as_vector(c.point, f"{name}.point", 3)
    return axis, d, theta, frame, point  # type: ignore[return-value]
