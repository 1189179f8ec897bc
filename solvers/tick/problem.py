r"""The problem of one tick, built apart from solving it.

Tasks give rows :math:`A\dot q \approx b` (:class:`TaskRows`), grouped in priority levels;
limits give :class:`Constraints`: a box :math:`lb \le \dot q \le ub` (:class:`Box`),
inequality rows :math:`G\dot q \le h` and equality rows :math:`C\dot q = d`, each row named.
:func:`build` merges the constraints (the boxes intersected, the rows stacked) and decides
how the levels are solved (:data:`Mode`):

- ``direction`` (the default's top level): :math:`\max s \in [0, 1]` with
  :math:`A\dot q = s\,b` within the constraints, the lower levels each exact within the optimal
  set of those above;
- ``least_squares``: every level a least-squares problem in the optimal set of those above
  (the tracking mode, and where standing still breaks a constraint, so that no scale of the
  command is feasible: a joint outside its range, a row with h < 0);
- ``weighted``: one level, its tasks traded by their weights.

Every level's stacked rows are made safe for the numerics here, once. Each level's weights are
divided by their largest (the optimum does not change). A least-squares level whose rates
exceed :data:`SATURATION` times what its rows can reach within the box
(``1 + max|A| sum_j max(|lb_j|, |ub_j|)``, the box's finite sides) is divided down to that
along its direction: its optimum is then saturated against the box, and a longer command no
longer changes it (capped at 1e100 instead, a tracking QP of panda hung proxqp for minutes:
gradient 1e99 against a box of 2 rad/s). A direction level's rates beyond :data:`LARGE` are
divided down the same way (to at most :data:`LARGE`): the direction problem's answer is then
the largest scale along the command that the box allows, as for any command beyond reach.
The factor each level's rates were multiplied by is kept (``Problem.factors``): an answer
that meets a divided command is a scale of the command, never the command itself.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from typing import Literal, NamedTuple

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers import linalg
from rrc_pin.solvers.checks import all_finite
from rrc_pin.solvers.compiled import kernel
from rrc_pin.solvers.errors import InvalidInput

Array = npt.NDArray[np.float64]

Mode = Literal["direction", "least_squares", "weighted"]

LARGE = 1e100
"""[task units] A direction level's rates beyond this are divided down to its reach (module
docstring), and never left above it: their squares stay far from overflow (1e308)."""

SATURATION = 1e6
"""A least-squares level's rates beyond this many times its reach within the box are divided
down to it (module docstring)."""


class TaskRows(NamedTuple):
    """The rows one task adds: ``A qdot ~= b``.

    Attributes:
        A: Jacobian rows (m, n).
        b: Desired rates (m,) [m/s, rad/s or rad/s].
        weight: Row weights (m,) > 0 (costs), or None for 1.
        name: The task's name, for the report.
        unit: Each row's unit (m,): the rows are divided by it to compare metres and radians
            (the arm's reach [m] for linear velocity rows, 1 for angular and joint rows), or
            None for 1.
    """

    A: Array
    b: Array
    weight: Array | None
    name: str
    unit: Array | None = None


class Box(NamedTuple):
    """Joint-rate bounds of one step, ``lb <= qdot <= ub``, and what sets each.

    Attributes:
        lb: Lower bounds (n,) [rad/s or m/s].
        ub: Upper bounds (n,), ``lb <= ub``.
        kind: (2, n) codes of what sets each bound (lower, upper):
            :data:`~rrc_pin.solvers.tick.joint_box.VELOCITY`, ``POSITION`` or ``ACCELERATION``.
        contains_zero: Whether standing still is allowed.
        recovering: Whether a joint is outside its range and must move back.
        velocity: The velocity limits (n,), the scale of the backends' tolerance.
    """

    lb: Array
    ub: Array
    kind: npt.NDArray[np.int8]
    contains_zero: bool
    recovering: bool
    velocity: Array

    def clip(self, qdot: Array | float) -> Array:
        """The rates (n,) nearest ``qdot`` inside the box (a scalar is every joint's rate)."""
        clipped: Array = np.minimum(np.maximum(qdot, self.lb), self.ub)
        return clipped


class Constraints(NamedTuple):
    """What one limit contributes to a tick: a box, inequality rows, equality rows.

    Attributes:
        box: Joint-rate bounds, or None.
        G: Inequality rows (p, n), ``G qdot <= h``, or None.
        h: Their bounds (p,) [the rows' units]; h >= 0 where standing still is allowed.
        C: Equality rows (r, n), ``C qdot = d``, or None.
        d: Their rates (r,).
        names: One name per row of G, then of C, for the report.
        slide: Per row of G (p,), whether the top level's command may slide along it (a
            collision pair: the command loses its component into the row, not its speed along
            the rest; :mod:`rrc_pin.solvers.tick.pipeline`), or None for none.
        distance: Per row of G (p,), the distance [m] the row keeps (a collision pair's signed
            distance, reported with the active rows), NaN where none, or None.
    """

    box: Box | None = None
    G: Array | None = None
    h: Array | None = None
    C: Array | None = None
    d: Array | None = None
    names: tuple[str, ...] = ()
    slide: npt.NDArray[np.bool_] | None = None
    distance: Array | None = None


class Rows(NamedTuple):
    """Constraint rows ``G qdot <= h`` of a problem, named.

    Attributes:
        G: Rows (p, n).
        h: Bounds (p,).
        names: One name per row.
        slide: Mask (p,) of the rows the top level's command may slide along, or None (none).
        distance: The distance [m] each row keeps (NaN where none), or None.
    """

    G: Array
    h: Array
    names: tuple[str, ...]
    slide: npt.NDArray[np.bool_] | None = None
    distance: Array | None = None

    @property
    def sliding(self) -> Rows | None:
        """The rows the command may slide along, or None."""
        if self.slide is None or not self.slide.any():
            return None
        keep = self.slide
        if keep.all():  # a collision limit's rows all slide: no copy, no names rebuilt
            return Rows(self.G, self.h, self.names)
        names = tuple(n for n, k in zip(self.names, keep.tolist(), strict=True) if k)
        return Rows(self.G[keep], self.h[keep], names)


class Problem(NamedTuple):
    """One tick's problem, ready for the numerics (module docstring).

    Attributes:
        levels: The task rows by priority level, highest first.
        stacked: Per level, its rows and rates stacked ``(A, b)`` in the metric it is solved
            in (row-weighted; the direction level also divided by the rows' units).
        factors: Per level, the factor its stacked rates were multiplied by (1 unless they
            were divided down, module docstring): a level's scale of its command is that of
            ``b`` times it.
        box: The intersected joint-rate bounds.
        rows: The inequality rows, or None.
        equalities: The equality rows ``(C, d)``, or None.
        equality_names: Names of the equality rows.
        mode: How the levels are solved.
        dt: The step [s].
    """

    levels: tuple[tuple[TaskRows, ...], ...]
    stacked: tuple[tuple[Array, Array], ...]
    factors: tuple[float, ...]
    box: Box
    rows: Rows | None
    equalities: tuple[Array, Array] | None
    equality_names: tuple[str, ...]
    mode: Mode
    dt: float

    @property
    def n(self) -> int:
        """Number of joint rates."""
        return self.box.lb.size

    @property
    def rate_factor(self) -> float:
        """The factor the top level's stacked rates were multiplied by (``factors[0]``)."""
        return self.factors[0] if self.factors else 1.0


def build(
    levels: Sequence[Sequence[TaskRows]],
    constraints: Sequence[Constraints],
    n: int,
    dt: float,
    *,
    weighted: bool = False,
    direction: bool = True,
) -> Problem:
    """The problem of ``levels`` within ``constraints`` (module docstring).

    Args:
        levels: Task rows per priority level, highest first (one level when ``weighted``).
        constraints: What each limit contributes.
        n: Number of joint rates.
        dt: The step [s].
        weighted: One level whose tasks trade off by their weights.
        direction: The top level as the direction problem where standing still is allowed.

    Returns:
        The :class:`Problem`.
    """
    box = _box(constraints, n)
    rows = merged_rows(constraints)
    equalities, equality_names = _equalities(constraints)
    mode = mode_of(box, rows, equalities is not None and bool(equalities[1].any()), weighted,
                   direction)  # fmt: skip
    stacked, factors = [], []
    for k, level in enumerate(levels):
        A, b, factor = _stack(level, k == 0 and mode == "direction", box)
        stacked.append((A, b))
        factors.append(factor)
    kept = tuple(map(tuple, levels))
    return Problem(kept, tuple(stacked), tuple(factors), box, rows, equalities, equality_names,
                   mode, dt)  # fmt: skip


def mode_of(box: Box, rows: Rows | None, keeps: bool, weighted: bool, direction: bool
            ) -> Mode:  # fmt: skip
    """How the levels of a problem with ``box`` and ``rows`` are solved, ``keeps`` where its
    equality rows have rates to keep (d not zero) (:func:`build`'s arguments ``weighted`` and
    ``direction``; module docstring).
    """  # noqa: D205
    if weighted:
        return "weighted"
    if direction and box.contains_zero and (rows is None or bool((rows.h >= 0.0).all())):
        # rates to keep: no scale of the command stands still
        return "least_squares" if keeps else "direction"
    return "least_squares"


def _stack(tasks: Sequence[TaskRows], normalised: bool, box: Box) -> tuple[Array, Array, float]:
    """Rows and rates of ``tasks`` stacked in the level's metric, and the rates' factor.

    Each row times the square root of its weight over the level's largest (and in the
    normalised metric divided by its unit, :func:`rrc_pin.solvers.linalg.weighted_rows`); the
    rates
    capped as the module docstring says (:func:`_capped`).
    """
    top = largest_weight(tasks)
    if _as_they_are(tasks, top, normalised):
        A, b = tasks[0].A, tasks[0].b
        peak = float(np.abs(b).max()) if b.size else 0.0
        return _capped(A, b, peak, normalised, box)
    A, b = _level_arrays(tasks)
    peak = _weighted(tasks, top, normalised, 1.0, A, b)
    if normalised and peak > LARGE:  # the direction first: b / its largest, before the
        # rows' factors (up to 1 / MIN_REACH) could overflow
        scale = 1.0 / max(float(np.abs(t.b).max(initial=0.0)) for t in tasks)
        return _capped(A, b, _weighted(tasks, top, normalised, scale, A, b), normalised, box,
                       scale)  # fmt: skip
    return _capped(A, b, peak, normalised, box)


def stacked_rows(tasks: Sequence[TaskRows], normalised: bool) -> Array:
    """A level's rows stacked in its metric: :func:`build`'s ``stacked`` rows, without their
    rates (whose factor and cap leave the rows as they are; ``normalised``: the direction
    mode's top level).
    """  # noqa: D205
    top = largest_weight(tasks)
    if _as_they_are(tasks, top, normalised):
        return tasks[0].A
    A, b = _level_arrays(tasks)
    _weighted(tasks, top, normalised, 1.0, A, b)
    return A


def _as_they_are(tasks: Sequence[TaskRows], top: float, normalised: bool) -> bool:
    """Whether a level's rows in its metric are its one task's own (no weight, no unit)."""
    return len(tasks) == 1 and top == 1.0 and tasks[0].weight is None and (
        not normalised or tasks[0].unit is None)  # fmt: skip


def _level_arrays(tasks: Sequence[TaskRows]) -> tuple[Array, Array]:
    """Empty rows (m, n) and rates (m,) for a level of ``tasks``."""
    m = tasks[0].b.size if len(tasks) == 1 else sum(t.b.size for t in tasks)
    return np.empty((m, tasks[0].A.shape[1])), np.empty(m)


def _weighted(
    tasks: Sequence[TaskRows], top: float, normalised: bool, scale: float, A: Array, b: Array
) -> float:
    """Fill ``A``, ``b`` with the tasks' rows in the level's metric, the rates times ``scale``.

    Returns:
        The rates' largest magnitude.
    """
    peak, r = 0.0, 0
    for t in tasks:
        k = t.b.size
        weight = _ones(k) if t.weight is None else _read_only(t.weight)
        unit = _read_only(t.unit) if normalised and t.unit is not None else _ones(k)
        rows_A, rows_b = (A, b) if k == b.size else (A[r : r + k], b[r : r + k])  # one task: all
        rows = linalg.weighted_rows(_read_only(t.A), _read_only(t.b), weight, top, unit, scale,
                                     rows_A, rows_b)  # fmt: skip
        peak, r = max(peak, rows), r + k
    return peak


def _capped(
    A: Array, b: Array, peak: float, normalised: bool, box: Box, factor: float = 1.0
) -> tuple[Array, Array, float]:
    """``(A, b, factor)``: b as :func:`_stack` gives it (capped by :func:`cap`), and its factor."""
    c = cap(A, peak, factor, normalised, box.lb, box.ub)
    return (A, b, factor) if c == 1.0 else (A, b * c, factor * c)


@kernel
def cap(A: Array, peak: float, factor: float, normalised: bool, lb: Array, ub: Array) -> float:
    """What a level's rates are multiplied by to cap a huge command (module docstring; 1: kept).

    Args:
        A: The level's stacked rows (m, n).
        peak: Its rates' largest magnitude, the command's times ``factor``.
        factor: What the command's rates were already multiplied by (> 0).
        normalised: The direction level (capped beyond :data:`LARGE`), else a least-squares
            one (beyond :data:`SATURATION`).
        lb: The step's lower bounds (n,), whose finite sides give the rows' reach.
        ub: Its upper bounds (n,).
    """
    command = peak / factor  # the command's own magnitude (inf beyond the float range)
    if command <= (LARGE if normalised else SATURATION):
        return 1.0
    m, n = A.shape
    sides = 0.0
    for j in range(n):
        side = max(-lb[j], ub[j])
        if math.isfinite(side):
            sides += side
    largest = 0.0
    for i in range(m):
        for j in range(n):
            largest = max(largest, abs(A[i, j]))
    limit = SATURATION * (1.0 + largest * sides)
    if normalised:
        limit = min(limit, LARGE)
    return 1.0 if command <= limit else limit / peak


def _read_only(a: Array) -> Array:
    """``a``, or a read-only view of it.

    The rows' kernel then has one signature whichever arrays a task gives (its constant rows
    read-only, its rates not), so that no tick compiles another.
    """
    if not a.flags.writeable:
        return a
    view: Array = a.view()
    view.flags.writeable = False
    return view


@functools.cache
def _ones(m: int) -> Array:
    """A read-only (m,) array of ones, made once per size."""
    ones = np.ones(m)
    ones.flags.writeable = False
    return ones


def finite_rows(levels: Sequence[Sequence[TaskRows]]) -> None:
    """Refuse a task whose rows are not finite (a user's task, or a command that overflowed).

    Raises:
        InvalidInput: Naming ``command`` and the task.
    """
    for level in levels:
        for t in level:
            if not (all_finite(t.b) and all_finite(t.A)):
                raise InvalidInput("command", f"task {t.name!r} gave rows that are not finite")


def largest_weight(tasks: Sequence[TaskRows]) -> float:
    """The largest row weight of ``tasks`` (1 for a task without weights)."""
    if len(tasks) == 1 and tasks[0].weight is None:
        return 1.0
    return max(1.0 if t.weight is None else float(np.max(t.weight)) for t in tasks)


def row_factors(t: TaskRows, top: float, units: bool) -> Array | None:
    """Factors (m,) of a task's rows in its level's metric, or None for all ones.

    The square root of each row's weight divided by the level's largest (``top``), and with
    ``units`` divided by the row's unit: the normalised metric, where metres and radians weigh
    alike.
    """
    factor = None if t.weight is None and top == 1.0 else np.sqrt(
        (np.ones(t.b.size) if t.weight is None else t.weight) / top)  # fmt: skip
    if units and t.unit is not None:
        factor = 1.0 / t.unit if factor is None else factor / t.unit
    return factor


def _box(constraints: Sequence[Constraints], n: int) -> Box:
    """The boxes intersected; where two are disjoint the first one's bound wins."""
    if len(constraints) == 1 and constraints[0].box is not None:
        return constraints[0].box
    boxes = [c.box for c in constraints if c.box is not None]
    if not boxes:
        free = np.full(n, math.inf)
        return Box(-free, free.copy(), np.zeros((2, n), np.int8), True, False, free.copy())
    box = boxes[0]
    for other in boxes[1:]:
        lb = np.minimum(np.maximum(box.lb, other.lb), box.ub)
        ub = np.maximum(np.minimum(box.ub, other.ub), lb)
        zero = bool((lb <= 0.0).all() and (ub >= 0.0).all())
        box = Box(lb, ub, box.kind, zero, box.recovering or other.recovering,
                  np.minimum(box.velocity, other.velocity))  # fmt: skip
    return box


def merged_rows(constraints: Sequence[Constraints]) -> Rows | None:
    """The constraints' rows stacked, named, with their slide masks and distances, or None."""
    Gs: list[Array] = []
    hs: list[Array] = []
    names: list[str] = []
    slides: list[npt.NDArray[np.bool_]] = []
    distances: list[Array] = []
    for c in constraints:
        if c.G is not None and c.h is not None and c.h.size:
            Gs.append(c.G)
            hs.append(c.h)
            names += c.names[: c.h.size]
            slides.append(np.zeros(c.h.size, bool) if c.slide is None else c.slide)
            distances.append(np.full(c.h.size, np.nan) if c.distance is None else c.distance)
    if not hs:
        return None
    if len(hs) == 1:
        c = next(c for c in constraints if c.h is not None and c.h.size)
        return Rows(Gs[0], hs[0], tuple(names), c.slide, c.distance)
    slide = np.concatenate(slides)
    distance = np.concatenate(distances)
    return Rows(np.vstack(Gs), np.concatenate(hs), tuple(names),
                slide if slide.any() else None,
                None if np.isnan(distance).all() else distance)  # fmt: skip


def merged_equalities(constraints: Sequence[Constraints]) -> tuple[Array, Array] | None:
    """The constraints' equality rows stacked, ``(C, d)``, or None."""
    return _equalities(constraints)[0]


def _equalities(
    constraints: Sequence[Constraints],
) -> tuple[tuple[Array, Array] | None, tuple[str, ...]]:
    Cs: list[Array] = []
    ds: list[Array] = []
    names: list[str] = []
    for c in constraints:
        if c.C is not None and c.d is not None and c.d.size:
            Cs.append(c.C)
            ds.append(c.d)
            skip = 0 if c.h is None else c.h.size
            names += c.names[skip : skip + c.d.size]
    if not ds:
        return None, ()
    return (np.vstack(Cs), np.concatenate(ds)), tuple(names)
