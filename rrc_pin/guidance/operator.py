"""Nadkarni's guidance Type IV: operator-commanded motion (chapter IV).

An operator asks for a displacement ``d`` along an axis ``R`` and a turn ``theta`` about the
same axis through a point ``rho_0``, the axis in base axes or in the hand's (``R = Q R'``).
Each command is a screw of pitch ``h = d / theta`` taken in k equal steps of the same twist
(eq. (4-21)), as in Type II. Its ``ref`` names the frame as everywhere in rrc-pin: the twist
``[d u; theta u] / T`` held for a time T in that frame is the same motion (the thesis's NTY = 0
is ``world_aligned``, NTY = 1 ``local``).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import numpy.typing as npt

from rrc_pin.deprecated import warn_renamed
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
from rrc_pin.solvers.checks import finite_number
from rrc_pin.solvers.spatial import REFERENCES, Reference

RENAMED: dict[str, Reference] = {"global": "world_aligned", "hand": "local"}
"""The thesis's frame names, kept for one release (deprecated)."""


class _Fields(NamedTuple):
    axis: npt.ArrayLike
    d: float
    theta: float
    ref: Reference = "world_aligned"
    point: npt.ArrayLike | None = None


class Command(_Fields):
    """One operator command (the thesis's SET THREE card: NTY, DC, DD, THA).

    Attributes:
        axis: (3,) direction R of the motion and of the turn, in ``ref``'s axes.
        d: Displacement along the axis [m].
        theta: Turn about the axis [rad], right-handed.
        ref: ``"world_aligned"`` (default; base axes, the axis through the hand point: the
            thesis's NTY = 0), ``"local"`` (hand axes, through the hand point: NTY = 1) or
            ``"world"`` (base axes, the axis through the base origin). ``"global"`` and
            ``"hand"``, and the keyword ``frame=``, are the old names (deprecated).
        point: (3,) a point of the turning axis, base frame [m]; None: the hand point when
            the command starts (``world_aligned``, ``local``) or the base origin (``world``).
    """

    __slots__ = ()

    def __new__(
        cls,
        axis: npt.ArrayLike,
        d: float,
        theta: float,
        ref: Reference = "world_aligned",
        point: npt.ArrayLike | None = None,
        *,
        frame: str | None = None,
    ) -> Command:
        """The command, its old frame names mapped to today's (with a warning)."""
        if frame is not None:
            warn_renamed("guidance.Command(frame=)", "guidance.Command(ref=)")
            ref = frame  # type: ignore[assignment]
        if isinstance(ref, str) and ref in RENAMED:
            warn_renamed(f"guidance.Command ref {ref!r}", repr(RENAMED[ref]))
            ref = RENAMED[ref]
        return super().__new__(cls, axis, d, theta, ref, point)

    @property
    def frame(self) -> Reference:
        """The old name of :attr:`ref` (deprecated)."""
        warn_renamed("guidance.Command.frame", "guidance.Command.ref")
        return self.ref


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
    ks = [steps] * len(commands) if not isinstance(steps, list) else steps
    if len(ks) != len(commands):
        raise InvalidInput("steps", f"expected {len(commands)} step counts, got {len(ks)}")
    ks = [check_steps(k) for k in ks]
    checked = [_check(c, i) for i, c in enumerate(commands)]
    paths = []
    for (axis, d, theta, ref, point), k in zip(checked, ks, strict=True):
        T = arm.fk(q)
        U = T[:3, :3] @ axis if ref == "local" else axis
        rho = point if point is not None else np.zeros(3) if ref == "world" else T[:3, 3]
        step = hand_twist(U, theta / k, d / k * U, rho)
        path = run_steps(arm, q, _constant(step), k, solver=solver, correction=correction)
        paths.append(path)
        q = path.q[-1]
    return paths


def _constant(step: Array) -> StepTwist:
    def twist(i: int, T: Array) -> Step:
        return screw_step(step, T)

    return twist


def _check(c: Command, i: int) -> tuple[Array, float, float, Reference, Array | None]:
    name = f"commands[{i}]"
    if not isinstance(c, Command):
        raise InvalidInput(name, f"expected a guidance.Command, got {c!r}")
    axis = unit_axis(c.axis, f"{name}.axis")
    d = finite_number(c.d, f"{name}.d")
    theta = finite_number(c.theta, f"{name}.theta")
    if not isinstance(c.ref, str) or c.ref not in REFERENCES:
        raise InvalidInput(f"{name}.ref", f"expected one of {', '.join(REFERENCES)}, got {c.ref!r}")
    point = None
    if c.point is not None:
        point = np.asarray(c.point, dtype=float)
        if point.shape != (3,) or not np.isfinite(point).all():
            raise InvalidInput(f"{name}.point", f"expected a finite (3,) point, got {c.point!r}")
    return axis, d, theta, c.ref, point
