r"""The answer to one tick and how it was obtained: :class:`Resolution`, an immutable record.

Its status, scale and veer are decided once, by the pipeline
(:mod:`rrc_pin.solvers.tick.pipeline`); what
costs more to report is computed on first access from the problem it answered: ``active``
(the joint bounds the answer touches, with the constraint behind each), ``active_rows`` (the
constraint rows it touches, by name), ``tasks`` (per task: achieved rates, residual, scale)
and ``residual``.

Scales and angles are unit-consistent: a level's rows are compared in its normalised metric,
each row divided by its unit (the arm's reach for linear velocity rows) and times the square
root of its weight, so that metres and radians weigh alike.
"""

from __future__ import annotations

import math
import warnings
from functools import cached_property
from typing import Literal, NamedTuple, Protocol

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.tick.joint_box import ACCELERATION, POSITION
from rrc_pin.solvers.tick.pipeline import Answer, LevelStatus, Method, Status, served
from rrc_pin.solvers.tick.problem import Box, Problem, TaskRows, largest_weight, row_factors
from rrc_pin.solvers.tick.statuses import norm, scale_and_veer

Array = npt.NDArray[np.float64]

BoundKind = Literal["velocity", "position", "acceleration"]
"""What sets a joint-rate bound."""

Served = Literal["met", "scaled", "traded", "dropped", "held"]
"""How one task was served: its level's words (:data:`LevelStatus`) for the task's own rows,
and ``held`` for a zero command whose rows stayed still (one whose rows moved is ``traded``)."""

ACTIVE_TOL = 1e-9
"""[rad/s or m/s, or the row's units] A bound or row closer than this to the answer is active."""


class ActiveLimit(NamedTuple):
    """A joint-rate bound that the answer touches.

    Attributes:
        joint: Joint index.
        side: ``"lower"`` or ``"upper"``.
        kind: The constraint behind the bound: ``"velocity"``, ``"position"`` or
            ``"acceleration"``.
        bound: The bound's value [rad/s or m/s].
        name: Joint name, when known (else None).
    """

    joint: int
    side: Literal["lower", "upper"]
    kind: BoundKind
    bound: float
    name: str | None = None


class ActiveRow(NamedTuple):
    """A constraint row ``g qdot <= h`` that the answer touches.

    Attributes:
        name: The row's name (its limit's, e.g. a collision pair).
        row: Its index among the problem's rows.
        value: ``g qdot`` [the row's units].
        bound: ``h``.
        distance: The distance [m] the row keeps (a collision pair's signed distance), or NaN.
    """

    name: str
    row: int
    value: float
    bound: float
    distance: float = math.nan


class TaskReport(NamedTuple):
    """How one task was served.

    Attributes:
        name: The task's name.
        level: Its priority level (0 the highest; 0 for every task of a weighted resolution).
        commanded: Desired rates of its rows (m,) [m/s, rad/s or rad/s].
        achieved: Rates of its rows produced by the answer, ``A qdot`` (m,).
        residual: ``|achieved - commanded|`` (Euclidean, in the task's own units).
        scale: Fraction of the command achieved along it, in [0, 1], in the task's
            normalised metric (module docstring); a zero command has no direction: 1 when
            ``held``, 0 when ``traded``.
        bound_by: The active joint bounds on joints this task moves.
        served: How the task was served (:data:`Served`): ``met``, ``scaled``, ``traded``,
            ``dropped``, or ``held`` (a zero command, its rows still).
    """

    name: str
    level: int
    commanded: Array
    achieved: Array
    residual: float
    scale: float
    bound_by: tuple[ActiveLimit, ...]
    served: Served


class Deferred(Protocol):
    """A problem built only where a resolution's report reads it (the compiled tick's)."""

    @property
    def box(self) -> Box:
        """The step's joint-rate bounds."""

    def problem(self) -> Problem:
        """The problem the tick answered."""


class _Record(NamedTuple):
    qdot: Array
    status: Status
    method: Method
    scale: float
    veer: float
    levels: tuple[LevelStatus, ...]
    attempts: tuple[tuple[str, str], ...]
    backend: str
    iterations: int
    clip: float
    lambda_sq: float
    build_time: float
    solve_time: float
    source: Problem | Deferred
    joint_names: tuple[str, ...] | None = None
    masked: tuple[str, ...] = ()


class Resolution(_Record):
    """The answer to one tick, and how it was obtained.

    An immutable record: the problem it answered holds the rows and commands it reports on
    (copies where the caller's arrays could change). A named tuple with a cache for the
    fields computed on access: the compiled tick builds its problem only where the report
    reads it (``source`` then defers it, :class:`Deferred`).

    Attributes:
        qdot: Joint rates (n,) [rad/s or m/s], finite and within the step's box (read-only).
        status: What the answer is for the top level
            (:data:`~rrc_pin.solvers.tick.pipeline.Status`; docs/api.md, "Reading a
            resolution"); how each lower level fared is in ``levels``.
        method: How the top level was answered (:data:`~rrc_pin.solvers.tick.pipeline.Method`).
        scale: Fraction in [0, 1] of the top level's command achieved along it (normalised
            metric): the common scale of its tasks when its direction was kept.
        veer: Angle [rad] between the top level's achieved and commanded rates (normalised
            metric): 0 unless damped, singular, least squares, a fallback, or scaled by the
            QP backend (its answer's angle as measured).
        levels: How each priority level was served, the top level's first
            (:data:`~rrc_pin.solvers.tick.pipeline.LevelStatus`: ``met``, ``scaled``,
            ``traded``, ``dropped``).
        attempts: ``(method or level, reason)`` of every method that failed.
        backend: Name of the last QP backend that answered, or "" (the exact kernels).
        iterations: Backend iterations (0 without a backend).
        clip: Size of the final clip into the box [rad/s]: the backend's tolerance.
        lambda_sq: Largest squared damping applied (normalised units), 0 when undamped.
        build_time: Time outside the backend [s].
        solve_time: Time inside the backend [s].
        problem: The problem it answers (tasks' rows, box, constraint rows), built on first
            access where it was deferred.
        joint_names: Joint names for :attr:`ActiveLimit.name`, or None.
        masked: The names (``joint_names``) of the rates a joint mask held at exactly zero
            (``Resolver.mask``): out of every task and limit, so never in :attr:`active`.
    """

    @classmethod
    def of(
        cls, problem: Problem, answer: Answer, elapsed: float, names: tuple[str, ...] | None
    ) -> Resolution:
        """The record of ``answer`` to ``problem``, ``elapsed`` [s] the tick's time."""
        return cls(
            answer.qdot, answer.status, answer.method, answer.scale, answer.veer, answer.levels,
            answer.attempts, answer.backend, answer.iterations, answer.clip, answer.lambda_sq,
            elapsed - answer.solve_time, answer.solve_time, problem, names,
        )  # fmt: skip

    @cached_property
    def problem(self) -> Problem:
        """The problem it answers (tasks' rows, box, constraint rows)."""
        source = self.source
        return source if isinstance(source, Problem) else source.problem()

    @cached_property
    def box(self) -> Box:
        """The step's joint-rate bounds."""
        return self.source.box

    @property
    def bounds(self) -> Box:
        """The old name of :attr:`box` (deprecated: goes in the next release)."""
        warnings.warn("Resolution.bounds is deprecated and goes in the next release: use "
                      "Resolution.box", DeprecationWarning, stacklevel=2)  # fmt: skip
        return self.box

    @cached_property
    def active(self) -> tuple[ActiveLimit, ...]:
        """Joint bounds the answer touches, by joint then side (:data:`ACTIVE_TOL`)."""
        active = active_limits(self.qdot, self.box, self.joint_names)
        if self.masked:  # held at a zero box by the mask, not by a limit
            active = tuple(a for a in active if a.name not in self.masked)
        return active

    @cached_property
    def active_rows(self) -> tuple[ActiveRow, ...]:
        """Constraint rows the answer touches (:data:`ACTIVE_TOL`), in the problem's order."""
        rows = self.problem.rows
        if rows is None:
            return ()
        values = rows.G @ self.qdot
        distance = rows.distance
        return tuple(
            ActiveRow(rows.names[i], i, float(values[i]), float(rows.h[i]),
                      math.nan if distance is None else float(distance[i]))
            for i in np.flatnonzero(values >= rows.h - ACTIVE_TOL).tolist()
        )  # fmt: skip

    @cached_property
    def tasks(self) -> tuple[TaskReport, ...]:
        """One :class:`TaskReport` per task, in priority order."""
        out = []
        active = self.active
        for k, level in enumerate(self.problem.levels):
            for t in level:
                bound_by: tuple[ActiveLimit, ...] = ()
                if active:
                    moved = (t.A != 0.0).any(axis=0).tolist()
                    bound_by = tuple(a for a in active if moved[a.joint])
                out.append(_report(t, k, t.A @ self.qdot, bound_by, self.levels[k] == "dropped"))
        return tuple(out)

    @cached_property
    def residual(self) -> float:
        r"""The top level's task error :math:`\|A\dot q - b\|_2` (its tasks' own units, mixed)."""
        level = self.problem.levels[0]
        return math.hypot(*(norm(t.A @ self.qdot - t.b) for t in level))

    def __setattr__(self, name: str, value: object) -> None:
        raise AttributeError(f"a Resolution is immutable: {name!r} cannot be set")

    def __repr__(self) -> str:
        return (
            f"Resolution(status={self.status!r}, method={self.method!r}, "
            f"scale={self.scale:.6g}, veer={self.veer:.3g}, levels={self.levels}, "
            f"active={len(self.active)}, qdot={np.array2string(self.qdot, precision=4)})"
        )


def _report(
    t: TaskRows, level: int, y: Array, bound_by: tuple[ActiveLimit, ...], dropped: bool
) -> TaskReport:
    """How task ``t`` of ``level`` was served by its achieved rates ``y``.

    Scale and verdict in the task's normalised metric (module docstring), both divided by the
    command's largest entry above 1 so that the metric cannot overflow.
    """
    factor = row_factors(t, largest_weight((t,)), units=True)
    peak = max(1.0, float(np.abs(t.b).max(initial=0.0)))
    ys, bs = (y, t.b) if factor is None else (factor * (y / peak), factor * (t.b / peak))
    how: Served = "dropped" if dropped else served(ys, bs)
    if t.b.any():
        scale = scale_and_veer(ys, bs)[0]
    else:  # a zero command: held still, or traded for a level above or a limit
        how, scale = ("held", 1.0) if how == "met" else (how, 0.0)
    return TaskReport(t.name, level, t.b, y, norm(y - t.b), scale, bound_by, how)


KIND_NAMES: dict[int, BoundKind] = {POSITION: "position", ACCELERATION: "acceleration"}


def active_limits(
    qdot: Array, box: Box, names: tuple[str, ...] | None = None
) -> tuple[ActiveLimit, ...]:
    """The bounds that ``qdot`` touches within :data:`ACTIVE_TOL`, with their constraints.

    Args:
        qdot: Joint rates (n,).
        box: The bounds they were computed within.
        names: Joint names for :attr:`ActiveLimit.name`, or None.

    Returns:
        The active bounds, by joint then side (lower first).
    """
    out: list[ActiveLimit] = []
    above = qdot - box.lb
    below = box.ub - qdot
    for j in np.flatnonzero((above <= ACTIVE_TOL) | (below <= ACTIVE_TOL)).tolist():
        low, high, kinds = above[j], below[j], box.kind[:, j].tolist()
        name = names[j] if names else None
        if low <= ACTIVE_TOL:
            kind = KIND_NAMES.get(kinds[0], "velocity")
            out.append(ActiveLimit(j, "lower", kind, float(box.lb[j]), name))
        if high <= ACTIVE_TOL:
            kind = KIND_NAMES.get(kinds[1], "velocity")
            out.append(ActiveLimit(j, "upper", kind, float(box.ub[j]), name))
    return tuple(out)
