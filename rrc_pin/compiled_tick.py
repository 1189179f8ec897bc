"""A resolver's ticks in one compiled call: its inputs loaded, its answer read back lazily.

The :class:`~rrc_pin.Resolver` hands a tick here where its joint box is one
:class:`~rrc_pin.limits.JointLimits` and no limit gives another box or equality rows (contacts):
the tasks' rows and the other limits' constraint rows go into the resolver's
:class:`~rrc_pin.solvers.tick.tick.Workspace`, one call of
:func:`rrc_pin.solvers.tick.tick.run` answers (the QPs its kernels do not answer go to the
backend from inside it), and the :class:`~rrc_pin.solvers.tick.resolution.Resolution` keeps the
tick's arrays: its problem, task reports and active sets are built where they are read
(:class:`TickSource`). Where the top level finds no usable answer, the fallbacks answer as the
Python pipeline's do (:func:`rrc_pin.solvers.tick.pipeline.fallback_answer`).
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from typing import Any, get_args

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.kinematics import Kinematics, Layout
from rrc_pin.limits import JointLimits
from rrc_pin.robot import PIN_REFERENCE
from rrc_pin.solvers.checks import as_vector
from rrc_pin.solvers.qp_backends.base import QPBackend
from rrc_pin.solvers.qp_backends.qp import Work, velocity_tolerance
from rrc_pin.solvers.tick import backend_calls, tick
from rrc_pin.solvers.tick.pipeline import LevelStatus, Options, Status, fallback_answer
from rrc_pin.solvers.tick.problem import (
    Box,
    Constraints,
    Problem,
    TaskRows,
    build,
    finite_rows,
    merged_rows,
)
from rrc_pin.solvers.tick.resolution import Resolution
from rrc_pin.solvers.tick.top import FAILED
from rrc_pin.tasks import FrameTask

Array = npt.NDArray[np.float64]

STATUSES: tuple[Status, ...] = get_args(Status)
"""The statuses by their compiled codes (:mod:`rrc_pin.solvers.tick.statuses`)."""

LEVELS: tuple[LevelStatus, ...] = get_args(LevelStatus)
"""How a level was served, by its compiled code (:data:`rrc_pin.solvers.tick.statuses.MET`...)."""

ONE_LEVEL: tuple[tuple[LevelStatus], ...] = tuple((s,) for s in LEVELS)
"""The levels of a one-level tick, by its code."""

_NO_ACCELERATION = np.array([np.inf])
_NO_WORK = Work()
"""The work of a tick that asked the backend nothing (read only)."""


class TickSource:
    """What a compiled tick's resolution builds its report from, when it is read.

    Args:
        out: The tick's rows of the workspace's joints (5, n), a copy: lb, ub, qdot, and what
            sets each bound (lower, upper).
        zero_inside: Whether standing still was allowed.
        recovering: Whether a joint was outside its range.
        velocity: The velocity limits (n,).
        levels: The tasks' rows by level; or ``(task, J, b, reach)`` of a one-twist tick, the
            rows its task gives from them (:meth:`~rrc_pin.tasks.FrameTask.rows_from`).
        constraints: The other limits' constraints, in the limits' order, None where the joint
            box stands.
        dt: The step [s].
        weighted: One weighted level.
        direction: The top level as the direction problem.
    """

    __slots__ = ("_box", "constraints", "direction", "dt", "levels", "out", "recovering",
                 "velocity", "weighted", "zero_inside")  # fmt: skip

    def __init__(
        self, out: Array, zero_inside: bool, recovering: bool, velocity: Array,
        levels: list[list[TaskRows]] | tuple[FrameTask, Array, Array, float],
        constraints: list[Constraints | None], dt: float, weighted: bool, direction: bool,
    ) -> None:  # fmt: skip
        self.out, self.zero_inside, self.recovering = out, zero_inside, recovering
        self.velocity, self.levels, self.constraints = velocity, levels, constraints
        self.dt, self.weighted, self.direction = dt, weighted, direction
        self._box: Box | None = None

    @property
    def box(self) -> Box:
        """The step's joint-rate bounds."""
        if self._box is None:
            out = self.out
            kind = out[3:5].astype(np.int8)
            self._box = Box(out[0], out[1], kind, self.zero_inside, self.recovering, self.velocity)
        return self._box

    def problem(self) -> Problem:
        """The problem the tick answered (:func:`rrc_pin.solvers.tick.problem.build`)."""
        levels = self.levels
        if isinstance(levels, tuple):
            task, J, b, reach = levels
            levels = [[task.rows_from(J, b, reach)]]
        box = Constraints(self.box)
        full = [box if c is None else c for c in self.constraints]
        return build(levels, full, self.out.shape[1], self.dt, weighted=self.weighted,
                     direction=self.direction)  # fmt: skip


class CompiledTick:
    """One resolver's compiled ticks (module docstring).

    Args:
        layout: The robot's layout.
        limit: The resolver's joint limits.
        options: Its damping and fallbacks.
        direction: Whether the top level is the direction problem.
        backend: Its QP backend.
        names: Joint names for the report.
        general: Compile the general entry now (:func:`rrc_pin.solvers.tick.tick.run`), not
            only the default tick's: the resolver's ticks will have rows, tasks or a box
            that may exclude standing still.
    """

    def __init__(self, layout: Layout, limit: JointLimits, options: Options, direction: bool,
                 backend: QPBackend, names: tuple[str, ...], general: bool) -> None:  # fmt: skip
        velocity = limit.velocities(layout)
        acceleration = _NO_ACCELERATION if limit.acceleration is None else np.asarray(
            limit.acceleration)  # fmt: skip
        damping = options.damping
        self.limit, self.options, self.backend, self.names = limit, options, backend, names
        self.direction, self.layout = direction, layout
        self.velocity = np.array(velocity, dtype=np.float64)
        self.velocity.flags.writeable = False
        self.workspace = tick.Workspace(
            layout.lower, layout.upper, self.velocity, acceleration, limit.margin,
            limit.position_gain, 0.0 if damping is None else damping.threshold, direction,
            velocity_tolerance(self.velocity),
        )  # fmt: skip
        self._context = backend_calls.Context(backend, self.velocity)
        self._loaded: tuple[Any, ...] | None = None  # the one twist task whose rows are loaded
        self.workspace.compile(general)
        if general:  # its ticks may hand QPs to the backend
            backend_calls.compile_calls(self._context)

    def twist(self, model: pin.Model, data: pin.Data, task: FrameTask, q: Array, b: Array,
              previous: Array, dt: float, start: float) -> Resolution | None:  # fmt: skip
        """The default tick: the rates ``b`` of ``task`` (the resolver's, without a target),
        its Jacobian Pinocchio's at ``q``, the joint box its only limit.

        For a robot whose Pinocchio vector is q itself; the values of ``q`` and ``b`` are
        checked in the compiled call. None where that call is not the tick's (its box excludes
        standing still): :meth:`tasks` answers it then.
        """  # noqa: D205
        ws, layout = self.workspace, self.layout
        loaded = (task, task.weight, task.ref, task.selected)
        if self._loaded != loaded:  # the task's weights and units, once
            rows = task.rows_from(np.zeros((6, ws.n)), np.zeros(len(task.selected)),
                                  layout.reach[task.frame])  # fmt: skip
            ws.load_levels([[rows]], False)
            ws.load_rows(None, None, None)
            self._loaded = loaded
        J = pin.computeFrameJacobian(model, data, q, layout.frames[task.frame],
                                     PIN_REFERENCE[task.ref])  # fmt: skip
        ws.load_twist(J, task.selected, b)
        twist = (task, J, b, layout.reach[task.frame])
        code = self._run(q, previous, dt, twist)
        if code == tick.ELSEWHERE:
            return None
        return self._answer(code, twist, [None], dt, False, start)

    def answers(self, constraints: Sequence[Constraints | None]) -> bool:
        """Whether the compiled tick answers with these limits' constraints: no other box, no
        equality rows."""  # noqa: D205, D209
        return all(c is None or (c.box is None and c.C is None) for c in constraints)

    def tasks(self, kin: Kinematics, levels: list[list[TaskRows]], weighted: bool,
              constraints: list[Constraints | None], previous: Array, dt: float,
              start: float) -> Resolution:  # fmt: skip
        """The tick of tasks' rows by level (one weighted level where ``weighted``), within
        the joint box and the other limits' ``constraints`` (None where the joint box stands);
        ``start`` [s] when the tick began (``time.perf_counter``)."""  # noqa: D205, D209
        ws = self.workspace
        ws.load_levels(levels, weighted)
        present = [c for c in constraints if c is not None]
        rows = merged_rows(present) if present else None
        if rows is None:
            ws.load_rows(None, None, None)
        else:
            ws.load_rows(rows.G, rows.h, rows.slide)
        self._loaded = None
        code = self._run(kin.q, previous, dt, levels)
        return self._answer(code, levels, constraints, dt, weighted, start)

    def _run(
        self, q: Array, previous: Array, dt: float,
        levels: list[list[TaskRows]] | tuple[FrameTask, Array, Array, float],
    ) -> int:  # fmt: skip
        """The loaded tick at ``q`` after ``previous`` [rad/s], its QPs handed to the backend.

        Raises:
            InvalidInput: A position (``q``), twist or task row (of ``levels``, as
                :meth:`_answer` takes them) not finite, with the message the checks give.
        """
        backend_calls.enter(self._context)
        try:
            code = self.workspace.run(q, previous, dt)
        finally:
            backend_calls.leave()
        if code == tick.INVALID_INPUT:
            bad = self.workspace.ints[tick.INVALID]
            if bad == tick.BAD_POSITION:
                as_vector(q, "q", q.size)
            if isinstance(levels, tuple):
                task, J, b, reach = levels
                if bad == tick.BAD_RATE:
                    as_vector(b, "twist", b.size)
                levels = [[task.rows_from(J, b, reach)]]
            finite_rows(levels)
        return code

    def _answer(
        self, code: int, levels: list[list[TaskRows]] | tuple[FrameTask, Array, Array, float],
        constraints: list[Constraints | None], dt: float, weighted: bool, start: float,
    ) -> Resolution:  # fmt: skip
        """The resolution of the tick just run (its code), deferring its problem."""
        ws, work = self.workspace, self._context.work
        out = ws.joints[tick.LB : tick.KIND + 2].copy()
        reals = ws.reals.tolist()
        source = TickSource(
            out, reals[tick.ZERO_INSIDE] == 1.0, reals[tick.RECOVERING] == 1.0, self.velocity,
            levels, constraints, dt, weighted, self.direction,
        )  # fmt: skip
        elapsed = time.perf_counter() - start
        if code == FAILED:
            problem = source.problem()
            answer = fallback_answer(problem, self.options, work or Work())
            return Resolution.of(problem, answer, elapsed, self.names)
        qdot = out[2]
        qdot.setflags(write=False)
        work = work or _NO_WORK
        codes = ws.level_codes()
        levels_served = ONE_LEVEL[codes[0]] if len(codes) == 1 else tuple(map(LEVELS.__getitem__,
                                                                              codes))  # fmt: skip
        return Resolution(
            qdot, STATUSES[code], "qp", reals[tick.SCALE], reals[tick.VEER], levels_served,
            tuple(work.attempts), work.backend,
            work.iterations, reals[tick.CLIP], reals[tick.LAMBDA_SQ],
            elapsed - work.solve_time, work.solve_time, source, self.names,
        )  # fmt: skip
