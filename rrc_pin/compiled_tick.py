"""A resolver's ticks in one compiled call: its inputs loaded, its answer read back lazily.

The :class:`~rrc_pin.Resolver` hands a tick here where its joint box is one
:class:`~rrc_pin.limits.JointLimits` and no limit gives another box (equality rows, contacts
and grips, only fewer than the rates and without rows the command slides along):
the tasks' rows and the other limits' constraint and equality rows go into the resolver's
:class:`~rrc_pin.solvers.tick.tick.Workspace`, one call of
:func:`rrc_pin.solvers.tick.tick.run` answers (the QPs its kernels do not answer go to the
backend from inside it), and the :class:`~rrc_pin.solvers.tick.resolution.Resolution` keeps the
tick's arrays: its problem, task reports and active sets are built where they are read
(:class:`TickSource`). Where the top level finds no usable answer, the fallbacks answer as the
Python pipeline's do (:func:`rrc_pin.solvers.tick.pipeline.fallback_answer`).

The default tick, ``solve(q, twist)`` with the joint box alone, loads nothing per tick: the
Jacobian, the twist and q go to :func:`rrc_pin.solvers.tick.tick.run_twist` as they are, which
writes the rates, the box and the twist into one new array; the resolution is made of it and
the report's scalars (:class:`TwistSource`).
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from typing import Any, NamedTuple, cast, get_args

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.kinematics import Kinematics, Layout
from rrc_pin.limits import JointLimits
from rrc_pin.robot import PIN_REFERENCE
from rrc_pin.solvers.checks import as_vector
from rrc_pin.solvers.qp_backends import active_set
from rrc_pin.solvers.qp_backends.base import QPBackend
from rrc_pin.solvers.qp_backends.qp import Work, velocity_tolerance
from rrc_pin.solvers.tick import backend_calls, statuses, tick
from rrc_pin.solvers.tick.pipeline import LevelStatus, Options, Status, fallback_answer
from rrc_pin.solvers.tick.problem import (
    Box,
    Constraints,
    Problem,
    Rows,
    TaskRows,
    build,
    finite_rows,
    merged_equalities,
    merged_rows,
    mode_of,
    stacked_rows,
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

LEVEL_OF: tuple[tuple[LevelStatus], ...] = tuple(ONE_LEVEL[statuses.top_served(code)]
                                                 for code in range(len(STATUSES)))  # fmt: skip
"""The levels of a one-level tick, by its top level's status code."""

_new = tuple.__new__
"""A named tuple made of its fields' tuple (:meth:`~typing.NamedTuple._make` less its check)."""

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
        levels: The tasks' rows by level.
        constraints: The other limits' constraints, in the limits' order, None where the joint
            box stands.
        dt: The step [s].
        weighted: One weighted level.
        direction: The top level as the direction problem.
        stacked: The top level's rows in the metric the tick solved it in (m, n), where the
            tick kept them (:meth:`Workspace.stacked_top`), else None.
    """

    __slots__ = ("_box", "constraints", "direction", "dt", "levels", "out", "recovering",
                 "stacked", "velocity", "weighted", "zero_inside")  # fmt: skip

    def __init__(
        self, out: Array, zero_inside: bool, recovering: bool, velocity: Array,
        levels: list[list[TaskRows]], constraints: list[Constraints | None], dt: float,
        weighted: bool, direction: bool, stacked: Array | None = None,
    ) -> None:  # fmt: skip
        self.out, self.zero_inside, self.recovering = out, zero_inside, recovering
        self.velocity, self.levels, self.constraints = velocity, levels, constraints
        self.dt, self.weighted, self.direction = dt, weighted, direction
        self.stacked = stacked
        self._box: Box | None = None

    @property
    def box(self) -> Box:
        """The step's joint-rate bounds."""
        if self._box is None:
            out = self.out
            kind = out[3:5].astype(np.int8)
            self._box = Box(out[0], out[1], kind, self.zero_inside, self.recovering, self.velocity)
        return self._box

    def top(self) -> tuple[tuple[TaskRows, ...], Array, Rows | None]:
        """The top level's task rows, its stacked rows in the metric it was solved in, and the
        constraint rows: :meth:`problem`'s ``levels[0]``, ``stacked[0][0]`` and ``rows``,
        without building the other levels.
        """  # noqa: D205
        levels = self.levels
        level = tuple(levels[0]) if isinstance(levels, list) else (
            levels[0].rows_from(levels[1], levels[2], levels[3]),)  # fmt: skip
        present = [c for c in self.constraints if c is not None]
        rows = merged_rows(present) if present else None
        if self.stacked is not None:
            return level, self.stacked, rows
        keeps = any(c.d is not None and np.count_nonzero(c.d) > 0 for c in present)
        box = self.box
        mode = mode_of(box, rows, keeps, self.weighted, self.direction)
        return level, stacked_rows(level, mode == "direction"), rows

    def problem(self) -> Problem:
        """The problem the tick answered (:func:`rrc_pin.solvers.tick.problem.build`)."""
        box = Constraints(self.box)
        full = [box if c is None else c for c in self.constraints]
        return build(self.levels, full, self.out.shape[1], self.dt, weighted=self.weighted,
                     direction=self.direction)  # fmt: skip


class TwistSpec(NamedTuple):
    """What every twist tick of one task shares (:class:`TwistSource`).

    Attributes:
        task: The resolver's task.
        reach: Its frame's reach [m], the unit of the linear rows.
        velocity: The velocity limits (n,).
        direction: The top level as the direction problem.
    """

    task: FrameTask
    reach: float
    velocity: Array
    direction: bool


class TwistSource(NamedTuple):
    """What a twist tick's resolution builds its report from, when it is read.

    Attributes:
        out: What :func:`~rrc_pin.solvers.tick.tick.run_twist` wrote (read-only once
            answered): the rates, the box's bounds and what sets each, the selected twist and
            the box's flags.
        J: The task frame's Jacobian (6, n).
        dt: The step [s].
        spec: The task's (:class:`TwistSpec`).
    """

    out: Array
    J: Array
    dt: float
    spec: TwistSpec

    @property
    def b(self) -> Array:
        """The task's commanded rates (m,), its selected rows of the twist."""
        n = self.J.shape[1]
        return self.out[5 * n : self.out.size - 2]

    @property
    def box(self) -> Box:
        """The step's joint-rate bounds."""
        out, n = self.out, self.J.shape[1]
        kind = out[3 * n : 5 * n].reshape(2, n).astype(np.int8)
        return Box(out[n : 2 * n], out[2 * n : 3 * n], kind, out[-2] == 1.0, out[-1] == 1.0,
                   self.spec.velocity)  # fmt: skip

    def levels(self) -> list[list[TaskRows]]:
        """The task's rows (:meth:`~rrc_pin.tasks.FrameTask.rows_from`), as one level."""
        spec = self.spec
        return [[spec.task.rows_from(self.J, self.b, spec.reach)]]

    def problem(self) -> Problem:
        """The problem the tick answered (:func:`rrc_pin.solvers.tick.problem.build`)."""
        return build(self.levels(), [Constraints(self.box)], self.J.shape[1], self.dt,
                     weighted=False, direction=self.spec.direction)  # fmt: skip


def asks_apart(c: Constraints) -> bool:
    """Whether a row of ``c`` the command slides along (a collision pair) has a bound below
    zero: standing still breaks it."""  # noqa: D205, D209
    return (c.slide is not None and c.h is not None and c.h.size > 0
            and bool((c.slide & (c.h < 0.0)).any()))  # fmt: skip


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
        twists: Compile the twist tick's entry (:func:`rrc_pin.solvers.tick.tick.run_twist`,
            :meth:`twist`): the resolver's ``solve(q, twist)`` reaches it; False only where the
            resolver never calls :meth:`twist`.
    """

    _spec: TwistSpec  # the loaded twist task's, once loaded

    def __init__(self, layout: Layout, limit: JointLimits, options: Options, direction: bool,
                 backend: QPBackend, names: tuple[str, ...], general: bool,
                 twists: bool = True) -> None:  # fmt: skip
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
        self._frame, self._reference = 0, pin.LOCAL_WORLD_ALIGNED  # its frame, its reference
        self._rows: list[int] | None = None  # its rows of the Jacobian, None: all six
        self._size = 0  # the size of run_twist's out for it
        self._answered: Array | None = None  # the last rates answered, joints[PREVIOUS]'s values
        self.workspace.compile(general, twists)
        if general:  # its ticks may hand QPs to the backend
            backend_calls.compile_calls(self._context)
            backend_calls.enter(self._context)
            try:
                self.workspace.compile_hand_overs()
            finally:
                backend_calls.leave()
                backend.reset()

    def twist(self, model: pin.Model, data: pin.Data, task: FrameTask, q: Array, twist: Array,
              previous: Array, dt: float, start: float) -> Resolution | None:  # fmt: skip
        """The default tick: the twist (6,) of ``task`` (the resolver's, without a target), its
        Jacobian Pinocchio's at ``q`` (nq = nv), the joint box its only limit, after the rates
        ``previous`` (n,); ``start`` [s] when the tick began (``time.perf_counter``).

        ``q`` and ``twist`` are float64 C-contiguous writable arrays of their shapes (the
        compiled entry's types); their values are checked in the compiled call. None where that
        call is not the tick's (its box excludes standing still): :meth:`tasks` answers it then.

        Raises:
            InvalidInput: ``q`` or ``twist`` not finite, named; nothing changed.
        """  # noqa: D205
        ws = self.workspace
        if self._loaded != (task, task.weight, task.ref, task.selected):
            self._load_twist(task)
        J = pin.computeFrameJacobian(model, data, q, self._frame, self._reference)
        rows, b = (J, twist) if self._rows is None else (J[self._rows], twist[self._rows])
        if previous is not self._answered:
            ws.joints[tick.PREVIOUS] = previous
            self._answered = None
        out = np.empty(self._size)
        backend_calls.enter(self._context)
        try:
            code, scale, veer, clip, lambda_sq = tick.run_twist(
                rows, b, q, dt, ws.joints, ws.rates, ws.ints, ws.reals, out)  # fmt: skip
        finally:
            backend_calls.leave()
        source = _new(TwistSource, (out, J, dt, self._spec))
        if code < 0:
            return self._twist_elsewhere(code, source, q, b, previous, start)
        out.setflags(write=False)
        qdot = out[: ws.n]
        self._answered = qdot
        work, solved = self._context.work, ws.reals[tick.SOLVED]
        if work is None and not solved:
            return _new(Resolution, (
                qdot, STATUSES[code], "qp", scale, veer, LEVEL_OF[code], (), "", 0, clip,
                lambda_sq, time.perf_counter() - start, 0.0, source, self.names, ()))  # fmt: skip
        work = work or _NO_WORK
        backend = work.backend or (active_set.NAME if solved else "")
        return _new(Resolution, (
            qdot, STATUSES[code], "qp", scale, veer, LEVEL_OF[code], tuple(work.attempts),
            backend, work.iterations + int(ws.reals[tick.SOLVED_STEPS]), clip, lambda_sq,
            time.perf_counter() - start - work.solve_time, work.solve_time, source, self.names,
            ()))  # fmt: skip

    def _load_twist(self, task: FrameTask) -> None:
        """Load ``task``'s weights and units into the workspace, and where its rows come from."""
        layout, n = self.layout, self.workspace.n
        reach = layout.reach[task.frame]
        rows = task.rows_from(np.zeros((6, n)), np.zeros(len(task.selected)), reach)
        self.workspace.load_levels([[rows]], False)
        self.workspace.load_rows(None, None, None)
        self._frame, self._reference = layout.frames[task.frame], PIN_REFERENCE[task.ref]
        self._rows = None if len(task.selected) == 6 else list(task.selected)
        self._size = tick.twist_size(n, len(task.selected))
        self._spec = TwistSpec(task, reach, self.velocity, self.direction)
        self._loaded = (task, task.weight, task.ref, task.selected)

    def _twist_elsewhere(self, code: int, source: TwistSource, q: Array, b: Array,
                         previous: Array, start: float) -> Resolution | None:  # fmt: skip
        """A twist tick that :func:`~rrc_pin.solvers.tick.tick.run_twist` did not answer: bad
        values named (``q``, the selected twist ``b``), the fallbacks' answer, or the general
        entry's.

        Raises:
            InvalidInput: A position (``q``) or twist not finite.
        """  # noqa: D205
        if code == tick.INVALID_INPUT:
            as_vector(q, "q", q.size)
            as_vector(b, "twist", b.size)
            spec = source.spec
            finite_rows([[spec.task.rows_from(source.J, b, spec.reach)]])
        if code == FAILED:
            return self._fallback(source, start)
        levels = source.levels()
        self.workspace.load_twist(source.J, source.spec.task.selected, source.b)
        code = self._run(q, previous, source.dt, levels)
        if code == tick.ELSEWHERE:
            return None
        return self.answer(code, levels, [None], source.dt, False, start)

    def answers(self, constraints: Sequence[Constraints | None]) -> bool:
        """Whether the compiled tick answers with these limits' constraints: no other box;
        equality rows fewer than the rates, and beside them no row the command slides along
        that asks a pair apart (below zero: the pipeline relaxes it where the least squares
        fails) (:func:`rrc_pin.solvers.tick.tick.run_within`)."""  # noqa: D205, D209
        equal = 0
        for c in constraints:
            if c is None:
                continue
            if c.box is not None:
                return False
            if c.C is not None and c.d is not None:
                equal += c.d.size
        if equal == 0:
            return True
        return equal < self.workspace.n and not any(c is not None and asks_apart(c)
                                                    for c in constraints)  # fmt: skip

    def tasks(self, kin: Kinematics, levels: list[list[TaskRows]], weighted: bool,
              constraints: list[Constraints | None], previous: Array, dt: float,
              start: float) -> Resolution:  # fmt: skip
        """The tick of tasks' rows by level (one weighted level where ``weighted``), within
        the joint box and the other limits' ``constraints`` (None where the joint box stands);
        ``start`` [s] when the tick began (``time.perf_counter``)."""  # noqa: D205, D209
        ws = self.workspace
        ws.load_levels(levels, weighted)
        self._load_constraints(constraints)
        self._loaded = None
        code = self._run(kin.q, previous, dt, levels)
        return self.answer(code, levels, constraints, dt, weighted, start)

    def loading(self) -> None:
        """Another compiled call is about to write the workspace's rows and sizes (a cell's,
        :func:`rrc_pin.cells.cell_kernels.cell_rows`): what it held is forgotten, and loaded
        again at the next tick of this one's own (:meth:`tasks`, :meth:`twist`).
        """  # noqa: D205
        self._loaded = None
        self.workspace.forget()

    def run_loaded(self, q: Array, previous: Array, dt: float) -> int:
        """The tick of the rows loaded in the workspace at ``q`` after ``previous`` [rad/s],
        step ``dt`` [s], its QPs handed to the backend: its code (:meth:`answer` reads the
        answer; :data:`~rrc_pin.solvers.tick.tick.INVALID_INPUT`: a value not finite).
        """  # noqa: D205
        self._answered = None  # joints[PREVIOUS] is written
        backend_calls.enter(self._context)
        try:
            code: int = self.workspace.run(q, previous, dt)
        finally:
            backend_calls.leave()
        return code

    def _load_constraints(self, constraints: list[Constraints | None]) -> None:
        """The other limits' constraint rows and equality rows into the workspace (a limit's
        own arrays where it alone has them, else merged in the limits' order)."""  # noqa: D205, D209
        ws = self.workspace
        with_rows, with_equalities = [], []
        for c in constraints:
            if c is not None:
                if c.G is not None and c.h is not None and c.h.size:
                    with_rows.append(c)
                if c.C is not None and c.d is not None and c.d.size:
                    with_equalities.append(c)
        if not with_rows:
            ws.load_rows(None, None, None)
        elif len(with_rows) == 1:  # one limit's rows: loaded as they are (names not needed)
            ws.load_rows(with_rows[0].G, with_rows[0].h, with_rows[0].slide)
        else:
            rows = cast(Rows, merged_rows(with_rows))
            ws.load_rows(rows.G, rows.h, rows.slide)
        if not with_equalities:
            ws.load_equalities(None, None)
        elif len(with_equalities) == 1:  # one limit's rows (the grip's): loaded as they are
            ws.load_equalities(with_equalities[0].C, with_equalities[0].d)
        else:
            ws.load_equalities(*cast(tuple[Array, Array], merged_equalities(with_equalities)))

    def _run(self, q: Array, previous: Array, dt: float, levels: list[list[TaskRows]]) -> int:
        """The loaded tick at ``q`` after ``previous`` [rad/s], its QPs handed to the backend.

        Raises:
            InvalidInput: A position (``q``) or task row (of ``levels``) not finite, with the
                message the checks give.
        """
        code = self.run_loaded(q, previous, dt)
        if code == tick.INVALID_INPUT:
            if self.workspace.ints[tick.INVALID] == tick.BAD_POSITION:
                as_vector(q, "q", q.size)
            finite_rows(levels)
        return code

    def answer(
        self, code: int, levels: list[list[TaskRows]], constraints: list[Constraints | None],
        dt: float, weighted: bool, start: float,
    ) -> Resolution:  # fmt: skip
        """The resolution of the tick just run (its code), deferring its problem: of ``levels``
        (the tasks' rows by level) within the joint box and the other limits' ``constraints``,
        ``start`` [s] when the tick began (``time.perf_counter``).
        """  # noqa: D205
        ws, work = self.workspace, self._context.work
        out = ws.joints[tick.LB : tick.KIND + 2].copy()
        reals = ws.reals.tolist()
        source = TickSource(
            out, reals[tick.ZERO_INSIDE] == 1.0, reals[tick.RECOVERING] == 1.0, self.velocity,
            levels, constraints, dt, weighted, self.direction, ws.stacked_top(),
        )  # fmt: skip
        if code == FAILED:
            return self._fallback(source, start)
        elapsed = time.perf_counter() - start
        qdot = out[2]
        qdot.setflags(write=False)
        work = work or _NO_WORK
        codes = ws.level_codes()
        # the backend's name where it answered a QP, else the compiled solver's where it did
        backend = work.backend or (active_set.NAME if reals[tick.SOLVED] else "")
        levels_served = ONE_LEVEL[codes[0]] if len(codes) == 1 else tuple(map(LEVELS.__getitem__,
                                                                              codes))  # fmt: skip
        return _new(Resolution, (
            qdot, STATUSES[code], "qp", reals[tick.SCALE], reals[tick.VEER], levels_served,
            tuple(work.attempts), backend, work.iterations + int(reals[tick.SOLVED_STEPS]),
            reals[tick.CLIP], reals[tick.LAMBDA_SQ], elapsed - work.solve_time, work.solve_time,
            source, self.names, ()))  # fmt: skip

    def _fallback(self, source: TickSource | TwistSource, start: float) -> Resolution:
        """The fallbacks' answer (:func:`~rrc_pin.solvers.tick.pipeline.fallback_answer`) to
        the problem of a tick whose top level found none.
        """  # noqa: D205
        problem = source.problem()
        elapsed = time.perf_counter() - start
        answer = fallback_answer(problem, self.options, self._context.work or Work())
        return Resolution.of(problem, answer, elapsed, self.names)
