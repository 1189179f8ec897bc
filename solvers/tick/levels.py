r"""A least-squares level inside the compiled tick.

The compiled twin of :func:`rrc_pin.solvers.tick.least_squares.least_squares` (whose module
docstring gives the math): the level's rates :math:`\dot q = x + N^Tz` minimise
:math:`\|Bz - c\|^2`, :math:`B = AN^T`, :math:`c = b - Ax`; its unconstrained optimum where it
keeps the constraints, else, where :math:`B^TB` is definite, that optimum projected onto them
in the metric :math:`B^TB` (:func:`~rrc_pin.solvers.tick.slide_kernels.project`), or where it
is semidefinite and its tie-broken metric well conditioned, the tie-broken QP's optimum in that
metric (:func:`~rrc_pin.solvers.tick.least_squares.tie_broken`). Where neither answers (an
ill-conditioned metric, a projection refused) the level is the pipeline's, with the backend's
QP (:func:`rrc_pin.solvers.tick.backend_calls.level`), from the same inputs.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
from numba import objmode

from rrc_pin.solvers import linalg
from rrc_pin.solvers.compiled import inlined, kernel
from rrc_pin.solvers.linalg import row_values
from rrc_pin.solvers.tick import backend_calls, factor, feasibility
from rrc_pin.solvers.tick.least_squares import tie_broken
from rrc_pin.solvers.tick.slide_kernels import (
    MARGIN,
    SOLVED,
    TINY,
    project,
    project_factored,
)

Array = npt.NDArray[np.float64]

ROUNDING = 1e-12
"""[rad/s] Slack given to the constraint rows of a lower level
(:data:`rrc_pin.solvers.tick.least_squares.ROUNDING`)."""


@kernel
def product(A: Array, B: Array) -> Array:
    """``A B`` (m, k) for A (m, n) and B (n, k)."""
    m, n = A.shape
    k = B.shape[1]
    C = np.zeros((m, k))
    for i in range(m):
        for p in range(n):
            a = A[i, p]
            for j in range(k):
                C[i, j] += a * B[p, j]
    return C


@inlined
def optimum(B: Array, c: Array, H: Array, g: Array, L: Array) -> tuple[Array, bool]:
    """The least-squares solution of least norm of ``B z ~= c``, and whether :math:`B^TB` is
    definite (:func:`rrc_pin.solvers.tick.least_squares.optimum`): then ``L`` (d, d), zeros
    on entry, holds its Cholesky factor (:func:`~rrc_pin.solvers.linalg.cholesky_solve`).
    """  # noqa: D205
    m, d = B.shape
    if m > d:
        z = np.empty(d)
        if linalg.cholesky(H, linalg.DEFINITE, L):  # cholesky_solve's steps, L kept
            linalg.solve_factored(L, g, z)
            return z, True
    return factor.least_norm(factor.qr(B), c)[1], False


@inlined
def metric_projection(B: Array, H: Array, L: Array, w: Array, lb: Array, ub: Array, G: Array,
                      h: Array, x: Array) -> int:  # fmt: skip
    r""":func:`~rrc_pin.solvers.tick.slide_kernels.project` of ``w`` in the metric
    :math:`B^TB` = ``H``, factorised as ``L`` by :func:`optimum`. ``project`` adds the
    smallest normal double to the metric's diagonal and factorises it anew: where that leaves
    the diagonal as it is (every entry above about 1e-292), its factor is ``L`` to the bit,
    and the factorisation is not repeated.
    """  # noqa: D205
    for i in range(H.shape[0]):
        if H[i, i] + TINY != H[i, i]:
            return project(B, 0.0, w, lb, ub, G, h, MARGIN, x)
    return project_factored(L, w, lb, ub, G, h, MARGIN, x)


@inlined
def one_sided(C: Array, lo: Array, hi: Array) -> tuple[Array, Array]:
    """Two-sided rows ``lo <= C z <= hi`` as one-sided ``G z <= h`` (finite sides only)."""
    high = np.flatnonzero(np.isfinite(hi))
    low = np.flatnonzero(np.isfinite(lo))
    G, h = np.empty((high.size + low.size, C.shape[1])), np.empty(high.size + low.size)
    for i in range(high.size):
        G[i] = C[high[i]]
        h[i] = hi[high[i]]
    for i in range(low.size):
        G[high.size + i] = -C[low[i]]
        h[high.size + i] = -lo[low[i]]
    return G, h


@inlined
def subspace_rows(x: Array, N: Array, lb: Array, ub: Array, G: Array, h: Array, tol: float
                  ) -> tuple[Array, Array]:  # fmt: skip
    """The box and rows of rates ``x + N^T z`` as one-sided rows in z, without those z cannot
    move (:func:`~rrc_pin.solvers.tick.feasibility.release_unmoved`), widened around z = 0
    where x breaks them by at most ``tol``, and by :data:`ROUNDING`
    (:func:`~rrc_pin.solvers.tick.feasibility.around_start`;
    :func:`rrc_pin.solvers.tick.least_squares._level_qp`).
    """  # noqa: D205
    n, p = x.size, h.size
    C = np.empty((n + p, N.shape[0]))
    C[:n] = N.T
    C[n:] = product(G, np.ascontiguousarray(N.T))
    Gx = row_values(G, x)
    lo, hi = np.empty(n + p), np.empty(n + p)
    for i in range(n):
        lo[i], hi[i] = lb[i] - x[i], ub[i] - x[i]
    for i in range(p):
        lo[n + i], hi[n + i] = -np.inf, h[i] - Gx[i]
    feasibility.release_unmoved(C, G, lo, hi)
    feasibility.around_start(lo, hi, tol, ROUNDING)
    return one_sided(C, lo, hi)


@inlined
def projected(B: Array, H: Array, L: Array, z: Array, x: Array, N: Array, whole: bool,
              lb: Array, ub: Array, G: Array, h: Array, tol: float) -> Array:  # fmt: skip
    r"""The level's optimum ``z`` projected onto its constraints in the metric ``H``
    (:math:`B^TB`, its Cholesky factor ``L``: :func:`optimum`; or the tie-broken metric,
    :func:`~rrc_pin.solvers.tick.least_squares.tie_broken`), as rates; empty where the kernel
    refuses or its answer leaves the box or rows beyond ``tol``
    (:func:`rrc_pin.solvers.tick.least_squares._projected`).
    """  # noqa: D205
    d = z.size
    out = np.empty(d)
    qdot: Array
    if whole:
        Gz, hz = one_sided(G, np.full(h.size, -np.inf), h)
        code = metric_projection(B, H, L, z, lb, ub, Gz, hz, out)
        qdot = out
    else:
        Gz, hz = subspace_rows(x, N, lb, ub, G, h, tol)
        free = np.full(d, np.inf)
        code = metric_projection(B, H, L, z, -free, free, Gz, hz, out)
        qdot = row_values(np.ascontiguousarray(N.T), out) + x
    if code != SOLVED:
        return np.empty(0)
    if feasibility.clip_into(qdot, lb, ub) > tol or not feasibility.rows_hold(G, qdot, h, tol):
        return np.empty(0)
    return qdot


@kernel
def backend_level(where: int, A: Array, b: Array, x: Array, N: Array, lb: Array, ub: Array,
                  G: Array, h: Array, need_null: bool) -> tuple[Array, Array]:  # fmt: skip
    """The level by the pipeline, with the backend's QP
    (:func:`rrc_pin.solvers.tick.backend_calls.level`).
    """  # noqa: D205
    with objmode(qdot="float64[::1]", null="float64[:, ::1]"):
        qdot, null = backend_calls.level(where, A, b, x, N, lb, ub, G, h, need_null)
    return qdot, null


@kernel
def least_squares(
    where: int, A: Array, b: Array, x: Array, N: Array, lb: Array, ub: Array, G: Array, h: Array,
    tol: float, need_null: bool,
) -> tuple[Array, Array]:  # fmt: skip
    """One least-squares level: its rates, and the null space left for the next level.

    Args:
        where: The level (0 the top), for the backend's record.
        A: The level's stacked rows (m, n).
        b: Their rates (m,).
        x: The rates of the levels above (n,) (not read for the top level).
        N: Orthonormal rows (d, n) of their free directions, d > 0; none (0, n) for the top
            level, which moves in every rate.
        lb: Lower bounds (n,).
        ub: Upper bounds (n,).
        G: Constraint rows (p, n).
        h: Their bounds (p,).
        tol: How far a projected answer may leave the box and rows.
        need_null: Whether the next level needs this level's null space.

    Returns:
        The rates (n,), empty where the backend failed, and the null space (d', n) (zero rows
        where not needed or failed). Where its QP needs the backend, the level is the
        pipeline's (:func:`backend_level`).
    """
    n = A.shape[1]
    whole = N.shape[0] == 0
    B = A if whole else product(A, np.ascontiguousarray(N.T))
    c = b if whole else b - row_values(A, x)
    m, d = B.shape
    H: Array = np.empty((d, d))  # the metric, tie-broken below where semidefinite
    L: Array = np.zeros((d, d))
    g = np.empty(d)
    linalg.normal_equations(B, c, np.ones(m), H, g)
    z, definite = optimum(B, c, H, g, L)
    candidate = z if whole else x + row_values(np.ascontiguousarray(N.T), z)
    if not (feasibility.inside(candidate, lb, ub) and feasibility.rows_hold(G, candidate, h, 0.0)):
        if not definite:  # the QP's tie-broken metric and optimum, where well conditioned
            H, L, z, definite = tie_broken(H, g)
        candidate = (projected(B, H, L, z, x, N, whole, lb, ub, G, h, tol) if definite
                     else np.empty(0))
        if candidate.size == 0:
            return backend_level(where, A, b, x, N, lb, ub, G, h, need_null)
    if not need_null:
        return candidate, np.empty((0, n))
    null = factor.null_basis(factor.least_norm(factor.qr(B), c)[0])[1]
    return candidate, null if whole else product(null, N)
