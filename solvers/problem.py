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

Every level's stacked rows are made safe for the numerics here, once: in the least-squares
modes each level's weights are divided by their largest (the optimum does not change), and a
level whose weighted rates exceed :data:`LARGE` is divided down to it along its direction
(the limits set the answer long before: it stays the optimum to rounding); the direction
problem depends on the command's direction only, so a command is divided by its largest
entry where it exceeds :data:`LARGE`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Literal, NamedTuple

import numpy as np
import numpy.typing as npt

Array = npt.NDArray[np.float64]

Mode = Literal["direction", "least_squares", "weighted"]

LARGE = 1e100
"""[task units] Weighted rates beyond this are divided down to it (module docstring): their
squares stay far from overflow (1e308)."""


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
            :data:`~solvers.kernels.VELOCITY`, ``POSITION`` or ``ACCELERATION``.
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


class Constraints(NamedTuple):
    """What one limit contributes to a tick: a box, inequality rows, equality rows.

    Attributes:
        box: Joint-rate bounds, or None.
        G: Inequality rows (p, n), ``G qdot <= h``, or None.
        h: Their bounds (p,) [the rows' units]; h >= 0 where standing still is allowed.
        C: Equality rows (r, n), ``C qdot = d``, or None.
        d: Their rates (r,).
        names: One name per row of G, then of C, for the report.
    """

    box: Box | None = None
    G: Array | None = None
    h: Array | None = None
    C: Array | None = None
    d: Array | None = None
    names: tuple[str, ...] = ()


class Rows(NamedTuple):
    """Constraint rows ``G qdot <= h`` of a problem, named."""

    G: Array
    h: Array
    names: tuple[str, ...]


class Problem(NamedTuple):
    """One tick's problem, ready for the numerics (module docstring).

    Attributes:
        levels: The task rows by priority level, highest first.
        stacked: Per level, its rows and rates stacked ``(A, b)`` in the metric it is solved
            in (row-weighted; the direction level also divided by the rows' units).
        rate_factor: The factor the top level's stacked rates were multiplied by (1 unless
            they exceeded :data:`LARGE`): its scale of the command is that of ``b`` times it.
        box: The intersected joint-rate bounds.
        rows: The inequality rows, or None.
        equalities: The equality rows ``(C, d)``, or None.
        equality_names: Names of the equality rows.
        mode: How the levels are solved.
        dt: The step [s].
    """

    levels: tuple[tuple[TaskRows, ...], ...]
    stacked: tuple[tuple[Array, Array], ...]
    rate_factor: float
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
    rows = _rows(constraints)
    equalities, equality_names = _equalities(constraints)
    if weighted:
        mode: Mode = "weighted"
    elif direction and box.contains_zero and (rows is None or bool((rows.h >= 0.0).all())):
        mode = "direction"
        if equalities is not None and bool(equalities[1].any()):
            mode = "least_squares"  # rates to keep: no scale of the command stands still
    else:
        mode = "least_squares"
    kept = tuple(tuple(level) for level in levels)
    stacks = [_stack(level, normalised=(k == 0 and mode == "direction"))
              for k, level in enumerate(kept)]  # fmt: skip
    stacked = tuple((A, b) for A, b, _ in stacks)
    return Problem(kept, stacked, stacks[0][2], box, rows, equalities, equality_names, mode, dt)


def _stack(tasks: Sequence[TaskRows], normalised: bool) -> tuple[Array, Array, float]:
    """Rows and rates of ``tasks`` stacked in the level's metric, and the rates' factor.

    Each row times :func:`row_factors` (the direction level's with the rows' units); the
    direction level's rates divided by their largest entry beyond :data:`LARGE`, a
    least-squares level's divided down to :data:`LARGE`.
    """
    top = largest_weight(tasks)
    As, bs = [], []
    for t in tasks:
        factor = row_factors(t, top, normalised)
        As.append(t.A if factor is None else t.A * factor[:, None])
        bs.append(t.b if factor is None else t.b * factor)
    A = As[0] if len(As) == 1 else np.vstack(As)
    b = bs[0] if len(bs) == 1 else np.concatenate(bs)
    peak = float(np.abs(b).max()) if b.size else 0.0
    if peak <= LARGE:
        return A, b, 1.0
    rate_factor = 1.0 / peak if normalised else LARGE / peak
    return A, b * rate_factor, rate_factor


def largest_weight(tasks: Sequence[TaskRows]) -> float:
    """The largest row weight of ``tasks`` (1 for a task without weights)."""
    return max(1.0 if t.weight is None else float(t.weight.max()) for t in tasks)


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


def _rows(constraints: Sequence[Constraints]) -> Rows | None:
    Gs: list[Array] = []
    hs: list[Array] = []
    names: list[str] = []
    for c in constraints:
        if c.G is not None and c.h is not None and c.h.size:
            Gs.append(c.G)
            hs.append(c.h)
            names += c.names[: c.h.size]
    if not hs:
        return None
    return Rows(np.vstack(Gs), np.concatenate(hs), tuple(names))


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
