"""The resolver users run at every control tick: a twist or a stack of tasks in, joint rates out.

One pipeline, down the layers once: the tasks give rows (:mod:`rrc_pin.tasks`; kinematics
computed once per tick, :mod:`rrc_pin.kinematics`), the limits give the step's bounds
(:mod:`rrc_pin.limits`, :mod:`solvers.joint_bounds`), :func:`solvers.resolve.resolve` builds
and solves the QPs and falls back when they fail, and the
:class:`~solvers.resolution.Resolution` is the immutable record of the answer.

``Resolver.solve(q, twist)`` is that pipeline with one :class:`~rrc_pin.tasks.FrameTask` for
the robot's tool frame (its Jacobian in one Pinocchio call); ``solve(q, tasks)`` takes any
tasks, weighted (one QP) or by strict priority levels.

Bad input raises :class:`~rrc_pin.errors.InvalidInput` (or another
:class:`~rrc_pin.errors.RrcPinError`) naming the argument before any state changes;
numerical trouble never raises: the resolution says which method answered and why.

Threads: a Resolver holds its own ``pinocchio.Data`` and warm starts, so one Resolver must
not be used by two threads at once; several Resolvers on one shared Robot may.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal, cast

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.errors import InvalidInput, UnknownBackend
from rrc_pin.kinematics import Kinematics, Layout
from rrc_pin.limits import JointLimits
from rrc_pin.loading import load
from rrc_pin.robot import PIN_REFERENCE, Robot
from rrc_pin.tasks import FrameTask, Task
from solvers import jacobian_svd
from solvers.errors import BackendNotFound, InputError
from solvers.qp_backends import make_backend
from solvers.resolution import Method, Resolution, TaskRows
from solvers.resolve import DEFAULT_FALLBACKS, ResolveOptions, resolve
from solvers.spatial import Reference
from solvers.validation import positive

Array = npt.NDArray[np.float64]

TaskCommand = Task | Sequence[Task | Sequence[Task]]
"""Tasks for :meth:`Resolver.solve`: one, a list (weighted), or a list of levels (strict)."""

Priority = Literal["weighted", "strict"]


class Damping(jacobian_svd.Damping):
    """Damping near singularities (:class:`solvers.jacobian_svd.Damping`), for the resolver.

    Attributes:
        ratio: A singular direction is weak when, at full joint rate, it delivers less than
            1/ratio of the task speed of the strongest direction; > 1.

    Raises:
        InvalidInput: ``ratio`` not a finite number > 1.
    """

    def __post_init__(self) -> None:
        try:
            super().__post_init__()
        except InputError as exc:
            raise InvalidInput(exc.argument, exc.reason) from exc


@dataclass(frozen=True)
class QPOptions:
    """The QP backend and the fallbacks of a resolver.

    Attributes:
        backend: A name of :func:`solvers.qp_backends.installed_backends`: ``"daqp"``
            (default: exact active-set answers, the fastest median and tail of rrc-pin's
            backends in docs/benchmarks.md), ``"osqp"``, or a qpsolvers solver (``proxqp``,
            ``quadprog``, ``clarabel``...).
        options: The backend's own settings, checked at construction.
        fallbacks: Methods tried after the QP fails, in order: ``"scipy"`` (the same problem
            solved exactly by scipy.optimize), ``"dls"``, ``"scaling"``; ``"hold"`` always ends
            the chain.
    """

    backend: str = "daqp"
    options: Mapping[str, Any] = field(default_factory=dict)
    fallbacks: Sequence[Method] = DEFAULT_FALLBACKS


class Resolver:
    """Joint rates for commanded twists or tasks, inside the joint limits, at every tick.

    Args:
        robot: A :class:`rrc_pin.Robot`, or a name or path that :func:`rrc_pin.load` takes.
        dt: Control period [s], > 0 (``solve`` may override it per call).
        task: The task of ``solve(q, twist)``: a :class:`~rrc_pin.tasks.FrameTask` whose
            frame, rows, ref and weights are used (its twist is the call's); default the
            robot's tool frame, full twist (position only below six joints), world_aligned.
            A robot with several tool frames has no default: solve it with tasks.
        limits: Joint limits (default :class:`~rrc_pin.limits.JointLimits()`).
        qp: Backend and fallbacks (default :class:`QPOptions()`: daqp, then the exact LP).
        damping: Damping near singularities (default :class:`Damping()`), or None.
        direction_preserving: When a command cannot be met, slow down along it instead of
            distorting it (the top level as Drake's scale-maximising QP); False: the
            least-squares tracking QP.
        use_closed_form: Take the single-twist Jacobian from ``robot.closed_form`` (the
            paper's equations; world_aligned only) instead of Pinocchio.

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
        limits: JointLimits | None = None,
        qp: QPOptions | None = None,
        damping: Damping | None = Damping(),  # noqa: B008 - immutable
        direction_preserving: bool = True,
        use_closed_form: bool = False,
    ) -> None:
        if isinstance(robot, str):
            robot = load(robot)
        if not isinstance(robot, Robot):
            raise InvalidInput("robot", f"expected a rrc_pin.Robot or a name, got {robot!r}")
        self.robot = robot
        self.dt = _dt(dt)
        self.limits = JointLimits() if limits is None else _typed(limits, JointLimits, "limits")
        self._bounds = self.limits.bounds(robot)
        self.qp = QPOptions() if qp is None else _typed(qp, QPOptions, "qp")
        try:
            self.options = ResolveOptions(direction_preserving, damping, self.qp.fallbacks)
            self.backend = make_backend(self.qp.backend, **dict(self.qp.options))
        except BackendNotFound as exc:
            raise UnknownBackend(exc.backend, exc.available) from exc
        except InputError as exc:
            name = {"backend_options": "qp.options", "fallbacks": "qp.fallbacks"}
            raise InvalidInput(name.get(exc.argument, exc.argument), exc.reason) from exc
        self._data = robot.model.createData()  # this resolver's own: thread-safe across resolvers
        self._layout = Layout.of(robot.model, list(robot.joint_names))
        self.task = self._default_task() if task is None else _typed(task, FrameTask, "task")
        self._frame = -1
        if self.task is not None:
            self.task.check(self._layout)
            self._frame = self._layout.frames[self.task.frame]
        elif use_closed_form:
            raise InvalidInput("use_closed_form", "the closed form needs a task (one frame)")
        self._closed_form = self._closed_form_for(self.task) if use_closed_form else None
        self._names = tuple(robot.joint_names)
        self._last_qdot: Array | None = None

    def reset(self) -> None:
        """Forget the warm starts and the previous joint rates."""
        self.backend.reset()
        self._last_qdot = None

    def warm_start_state(self) -> dict[str, Any]:
        """Copies of every value that carries over to the next ``solve``."""
        state: dict[str, Any] = dict(self.backend.warm_start_state())
        state["last_qdot"] = None if self._last_qdot is None else self._last_qdot.copy()
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
                of them (``priority="weighted"``: one QP, their weights trade them off), or a
                list of levels, each a task or a list of tasks (``priority="strict"``: each
                level exactly optimal within the optimal set of those above; the top level
                direction-preserving with one common scale).
            ref: Frame of a twist: ``world_aligned``, ``local`` or ``world``; default the
                resolver's task's. Not used with tasks (each task has its own).
            priority: ``"weighted"`` or ``"strict"``, for a list of tasks.
            dt: Step [s] for this call; default the constructor's.
            qdot_prev: Previous joint rates (nq,) for the acceleration limits; default the
                rates this resolver returned last (zero at the first step).

        Returns:
            The :class:`~solvers.resolution.Resolution` (finite, within the bounds).

        Raises:
            InvalidInput: A bad q, twist, task, level, ref, priority, dt or qdot_prev, named;
                raised before any state changes.
            FrameNotFound: A task names a frame the robot does not have (the error lists
                them).
        """
        q, q_pin = self.robot.configuration(q)
        step = self.dt if dt is None else _dt(dt)
        prev = None if qdot_prev is None else self.robot.check_q(qdot_prev, "qdot_prev")
        if isinstance(command, Task) or _is_tasks(command):
            if ref is not None:
                raise InvalidInput("ref", "tasks carry their own ref; pass ref to FrameTask")
            levels, weighted = self._levels(cast(TaskCommand, command), priority)
            kin = Kinematics(self.robot.model, self._data, self._layout, q, q_pin)
            rows = [[t.rows(kin) for t in level] for level in levels]
            # the tasks' arrays may be the caller's: the resolution keeps copies
            return self._resolve(rows, q, step, prev, weighted, copy_rows=True)
        task = self._twist_task()
        b = task.check_twist(cast(npt.ArrayLike, command)).copy()  # the resolution keeps it
        ref = task.ref if ref is None else task.check_ref(ref)
        return self._resolve([[self._twist_rows(task, q, q_pin, b, ref)]], q, step, prev)

    def _solve_checked_twist(
        self, q: Array, q_pin: Array, twist: Array, ref: Reference
    ) -> Resolution:
        """``solve(q, twist, ref)`` on arguments the caller has checked and owns.

        For :class:`~rrc_pin.control.Controller`, which checks the operator's command at its
        boundary and holds q itself: one check per tick instead of two (with the read-only q
        this cut the controller's own work per tick on panda from 79k to 53k instructions,
        callgrind).

        Args:
            q: Joint positions (nq,), finite (the controller's own).
            q_pin: The same as Pinocchio's configuration vector.
            twist: A finite (6,) twist nobody changes afterwards (the resolution keeps it).
            ref: ``local`` or ``world_aligned``.
        """
        task = self._twist_task()
        b = task.selected_rates(twist)
        return self._resolve([[self._twist_rows(task, q, q_pin, b, ref)]], q, self.dt, None)

    def _resolve(
        self,
        rows: list[list[TaskRows]],
        q: Array,
        step: float,
        prev: Array | None,
        weighted: bool = False,
        copy_rows: bool = False,
    ) -> Resolution:
        """The step's bounds and the pipeline (:func:`solvers.resolve.resolve`) on ``rows``."""
        if self.limits.acceleration is None:
            prev = None
        elif prev is None:
            prev = np.zeros(self.robot.nq) if self._last_qdot is None else self._last_qdot
        bounds = self._bounds.step(q, step, prev)
        result = resolve(
            rows, bounds, self.backend, self.options, weighted=weighted, joint_names=self._names,
            copy_rows=copy_rows,
        )  # fmt: skip
        self._last_qdot = result.qdot
        return result

    def rows_of(self, task: Task, q: npt.ArrayLike) -> TaskRows:
        """The rows ``A qdot ~= b`` that ``task`` gives at ``q`` (what ``solve`` stacks).

        Raises:
            InvalidInput: A bad q, or a task that does not fit the robot.
            FrameNotFound: The task names a frame the robot does not have.
        """
        q, q_pin = self.robot.configuration(q)
        _typed(task, Task, "task").check(self._layout)
        return task.rows(Kinematics(self.robot.model, self._data, self._layout, q, q_pin))

    def _twist_task(self) -> FrameTask:
        """The task of ``solve(q, twist)``; a robot with several tool frames has none."""
        if self.task is None:
            raise InvalidInput(
                "command", f"{self.robot.name} has several tool frames "
                f"({', '.join(self.robot.tool_frames)}): pass tasks, e.g. [FrameTask(frame, "
                "twist)], or Resolver(robot, task=FrameTask(frame))",
            )  # fmt: skip
        return self.task

    def _twist_rows(
        self, task: FrameTask, q: Array, q_pin: Array, b: Array, ref: Reference
    ) -> TaskRows:
        """``task`` at ``q``, rates ``b`` of its rows in frame ``ref`` (one Jacobian call)."""
        if self._closed_form is not None:
            if ref != "world_aligned":
                raise InvalidInput("ref", f"the closed form gives world_aligned rows, got {ref!r}")
            J = np.asarray(self._closed_form.jacobian(q), dtype=np.float64)
        else:
            J = pin.computeFrameJacobian(
                self.robot.model, self._data, q_pin, self._frame, PIN_REFERENCE[ref]
            )
        return task.rows_from(J, b)

    def _levels(
        self, command: TaskCommand, priority: str
    ) -> tuple[list[list[Task]], bool]:
        """The tasks as priority levels, every task checked against the robot."""
        if priority not in ("weighted", "strict"):
            raise InvalidInput("priority", f"expected 'weighted' or 'strict', got {priority!r}")
        items = [command] if isinstance(command, Task) else list(command)  # never empty
        if priority == "weighted":
            if not all(isinstance(t, Task) for t in items):
                raise InvalidInput(
                    "command", "a weighted resolution takes a flat list of tasks (levels are "
                    "for priority='strict')",
                )  # fmt: skip
            levels = [items]
        else:
            levels = [[t] if isinstance(t, Task) else list(t) for t in items]
            for k, level in enumerate(levels):
                if not level:
                    raise InvalidInput("command", f"priority level {k} is empty")
                for t in level:
                    if not isinstance(t, Task):
                        raise InvalidInput("command", f"level {k}: expected tasks, got {t!r}")
        for level in levels:
            for t in level:
                t.check(self._layout)  # type: ignore[union-attr]
        return levels, priority == "weighted"  # type: ignore[return-value]

    def _default_task(self) -> FrameTask | None:
        """The robot's tool frame, full twist (position below six joints).

        None when the robot has several tool frames (then ``solve`` takes tasks).
        """
        frame = self.robot.tool_frame
        if frame is None:
            return None
        return FrameTask(frame, rows="full" if self.robot.nq >= 6 else "position")

    def _closed_form_for(self, task: FrameTask | None) -> Any:
        cf = self.robot.closed_form
        assert task is not None
        if cf is None or task.frame != cf.frame or task.frame != self.robot.tool_frame:
            raise InvalidInput(
                "use_closed_form",
                f"{self.robot.name} has no closed form for frame {task.frame!r} (the papers' "
                "closed forms answer for the catalogue arms' 'tool' frame)",
            )
        if max(task.selected) >= cf.task_dim:
            raise InvalidInput(
                "task", f"the closed form has {cf.task_dim} rows; rows {task.selected} asked"
            )
        return cf


def _dt(dt: float) -> float:
    return positive(dt, "dt", InvalidInput)


def _typed(value: Any, kind: type, name: str) -> Any:
    if not isinstance(value, kind):
        raise InvalidInput(name, f"expected a {kind.__name__}, got {value!r}")
    return value


def _is_tasks(command: Any) -> bool:
    """True when ``command`` is a list of tasks or of levels (lists) of tasks, not a twist."""
    if isinstance(command, np.ndarray) or not isinstance(command, (list, tuple)):
        return False
    return any(isinstance(t, (Task, list, tuple)) for t in command)
