r"""One resolver tick in one compiled call, on a workspace of preallocated arrays.

:func:`run` goes down the stages of docs/api.md ("One tick, one pipeline") once:

1. the inputs' **checks** (every position and commanded rate finite);
2. the step's **box** (:func:`~rrc_pin.solvers.tick.joint_box.joint_box`);
3. the **problem**: the mode, and each level's rows in the metric it is solved in
   (:func:`stacked`: :func:`rrc_pin.solvers.tick.problem.build`'s);
4. the **top level** (:func:`rrc_pin.solvers.tick.top.direction`, or a least squares), then each
   **lower level** within the optimal set of those above
   (:func:`rrc_pin.solvers.tick.levels.least_squares`);
5. the **clip** into the box and the rows.

Its arguments are a few packed arrays (numba's call costs grow with the number of arguments:
docs/api.md, "One compiled pass per tick"), the rows of which the module constants name;
:class:`Workspace` holds them for one resolver and reads the answer back. The QPs the kernels do
not answer go to the backend from inside the call (:mod:`rrc_pin.solvers.tick.backend_calls`);
where the top level finds no usable answer, :func:`run` returns
:data:`~rrc_pin.solvers.tick.top.FAILED` and the fallbacks (:mod:`rrc_pin.solvers.tick.fallbacks`)
answer. Problems with equality rows (contacts, grips) have an entry of their own,
:func:`run_within`: its top level solved within the rows
(:mod:`rrc_pin.solvers.tick.equalities`), the rest as :func:`run`. The default tick (one
level, the joint box alone) has an entry of its own, :func:`run_box`: the same stages
without the code it does not reach, compiled in a fraction of the general entry's time.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers import linalg
from rrc_pin.solvers.compiled import inlined, kernel
from rrc_pin.solvers.linalg import row_values
from rrc_pin.solvers.tick import equalities, factor, feasibility, statuses, top
from rrc_pin.solvers.tick.joint_box import joint_box
from rrc_pin.solvers.tick.levels import least_squares
from rrc_pin.solvers.tick.problem import LARGE, TaskRows, cap
from rrc_pin.solvers.tick.statuses import DROPPED
from rrc_pin.solvers.tick.top import FAILED, Rows, Top

Array = npt.NDArray[np.float64]
Ints = npt.NDArray[np.int64]
Held = list[Any]
"""What rows from a start row hold: the end row, then the task's rows, weights and units where
they are constants (:func:`_constant`), else :data:`_LOADED`."""

_LOADED = object()
"""A part of a task loaded that is not a constant: never the same as the next tick's."""

# Rows of ``joints`` (k, n): the inputs, then the outputs.
POSITION, LOWER, UPPER, VELOCITY, ACCELERATION, PREVIOUS, LB, UB, QDOT, KIND = range(10)
JOINT_ROWS = 11  # KIND takes two rows: the lower bounds', then the upper ones'
# Rows of ``rates`` (k, m): each task row's commanded rate, weight and unit.
RATE, WEIGHT, UNIT = range(3)
# Entries of ``ints``: sizes and flags in, codes out, then the levels' row offsets and codes.
LEVELS, ROWS, CONSTRAINTS, WEIGHTED, DIRECTION, UNITS, INVALID, STARTS = range(8)
# Entries of ``reals``: the step and the limits' settings in, the report out.
(DT, MARGIN, GAIN, THRESHOLD, TOLERANCE, SCALE, VEER, LAMBDA_SQ, CLIP, ZERO_INSIDE,
 RECOVERING, SOLVED, SOLVED_STEPS, REAL_SIZE) = range(14)  # fmt: skip
# SOLVED, SOLVED_STEPS: the QPs the compiled active-set solver answered, and its steps

BAD_POSITION, BAD_RATE, BAD_ROWS = 1, 2, 3
"""Codes of ``ints[INVALID]``: a position, a commanded rate, or a task row not finite."""

INVALID_INPUT = -2
"""What :func:`run` returns for a position, commanded rate or task row that is not finite."""

ELSEWHERE = -3
"""What :func:`run_box` returns for a tick that is not its own (:func:`run` answers it)."""


def _constant(part: Array | None) -> object:
    """``part`` of a task's rows (A, weights or units) if it cannot change: None, or read-only
    owning its values; else :data:`_LOADED`."""  # noqa: D205, D209
    if part is None or (part.base is None and not part.flags.writeable):
        return part
    return _LOADED


@kernel
def stacked(A: Array, b: Array, weight: Array, unit: Array, normalised: bool, lb: Array,
            ub: Array) -> tuple[Array, Array, float]:  # fmt: skip
    """A level's rows and rates in its metric, and the factor its rates were multiplied by.

    Each row times the square root of its weight over the level's largest, and in the
    normalised metric divided by its unit; the rates capped
    (:func:`rrc_pin.solvers.tick.problem._stack`).
    """
    m, n = A.shape
    top_weight = weight[0]
    for i in range(m):
        top_weight = max(top_weight, weight[i])
    space = np.empty(m * (n + 1))  # one allocation: the rows and rates
    rows, rates = space[: m * n].reshape(m, n), space[m * n :]
    units = unit if normalised else np.ones(m)
    peak = linalg.weighted_rows(A, b, weight, top_weight, units, 1.0, rows, rates)
    factor = 1.0
    if normalised and peak > LARGE:  # the direction first: b over its largest entry, before
        # the rows' factors could overflow
        b_max = 0.0
        for i in range(m):
            b_max = max(b_max, abs(b[i]))
        factor = 1.0 / b_max
        peak = linalg.weighted_rows(A, b, weight, top_weight, units, factor, rows, rates)
    c = cap(rows, peak, factor, normalised, lb, ub)
    return (rows, rates, factor) if c == 1.0 else (rows, rates * c, factor * c)


@inlined
def served(A: Array, b: Array, qdot: Array, rate_factor: float) -> int:
    """How a lower level was served by ``qdot`` (:func:`rrc_pin.solvers.tick.statuses.served`)."""
    return statuses.served(row_values(A, qdot), b, rate_factor)


@kernel
def within_rows(x: Array, rows: Rows, zero_inside: bool) -> float:
    """``x`` shrunk toward zero in place until the rows hold (:func:`feasibility.into_rows`); the
    factor (1: kept). Standing still must be allowed.
    """  # noqa: D205
    if rows.h.size == 0 or not zero_inside or (rows.h < 0.0).any():
        return 1.0
    factor = feasibility.into_rows(rows.G, rows.h, x)
    if factor != 1.0:
        for i in range(x.size):
            x[i] *= factor
    return factor


@inlined
def checked(joints: Array, task_rows: Array, rates: Array, m: int) -> int:
    """0 where every position, commanded rate and task row is finite, else the code of the
    first bad.
    """  # noqa: D205
    if not feasibility.all_finite(joints[POSITION]):
        return BAD_POSITION
    if not feasibility.all_finite(rates[RATE][:m]):
        return BAD_RATE
    if not feasibility.all_finite(task_rows.ravel()[: m * task_rows.shape[1]]):  # a view: C order
        return BAD_ROWS
    return 0


@inlined
def level(task_rows: Array, rates: Array, ints: Ints, k: int, normalised: bool, lb: Array,
          ub: Array) -> tuple[Array, Array, float]:  # fmt: skip
    """Level ``k``'s rows and rates in its metric (:func:`stacked`)."""
    start, end = ints[STARTS + k], ints[STARTS + k + 1]
    return stacked(task_rows[start:end], rates[RATE][start:end], rates[WEIGHT][start:end],
                   rates[UNIT][start:end], normalised, lb, ub)  # fmt: skip


@inlined
def top_level(A: Array, b: Array, rate_factor: float, rates: Array, ints: Ints, reals: Array,
              rows: Rows, direction: bool, recovering: bool) -> Top:  # fmt: skip
    """The top level's answer to its rows ``A`` and rates ``b`` (:func:`level`): the direction
    problem's stages or a least squares.
    """  # noqa: D205
    need_null = ints[LEVELS] > 1
    if direction:
        return top.direction(A, b, rows, reals[DT], reals[THRESHOLD], rate_factor, need_null)
    per_unit = 1.0 / rates[UNIT][: ints[STARTS + 1]] if ints[UNITS] else np.empty(0)
    return top.least_squares_top(A, b, per_unit, rows, recovering, rate_factor, need_null,
                                 reals[THRESHOLD])  # fmt: skip


@inlined
def lower_levels(task_rows: Array, rates: Array, ints: Ints, rows: Rows, answer: Top
                 ) -> Array:  # fmt: skip
    """Each level below the top within the optimal set of those above, its code in ``ints``:
    the rates (a level whose QP the backend fails is dropped, those above kept).
    """  # noqa: D205
    qdot, null = answer.qdot, answer.null
    codes = STARTS + ints[LEVELS] + 1
    for k in range(1, ints[LEVELS]):
        A, b, rate_factor = level(task_rows, rates, ints, k, k == 0, rows.lb, rows.ub)
        if null.shape[0] == 0:
            ints[codes + k] = served(A, b, qdot, rate_factor)
            continue
        kept, null = least_squares(k, A, b, qdot, null, rows.lb, rows.ub, rows.G, rows.h,
                                   rows.tol, k < ints[LEVELS] - 1)  # fmt: skip
        if kept.size == 0:  # the backend failed: the levels above kept
            ints[codes + k] = DROPPED
            continue
        qdot = kept
        ints[codes + k] = served(A, b, qdot, rate_factor)
    return qdot


@inlined
def bounds(q: Array, dt: float, joints: Array, reals: Array, lb: Array, ub: Array,
           kinds: Array) -> tuple[bool, bool]:  # fmt: skip
    """Stage 2 at positions ``q`` (n,) for the step ``dt`` [s]: the box into ``lb`` and ``ub``
    (n,), what sets each bound into ``kinds`` (2, n), the lower bounds' row then the upper
    ones' (:func:`~rrc_pin.solvers.tick.joint_box.joint_box`); whether standing still is
    allowed, whether a joint was outside its range.
    """  # noqa: D205
    kind = np.empty((2, q.size), np.int8)
    zero_inside, recovering = joint_box(
        q, joints[LOWER], joints[UPPER], joints[VELOCITY], reals[MARGIN], reals[GAIN], dt,
        joints[PREVIOUS], joints[ACCELERATION], lb, ub, kind,
    )  # fmt: skip
    for j in range(q.size):
        kinds[0, j], kinds[1, j] = kind[0, j], kind[1, j]
    return zero_inside, recovering


@inlined
def box(joints: Array, task_rows: Array, rates: Array, ints: Ints, reals: Array) -> bool:
    """Stages 1 and 2: the inputs checked (the code of a bad one in ``ints[INVALID]``, then
    False), the step's box and what sets each bound into ``joints``, its flags into ``reals``.
    """  # noqa: D205
    ints[INVALID] = checked(joints, task_rows, rates, ints[ROWS])
    reals[SOLVED], reals[SOLVED_STEPS] = 0.0, 0.0
    if ints[INVALID]:
        return False
    zero_inside, recovering = bounds(joints[POSITION], reals[DT], joints, reals, joints[LB],
                                     joints[UB], joints[KIND : KIND + 2])  # fmt: skip
    reals[ZERO_INSIDE] = 1.0 if zero_inside else 0.0
    reals[RECOVERING] = 1.0 if recovering else 0.0
    return True


@inlined
def clipped(qdot: Array, rows: Rows, zero_inside: bool) -> tuple[float, float]:
    """Stage 5: ``qdot`` clipped into the box and shrunk into the rows, in place; the clip's
    size and the shrink's factor.
    """  # noqa: D205
    clip = feasibility.clip_into(qdot, rows.lb, rows.ub)
    return clip, within_rows(qdot, rows, zero_inside)


@inlined
def report(joints: Array, task_rows: Array, rates: Array, ints: Ints, reals: Array, rows: Rows,
           answer: Top, qdot: Array, A: Array, b: Array, direction: bool, rate_factor: float
           ) -> int:  # fmt: skip
    """Stage 5: ``qdot`` clipped into the box and shrunk into the rows, and the top level's
    report as they bear it out (its rows ``A``, rates ``b``:
    :func:`rrc_pin.solvers.tick.statuses.borne_out`), into ``joints`` and ``reals``; the status
    code, or :data:`~rrc_pin.solvers.tick.top.FAILED`. A shrink serves the lower levels anew.
    """  # noqa: D205
    clip, shrink = clipped(qdot, rows, reals[ZERO_INSIDE] == 1.0)
    status, scale, veer = statuses.borne_out(answer.status, row_values(A, qdot), b, direction,
                                             rate_factor, answer.scale * shrink, answer.veer)
    if status == FAILED:
        return FAILED
    reals[CLIP], reals[SCALE], reals[VEER], reals[LAMBDA_SQ] = clip, scale, veer, answer.lambda_sq
    for c in range(qdot.size):  # element by element: an array copy compiles numba's shape error
        joints[QDOT, c] = qdot[c]
    codes = STARTS + ints[LEVELS] + 1
    ints[codes] = statuses.top_served(status)
    for k in range(1, ints[LEVELS] if shrink < 1.0 - statuses.EXACT_TOL else 1):
        if ints[codes + k] != DROPPED:
            # k == 0: False, not the literal, one compiled signature of stacked
            Ak, bk, factor_k = level(task_rows, rates, ints, k, k == 0, rows.lb, rows.ub)
            ints[codes + k] = served(Ak, bk, qdot, factor_k)
    return status


@kernel
def run_box(joints: Array, task_rows: Array, rates: Array, ints: Ints, reals: Array) -> int:
    """The default tick: one level in the direction mode, within the joint box alone.

    What :func:`run` does for it, without the code of the rows, the least squares and the
    lower levels (a fraction of its compile): the status code, :data:`INVALID_INPUT`, or
    :data:`ELSEWHERE` where the mode is not the direction one (:func:`run` answers then).
    """
    if not box(joints, task_rows, rates, ints, reals):
        return INVALID_INPUT
    if reals[ZERO_INSIDE] == 0.0 or ints[WEIGHTED] == 1 or ints[DIRECTION] == 0:
        return ELSEWHERE
    rows = Rows(joints[LB], joints[UB], task_rows[:0], reals[:0], reals[:0], reals[TOLERANCE],
                reals[SOLVED : SOLVED_STEPS + 1])  # fmt: skip
    # the direction flag, not the literal True: one compiled signature of stacked
    A, b, rate_factor = level(task_rows, rates, ints, 0, ints[DIRECTION] == 1, rows.lb, rows.ub)
    answer = top.direction_box(A, b, rows, reals[DT], reals[THRESHOLD], rate_factor)
    if answer.status == FAILED:
        return FAILED
    return report(joints, task_rows, rates, ints, reals, rows, answer, answer.qdot, A, b, True,
                  rate_factor)  # fmt: skip


@kernel
def run_twist(J: Array, b: Array, q: Array, dt: float, joints: Array, rates: Array, ints: Ints,
              reals: Array, out: Array) -> tuple[int, float, float, float, float]:  # fmt: skip
    """The default tick, ``solve(q, twist)``: what :func:`run_box` does, on the caller's arrays.

    One task's rows ``J`` (m, n) and commanded rates ``b`` (m,) at positions ``q`` (n,), the
    step ``dt`` [s], within the joint box alone; the task's weights and units are the loaded
    ones (``rates``, :meth:`Workspace.load_levels`), the previous rates ``joints[PREVIOUS]``.
    Writes ``out`` (:func:`twist_size`): the rates, the box's bounds, what sets each bound
    (lower, upper), then ``b`` and the box's flags (standing still allowed, recovering); and
    the rates into ``joints[PREVIOUS]``, the next tick's previous ones.

    Returns:
        ``(code, scale, veer, clip, lambda_sq)``: the status code and the report, or
        :data:`INVALID_INPUT` (a position, rate or row not finite), :data:`ELSEWHERE` (the box
        excludes standing still, or the mode is not the direction one: :func:`run` answers)
        or :data:`FAILED` (the fallbacks answer) and zeros.
    """
    n, m = q.size, b.size
    reals[SOLVED], reals[SOLVED_STEPS] = 0.0, 0.0
    if not (feasibility.all_finite(q) and feasibility.all_finite(b)
            and feasibility.all_finite(J.ravel())):  # fmt: skip
        return INVALID_INPUT, 0.0, 0.0, 0.0, 0.0
    lb, ub = out[n : 2 * n], out[2 * n : 3 * n]
    zero_inside, recovering = bounds(q, dt, joints, reals, lb, ub,
                                     out[3 * n : 5 * n].reshape(2, n))  # fmt: skip
    flags = 5 * n + m
    for i in range(m):
        out[5 * n + i] = b[i]
    out[flags] = 1.0 if zero_inside else 0.0
    out[flags + 1] = 1.0 if recovering else 0.0
    if not zero_inside or ints[WEIGHTED] == 1 or ints[DIRECTION] == 0:
        return ELSEWHERE, 0.0, 0.0, 0.0, 0.0
    rows = Rows(lb, ub, J[:0], reals[:0], reals[:0], reals[TOLERANCE],
                reals[SOLVED : SOLVED_STEPS + 1])  # fmt: skip
    A, c, rate_factor = stacked(J, b, rates[WEIGHT][:m], rates[UNIT][:m], ints[DIRECTION] == 1,
                                lb, ub)  # fmt: skip
    answer = top.direction_box(A, c, rows, dt, reals[THRESHOLD], rate_factor)
    if answer.status == FAILED:
        return FAILED, 0.0, 0.0, 0.0, 0.0
    qdot = answer.qdot
    clip, shrink = clipped(qdot, rows, zero_inside)
    status, scale, veer = statuses.borne_out(answer.status, row_values(A, qdot), c, True,
                                             rate_factor, answer.scale * shrink, answer.veer)
    if status == FAILED:
        return FAILED, 0.0, 0.0, 0.0, 0.0
    for j in range(n):
        out[j] = joints[PREVIOUS, j] = qdot[j]
    return status, scale, veer, clip, answer.lambda_sq


def twist_size(n: int, m: int) -> int:
    """The size of :func:`run_twist`'s ``out`` for n joints and m task rows."""
    return 5 * n + m + 2


def compile_stages(n: int = 6) -> None:
    """Compile the default tick's two longest stages, or load them from numba's cache: the
    direction problem along the least-norm rates (:func:`rrc_pin.solvers.tick.top.scaled_along`)
    and the damping (:func:`rrc_pin.solvers.tick.top.damping`), for arrays of the types
    :func:`run_box` passes them (C order, writable), on ``n`` joints.

    For a second process, while the first compiles :func:`run_box`: that compilation loads
    from the cache each stage cached by the time it reaches it (the first ``rrc-pin demo``,
    :func:`rrc_pin.demo.compiling_beside`).
    """  # noqa: D205
    A, w, lb, ub = np.eye(n), np.ones(n), -np.ones(n), np.ones(n)
    rows = Rows(lb, ub, np.zeros((0, n)), np.zeros(0), np.zeros(0), 1e-9, np.zeros(2))
    top.scaled_along(A, w, np.zeros((0, n)), rows)
    top.damping(factor.qr(A), w, w, 0.5, rows, 0.01, 100.0)


@kernel
def run(joints: Array, task_rows: Array, rates: Array, G: Array, h: Array, slide: Array,
        ints: Ints, reals: Array) -> int:  # fmt: skip
    """One tick: its status code, :data:`FAILED` (the fallbacks answer) or :data:`INVALID_INPUT`.

    Reads the sizes, flags and settings in ``ints`` and ``reals`` and the inputs' rows of
    ``joints``, ``task_rows``, ``rates`` and the constraint rows ``G``, ``h``, ``slide``
    (``ints[CONSTRAINTS]`` of them); writes the box, the rates and the report.
    """
    if not box(joints, task_rows, rates, ints, reals):
        return INVALID_INPUT
    p = ints[CONSTRAINTS]
    rows = Rows(joints[LB], joints[UB], G[:p], h[:p], slide[:p], reals[TOLERANCE],
                reals[SOLVED : SOLVED_STEPS + 1])  # fmt: skip
    zero_inside, recovering = reals[ZERO_INSIDE] == 1.0, reals[RECOVERING] == 1.0
    direction = (ints[WEIGHTED] == 0 and ints[DIRECTION] == 1 and zero_inside
                 and not (rows.h < 0.0).any())  # fmt: skip
    A, b, rate_factor = level(task_rows, rates, ints, 0, direction, rows.lb, rows.ub)
    answer = top_level(A, b, rate_factor, rates, ints, reals, rows, direction, recovering)
    if answer.status == FAILED:
        return FAILED
    qdot = lower_levels(task_rows, rates, ints, rows, answer)
    return report(joints, task_rows, rates, ints, reals, rows, answer, qdot, A, b, direction,
                  rate_factor)  # fmt: skip


@kernel
def run_within(joints: Array, task_rows: Array, rates: Array, G: Array, h: Array, slide: Array,
               E: Array, ints: Ints, reals: Array, top: Array) -> int:  # fmt: skip
    """One tick within the equality rows ``E`` = [C | d] (r, n + 1): :func:`run`'s stages, the
    top level's within the rows (:func:`rrc_pin.solvers.tick.equalities.within`), its rows in
    their metric kept in ``top`` (what a cell's closure keeps, :meth:`Workspace.stacked_top`).

    The direction mode where :func:`run` takes it and ``d`` is zero (standing still then
    meets the rows; :func:`rrc_pin.solvers.tick.problem.build`).
    """  # noqa: D205
    if not box(joints, task_rows, rates, ints, reals):
        return INVALID_INPUT
    p, n = ints[CONSTRAINTS], joints.shape[1]
    rows = Rows(joints[LB], joints[UB], G[:p], h[:p], slide[:p], reals[TOLERANCE],
                reals[SOLVED : SOLVED_STEPS + 1])  # fmt: skip
    zero_inside, recovering = reals[ZERO_INSIDE] == 1.0, reals[RECOVERING] == 1.0
    C, d = np.ascontiguousarray(E[:, :n]), np.ascontiguousarray(E[:, n])
    direction = (ints[WEIGHTED] == 0 and ints[DIRECTION] == 1 and zero_inside
                 and not (rows.h < 0.0).any() and not (d != 0.0).any())  # fmt: skip
    A, b, rate_factor = level(task_rows, rates, ints, 0, direction, rows.lb, rows.ub)
    top[: A.shape[0]] = A
    per_unit = 1.0 / rates[UNIT][: ints[STARTS + 1]] if ints[UNITS] else np.empty(0)
    answer = equalities.within(A, b, per_unit, C, d, rows, direction, recovering, reals[DT],
                               reals[THRESHOLD], rate_factor, ints[LEVELS] > 1)  # fmt: skip
    if answer.status == FAILED:
        return FAILED
    qdot = lower_levels(task_rows, rates, ints, rows, answer)
    return report(joints, task_rows, rates, ints, reals, rows, answer, qdot, A, b, direction,
                  rate_factor)  # fmt: skip


class Workspace:
    """The preallocated arrays of one resolver's ticks, and the compiled tick on them.

    Args:
        lower: Lower position limits (n,) [rad or m] of the step's box.
        upper: Upper position limits (n,).
        velocity: Velocity limits (n,) [rad/s or m/s].
        acceleration: Acceleration limits (n,) or (1,) [rad/s^2 or m/s^2], inf for none.
        margin: The box's margin from the position limits [rad or m].
        gain: Its position gain in (0, 1].
        threshold: The damping threshold, or 0 for no damping.
        direction: Whether the top level is the direction problem where standing still is
            allowed.
        tolerance: How far a kernel's answer may leave the box and rows before it is refused.
    """

    def __init__(self, lower: Array, upper: Array, velocity: Array, acceleration: Array,
                 margin: float, gain: float, threshold: float, direction: bool,
                 tolerance: float) -> None:  # fmt: skip
        n = lower.size
        self.n = n
        self.joints = np.zeros((JOINT_ROWS, n))
        self.joints[LOWER], self.joints[UPPER], self.joints[VELOCITY] = lower, upper, velocity
        self.joints[ACCELERATION] = np.broadcast_to(acceleration, (n,))
        self.reals = np.zeros(REAL_SIZE)
        self.reals[MARGIN], self.reals[GAIN], self.reals[THRESHOLD] = margin, gain, threshold
        self.reals[TOLERANCE] = tolerance
        self.ints: npt.NDArray[np.int64] = np.zeros(STARTS + 8, np.int64)
        self.ints[DIRECTION] = int(direction)
        self.task_rows, self.rates = np.zeros((6, n)), np.ones((3, 6))
        self.G, self.h, self.slide = np.zeros((0, n)), np.zeros(0), np.zeros(0)
        self.E = np.zeros((0, n + 1))  # the equality rows [C | d]: none
        self.top = np.zeros((6, n))  # a tick within them: its top level's rows in their metric
        self._held: dict[int, Held] = {}
        self._header: tuple[int, bool, bool, list[int]] | None = None  # what ints holds

    def load_levels(self, levels: Sequence[Sequence[TaskRows]], weighted: bool) -> None:
        """The tasks' rows and rates, by level (highest first).

        A task's rows, weights and units that are None or read-only arrays owning their
        values (constants: a joint-space task's identity rows, cached units and weights) are
        loaded once while the same arrays come at the same rows (``_held``); the sizes and
        flags in ``ints`` are written where they changed (``_header``).
        """
        held, task_rows, rates = self._held, self.task_rows, self.rates
        size, rate, r, starts = rates.shape[1], rates[RATE], 0, []
        for tasks in levels:
            starts.append(r)
            for A, b, weight, _, unit in tasks:
                end = r + b.size
                if end > size:  # no room: made, then every level loaded again
                    self._fit(sum(t.b.size for level in levels for t in level))
                    self.load_levels(levels, weighted)
                    return
                was = held.get(r)
                if was is None or was[0] != end:  # other rows here: every part loaded
                    self._overwrite(r, end)
                    was = held[r] = [end, _LOADED, _LOADED, _LOADED]
                if was[1] is not A:
                    task_rows[r:end] = A
                    was[1] = _constant(A)
                if was[2] is not weight:
                    rates[WEIGHT, r:end] = 1.0 if weight is None else weight
                    was[2] = _constant(weight)
                if was[3] is not unit:
                    rates[UNIT, r:end] = 1.0 if unit is None else unit
                    was[3] = _constant(unit)
                rate[r:end] = b
                r = end
        units = False
        for t in levels[0]:
            units = units or t.unit is not None
        header = (r, weighted, units, starts)
        if header != self._header:
            self._write_header(header)

    def _write_header(self, header: tuple[int, bool, bool, list[int]]) -> None:
        """The sizes and flags of the levels loaded into ``ints`` (:meth:`load_levels`)."""
        m, weighted, units, starts = header
        k = len(starts)
        if self.ints.size < STARTS + 2 * k + 2:
            self.ints = np.concatenate([self.ints, np.zeros(2 * k + 2, np.int64)])
        ints = self.ints
        ints[STARTS : STARTS + k] = starts
        ints[STARTS + k] = m
        ints[LEVELS], ints[ROWS], ints[WEIGHTED], ints[UNITS] = k, m, weighted, units
        self._header = header

    def _fit(self, m: int) -> None:
        """Room for ``m`` task rows."""
        self.task_rows, self.rates = np.zeros((m, self.n)), np.ones((3, m))
        self.top = np.zeros((m, self.n))
        self._held.clear()

    def _overwrite(self, start: int, end: int) -> None:
        """Forget what ``_held`` says rows ``start:end`` hold (they are being written)."""
        held = self._held
        if held:
            for s in [s for s, was in held.items() if s < end and start < was[0]]:
                del held[s]

    def forget(self) -> None:
        """Forget what the arrays hold: another compiled call writes them (a cell's rows,
        :func:`rrc_pin.cells.cell_kernels.cell_rows`), so the next :meth:`load_levels` loads
        every part and writes the sizes and flags.
        """  # noqa: D205
        self._held.clear()
        self._header = None

    def load_twist(self, J: Array, selected: tuple[int, ...], b: Array) -> None:
        """One task's rows ``J`` (6, n) (the ``selected`` ones) and rates ``b``, over those
        loaded last (:meth:`load_levels`: the same task, whose weights and units stay).
        """  # noqa: D205
        m = b.size
        self.task_rows[:m] = J if m == 6 else J[list(selected)]
        self.rates[RATE, :m] = b
        self._overwrite(0, m)

    def load_rows(
        self, G: Array | None, h: Array | None, slide: npt.NDArray[np.bool_] | None
    ) -> None:
        """The constraint rows ``G qdot <= h`` (None: none) and which the command may slide
        along (None: none).
        """  # noqa: D205
        if h is None or G is None:
            self.ints[CONSTRAINTS] = 0
            return
        p = h.size
        if p > self.h.size:
            self.G, self.h, self.slide = np.zeros((p, self.n)), np.zeros(p), np.zeros(p)
        self.G[:p], self.h[:p] = G, h
        self.slide[:p] = 0.0 if slide is None else slide
        self.ints[CONSTRAINTS] = p

    def load_equalities(self, C: Array | None, d: Array | None) -> None:
        """The equality rows ``C qdot = d`` (r, n) of the next ticks (None: none).

        :meth:`run` answers with them by :func:`run_within`.
        """
        if C is None or d is None:
            if self.E.shape[0]:
                self.E = np.zeros((0, self.n + 1))
            return
        r = d.size
        if self.E.shape[0] != r:
            self.E = np.empty((r, self.n + 1))
        self.E[:, : self.n], self.E[:, self.n] = C, d

    def run(self, q: Array, previous: Array, dt: float) -> int:
        """The tick at positions ``q`` (n,) after rates ``previous`` (n,), step ``dt`` [s].

        One level without rows in the direction mode goes to :func:`run_box`, and to
        :func:`run` only where that is not its tick.
        """
        self.joints[POSITION], self.joints[PREVIOUS] = q, previous
        self.reals[DT] = dt
        if self.E.shape[0]:
            within: int = run_within(self.joints, self.task_rows, self.rates, self.G,
                                     self.h, self.slide, self.E, self.ints, self.reals,
                                     self.top)  # fmt: skip
            return within
        ints = self.ints
        if ints[LEVELS] == 1 and ints[CONSTRAINTS] == 0 and ints[DIRECTION] and not ints[WEIGHTED]:
            code: int = run_box(self.joints, self.task_rows, self.rates, self.ints, self.reals)
            if code != ELSEWHERE:
                return code
        return run(self.joints, self.task_rows, self.rates, self.G, self.h, self.slide,
                   self.ints, self.reals)  # fmt: skip

    def compile(self, general: bool, twists: bool = True) -> None:
        """Compile the default tick's entries (:func:`run_box`; :func:`run_twist` where
        ``twists``), and the general ones where ``general`` (with the pipeline's shrink into
        the rows, :func:`feasibility.into_rows`), or load them from numba's cache: on a problem
        without rows whose answer is exact, so that no QP is asked for and nothing is kept.
        """  # noqa: D205
        n = self.n
        ws = self._scratch()
        one = TaskRows(np.eye(1, n), np.zeros(1), None, "", np.ones(1))
        ws.load_levels([[one]], False)
        ws.load_rows(None, None, None)
        ws.joints[POSITION] = np.clip(np.zeros(n), self.joints[LOWER], self.joints[UPPER])
        ws.reals[DT] = 0.01
        run_box(ws.joints, ws.task_rows, ws.rates, ws.ints, ws.reals)
        if twists:
            run_twist(np.eye(1, n), np.zeros(1), ws.joints[POSITION].copy(), 0.01, ws.joints,
                      ws.rates, ws.ints, ws.reals, np.empty(twist_size(n, 1)))  # fmt: skip
        if general:
            run(ws.joints, ws.task_rows, ws.rates, ws.G, ws.h, ws.slide, ws.ints, ws.reals)
            feasibility.into_rows(np.zeros((1, n)), np.zeros(1), np.zeros(n))  # the pipeline's call
            if n > 1:  # a tick within equality rows (contacts, grips): the rates of joint 1 zero
                ws.load_equalities(np.eye(1, n, 1), np.zeros(1))
                run_within(ws.joints, ws.task_rows, ws.rates, ws.G, ws.h, ws.slide, ws.E,
                           ws.ints, ws.reals, ws.top)  # fmt: skip

    def compile_hand_overs(self) -> None:
        """Run :func:`run` and :func:`run_within` once each on a problem whose lower level's QP
        goes to the backend (one row beyond the box on the rates the top level leaves free, a
        semidefinite metric), and whose sliding stage's does (within the equality row).

        numba compiles an entry's hand-over of a QP to Python (``objmode``,
        :func:`rrc_pin.solvers.tick.levels.backend_level`) at its first run, not from its cache:
        50-60 ms, which would stall the first tick of a session that needs the backend. The
        caller has handed this thread's QPs to a backend (:func:`backend_calls.enter`).
        """  # noqa: D205
        n = self.n
        if n < 3:  # no semidefinite lower level
            return
        ws = self._scratch()
        top = TaskRows(np.eye(1, n), np.full(1, 1.0), None, "", np.ones(1))
        beyond = TaskRows(np.eye(1, n, 1), np.full(1, 1e3), None, "", None)
        ws.load_levels([[top], [beyond]], False)
        ws.load_rows(np.eye(1, n), np.full(1, 1e-3), np.ones(1, dtype=np.bool_))
        ws.joints[POSITION] = np.clip(np.zeros(n), self.joints[LOWER], self.joints[UPPER])
        ws.reals[DT] = 0.01
        run(ws.joints, ws.task_rows, ws.rates, ws.G, ws.h, ws.slide, ws.ints, ws.reals)
        if n < 4:  # within one equality row, no semidefinite lower level
            return
        ws.load_equalities(np.eye(1, n, n - 1), np.zeros(1))
        run_within(ws.joints, ws.task_rows, ws.rates, ws.G, ws.h, ws.slide, ws.E, ws.ints,
                   ws.reals, ws.top)  # fmt: skip

    def _scratch(self) -> Workspace:
        """A workspace of the same joints for a compiling run, its margin, damping and gains
        neutral (:meth:`compile`, :meth:`compile_hand_overs`)."""  # noqa: D205, D209
        return Workspace(self.joints[LOWER], self.joints[UPPER], self.joints[VELOCITY],
                         self.joints[ACCELERATION], 0.0, 1.0, 0.0, True, 1.0)  # fmt: skip

    def stacked_top(self) -> Array | None:
        """The top level's rows in their metric (m, n) of the tick just run within equality rows
        (a copy), or None for a tick without them.
        """  # noqa: D205
        if not self.E.shape[0]:
            return None
        rows: Array = self.top[: self.ints.item(STARTS + 1)].copy()
        return rows

    def level_codes(self) -> list[int]:
        """How each level was served (the codes of :mod:`rrc_pin.solvers.tick.statuses`)."""
        ints = self.ints
        levels = ints.item(LEVELS)
        if levels == 1:
            return [ints.item(STARTS + 2)]
        codes: list[int] = ints[STARTS + levels + 1 : STARTS + 2 * levels + 1].tolist()
        return codes
