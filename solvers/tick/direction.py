r"""The direction problem: the largest scale of a command within the constraints.

With w the rates of the command and :math:`V_n` (d, n) orthonormal rows spanning the motions
that leave the level's task rates unchanged (the null space of its rows, within the levels
and equality rows above), every

.. math::

    \dot q = u\,w + V_n^T y \quad\Rightarrow\quad A\dot q = u\,Aw

moves the task along the command at the fraction u of its speed, whatever y. The problem is
the LP (Drake's differential IK, with the null space parametrised so that no rank-deficient
equality rows appear)

.. math::

    \max_{u, y}\ u \quad \text{s.t.} \quad lb \le u\,w + V_n^T y \le ub,\quad
    G(u\,w + V_n^T y) \le h,\quad 0 \le u \le 1,

solved here (:func:`along`):

- without rows and null space: the largest uniform scale
  (:func:`~rrc_pin.solvers.tick.kernels.uniform_scale`);
- without rows, one null direction (a 7-joint arm's six rows): exactly, by eliminating y
  (:func:`~rrc_pin.solvers.tick.kernels.line_scale`); for the top level's exact rates these two
  come in
  the same kernel call as the rates (:func:`~rrc_pin.solvers.tick.kernels.direction_step`, through
  :meth:`~rrc_pin.solvers.tick.factorization.Factorization.fitted`);
- otherwise by the QP backend (:func:`direction_qp`: the LP with a small regularisation that
  picks the least-norm y; DAQP returns the LP's vertex), or exactly by scipy's HiGHS
  (:func:`direction_lp`, the fallback).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
import numpy.typing as npt
from scipy.optimize import linprog

from rrc_pin.solvers.errors import NumericalFailure
from rrc_pin.solvers.qp_backends.qp import QP, Decoding
from rrc_pin.solvers.tick import kernels
from rrc_pin.solvers.tick.problem import Box, Rows

Array = npt.NDArray[np.float64]

REGULARIZATION = 1e-4
r"""Weight :math:`\epsilon` of :math:`\tfrac12 u^2 + \tfrac12\|y\|^2/R^2` in the direction QP
(R the radius of the box): small enough that the answer is the LP's vertex (checked against
HiGHS in tests/test_direction.py), large enough that DAQP's factorisations stay well
conditioned (below 1e-6 it declared up to 12 % of feasible problems infeasible)."""


class Along(NamedTuple):
    """An answer of the direction problem.

    Attributes:
        qdot: The rates (n,), ``u w + V_n^T y``.
        u: The scale along the command, in [0, 1].
        veer: The angle [rad] of the rates' task rates off the command's, measured where a
            backend answered (:func:`rrc_pin.solvers.tick.pipeline.backend_along`); 0 for the
            kernels' answers, along the command by construction.
    """

    qdot: Array
    u: float
    veer: float = 0.0


def along(w: Array, null: Array, box: Box, rows: Rows | None) -> Along | None:
    """The direction problem along ``w`` by the exact kernels, or None where a QP is needed.

    Args:
        w: Rates of the command (n,).
        null: Orthonormal rows (d, n) of the motions that keep the task rates.
        box: The step's bounds (containing zero).
        rows: Constraint rows, or None.

    Returns:
        The answer (exact), or None with rows or a null space of two or more dimensions.
    """
    if rows is not None or null.shape[0] > 1:
        return None
    if null.shape[0] == 0:
        u = kernels.uniform_scale(w, box.lb, box.ub)
        return Along(u * w, u)
    u, y = kernels.line_scale(w, null[0], box.lb, box.ub)
    return Along(u * w + y * null[0], u)


def direction_qp(w: Array, null: Array, box: Box, rows: Rows | None) -> tuple[QP, Decoding]:
    """The direction problem as a QP in z = (y, u), for the backend (module docstring).

    w is first capped to the radius R of the box (no feasible rates are longer), so that u
    is of order one for any command.

    Returns:
        The QP (its rows: the box, then G) and its decoding ``qdot = M z``.
    """
    d, n = null.shape
    R = radius(box)
    length = math.hypot(*w.tolist())
    M = np.empty((n, d + 1))
    M[:, :d] = null.T
    M[:, d] = w * (R / length) if length > R else w
    P = np.zeros((d + 1, d + 1))
    P.flat[:: d + 2] = REGULARIZATION / (R * R or 1.0)
    P[d, d] = REGULARIZATION
    q = np.zeros(d + 1)
    q[d] = -1.0
    z_lb = np.full(d + 1, -np.inf)
    z_ub = np.full(d + 1, np.inf)
    z_lb[d], z_ub[d] = 0.0, 1.0
    C, lo, hi = constraint_rows(M, box, rows)
    return QP(P, q, C, lo, hi, z_lb, z_ub, f"direction:{n}:{d}:{len(hi)}"), Decoding(None, M)


def direction_lp(w: Array, null: Array, box: Box, rows: Rows | None) -> Array:
    """The direction problem along ``w`` solved exactly by scipy's HiGHS (any y).

    Returns:
        The rates (n,).

    Raises:
        NumericalFailure: HiGHS found no solution.
    """
    d, n = null.shape
    M = np.empty((n, d + 1))
    M[:, :d] = null.T
    M[:, d] = w
    C, lo, hi = constraint_rows(M, box, rows)
    cost = np.zeros(d + 1)
    cost[d] = -1.0
    finite = np.isfinite(lo)
    upper = np.isfinite(hi)
    try:
        result = linprog(
            cost,
            A_ub=np.vstack([C[upper], -C[finite]]),
            b_ub=np.concatenate([hi[upper], -lo[finite]]),
            bounds=[(None, None)] * d + [(0.0, 1.0)],
            method="highs",
        )
    except ValueError as exc:  # data linprog refuses (non-finite entries)
        raise NumericalFailure(f"linprog: {exc}") from exc
    if result.status != 0 or result.x is None:
        raise NumericalFailure(f"linprog: {result.message}")
    return np.asarray(M @ result.x, dtype=np.float64)


def constraint_rows(
    M: Array, box: Box, rows: Rows | None, x0: Array | None = None
) -> tuple[Array, Array, Array]:
    """Two-sided rows ``lo <= C z <= hi`` of rates ``x0 + M z``: the box, then ``G``.

    Box sides that are infinite stay infinite (the backends take them as absent).
    """
    lo = box.lb if x0 is None else box.lb - x0
    hi = box.ub if x0 is None else box.ub - x0
    if rows is None:
        return M, lo, hi
    h = rows.h if x0 is None else rows.h - rows.G @ x0
    return (
        np.vstack([M, rows.G @ M]),
        np.concatenate([lo, np.full(h.size, -np.inf)]),
        np.concatenate([hi, h]),
    )


def radius(box: Box) -> float:
    """R, the norm of the largest rates within the box [rad/s or m/s] (finite sides only)."""
    reach = np.maximum(-box.lb, box.ub)
    return math.hypot(*reach[np.isfinite(reach)].tolist())
