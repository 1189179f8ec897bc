"""The resolver users run at every control tick: a twist or tasks in, joint rates out.

One pipeline, each stage a module, entered once per tick (docs/api.md, "The resolver"):

1. **tasks** give rows ``A qdot ~= b`` (:mod:`rrc_pin.tasks`), from one :class:`Kinematics`
   of the tick; ``solve(q, twist)`` is its :class:`~rrc_pin.tasks.FrameTask` with this tick's
   twist;
2. **limits** give a box and named constraint rows (:mod:`rrc_pin.limits`);
3. **the problem** is built apart from solving it (:func:`rrc_pin.solvers.tick.problem.build`);
4. **the numerics** solve it: compiled kernels, the QP backend where rows need it, the
   fallbacks (:func:`rrc_pin.solvers.tick.pipeline.solve`);
5. **the report**, decided once (:class:`~rrc_pin.solvers.tick.resolution.Resolution`).

Every argument is checked here, at the public boundary, before any state changes: bad input
raises :class:`~rrc_pin.errors.InvalidInput` (or another
:class:`~rrc_pin.errors.RrcPinError`) naming the argument. Numerical trouble never raises: the
resolution says which method answered and why.

Threads: a Resolver may be shared; its ticks run one at a time (a lock), each on its own
arguments. Its state across ticks (the backend's warm starts, the previous rates for the
acceleration limits) is then shared too: give each thread its own Resolver for independent
sequences, or pass ``qdot_prev`` explicitly.
"""

from __future__ import annotations

import os
import threading
import time
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal, TypeGuard, cast

import numpy as np
import numpy.typing as npt

from rrc_pin.compiled_tick import CompiledTick
from rrc_pin.errors import InvalidInput, UnknownBackend
from rrc_pin.kinematics import Kinematics, Layout
from rrc_pin.limits import JointLimits, Limit
from rrc_pin.loading import loaded
from rrc_pin.robot import Robot
from rrc_pin.solvers.checks import as_vector, finite_number, positive
from rrc_pin.solvers.qp_backends import make_backend
from rrc_pin.solvers.spatial import Reference
from rrc_pin.solvers.tick.damping import Damping
from rrc_pin.solvers.tick.joint_mask import free_columns, scattered, widened_rates
from rrc_pin.solvers.tick.pipeline import DEFAULT_FALLBACKS, Method, Options, solve
from rrc_pin.solvers.tick.problem import Constraints, TaskRows, build, finite_rows
from rrc_pin.solvers.tick.resolution import Resolution
from rrc_pin.tasks import FrameTask, Task

Array = npt.NDArray[np.float64]

TaskCommand = Task | Sequence[Task | Sequence[Task]]
"""Tasks for :meth:`Resolver.solve`: one, a list (weighted), or a list of levels (strict)."""

Priority = Literal["weighted", "strict"]

_FLOAT = np.dtype(np.float64)
_TWIST = (6,)
_WEIGHTED = "weighted"

MIN_DT = 1e-6
"""[s] The shortest control period accepted (a 1 MHz loop): below it the one-step position
bounds divide by a step that no joint can use (dt = 1e-310 made them infinite, and NaN)."""

DEFAULT_TIME_LIMIT = 0.05
"""[s] The backend's time cap per QP by default (:class:`QPOptions`): five periods at 100 Hz."""


@dataclass(frozen=True)
class QPOptions:
    """The QP backend, its time cap and the fallbacks of a resolver.

    Attributes:
        backend: A name of :func:`rrc_pin.solvers.qp_backends.installed_backends`: ``"daqp"``
            (default: exact active-set answers), ``"osqp"``, or a qpsolvers solver
            (``proxqp``, ``quadprog``, ``clarabel``...).
        options: The backend's own settings (a mapping), checked at construction.
        fallbacks: Methods tried after the pipeline fails, in order: ``"scipy"`` (the same
            problem solved exactly by scipy.optimize), ``"scaling"``; ``"hold"`` always ends
            the chain.
        time_limit: [s] > 0, the backend's time per QP: past it the answer is refused and the
            fallbacks answer (reported in ``attempts``).

    Raises:
        InvalidInput: ``options`` not a mapping, ``time_limit`` not a finite number > 0.
    """

    backend: str = "daqp"
    options: Mapping[str, Any] = field(default_factory=dict)
    fallbacks: Sequence[Method] = DEFAULT_FALLBACKS
    time_limit: float = DEFAULT_TIME_LIMIT

    def __post_init__(self) -> None:
        if not isinstance(self.options, Mapping):
            raise InvalidInput(
                "qp.options", f"expected a mapping of settings, got {self.options!r}"
            )
        if not isinstance(self.backend, str):
            raise InvalidInput("qp.backend", f"expected a backend name, got {self.backend!r}")
        object.__setattr__(self, "time_limit", positive(self.time_limit, "qp.time_limit"))


class Resolver:
    """Joint rates for commanded twists or tasks, inside the limits, at every tick.

    Args:
        robot: A :class:`rrc_pin.Robot`, or a name or path that :func:`rrc_pin.load` takes.
        dt: Control period [s], > 0 (``solve`` may override it per call).
        task: The task of ``solve(q, twist)``: a :class:`~rrc_pin.tasks.FrameTask` whose
            frame, rows, ref and weights are used (its twist is the call's); default the
            robot's tool frame, full twist (position only below six joints), world_aligned.
            A robot with several tool frames has no default: solve it with tasks.
        limits: A :class:`~rrc_pin.limits.Limit` or a sequence of them (default
            ``JointLimits()``); include ``JointLimits`` to keep the joint limits.
        qp: Backend, time cap and fallbacks (default :class:`QPOptions()`: daqp).
        damping: Damping near singularities (default :class:`Damping()`), or None.
        direction_preserving: When the top level's command cannot be met, slow down along it
            instead of distorting it (the direction problem); False: least squares.
        use_closed_form: Take the tool frame's world_aligned Jacobian from
            ``robot.closed_form`` (the paper's equations) instead of Pinocchio.
        twists: Whether ``solve(q, twist)`` takes its own compiled entry, built with the
            resolver; False builds none (for callers that tick through :meth:`solve_at` or
            tasks alone, as the controller does): a twist then takes the tasks' way, the
            same answers, nothing compiled in the loop.

    Raises:
        InvalidInput: Any invalid argument, named.
        UnknownBackend: ``qp.backend`` is not installed (the error lists the installed ones).
        UnknownArm, URDFError: ``robot`` is a name or path that does not load.
    """

    def __init__(
        self,
        robot: Robot | str,
        dt: float = 0.01,
        *,
        task: FrameTask | None = None,
        limits: Limit | Sequence[Limit] | None = None,
        qp: QPOptions | None = None,
        damping: Damping | None = Damping(),  # noqa: B008 - immutable
        direction_preserving: bool = True,
        use_closed_form: bool = False,
        twists: bool = True,
    ) -> None:
        if isinstance(robot, (str, os.PathLike)):
            robot = loaded(robot, "robot")
        if not isinstance(robot, Robot):
            raise InvalidInput("robot", f"expected a rrc_pin.Robot or a name, got {robot!r}")
        if not isinstance(direction_preserving, bool):
            raise InvalidInput("direction_preserving", f"expected True or False, got "
                               f"{direction_preserving!r}")
        if not isinstance(use_closed_form, bool):
            raise InvalidInput("use_closed_form", f"expected True or False, got "
                               f"{use_closed_form!r}")
        if not isinstance(twists, bool):
            raise InvalidInput("twists", f"expected True or False, got {twists!r}")
        self.robot = robot
        self.dt = _dt(dt)
        self.qp = QPOptions() if qp is None else _typed(qp, QPOptions, "qp")
        try:
            self.options = Options(damping, self.qp.fallbacks)  # type: ignore[arg-type]
            self.backend = make_backend(self.qp.backend, self.qp.time_limit,
                                        **dict(self.qp.options))
        except UnknownBackend as exc:  # the names as the caller spells them: qp.backend
            raise UnknownBackend(exc.backend, exc.available, "qp.backend") from exc
        except InvalidInput as exc:
            name = {"backend_options": "qp.options", "fallbacks": "qp.fallbacks"}
            raise InvalidInput(name.get(exc.argument, exc.argument), exc.reason) from exc
        self.direction_preserving = direction_preserving
        self.task = self._default_task() if task is None else _typed(task, FrameTask, "task")
        closed_form = self._closed_form_for(self.task) if use_closed_form else None
        self._layout = Layout.of(robot, closed_form)
        if self.task is not None:
            self.task.check(self._layout)
        self.limits = _limits(limits)
        for limit in self.limits:
            limit.check(self._layout)
        self._data = robot.model.createData()  # this resolver's own
        self._names = robot.dof_names
        self._last_qdot: Array = np.zeros(robot.nv)
        self._lock = threading.Lock()
        self._masked: tuple[str, ...] = ()  # joint names, in the model's order
        self._free: npt.NDArray[np.intp] | None = None  # the rates that may move, or None: all
        joint = [limit for limit in self.limits if isinstance(limit, JointLimits)]
        # the general entry now where ticks will need it; else at the first that does (tasks
        # given to a one-tool resolver, a start outside the joint limits)
        general = (len(self.limits) > 1 or self.task is None or not direction_preserving
                   or (len(joint) == 1 and joint[0].acceleration is not None))  # fmt: skip
        # solve(q, twist) straight into the compiled tick: the joint box the only limit, the
        # Jacobian Pinocchio's and its vector q itself
        self._box_only = len(joint) == 1 and self.limits == (joint[0],)
        self._twists = (twists and self._box_only and self.task is not None
                        and closed_form is None and robot.model.nq == robot.model.nv)  # fmt: skip
        self._compiled = None if len(joint) != 1 else CompiledTick(
            self._layout, joint[0], self.options, direction_preserving, self.backend,
            self._names, general, self._twists)  # fmt: skip
        self._q_shape = (robot.nq,)

    @property
    def layout(self) -> Layout:
        """What its tasks and limits may name on the robot (:meth:`solve_at`'s kinematics are
        made on it)."""  # noqa: D205, D209
        return self._layout

    @property
    def masked(self) -> tuple[str, ...]:
        """The joints held still by the mask (:meth:`mask`), in the robot's order."""
        return self._masked

    def mask(self, joints: str | Iterable[str]) -> None:
        """Hold ``joints`` still from the next tick on, beside those masked already.

        A masked joint's rate is exactly zero, and its column leaves every task's rows and
        every limit's (the box loses its entry): the other joints solve as the model reduced
        by ``pinocchio.buildReducedModel``, the masked joints locked where they are, would
        (the same rows, limits and options; the task rows' units stay the full robot's). A
        floating base's joint (``robot.base_joint``) masks its six rates; a joint's mimics
        (:mod:`rrc_pin.mimic`) follow it, so are still too. Ticks with a mask take the
        general path (not the compiled tick).

        Args:
            joints: A joint name or several (``robot.joint_names``, or ``robot.base_joint``).

        Raises:
            InvalidInput: ``joints`` is not names of the robot's joints, or names a mimic
                joint (mask the joint it follows); the mask is then unchanged.
        """
        names = self._joint_names(joints)
        with self._lock:
            self._set_mask({*self._masked, *names})

    def unmask(self, joints: str | Iterable[str] | None = None) -> None:
        """Let ``joints`` move again from the next tick on (default every masked joint).

        Raises:
            InvalidInput: ``joints`` is not names of the robot's joints (as :meth:`mask`);
                the mask is then unchanged. A joint that is not masked is left as it is.
        """
        names = set(self._masked) if joints is None else set(self._joint_names(joints))
        with self._lock:
            self._set_mask(set(self._masked) - names)

    def _joint_names(self, joints: str | Iterable[str]) -> list[str]:
        """``joints`` as a list of names that a mask takes, checked."""
        robot = self.robot
        items = [joints] if isinstance(joints, str) else joints
        try:
            names = list(items)
        except TypeError:
            raise InvalidInput("joints", f"expected joint names, got {joints!r}") from None
        known = {*robot.joint_names, *([robot.base_joint] if robot.base_joint else [])}
        followed = {m.name: m.primary for m in robot.mimics}
        for name in names:
            if isinstance(name, str) and name in followed:
                raise InvalidInput("joints", f"{name!r} is a mimic joint: it follows "
                                   f"{followed[name]!r}; mask that joint (its mimics are then "
                                   "still too)")  # fmt: skip
            if not isinstance(name, str) or name not in known:
                raise InvalidInput("joints", f"{name!r} is not a joint of {robot.name} (its "
                                   f"joints: {', '.join(sorted(known))})")  # fmt: skip
        return names

    def _set_mask(self, names: set[str]) -> None:
        """The mask of the joints ``names`` (checked), for the ticks that follow."""
        robot = self.robot
        dofs = self._layout.joints
        held = np.zeros(robot.nv, dtype=bool)
        for name in names:
            if name == robot.base_joint:
                held[:6] = True
            else:
                held[dofs[name]] = True
        order = [*([robot.base_joint] if robot.base_joint else []), *robot.joint_names]
        self._masked = tuple(n for n in order if n in names)
        self._free = np.flatnonzero(~held) if held.any() else None

    def reset(self) -> None:
        """Forget the warm starts and the previous joint rates."""
        with self._lock:
            self.backend.reset()
            self._last_qdot = np.zeros(self.robot.nv)

    def warm_start_state(self) -> dict[str, Any]:
        """Copies of every value that carries over to the next ``solve``."""
        with self._lock:
            state: dict[str, Any] = dict(self.backend.warm_start_state())
            state["last_qdot"] = self._last_qdot.copy()
            return state

    def solve(
        self,
        q: npt.ArrayLike,
        command: npt.ArrayLike | TaskCommand,
        ref: Reference | None = None,
        *,
        priority: Priority = "weighted",
        dt: float | None = None,
        qdot_prev: npt.ArrayLike | None = None,
    ) -> Resolution:
        """Joint rates serving ``command`` at ``q`` at best, within this step's limits.

        Args:
            q: Joint positions (nq,) [rad or m].
            command: A twist [v; w] (6,) [m/s, rad/s] of the resolver's task (or only its
                rows), in frame ``ref``; or tasks: one :class:`~rrc_pin.tasks.Task`, a list
                of them (``priority="weighted"``: their weights trade them off), or a list of
                levels, each a task or a list of tasks (``priority="strict"``: each level
                exactly optimal within the optimal set of those above; the top level
                direction-preserving with one common scale).
            ref: Frame of a twist: ``world_aligned``, ``local`` or ``world``; default the
                resolver's task's. Not used with tasks (each task has its own).
            priority: ``"weighted"`` or ``"strict"``, for a list of tasks.
            dt: Step [s] for this call; default the constructor's.
            qdot_prev: Previous joint rates (nv,) for the acceleration limits; default the
                rates this resolver returned last (zero at the first step).

        Returns:
            The :class:`~rrc_pin.solvers.tick.resolution.Resolution` (finite, within the box).

        Raises:
            InvalidInput: A bad q, twist, task, level, ref, priority, dt or qdot_prev, named;
                raised before any state changes.
            FrameNotFound: A task names a frame the robot does not have (the error lists
                them).
        """
        if (self._twists and self._free is None and type(command) is np.ndarray
                and type(q) is np.ndarray and ref is None and dt is None and qdot_prev is None
                and (priority is _WEIGHTED or (type(priority) is str and priority == _WEIGHTED))):
            r = self._twist(q, command)
            if r is not None:
                return r
        q, dof, q_pin = self.robot.positions(q)
        return self._solve(dof, q_pin, None, command, ref, priority, dt, qdot_prev)

    def _twist(self, q: Array, twist: Array) -> Resolution | None:
        """``solve(q, twist)`` of the resolver's task in its ref, in the compiled tick alone
        (:meth:`CompiledTick.twist`), or None where the general path answers: arrays of other
        shapes or types (it checks them), a task with a target, a box that excludes standing
        still."""  # noqa: D205, D209
        task: FrameTask = self.task  # type: ignore[assignment]  # one, where _twists
        if (q.dtype is not _FLOAT or twist.dtype is not _FLOAT or q.shape != self._q_shape
                or twist.shape != _TWIST or task.target is not None):  # fmt: skip
            return None
        if not q.flags.carray:  # the compiled entry's type: C-contiguous, aligned, writable
            q = q.copy()
        if not twist.flags.carray:
            twist = twist.copy()
        compiled: CompiledTick = self._compiled  # type: ignore[assignment]  # where _twists
        self._lock.acquire()
        try:
            r = compiled.twist(self.robot.model, self._data, task, q, twist, self._last_qdot,
                               self.dt, time.perf_counter())  # fmt: skip
            if r is not None:
                self._last_qdot = r.qdot
            return r
        finally:
            self._lock.release()

    def solve_at(
        self,
        kinematics: Kinematics,
        command: npt.ArrayLike | TaskCommand,
        ref: Reference | None = None,
        *,
        priority: Priority = "weighted",
        dt: float | None = None,
        qdot_prev: npt.ArrayLike | None = None,
    ) -> Resolution:
        """:meth:`solve` at the configuration of ``kinematics``, read instead of computed.

        For a loop that computes one :class:`~rrc_pin.kinematics.Kinematics` per tick and
        shares it (a controller's drift correction, strategy, resolver and log read the same
        one); it must be of this resolver's robot, its ``q`` checked by its maker.

        Raises:
            InvalidInput: As :meth:`solve`, and ``kinematics`` of another robot.
        """
        if not isinstance(kinematics, Kinematics) or kinematics.layout.nv != self.robot.nv:
            raise InvalidInput("kinematics", f"expected a Kinematics of {self.robot.name}, got "
                               f"{kinematics!r}")  # fmt: skip
        return self._solve(kinematics.q, kinematics.q_pin, kinematics, command, ref, priority,
                           dt, qdot_prev)  # fmt: skip

    def _solve(
        self, dof: Array, q_pin: Array, kin: Kinematics | None,
        command: npt.ArrayLike | TaskCommand, ref: Reference | None, priority: Priority,
        dt: float | None, qdot_prev: npt.ArrayLike | None,
    ) -> Resolution:  # fmt: skip
        """The tick (:meth:`solve`) once q is checked: the other arguments checked, then the
        kinematics, the tasks' rows, the limits, the answer."""  # noqa: D205, D209
        step = self.dt if dt is None else _dt(dt)
        previous = None if qdot_prev is None else as_vector(qdot_prev, "qdot_prev", self.robot.nv)
        if type(command) is not np.ndarray and (_is_task(command) or _is_tasks(command)):
            if ref is not None:
                raise InvalidInput("ref", "tasks carry their own ref; pass ref to FrameTask")
            levels, weighted = self._levels(cast(TaskCommand, command), priority)
            twist = None
        else:
            task = self._twist_task()
            twist = task.check_twist(cast(npt.ArrayLike, command))  # a bad one named first
            if not isinstance(priority, str) or priority != "weighted":
                raise InvalidInput("priority", "a twist is one task: priority is for lists of "
                                   f"tasks, got {priority!r}")
            levels, weighted = [[task]], False
            ref = task.ref if ref is None else task.check_ref(ref)
        with self._lock:
            start = time.perf_counter()
            if kin is None:
                kin = Kinematics(self.robot.model, self._data, self._layout, dof, q_pin)
            if twist is None:
                rows = [[t.rows(kin) for t in level] for level in levels]
            else:
                rows = [[cast(FrameTask, levels[0][0]).rows_at(kin, twist, cast(Reference, ref))]]
            before = self._last_qdot if previous is None else previous
            r = self._tick(kin, rows, weighted, step, before, start, levels)
            self._last_qdot = r.qdot
            return r

    def run_compiled(self, tick: Callable[..., Resolution | None], *args: Any) -> Resolution | None:
        """``tick(compiled, previous, within, *args)`` under the resolver's lock: a caller's tick
        on its compiled tick (:class:`~rrc_pin.compiled_tick.CompiledTick`, a cell's,
        :class:`~rrc_pin.cells.cell_tick.CellTick`), after the rates it returned last
        (``previous``), which may hand the tick back to the resolver with the rows and the
        limits' constraints it has (``within(kin, rows, constraints, weighted, dt, previous,
        start, tasks)``, as :meth:`solve_at` goes on once its limits have given theirs); the
        rates answered are its last from then on. None where there is no compiled tick
        (several joint boxes, a mask) or ``tick`` answers none.
        """  # noqa: D205
        with self._lock:
            compiled = self._compiled if self._free is None else None
            if compiled is None:
                return None
            r = tick(compiled, self._last_qdot, self._tick_within, *args)
            if r is not None:
                self._last_qdot = r.qdot
            return r

    def _tick(self, kin: Kinematics, rows: list[list[TaskRows]], weighted: bool, step: float,
              before: Array, start: float, tasks: list[list[Task]]) -> Resolution:  # fmt: skip
        """The tick of ``rows`` (those of ``tasks``) within the limits: compiled where it can be,
        else the Python pipeline (equality rows, a joint box that is not one JointLimits, a
        joint mask)."""  # noqa: D205, D209
        compiled = self._compiled if self._free is None else None
        if self._box_only and compiled is not None:  # its compiled call checks the rows first
            return compiled.tasks(kin, rows, weighted, [None], before, step, start)
        finite_rows(rows)  # before any limit computes its rows
        joint = None if compiled is None else compiled.limit
        constraints = [None if limit is joint else limit.constraints(kin, step, before)
                       for limit in self.limits]  # fmt: skip
        return self._tick_within(kin, rows, constraints, weighted, step, before, start, tasks)

    def _tick_within(
        self, kin: Kinematics, rows: list[list[TaskRows]], constraints: list[Constraints | None],
        weighted: bool, step: float, before: Array, start: float, tasks: list[list[Task]],
    ) -> Resolution:  # fmt: skip
        """The tick of ``rows`` (those of ``tasks``) within the limits' ``constraints`` (each
        limit's, in the limits' order; None for the compiled tick's joint limits, whose box it
        computes): :meth:`_tick` once the limits have given them."""  # noqa: D205, D209
        compiled = self._compiled if self._free is None else None
        joint = None if compiled is None else compiled.limit
        if compiled is not None and compiled.answers(constraints):
            return compiled.tasks(kin, rows, weighted, constraints, before, step, start)
        if joint is not None:
            constraints = [joint.constraints(kin, step, before) if c is None else c
                           for c in constraints]  # fmt: skip
        if self._free is not None:
            joint_rows = [[t.joint_rows for t in level] for level in tasks]
            return self._masked_tick(rows, joint_rows, cast(list[Constraints], constraints),
                                     weighted, step, start)  # fmt: skip
        problem = build(rows, cast(list[Constraints], constraints), self.robot.nv, step,
                        weighted=weighted, direction=self.direction_preserving)  # fmt: skip
        answer = solve(problem, self.backend, self.options)
        return Resolution.of(problem, answer, time.perf_counter() - start, self._names)

    def _masked_tick(self, rows: list[list[TaskRows]], joint_rows: list[list[bool]],
                     constraints: list[Constraints], weighted: bool, step: float,
                     start: float) -> Resolution:  # fmt: skip
        """The tick on the free joints' columns (:mod:`rrc_pin.solvers.tick.joint_mask`), its
        answer and problem written back over every joint."""  # noqa: D205, D209
        free = cast(npt.NDArray[np.intp], self._free)
        nv = self.robot.nv
        levels, kept = free_columns(rows, joint_rows, constraints, free)
        problem = build(levels, kept, free.size, step, weighted=weighted,
                        direction=self.direction_preserving)  # fmt: skip
        answer = solve(problem, self.backend, self.options)
        qdot = widened_rates(answer.qdot, free, nv)
        qdot.flags.writeable = False
        report = scattered(problem, rows, free, nv)
        masked = tuple(self._names[i] for i in np.setdiff1d(np.arange(nv), free).tolist())
        return Resolution.of(report, answer._replace(qdot=qdot), time.perf_counter() - start,
                             self._names)._replace(masked=masked)  # fmt: skip

    def rows_of(self, task: Task, q: npt.ArrayLike) -> TaskRows:
        """The rows ``A qdot ~= b`` that ``task`` gives at ``q`` (what ``solve`` stacks).

        Raises:
            InvalidInput: A bad q, or a task that does not fit the robot.
            FrameNotFound: The task names a frame the robot does not have.
        """
        q, dof, q_pin = self.robot.positions(q)
        _typed(task, Task, "task").check(self._layout)
        with self._lock:
            kin = Kinematics(self.robot.model, self._data, self._layout, dof, q_pin)
            return task.rows(kin)

    def _twist_task(self) -> FrameTask:
        """The task of ``solve(q, twist)``; a robot with several tool frames has none."""
        if self.task is None:
            raise InvalidInput(
                "command", f"{self.robot.name} has several tool frames "
                f"({', '.join(self.robot.tool_frames)}): pass tasks, e.g. [FrameTask(frame, "
                "twist)], or Resolver(robot, task=FrameTask(frame))",
            )
        return self.task

    def _levels(self, command: TaskCommand, priority: str) -> tuple[list[list[Task]], bool]:
        """The tasks as priority levels, every task checked against the robot."""
        if not isinstance(priority, str) or priority not in ("weighted", "strict"):
            raise InvalidInput("priority", f"expected 'weighted' or 'strict', got {priority!r}")
        items: list[Any] = [command] if _is_task(command) else list(cast(Sequence[Any], command))
        if not items:
            raise InvalidInput("command", "no tasks: pass a twist, a task or a list of tasks")
        layout = self._layout
        if priority == "weighted":
            for t in items:
                if not _is_task(t):
                    raise InvalidInput(
                        "command", "a weighted resolution takes a flat list of tasks (levels "
                        "are for priority='strict')",
                    )
            for t in items:
                t.check(layout)
            return [items], True
        levels: list[list[Any]] = [[t] if _is_task(t) else list(t) for t in items]
        for k, level in enumerate(levels):
            if not level:
                raise InvalidInput("command", f"priority level {k} is empty")
            for t in level:
                if not _is_task(t):
                    raise InvalidInput("command", f"level {k}: expected tasks, got {t!r}")
        for level in levels:
            for t in level:
                t.check(layout)
        return levels, False

    def _default_task(self) -> FrameTask | None:
        """The robot's tool frame, full twist (position below six joints).

        None when the robot has several tool frames (then ``solve`` takes tasks).
        """
        frame = self.robot.tool_frame
        if frame is None:
            return None
        return FrameTask(frame, rows="full" if self.robot.nv >= 6 else "position")

    def _closed_form_for(self, task: FrameTask | None) -> Any:
        cf = self.robot.closed_form
        if (
            task is None
            or cf is None
            or task.frame != cf.frame
            or task.frame != self.robot.tool_frame
        ):
            raise InvalidInput(
                "use_closed_form",
                f"{self.robot.name} has no closed form for this task's frame (the papers' "
                "closed forms answer for the catalogue arms' 'tool' frame)",
            )
        if max(task.selected) >= cf.task_dim:
            raise InvalidInput(
                "task", f"the closed form has {cf.task_dim} rows; rows {task.selected} asked"
            )
        return cf


def _dt(dt: float) -> float:
    """A control period: finite, at least :data:`MIN_DT` [s]."""
    return finite_number(dt, "dt", MIN_DT)


def _typed(value: Any, kind: type, name: str) -> Any:
    if not isinstance(value, kind):
        raise InvalidInput(name, f"expected a {kind.__name__}, got {value!r}")
    return value


def _limits(limits: Limit | Sequence[Limit] | None) -> tuple[Limit, ...]:
    if limits is None:
        return (JointLimits(),)
    items = (limits,) if isinstance(limits, Limit) else limits
    if not isinstance(items, (list, tuple)) or not all(isinstance(x, Limit) for x in items):
        raise InvalidInput("limits", f"expected a Limit or a sequence of them, got {limits!r}")
    return tuple(items)


def _is_task(x: object) -> TypeGuard[Task]:
    """``isinstance(x, Task)``, without ABCMeta's instance check (every task subclasses Task)."""
    return Task in type(x).__mro__


def _is_tasks(command: Any) -> bool:
    """True when ``command`` is a list of tasks or of levels (lists) of tasks, not a twist."""
    if isinstance(command, np.ndarray) or not isinstance(command, (list, tuple)):
        return False
    for t in command:
        if isinstance(t, (list, tuple)) or _is_task(t):
            return True
    return not command
