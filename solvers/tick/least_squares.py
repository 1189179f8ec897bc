r"""A least-squares level: :math:`\min \|A\dot q - b\|^2` within the constraints and levels above.

The rates are :math:`\dot q = x + N^T z` (a :class:`Subspace`: the answer of
the levels above and their null space; all rates for the first level), so the level solves

.. math::

    \min_z \|Bz - c\|^2,\quad B = AN^T,\ c = b - Ax
    \quad \text{s.t.} \quad lb \le x + N^Tz \le ub,\quad G(x + N^Tz) \le h.

Its unconstrained optimum of least norm is the answer when it satisfies the constraints:
by the normal equations :math:`B^TBz = B^Tc` (:func:`~rrc_pin.solvers.linalg.cholesky_solve`)
for
more rows than unknowns, by the QR of :math:`B^T`
(:class:`~rrc_pin.solvers.tick.factorization.Factorization`)
otherwise, and by the SVD where either is rank deficient. Else, where :math:`B^TB` is
definite (the optimum one point), the optimum is projected onto the constraints in
the metric :math:`B^TB` by hand (:func:`~rrc_pin.solvers.tick.slide_kernels.project`: the same
costs up to a constant); else, or where that kernel refuses, the backend solves the QP
with :math:`P = B^TB` and :math:`q = -B^Tc` (the same normal equations, computed once):
exactly the stated costs where P is definite (their optimum is one point). Where it is not
(as many rows as unknowns or fewer: one frame task on a redundant arm, a lower level in a
null space) the optimal rates may form a set, and the term
:math:`\epsilon\|z\|^2`, :math:`\epsilon` = :data:`TIE_BREAK` times the trace of P, picks
the least-norm ones among them; it moves the optimum of the stated costs by at most
:math:`\epsilon/\lambda` relative along an eigenvector of P of eigenvalue :math:`\lambda`,
as Levenberg-Marquardt damping would. (Measured on 2,000 random three-level problems: at
1e-10, DAQP declared 154 feasible lower levels infeasible, at 1e-8 33, at 1e-6 2; DAQP's
exact proximal iterations instead took up to 0.3 s and hit their iteration limit on 2-5 of
200 tracking steps of rrc_k1607 and panda.) Where that QP's metric :math:`P + \epsilon I` is
well conditioned (:func:`tie_broken`: a square B of full rank), its optimum is projected in it
by hand as well; an ill-conditioned one (fewer rows than unknowns: a condition number of about
:math:`1/\epsilon`) stays the backend's (:data:`WELL_CONDITIONED`).

The next level moves in the null space of B (the optimal set of a convex least squares has one
value of Bz).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers import linalg
from rrc_pin.solvers.compiled import kernel
from rrc_pin.solvers.qp_backends.qp import QP, Decoding, Work, solve_within, tolerance
from rrc_pin.solvers.tick import feasibility
from rrc_pin.solvers.tick.direction import constraint_rows
from rrc_pin.solvers.tick.factorization import Factorization
from rrc_pin.solvers.tick.problem import Box, Rows
from rrc_pin.solvers.tick.slide_kernels import MARGIN, SOLVED, project, project_factored

if TYPE_CHECKING:
    from rrc_pin.solvers.qp_backends.base import QPBackend

Array = npt.NDArray[np.float64]

TIE_BREAK = 1e-6
"""Weight of the least-norm tie-break of a semidefinite least-squares QP, relative to the
trace of its P (module docstring)."""

ROUNDING = 1e-12
"""[rad/s] Slack given to the constraint rows of a lower level's QP, whose start z = 0 sits on
them wherever a joint is at a bound."""


WELL_CONDITIONED = 1e4
"""Condition number of a tie-broken level's metric up to which the kernel projects in it
(:func:`tie_broken`). An answer moves with its data's last bits by about the condition number
times their rounding, and the compiled tick forms the level's products in loops of its own: at
8.6e5 (fewer rows than unknowns make about 1e6) its rates were 4e-8 from the pipeline's on a
random three-level problem, and the clip back into the box turned one's exact top level into
scaled. Handed to the backend instead, both paths solve the same floats."""

_TINY = float(np.finfo(np.float64).tiny)


@kernel
def tie_broken(H: Array, g: Array) -> tuple[Array, Array, Array, bool]:
    r"""A semidefinite level's QP (module docstring): its metric :math:`P = H + \epsilon I`
    (d, d), P's Cholesky factor L (d, d) and unconstrained optimum :math:`P^{-1}g` (d,), from
    the normal equations ``H`` = :math:`B^TB` (d, d) and ``g`` = :math:`B^Tc` (d,); and
    whether the kernel may project in that metric (factorised, its condition number at most
    :data:`WELL_CONDITIONED`; L and the optimum zeros where not).
    """  # noqa: D205
    d = g.size
    P = H.copy()
    trace = 0.0
    for i in range(d):
        trace += H[i, i]
    epsilon = TIE_BREAK * max(trace, 1.0)
    for i in range(d):
        P[i, i] += epsilon
    L, w = np.zeros((d, d)), np.zeros(d)
    if not math.isfinite(epsilon):  # rows beyond 1e154: eigvalsh would raise
        return P, L, w, False
    eigenvalues = np.linalg.eigvalsh(P)
    if not eigenvalues[-1] <= WELL_CONDITIONED * eigenvalues[0]:
        return P, L, w, False
    if not linalg.cholesky(P, linalg.DEFINITE, L):
        return P, L, w, False
    linalg.solve_factored(L, g, w)
    return P, L, w, True


class Subspace(NamedTuple):
    """Where a level may move: rates ``x + N^T z``.

    Attributes:
        x: The rates so far (n,), or None (zero) with N None.
        N: Orthonormal rows (d, n) spanning the free directions, or None for all of them.
    """

    x: Array | None
    N: Array | None


def normal_equations(B: Array, c: Array) -> tuple[Array, Array]:
    r""":math:`(B^TB, B^Tc)` (:func:`~rrc_pin.solvers.linalg.normal_equations`): the
    optimum's normal
    equations, and the QP's costs."""  # noqa: D205, D209
    m, d = B.shape
    H, g = np.empty((d, d)), np.empty(d)
    linalg.normal_equations(B, c, np.ones(m), H, g)
    return H, g


def optimum(B: Array, c: Array, H: Array, g: Array) -> tuple[Array, Factorization | None, bool]:
    """The least-squares solution of least norm of ``B z ~= c``.

    Args:
        B: Rows (m, d).
        c: Rates (m,).
        H: :math:`B^TB` (d, d).
        g: :math:`B^Tc` (d,).

    Returns:
        z (d,), the :class:`Factorization` of B when it was computed (else None: the normal
        equations answered), and whether :math:`B^TB` is definite (the optimum one point).
    """
    m, d = B.shape
    if m > d:
        z = np.empty(d)
        if linalg.cholesky_solve(H, g, z):
            return z, None, True
    factor = Factorization(B)
    return factor.least_norm(c), factor, False


def least_squares(
    A: Array,
    b: Array,
    space: Subspace,
    box: Box,
    rows: Rows | None,
    backend: QPBackend,
    work: Work,
    key: str,
    need_null: bool,
) -> tuple[Array, Array | None]:
    """One least-squares level within ``space`` and the constraints (module docstring).

    Args:
        A: The level's stacked, row-weighted rows (m, n).
        b: Their rates (m,).
        space: Where the level may move.
        box: The step's bounds.
        rows: Constraint rows, or None.
        backend: The QP backend.
        work: Where the backend's work and failures are counted.
        key: Warm-start key prefix of the QP.
        need_null: Whether the next level needs this level's null space.

    Returns:
        The rates (n,), and the null space (d', n) left for the next level (None when not
        needed).

    Raises:
        NumericalFailure: The backend found no usable answer.
    """
    x, N = space
    B = A if N is None else A @ N.T
    c = b if N is None or x is None else b - A @ x
    H, g = normal_equations(B, c)
    z, factor, definite = optimum(B, c, H, g)
    candidate = z if N is None or x is None else x + z @ N
    feasible = feasibility.inside(candidate, box.lb, box.ub) and (
        rows is None or feasibility.rows_hold(rows.G, candidate, rows.h, 0.0)
    )
    if not feasible:
        P, L, w, projects = (H, None, z, True) if definite else tie_broken(H, g)
        qp, decoding = _level_qp(P, g, space, box, rows, key)
        kept = _projected(B, L, w, qp, decoding, box, rows) if projects else None
        candidate = kept if kept is not None else solve_within(qp, decoding, box, rows,
                                                               backend, work)  # fmt: skip
    if not need_null:
        return candidate, None
    if factor is None:
        factor = Factorization(B)
        factor.least_norm(c)  # records whether B has full row rank, for its null basis
    null = factor.null_basis()
    return candidate, null if N is None else null @ N


def _level_qp(
    P: Array, g: Array, space: Subspace, box: Box, rows: Rows | None, key: str
) -> tuple[QP, Decoding]:
    """The level's QP in z (module docstring) from its metric ``P`` (the normal equations'
    H, or :func:`tie_broken`'s) and ``g``, and how its answer decodes into rates."""  # noqa: D205, D209
    x, N = space
    d = g.size
    q = -g
    # Divided by their largest entry, the costs have the same minimiser and the backends'
    # absolute tolerances read as relative ones (a command saturating the box gave
    # gradients 1e7 times P, and proxqp iterated for 10 s).
    size = max(float(np.abs(P).max()), float(np.abs(q).max()), _TINY)
    P, q = P / size, q / size
    if N is None:
        if rows is None:
            return QP(P, q, None, None, None, box.lb, box.ub, f"{key}:{d}"), Decoding(None, None)
        qp = QP(P, q, rows.G, np.full(rows.h.size, -np.inf), rows.h, box.lb, box.ub,
                f"{key}:{d}")  # fmt: skip
        return qp, Decoding(None, None)
    C, lo, hi = constraint_rows(N.T, box, rows, x)
    # z = 0, the answer so far, kept feasible where it is one to the backend's tolerance (joints
    # exactly on their bounds); a start farther out (the equality rows' least-norm rates of a
    # top level) is no answer: the constraints stand
    C, lo, hi = np.ascontiguousarray(C), np.array(lo), np.array(hi)  # one compiled signature
    G = np.empty((0, N.shape[1])) if rows is None else np.ascontiguousarray(rows.G)
    feasibility.release_unmoved(C, G, lo, hi)
    moved = np.isfinite(lo) | np.isfinite(hi)
    C, lo, hi = C[moved], lo[moved], hi[moved]
    feasibility.around_start(lo, hi, tolerance(box), ROUNDING)
    free = np.full(d, np.inf)
    return QP(P, q, C, lo, hi, -free, free, f"{key}:{d}:{hi.size}"), Decoding(x, N.T)


def _projected(
    B: Array, L: Array | None, w: Array, qp: QP, decoding: Decoding, box: Box, rows: Rows | None
) -> Array | None:
    r"""The level's QP solved by hand: its unconstrained optimum ``w`` projected onto the QP's
    constraints in its metric (:func:`~rrc_pin.solvers.tick.slide_kernels.project`; the same
    costs up to a constant), as rates: :math:`B^TB` where L is None, else the metric whose
    Cholesky factor is L (:func:`tie_broken`).

    Returns:
        The rates (n,), or None where the kernel refuses or its answer leaves the box or rows
        beyond :func:`~rrc_pin.solvers.qp_backends.qp.tolerance` (the backend then answers).
    """  # noqa: D205
    d = w.size
    if qp.C is None or qp.l is None or qp.u is None:
        G, h = np.empty((0, d)), np.empty(0)
    else:
        low, high = np.isfinite(qp.l), np.isfinite(qp.u)
        G, h = np.vstack([qp.C[high], -qp.C[low]]), np.concatenate([qp.u[high], -qp.l[low]])
    out = np.empty(d)
    # C order always (Pinocchio's Jacobians are Fortran's): one compiled signature, no
    # compilation inside a running control loop
    if L is None:
        code = project(np.ascontiguousarray(B), 0.0, w, qp.lb, qp.ub, G, h, MARGIN, out)
    else:
        code = project_factored(L, w, qp.lb, qp.ub, G, h, MARGIN, out)
    if code != SOLVED:
        return None
    qdot = decoding.rates(out)
    tol = tolerance(box)
    if feasibility.clip_into(qdot, box.lb, box.ub) > tol or (
        rows is not None and not feasibility.rows_hold(rows.G, qdot, rows.h, tol)
    ):
        return None
    return qdot
