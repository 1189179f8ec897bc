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
- otherwise as the QP :func:`direction_qp` (the LP with a small regularisation that picks the
  least-norm y; its optimum is the LP's vertex): by the compiled active-set solver
  (:func:`solved_along`, :mod:`rrc_pin.solvers.qp_backends.active_set`), else by the QP
  backend (DAQP by default) from the same data, or exactly by scipy's HiGHS
  (:func:`direction_lp`, the fallback).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
import numpy.typing as npt
from scipy.optimize import linprog

from rrc_pin.solvers.compiled import inlined, kernel
from rrc_pin.solvers.errors import NumericalFailure
from rrc_pin.solvers.qp_backends import active_set
from rrc_pin.solvers.qp_backends.qp import QP, Decoding
from rrc_pin.solvers.tick import feasibility, kernels, linalg, statuses
from rrc_pin.solvers.tick.problem import Box, Rows
from rrc_pin.solvers.tick.statuses import STILL_SCALE, scale_and_veer

Array = npt.NDArray[np.float64]

REGULARIZATION = 1e-4
r"""Weight :math:`\epsilon` of :math:`\tfrac12 u^2 + \tfrac12\|y\|^2/R^2` in the direction QP
(R the radius of the box): small enough that the answer is the LP's vertex (checked against
HiGHS in tests/test_direction.py), large enough that DAQP's factorisations stay well
conditioned (below 1e-6 it declared up to 12 % of feasible problems infeasible)."""

DIRECTION_TOL = 1e-7
"""A QP's answer to the direction problem may have task rates off the command's direction
up to this much times the largest its size can give (``|A| |qdot|``: the null basis' rounding
times the answer's size) before it is refused. As an angle instead (1e-7 rad), the rounding
of an answer at a small scale along the command was refused (a few 1e-11 off the direction
at a scale of 1e-3, 448 fallback ticks in 30,000 of baxter's hands commanded in full)."""


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
    """The direction problem as a QP in z = (y, u), for the backend (module docstring;
    :func:`problem`'s data).

    Returns:
        The QP (its rows: the box, then G) and its decoding ``qdot = M z``.
    """  # noqa: D205
    n = w.size
    G, h = (np.zeros((0, n)), np.zeros(0)) if rows is None else (rows.G, rows.h)
    P, q, C, lo, hi, z_lb, z_ub, M = problem(w, np.ascontiguousarray(null), box.lb, box.ub,
                                             np.ascontiguousarray(G), h)  # fmt: skip
    key = f"direction:{n}:{null.shape[0]}:{hi.size}"
    return QP(P, q, C, lo, hi, z_lb, z_ub, key), Decoding(None, M)


@inlined
def problem(w: Array, null: Array, lb: Array, ub: Array, G: Array, h: Array
            ) -> tuple[Array, Array, Array, Array, Array, Array, Array, Array]:  # fmt: skip
    r"""The direction QP's data in z = (y, u) (module docstring): ``(P, q, C, lo, hi, z_lb,
    z_ub, M)``, rows ``lo <= C z <= hi`` (the box, then G), rates ``qdot = M z``.

    w is first capped to the radius R of the box (no feasible rates are longer), so that u
    is of order one for any command; the costs are
    :math:`\epsilon(\tfrac12 u^2 + \tfrac12\|y\|^2/R^2) - u` (:data:`REGULARIZATION`).
    """  # noqa: D205
    d, n = null.shape
    R = radius_of(lb, ub)
    length = statuses.norm(w)
    M = np.empty((n, d + 1))
    for i in range(n):
        for j in range(d):
            M[i, j] = null[j, i]
        M[i, d] = w[i] * (R / length) if length > R else w[i]
    P = np.zeros((d + 1, d + 1))
    for j in range(d):
        P[j, j] = REGULARIZATION / (R * R if R * R != 0.0 else 1.0)
    P[d, d] = REGULARIZATION
    q = np.zeros(d + 1)
    q[d] = -1.0
    z_lb, z_ub = np.full(d + 1, -np.inf), np.full(d + 1, np.inf)
    z_lb[d], z_ub[d] = 0.0, 1.0
    p = h.size
    C = np.empty((n + p, d + 1))
    lo, hi = np.full(n + p, -np.inf), np.empty(n + p)
    for i in range(n):  # element by element: an array copy compiles numba's shape error
        for j in range(d + 1):
            C[i, j] = M[i, j]
        lo[i], hi[i] = lb[i], ub[i]
    for r in range(p):
        hi[n + r] = h[r]
        for j in range(d + 1):
            s = 0.0
            for i in range(n):
                s += G[r, i] * M[i, j]
            C[n + r, j] = s
    return P, q, C, lo, hi, z_lb, z_ub, M


@inlined
def solved_along(A: Array, w: Array, null: Array, lb: Array, ub: Array, G: Array, h: Array,
                 tol: float) -> tuple[Array, float, float, int]:  # fmt: skip
    """The direction problem along ``w`` by the compiled active-set solver: its rates (n,),
    their scale along the command, their veer off it [rad] and the solver's steps; a scale
    of -1 where it does not answer, or its answer leaves the box or rows by more than
    ``tol`` or veers off the command (the checks of
    :func:`rrc_pin.solvers.tick.pipeline.backend_along`): the backend answers then.
    """  # noqa: D205
    P, q, C, lo, hi, z_lb, z_ub, M = problem(w, null, lb, ub, G, h)
    z = np.empty(q.size)
    code, steps = active_set.solve(P, q, C, lo, hi, z_lb, z_ub, z)
    if code != active_set.SOLVED:
        return w, -1.0, 0.0, steps
    qdot = linalg.row_values(M, z)
    clipped = qdot.copy()
    if not (feasibility.all_finite(qdot) and feasibility.clip_into(clipped, lb, ub) <= tol
            and feasibility.rows_hold(G, qdot, h, tol)):  # fmt: skip
        return w, -1.0, 0.0, steps
    scale, veer, kept = along_checked(A, w, qdot)
    if not (kept and math.isfinite(scale) and math.isfinite(veer)):
        return w, -1.0, 0.0, steps
    return qdot, scale, veer, steps


@inlined
def along_checked(A: Array, w: Array, qdot: Array) -> tuple[float, float, bool]:
    """The scale and veer of a QP's rates ``qdot`` along ``A w``, and whether they keep its
    direction to :data:`DIRECTION_TOL` (their task rates off it at most that times
    ``|A| |qdot|``, or a scale at most :data:`~rrc_pin.solvers.tick.statuses.STILL_SCALE`).
    """  # noqa: D205
    m, n = A.shape
    y, b = np.empty(m), np.empty(m)
    for i in range(m):
        s, t = 0.0, 0.0
        for j in range(n):
            s += A[i, j] * qdot[j]
            t += A[i, j] * w[j]
        y[i], b[i] = s, t
    scale, veer = scale_and_veer(y, b)
    off = statuses.norm(y) * math.sin(min(veer, 0.5 * math.pi))
    kept = not (off > DIRECTION_TOL * statuses.norm(A.ravel()) * statuses.norm(qdot)
                and scale > STILL_SCALE)  # fmt: skip
    return scale, veer, kept


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
    return radius_of(box.lb, box.ub)


@kernel
def radius_of(lb: Array, ub: Array) -> float:
    """R of the box ``[lb, ub]`` (:func:`radius`)."""
    reach = np.empty(lb.size)
    k = 0
    for i in range(lb.size):
        r = max(-lb[i], ub[i])
        if np.isfinite(r):
            reach[k] = r
            k += 1
    return statuses.norm(reach[:k])
