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

- without rows and null space: the largest uniform scale (:func:`uniform_scale`);
- without rows, one null direction (a 7-joint arm's six rows): exactly, by eliminating y
  (:func:`line_scale`); for the top level's exact rates these two come in the same kernel call
  as the rates (:func:`direction_step`, through
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

from rrc_pin.solvers import linalg
from rrc_pin.solvers.compiled import inlined, kernel
from rrc_pin.solvers.errors import NumericalFailure
from rrc_pin.solvers.linalg import householder_qr, least_norm_rates, max_abs
from rrc_pin.solvers.qp_backends import active_set
from rrc_pin.solvers.qp_backends.qp import QP, Decoding
from rrc_pin.solvers.tick import feasibility, statuses
from rrc_pin.solvers.tick.feasibility import inside
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
        u = uniform_scale(w, box.lb, box.ub)
        return Along(u * w, u)
    u, y = line_scale(w, null[0], box.lb, box.ub)
    return Along(u * w + y * null[0], u)


@kernel
def uniform_scale(x: Array, lb: Array, ub: Array) -> float:
    """Largest s in [0, 1] with ``lb <= s x <= ub``, for bounds with ``lb <= 0 <= ub``."""
    s = 1.0
    for i in range(x.size):
        if x[i] > 0.0:
            s = min(s, ub[i] / x[i])
        elif x[i] < 0.0:
            s = min(s, lb[i] / x[i])
    return max(s, 0.0)


NULL_ROUNDING = 1e-12
"""[relative to its largest entry] A component of a null direction this small is the SVD's
rounding (a joint that no row moves): the row it belongs to does not bound the null
coefficient y (:func:`line_scale`; its bound there would be its slack's rounding over the
component's, anywhere in the box)."""


@kernel
def line_scale(w: Array, v: Array, lb: Array, ub: Array) -> tuple[float, float]:
    r"""The largest u in [0, 1] with ``lb <= u w + y v <= ub`` for some y, and that y nearest 0.

    Each row gives two half-planes :math:`\alpha u + \beta y \le \gamma` (:math:`\gamma \ge
    0`); eliminating y between each pair bounding it from opposite sides (Fourier-Motzkin
    elimination, Dantzig & Eaves 1973) leaves bounds on u alone. The direction problem of
    one null direction v, exactly. A component of v within :data:`NULL_ROUNDING` of its
    largest is taken as zero: its row bounds u alone, and is met by the rates to that
    component times ``|y|`` (the caller's clip).

    Args:
        w: Rates of the command (n,).
        v: Null-space direction (n,).
        lb: Lower bounds (n,) <= 0.
        ub: Upper bounds (n,) >= 0.

    Returns:
        u and y: the rates are ``u w + y v``.
    """
    n = w.size
    c = np.empty(n)  # v without its rounding
    rounding = NULL_ROUNDING * max_abs(v)
    for i in range(n):
        c[i] = v[i] if abs(v[i]) > rounding else 0.0
    u = 1.0
    for i in range(n):  # rows without y bound u alone
        if c[i] == 0.0:
            if w[i] > 0.0:
                u = min(u, ub[i] / w[i])
            elif w[i] < 0.0:
                u = min(u, lb[i] / w[i])
    # half-plane (a, b, g) of row i bounding y from above: b > 0 (the row's side where v > 0)
    for i in range(n):
        if c[i] == 0.0:
            continue
        a1, b1, g1 = (w[i], c[i], ub[i]) if c[i] > 0.0 else (-w[i], -c[i], -lb[i])
        for j in range(n):
            if c[j] == 0.0:
                continue
            a2, b2, g2 = (-w[j], -c[j], -lb[j]) if c[j] > 0.0 else (w[j], c[j], ub[j])
            coefficient = b1 * a2 - b2 * a1  # -b2 (plane 1) + b1 (plane 2): y eliminated
            if coefficient > 0.0 and b1 * g2 - b2 * g1 < u * coefficient:
                u = (b1 * g2 - b2 * g1) / coefficient
    u = max(u, 0.0)
    y_hi, v_hi, y_lo, v_lo = math.inf, 1.0, -math.inf, 1.0
    for i in range(n):
        if c[i] == 0.0:
            continue
        a1, b1, g1 = (w[i], c[i], ub[i]) if c[i] > 0.0 else (-w[i], -c[i], -lb[i])
        if (g1 - a1 * u) / b1 < y_hi:
            y_hi, v_hi = (g1 - a1 * u) / b1, b1
        a2, b2, g2 = (-w[i], -c[i], -lb[i]) if c[i] > 0.0 else (w[i], c[i], ub[i])
        if (g2 - a2 * u) / b2 > y_lo:
            y_lo, v_lo = (g2 - a2 * u) / b2, -b2
    if y_lo <= y_hi:
        return u, min(max(0.0, y_lo), y_hi)
    # rounding at a vertex: the y that leaves both rows by the same rate (a row with a
    # null component of rounding size, 1e-15, pins u; its y bound is off by up to 0.1)
    return u, (v_lo * y_lo + v_hi * y_hi) / (v_lo + v_hi)


@kernel
def direction_step(
    J: Array, b: Array, lb: Array, ub: Array, Q: Array, R: Array, w: Array, qdot: Array
) -> tuple[int, float]:
    r"""The top level's step within a box: its exact rates, whether they fit, else their scale.

    :func:`~rrc_pin.solvers.linalg.householder_qr` of :math:`J^T`, the least-norm rates w
    of :math:`Jx = b` (:func:`~rrc_pin.solvers.linalg.least_norm_rates`),
    :func:`~rrc_pin.solvers.tick.feasibility.inside`; where w leaves the box and the null space
    of J has at most one direction (:math:`Q_{:,m}`, a 7-joint arm's six rows), the direction
    problem's exact answer :math:`u\,w + y\,Q_{:,m}` (:func:`uniform_scale`,
    :func:`line_scale`); one call for what most ticks need.

    Args:
        J: Rows (m, n).
        b: Their rates (m,).
        lb: Lower bounds (n,) (containing zero where the scale is asked for).
        ub: Upper bounds (n,).
        Q: Out: orthogonal factor (n, n).
        R: Out: triangular factor (n, m).
        w: Out: the least-norm rates (n,), set unless 0 is returned.
        qdot: Out: the scaled rates (n,), set where 1 is returned with u >= 0.

    Returns:
        ``(fit, u)``: fit 0 where the rows are numerically dependent or more than the joints
        (w not set), 1 where w is outside ``[lb, ub]``, 2 inside; u the largest scale in
        [0, 1] along w where fit is 1 and n - m <= 1, else -1.
    """
    m, n = J.shape
    householder_qr(J.T, Q, R)
    if m > n or not least_norm_rates(Q, R, b, w):
        return 0, -1.0
    if inside(w, lb, ub):
        return 2, -1.0
    if n - m > 1:
        return 1, -1.0
    if n == m:
        u = uniform_scale(w, lb, ub)
        for i in range(n):
            qdot[i] = u * w[i]
        return 1, u
    v = qdot  # Q's column m, contiguous: one compiled signature of line_scale
    for i in range(n):
        v[i] = Q[i, m]
    u, y = line_scale(w, v, lb, ub)
    for i in range(n):
        qdot[i] = u * w[i] + y * v[i]
    return 1, u


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
