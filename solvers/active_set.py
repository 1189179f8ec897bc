r"""The tracking QP solved exactly on a guessed active set, with the optimality check.

Along a trajectory the joints pinned at a bound change rarely: the previous step's active
set is the current one about 95% of the time (panda and K-1607 benchmark trajectories).
Given a guess, the box-constrained tracking QP (:func:`solvers.qp_problem.tracking_problem`)

.. math::

    \min_x \tfrac12 x^T P x + q^T x \quad \text{s.t.} \quad lb \le x \le ub

restricted to :math:`x_E = b_E` on the guessed joints E (each at its lower or upper bound)
has the closed-form minimiser (the equality-constrained QP through the inverse of P;
Nocedal & Wright, *Numerical Optimization*, 2nd ed., eq. (16.4)-(16.5)):

.. math::

    x = x_{free} - H\nu, \qquad H = P^{-1}E^T, \qquad
    \nu = (E P^{-1} E^T)^{-1}(x_{free,E} - b_E)

with :math:`x_{free} = -P^{-1}q` the box-free minimiser. The gradient there is
:math:`Px + q = -E^T\nu`, so x solves the box QP exactly (KKT conditions, sufficient for a
convex QP: Nocedal & Wright Theorem 16.4) iff the joints outside E satisfy their bounds and
every multiplier has the sign of its side: :math:`\nu_i \le 0` at a lower bound,
:math:`\nu_i \ge 0` at an upper bound. Otherwise the guess is wrong and the caller asks
the backend. :math:`P^{-1}` is never formed, only its columns E, from the factorisation the
step has already: :math:`V \operatorname{diag}(1/d) V^T E^T` (SVD) or
:math:`(C - \tilde J/\mu)^T C E^T + E^T/\mu`, :math:`C = A^{-1}\tilde J`
(:class:`~solvers.task_factor.TaskInverse`, where
:math:`P^{-1} = C^TC + (I - \tilde J^T C)/\mu`).
"""

from __future__ import annotations

from operator import le

import numpy as np
import numpy.typing as npt

from solvers.joint_bounds import VelocityBounds
from solvers.qp_problem import TrackingFree
from solvers.task_factor import Task, TaskInverse, posv

Array = npt.NDArray[np.float64]

SLACK = 1e-12
"""[rad/s] Rounding allowed in the bound and multiplier-sign checks."""


def tracking_inverse(task: Task, free: TrackingFree) -> Array:
    r""":math:`P^{-1}` (n, n) of the tracking problem of ``free`` (module docstring).

    Args:
        task: The factorisation the tracking problem was built from.
        free: Its :func:`~solvers.qp_problem.tracking_free` minimiser (the SVD route needs
            the eigenvalues ``d`` of P it holds).

    Returns:
        The inverse of the tracking problem's P, (n, n).
    """
    return np.array(_inverse_rows(task, free, list(range(task.n))))


def _inverse_rows(task: Task, free: TrackingFree, rows: list[int]) -> list[list[float]]:
    """Rows ``rows`` of :func:`tracking_inverse` (k, n), as Python floats."""
    if isinstance(task, TaskInverse):
        # C^T (C - J/mu) by numpy (all rows: cheaper than indexing columns of C first),
        # then + 1/mu at (i, i) on Python floats
        W = task.J * (-1.0 / free.mu)
        W += task.C
        full = np.dot(task.C.T, W).tolist()
        inverse_mu = 1.0 / free.mu
        out = []
        for i in rows:
            row = full[i]
            row[i] += inverse_mu
            out.append(row)
        return out
    full = ((task.Vt.T / free.d) @ task.Vt).tolist()  # type: ignore[union-attr,operator]
    return [full[i] for i in rows]


def solve_on_active_set(
    task: Task,
    free: TrackingFree,
    bounds: VelocityBounds,
    lower: tuple[int, ...],
    upper: tuple[int, ...],
) -> tuple[Array, float] | None:
    """The tracking QP's exact solution if its active set is ``lower`` and ``upper``, else None.

    Apart from :math:`P^{-1}` the arithmetic is on Python floats: k (the active joints)
    and n are a handful.

    Args:
        task: The factorisation of the step.
        free: The box-free minimiser of the tracking problem (outside the box).
        bounds: Joint-rate bounds.
        lower: Joints guessed at their lower bound.
        upper: Joints guessed at their upper bound (disjoint from ``lower``).

    Returns:
        The joint rates (n,), clipped into the bounds, and the size of that clip (at most
        :data:`SLACK`); None when the guess fails the optimality check (module docstring)
        or is empty.
    """
    joints = [*lower, *upper]
    if not joints:
        return None
    lb, ub = bounds.lists()
    x = free.x.tolist()
    gap = [x[i] - lb[i] for i in lower] + [x[i] - ub[i] for i in upper]
    rows = _inverse_rows(task, free, joints)  # P^-1 E^T, transposed (P is symmetric)
    nu = _solve_small([[row[j] for j in joints] for row in rows], gap)
    if nu is None:
        return None
    k = len(lower)
    for t, nu_t in enumerate(nu):  # the multipliers' signs
        if (nu_t > SLACK) if t < k else (nu_t < -SLACK):
            return None
    for row, nu_j in zip(rows, nu):  # noqa: B905  x -= P^-1 E^T nu
        x = [v - p * nu_j for v, p in zip(x, row)]  # noqa: B905
    for i in lower:  # x_E = b_E up to rounding: exactly, as the constraint says
        x[i] = lb[i]
    for i in upper:
        x[i] = ub[i]
    if all(map(le, lb, x)) and all(map(le, x, ub)):
        return np.array(x), 0.0
    clip = 0.0
    for i, (low, v, high) in enumerate(zip(lb, x, ub)):  # noqa: B905
        gap_i = max(low - v, v - high)  # > 0: outside by rounding, or a wrong guess
        if gap_i > SLACK:
            return None
        if gap_i > 0.0:
            clip, x[i] = max(clip, gap_i), min(max(v, low), high)
    return np.array(x), clip


def _solve_small(S: list[list[float]], b: list[float]) -> list[float] | None:
    """Solution of ``S x = b`` for a small symmetric positive definite S, or None if it is not.

    Closed form for k <= 2 (Python floats), LAPACK's Cholesky solve beyond.
    """
    k = len(b)
    if k == 1:
        return [b[0] / S[0][0]] if S[0][0] > 0.0 else None
    if k == 2:
        (a, c), (_, d) = S
        det = a * d - c * c
        if not (a > 0.0 and det > 0.0):
            return None
        return [(d * b[0] - c * b[1]) / det, (a * b[1] - c * b[0]) / det]
    _, x, info = posv(np.array(S), np.array(b))
    return x.tolist() if info == 0 else None  # type: ignore[no-any-return]


def active_joints(
    qdot: Array, bounds: VelocityBounds, tol: float = 1e-9
) -> tuple[tuple[int, ...], tuple[int, ...]]:
    """Joints of ``qdot`` within ``tol`` of their lower, and of their upper bound.

    A joint whose bounds are closer than ``tol`` counts at the side it is nearer to.
    """
    values = qdot.tolist()
    lower: list[int] = []
    upper: list[int] = []
    lb, ub = bounds.lists()
    for i, (low, v, high) in enumerate(zip(lb, values, ub)):  # noqa: B905
        if v - low <= tol and v - low <= high - v:
            lower.append(i)
        elif high - v <= tol:
            upper.append(i)
    return tuple(lower), tuple(upper)
