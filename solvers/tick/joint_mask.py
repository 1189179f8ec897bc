r"""A tick with some joints held still: the problem on the free joints' columns alone.

A joint mask holds some rates at exactly zero. Every task's rows and every limit's rows lose
those columns (:math:`A_{:,F}`, :math:`G_{:,F}`, :math:`C_{:,F}` for the free set F) and the
box its entries, so that the free rates solve the problem a model without the masked joints
would give (a reduced model, the masked joints locked where they are):

.. math::

    A\dot q = A_{:,F}\,\dot q_F \quad\text{when}\quad \dot q_{\bar F} = 0 .

:func:`free_columns` makes that problem's parts; :func:`scattered` writes the answer's problem
back over every joint (zero columns and a zero box for the masked ones), the problem a
resolution reports on.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.tick.joint_box import VELOCITY
from rrc_pin.solvers.tick.problem import Box, Constraints, Problem, TaskRows

Array = npt.NDArray[np.float64]
Index = npt.NDArray[np.intp]

STILL = 1e-9
"""[the row's units per rad/s] An inequality row whose free joints' entries are all within
this, and whose masked joints' are not, leaves the problem (:func:`free_columns`)."""


def free_columns(
    levels: Sequence[Sequence[TaskRows]], joint_rows: Sequence[Sequence[bool]],
    constraints: Sequence[Constraints], free: Index,
) -> tuple[list[list[TaskRows]], list[Constraints]]:  # fmt: skip
    """The tasks' rows and the limits' constraints on the columns ``free`` alone.

    Args:
        levels: Task rows per priority level, over every joint (n columns).
        joint_rows: Per task of ``levels``, whether its rows are joints' own rates (rows of
            the identity: a joint, posture, damping or rates task).
        constraints: What each limit contributes, over every joint.
        free: Indices of the joints that may move (ascending).

    Returns:
        ``(levels, constraints)`` over ``free.size`` columns, less the masked joints' own
        rows of joint-space tasks (:func:`_free_rows`) and the inequality rows only masked
        joints move (:func:`_free_constraints`).
    """
    rows = [[_free_rows(t, free) if joint else t._replace(A=t.A[:, free])
             for t, joint in zip(level, flags, strict=True)]
            for level, flags in zip(levels, joint_rows, strict=True)]  # fmt: skip
    kept = [_free_constraints(c, free) for c in constraints]
    return rows, kept


def _free_constraints(c: Constraints, free: Index) -> Constraints:
    """The constraints ``c`` on the columns ``free``, without the inequality rows that only
    masked joints move (beyond :data:`STILL`).

    Such a row bounds what no free joint can change: a limit gives none for a pair no joint
    moves (:class:`~rrc_pin.limits.CollisionLimit`), and the reduced model gives none.
    Equality rows are all kept.
    """  # noqa: D205
    box = None if c.box is None else _free_box(c.box, free)
    C = None if c.C is None else c.C[:, free]
    if c.G is None or c.h is None:
        return c._replace(box=box, C=C)
    G = c.G[:, free]
    moved = np.abs(G).max(axis=1, initial=0.0) > STILL
    kept = moved | ~(np.abs(c.G).max(axis=1, initial=0.0) > STILL)
    if kept.all():
        return c._replace(box=box, G=G, C=C)
    p = c.h.size
    names = tuple(n for n, k in zip(c.names[:p], kept.tolist(), strict=True) if k)
    return Constraints(box, G[kept], c.h[kept], C, c.d, names + tuple(c.names[p:]),
                       None if c.slide is None else c.slide[kept],
                       None if c.distance is None else c.distance[kept])  # fmt: skip


def _free_rows(t: TaskRows, free: Index) -> TaskRows:
    """The joint-space rows of ``t`` on the columns ``free``, without the masked joints' own.

    A model without the masked joints has no row for them; any other task (a frame's) keeps
    every row, a direction only masked joints move then a zero row, as in that model (its
    command unmet, and reported so).
    """
    A = t.A[:, free]
    kept = (A != 0.0).any(axis=1) | ~(t.A != 0.0).any(axis=1)
    if kept.all():
        return t._replace(A=A)
    return TaskRows(A[kept], t.b[kept], None if t.weight is None else t.weight[kept], t.name,
                    None if t.unit is None else t.unit[kept])  # fmt: skip


def _free_box(box: Box, free: Index) -> Box:
    """The bounds of the joints ``free``.

    Standing still is allowed when it is for each of them; a joint out of its range (the box
    ``recovering``) counts where a free joint's bounds exclude zero (a masked joint out of
    range does not move: nothing is recovered).
    """
    lb, ub = box.lb[free], box.ub[free]
    zero = bool((lb <= 0.0).all() and (ub >= 0.0).all())
    return Box(lb, ub, box.kind[:, free], zero, box.recovering and not zero,
               box.velocity[free])  # fmt: skip


def scattered(reduced: Problem, levels: Sequence[Sequence[TaskRows]], free: Index,
              n: int) -> Problem:  # fmt: skip
    """The problem ``reduced`` (on the joints ``free``) over every joint, for the report.

    Args:
        reduced: The problem solved, on ``free.size`` columns.
        levels: The tasks' rows over every joint (reported as the tasks gave them).
        free: Indices of the joints that moved.
        n: Number of joints.

    Returns:
        The problem with zero columns for the masked joints in its stacked and constraint
        rows, and a box holding them at zero (their speed limit zero); its mode, factors and
        step those of ``reduced``.
    """
    small = reduced.box
    kind = np.full((2, n), VELOCITY, np.int8)
    kind[:, free] = small.kind
    full = Box(widened_rates(small.lb, free, n), widened_rates(small.ub, free, n), kind,
               small.contains_zero, small.recovering, widened_rates(small.velocity, free, n))
    stacked = tuple((_widened(A, free, n), b) for A, b in reduced.stacked)
    rows = reduced.rows
    if rows is not None:
        rows = rows._replace(G=_widened(rows.G, free, n))
    equalities = reduced.equalities
    if equalities is not None:
        equalities = (_widened(equalities[0], free, n), equalities[1])
    return reduced._replace(levels=tuple(map(tuple, levels)), stacked=stacked, box=full,
                            rows=rows, equalities=equalities)  # fmt: skip


def widened_rates(qdot: Array, free: Index, n: int) -> Array:
    """The rates ``qdot`` of the joints ``free`` over all ``n`` joints, zero elsewhere."""
    out = np.zeros(n)
    out[free] = qdot
    return out


def _widened(M: Array, free: Index, n: int) -> Array:
    """The columns ``M`` of the joints ``free`` over all ``n`` joints, zero elsewhere."""
    out = np.zeros((M.shape[0], n))
    out[:, free] = M
    return out
