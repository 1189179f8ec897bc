"""The stepping core shared by Nadkarni's guidance types I-IV (chapter IV).

Every type gives, at each step, the small displacement of the hand as a twist ``B`` (6,) in
Pinocchio's WORLD frame, rows [v; w]: the velocity of the base origin times the step,
Nadkarni's vector B of eq. (4-11a) with its two halves swapped. The core turns it into joint
increments ``D`` with ``J_world(q) D = B`` (eq. (4-11b)) by one of two solvers:

- ``"thesis"``: the thesis's own linear solve (least squares of minimum norm where the arm is
  not square), with his singularity escape (chapter IV, "Singularities" 1): where ``J`` is
  singular (condition number above ``singular_cond``), small increments are given to the
  joints until it is not, and the step is taken from the new configuration;
- a :class:`rrc_pin.Resolver`: ``B / dt`` as a WORLD twist, so the joint limits hold (the
  resolver slows a step down rather than leave them; its report says so).

The second-order correction the thesis suggests (chapter V, suggestion 2) refines the
first-order increments by a few iterations, aiming at the exact pose of the step (its
:class:`Step`'s target: ``exp(B) T`` along a screw, or the turned hand at the moved point for
Type I): ``correction="eq5_5"`` solves his eqs (4-9) and (5-5) by
fixed-point iterations (each joint's own second-order term, no cross terms between joints:
second order only where one revolute joint turns, docs/errata.md); ``correction="newton"``
iterates on the exact pose (every term, quadratic convergence).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Literal, NamedTuple, Protocol

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.errors import InvalidInput
from rrc_pin.resolver import Resolver
from rrc_pin.robot import Robot
from rrc_pin.solvers.checks import as_array, as_vector, choice, direction, finite_number, integer
from rrc_pin.tasks import FrameTask

Array = npt.NDArray[np.float64]
Correction = Literal["none", "eq5_5", "newton"]
SINGULAR_COND = 1e4
"""Condition number of the WORLD Jacobian above which the thesis solver escapes."""
FULL_STEP = 1.0 - 1e-9
"""A resolver's scale at or above this is a full step (the corrections apply)."""
ESCAPE_STEP = 0.05
"""Size [rad or m] of the joint increments of the singularity escape."""


@dataclass(frozen=True)
class ThesisSolver:
    """The thesis's linear solve of eq. (4-11b) with his singularity escape.

    Attributes:
        singular_cond: Condition number of ``J_world`` above which the arm counts as
            singular (> 1).
        escape: (nq,) joint increments [rad or m] given until ``J`` is regular (at most 20
            times); None: :data:`ESCAPE_STEP` with alternating signs (joint 1 down, 2 up...).
    """

    singular_cond: float = SINGULAR_COND
    escape: tuple[float, ...] | None = None

    def __post_init__(self) -> None:
        finite_number(self.singular_cond, "singular_cond", lower=1.0, inclusive=False)  # fmt: skip
        if self.escape is not None:
            kick = as_array(self.escape, "escape", (None,))
            if not kick.any():
                raise InvalidInput("escape", f"expected nonzero increments, got {kick}")

    def kick(self, nq: int) -> Array:
        """The escape's joint increments (nq,).

        Raises:
            InvalidInput: ``escape`` has not ``nq`` entries.
        """
        if self.escape is None:
            return ESCAPE_STEP * np.where(np.arange(nq) % 2 == 0, -1.0, 1.0)
        if len(self.escape) != nq:
            raise InvalidInput("escape", f"expected {nq} increments, got {len(self.escape)}")
        return np.asarray(self.escape, dtype=np.float64)


Solver = Literal["thesis"] | ThesisSolver | Resolver


class Kinematics(Protocol):
    """What the stepping needs of an arm: :class:`rrc_pin.Robot` and :class:`rrc_pin.dh.DHChain`."""

    @property
    def nq(self) -> int: ...  # noqa: D102

    def fk(self, q: npt.ArrayLike) -> Array: ...  # noqa: D102

    def jacobian(  # noqa: D102
        self, q: npt.ArrayLike, ref: Literal["world", "world_aligned"]
    ) -> Array: ...


@dataclass(frozen=True)
class OnFrame:
    """A robot's kinematics at one named frame: what guidance steers when given ``frame=``.

    On a robot with several tool frames (a cell, a combined robot) ``fk`` and ``jacobian``
    need a frame; this names it once. Made by :func:`on_frame`.

    Attributes:
        robot: The robot.
        frame: The frame guided (a frame of ``robot.model``).
    """

    robot: Robot
    frame: str

    @property
    def nq(self) -> int:
        """Length of q."""
        return self.robot.nq

    def fk(self, q: npt.ArrayLike) -> Array:
        """Pose (4, 4) of :attr:`frame` at ``q`` in the robot's base frame [m]."""
        return self.robot.fk(q, self.frame)

    def jacobian(self, q: npt.ArrayLike, ref: Literal["world", "world_aligned"]) -> Array:
        """Jacobian (6, nv) of :attr:`frame` at ``q`` in ``ref``."""
        return self.robot.jacobian(q, ref, self.frame)


def on_frame(arm: Kinematics, frame: str | None) -> Kinematics:
    """``arm`` as guidance steers it.

    Itself (``frame`` None: its one tool frame) or :class:`OnFrame` at ``frame``.

    Raises:
        InvalidInput: Naming ``frame``: not a str, ``arm`` not a :class:`rrc_pin.Robot` (a
            DH chain has its one hand), or no frame of the robot (the error lists its tool
            frames, and a cell's objects and body); naming ``arm``: neither a robot nor a
            chain, or a floating base (guidance adds increments to q).
    """
    if not isinstance(arm, (Robot, OnFrame)) and not (
        isinstance(getattr(arm, "nq", None), int) and callable(getattr(arm, "fk", None))
        and callable(getattr(arm, "jacobian", None))
    ):  # fmt: skip
        raise InvalidInput("arm", f"expected a rrc_pin.Robot or a DHChain, got "
                           f"{type(arm).__name__}")  # fmt: skip
    if isinstance(arm, Robot) and arm.nq != arm.nv:
        raise InvalidInput("arm", f"{arm.name} has a floating base: guidance steps q + dq "
                           "on joints only (drive a legged cell with its controller)")  # fmt: skip
    if frame is None:
        return arm
    if not isinstance(frame, str):
        raise InvalidInput("frame", f"expected a frame name (str) or None, got {frame!r}")
    if not isinstance(arm, Robot):
        raise InvalidInput("frame", f"frame= needs a rrc_pin.Robot, got {type(arm).__name__} "
                           "(its one hand is guided)")  # fmt: skip
    if not arm.model.existFrame(frame):
        names = [*arm.tool_frames, *getattr(arm, "objects", {}), *[
            b for b in [getattr(arm, "body", None)] if b is not None]]  # fmt: skip
        raise InvalidInput("frame", f"{arm.name} has no frame {frame!r}; its tool frames: "
                           f"{', '.join(names)} (or any frame of its model)")  # fmt: skip
    return OnFrame(arm, frame)


@dataclass(frozen=True)
class GuidancePath:
    """Joint path of a guidance run.

    Attributes:
        q: (k + 1, nq) joint positions, the start first [rad or m].
        hand: (k + 1, 4, 4) hand poses reached, base frame.
        escapes: Indices of the steps before which the singularity escape moved the joints.
        scale: (k,) fraction of each step's displacement achieved (1 with the thesis solver;
            below 1 where the resolver stopped short at a joint limit).
        division_ends: Indices into ``q`` of the rows that end each division of Type III
            (and each closing step), its divisions possibly taken in several steps
            (``substeps``); empty for the other types.
    """

    q: Array
    hand: Array
    escapes: tuple[int, ...]
    scale: Array
    division_ends: tuple[int, ...] = ()


class Step(NamedTuple):
    """One step of a guidance type.

    Attributes:
        twist: (6,) WORLD twist [v; w] of the step (Nadkarni's B, eq. (4-11a)).
        target: (4, 4) the exact hand pose the step aims at (what the corrections reach).
    """

    twist: Array
    target: Array


StepTwist = Callable[[int, Array], Step]
"""``step(i, T)``: the :class:`Step` ``i`` (0-based) from the hand pose ``T`` reached."""


def screw_step(twist: Array, T: Array) -> Step:
    """A step along a screw: the target is ``exp(twist) T`` (Types II-IV)."""
    return Step(twist, (pin.exp6(pin.Motion(twist)) * pin.SE3(T)).homogeneous)


def hand_step(axis: Array, angle: float, translation: Array, T: Array) -> Step:
    """A turn about ``axis`` through the hand point and a ``translation`` (3,) of it (Type I).

    The target turns the hand by ``angle`` in place and moves its point by the chord.
    """
    target = T.copy()
    target[:3, :3] = pin.exp3(angle * axis) @ T[:3, :3]
    target[:3, 3] = T[:3, 3] + translation
    return Step(hand_twist(axis, angle, translation, T[:3, 3]), target)


MAX_STEPS = 1_000_000
"""The most steps a guided motion takes (the thesis's k is tens): more would run for hours."""


def check_steps(steps: int, name: str = "steps") -> int:
    """``steps`` as a positive int (the thesis's k), at most :data:`MAX_STEPS`.

    Raises:
        InvalidInput: ``steps`` is not an integer in [1, MAX_STEPS], naming ``name``.
    """
    return integer(steps, name, 1, MAX_STEPS)


def run_steps(
    arm: Kinematics,
    q0: npt.ArrayLike,
    twist: StepTwist,
    steps: int,
    *,
    solver: Solver = "thesis",
    correction: Correction = "none",
    frame: str | None = None,
) -> GuidancePath:
    """Take ``steps`` steps, step ``i`` realising ``twist(i, hand pose)``.

    Args:
        arm: The arm (a :class:`rrc_pin.Robot`, or a :class:`rrc_pin.dh.DHChain` for screw
            joints).
        q0: Start configuration (nq,) [rad or m].
        twist: The step's WORLD twist from its index and the hand pose reached.
        steps: Number of steps k >= 1.
        solver: ``"thesis"`` (:class:`ThesisSolver` with its defaults), a
            :class:`ThesisSolver`, or a :class:`rrc_pin.Resolver` of ``arm`` (joint limits).
        correction: ``"none"`` (first order, eq. (4-11)), ``"eq5_5"`` (the thesis's
            eq. (5-5)) or ``"newton"`` (the exact pose of each step).
        frame: The frame to guide on a robot with several tool frames (a cell, a combined
            robot), or any frame of a :class:`rrc_pin.Robot`; None: its one tool frame.

    Raises:
        InvalidInput: A bad ``q0``, ``steps``, ``solver`` or ``correction``, named.
    """
    arm = on_frame(arm, frame)
    steps = check_steps(steps)
    q = check_q0(arm, q0)
    choice(correction, "correction", ("none", "eq5_5", "newton"))
    if isinstance(solver, str) and solver == "thesis":
        solver = ThesisSolver()
    if not isinstance(solver, (ThesisSolver, Resolver)):
        raise InvalidInput(
            "solver", f"expected 'thesis', a ThesisSolver or a rrc_pin.Resolver, got {solver!r}"
        )
    thesis = solver if isinstance(solver, ThesisSolver) else None
    kick = thesis.kick(q.size) if thesis is not None else None
    qs, hands, scales, escapes = [q], [arm.fk(q)], [], []
    for i in range(steps):
        if thesis is not None and kick is not None:
            escaped = escape_singularity(arm, q, kick, thesis.singular_cond)
            if escaped is not None:
                q = escaped
                escapes.append(i)
                qs[-1], hands[-1] = q, arm.fk(q)
        step = twist(i, hands[-1])
        dq, scale = first_order(arm, q, step.twist, solver)
        if correction != "none" and scale >= FULL_STEP:
            dq = corrected(arm, q, dq, step, correction, solver)
        q = q + dq
        qs.append(q)
        hands.append(arm.fk(q))
        scales.append(scale)
    return GuidancePath(np.array(qs), np.array(hands), tuple(escapes), np.array(scales))


def corrected(
    arm: Kinematics,
    q: Array,
    dq: Array,
    step: Step,
    correction: Correction,
    solver: ThesisSolver | Resolver,
) -> Array:
    """The increments refined by ``correction``.

    The first-order ones stay where the refined step would leave the resolver's joint position
    limits (the corrections know no limits).
    """
    better = (
        newton(arm, q, dq, step.target)
        if correction == "newton"
        else second_order(arm, q, dq, step)
    )
    if isinstance(solver, Resolver):
        moved = q + better
        if np.any(moved < solver.robot.lower) or np.any(moved > solver.robot.upper):
            return dq
    return better


def first_order(
    arm: Kinematics, q: Array, B: Array, solver: ThesisSolver | Resolver
) -> tuple[Array, float]:
    """Joint increments (nq,) of eq. (4-11b), ``J_world D = B``, and the fraction achieved."""
    if isinstance(solver, Resolver):
        if isinstance(arm, OnFrame):  # one of several frames: its task
            r = solver.solve(q, [FrameTask(arm.frame, B / solver.dt, ref="world")])
        else:
            r = solver.solve(q, B / solver.dt, ref="world")
        return np.asarray(r.qdot) * solver.dt, float(r.scale)
    J = arm.jacobian(q, ref="world")
    if J.shape[0] == J.shape[1]:
        return np.asarray(np.linalg.solve(J, B), dtype=np.float64), 1.0
    return lstsq(J, B), 1.0


def escape_singularity(
    arm: Kinematics, q: Array, kick: Array, singular_cond: float, tries: int = 20
) -> Array | None:
    """Nadkarni's escape: a new configuration where ``J`` is regular, or None if ``q``'s is.

    The joints are moved by ``kick`` (nq,) until the condition number of ``J_world`` falls
    below ``singular_cond`` (at most ``tries`` times).
    """
    if _regular(arm, q, singular_cond):
        return None
    moved: Array = q.copy()
    for _ in range(tries):
        moved = moved + kick
        if _regular(arm, moved, singular_cond):
            break
    return moved


def _regular(arm: Kinematics, q: Array, singular_cond: float) -> bool:
    return bool(np.linalg.cond(arm.jacobian(q, ref="world")) < singular_cond)


def newton(arm: Kinematics, q: Array, dq: Array, goal: Array, iterations: int = 3) -> Array:
    """Refine the increments so that the hand reaches the step's ``goal`` (4, 4) exactly.

    The thesis keeps, in eq. (5-5), the second-order term of each joint's own motion; a Newton
    iteration on the exact pose keeps every second-order term (the cross terms between joints
    too) and converges quadratically from the first-order answer of eq. (4-11).
    """
    target = pin.SE3(goal)
    for _ in range(iterations):
        T = pin.SE3(arm.fk(q + dq))
        error = pin.log6(target * T.inverse()).vector  # WORLD twist still to go
        if np.abs(error).max() < 1e-15:
            break
        J = arm.jacobian(q + dq, ref="world")
        dq = dq + lstsq(J, error)
    return dq


def second_order(arm: Kinematics, q: Array, dq: Array, step: Step, iterations: int = 4) -> Array:
    """Nadkarni's eqs (4-9) and (5-5) solved by fixed-point iterations from eq. (4-11)'s answer.

    .. math::

        delta r u_v = sum_j [h_j dtheta_j u_j + dtheta_j u_j x rho_jH
                             + dtheta_j^2 / 2 u_j x (u_j x rho_jH)]      (5-5)

    with ``delta r u_v`` the hand point's displacement to the step's target; the rotation
    keeps eq. (4-9). Prismatic joints have no second-order term. The joint axes
    ``u_j`` and the arms ``rho_jH`` from the hand point are the Jacobian's (revolute and screw
    columns: ``w_j = u_j``, ``v_j = u_j x rho_jH + h_j u_j``).
    """
    p = arm.fk(q)[:3, 3]
    w = step.twist[3:]
    moved = step.target[:3, 3] - p  # the hand point's chord
    target = np.concatenate([moved - np.cross(w, p), w])  # as a WORLD twist
    J = arm.jacobian(q, ref="world")
    Jh = arm.jacobian(q, ref="world_aligned")  # columns at the hand point
    u = Jh[3:].T  # (nq, 3): zero for prismatic joints
    # v_j = u_j x rho_jH + h_j u_j at the hand point, so u_j x v_j = u_j x (u_j x rho_jH).
    square = np.cross(u, Jh[:3].T)  # (nq, 3)
    first = dq
    for _ in range(iterations):
        extra = 0.5 * (dq**2) @ square
        dq = lstsq(J, target - np.concatenate([extra, np.zeros(3)]))
    # the fixed point diverges where J is ill-conditioned: keep the first-order step there
    diverged = not np.isfinite(dq).all() or np.linalg.norm(dq - first) > np.linalg.norm(first)
    return first if diverged else dq


def lstsq(J: Array, b: Array) -> Array:
    """Least-squares solution of minimum norm of ``J x = b``."""
    return np.asarray(np.linalg.lstsq(J, b, rcond=None)[0], dtype=np.float64)


def hand_twist(axis: Array, angle: float, translation: Array, point: Array) -> Array:
    """WORLD twist (6,) [v; w]: a turn ``angle`` about ``axis`` through ``point``, a translation.

    Nadkarni's B of eq. (4-11a), ``[dr u_v - dtheta u_w x rho_0; dtheta u_w]`` (rows swapped).
    """
    out: Array = np.concatenate([translation - angle * np.cross(axis, point), angle * axis])
    return out


def unit_axis(axis: npt.ArrayLike, name: str) -> Array:
    """``axis`` (3,) normalised.

    Raises:
        InvalidInput: Not a finite, nonzero 3-vector.
    """
    out, length = direction(axis, name)
    if length < 1e-12:
        raise InvalidInput(name, f"expected a nonzero axis of shape (3,), got {axis!r}")
    return out


def check_q0(arm: Kinematics, q0: npt.ArrayLike) -> Array:
    """``q0`` as a finite (nq,) float vector (a copy).

    Raises:
        InvalidInput: Wrong shape or non-finite.
    """
    q: Array = as_vector(q0, "q0", arm.nq).copy()
    return q
