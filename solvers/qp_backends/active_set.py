r"""A compiled dual active-set solver for small dense strictly convex QPs.

.. math::

    \min_z \tfrac12 z^T P z + q^T z \quad \text{s.t.} \quad lo \le C z \le hi,\quad
    lb \le z \le ub

(:class:`~rrc_pin.solvers.qp_backends.qp.QP`'s form; P definite, a few variables, a few tens of
rows), by Goldfarb & Idnani's dual method ("A numerically stable dual method for solving
strictly convex quadratic programs", Math. Programming 27, 1983): from the unconstrained
minimum, the most violated constraint enters the active set, the step toward it keeping the
multipliers of the active ones nonnegative (an active constraint whose multiplier would turn
negative leaves). Every iterate is the optimum over its active set, so the answer is the QP's
optimum to rounding, as DAQP's (a dual active-set method too) is. The step's two directions
are solved afresh from the active rows at each step
(:math:`(N^TP^{-1}N) r = N^TP^{-1}n_p`, Cholesky), which costs nothing at these sizes and keeps
no factorisation to update.

Each side of a row becomes a one-sided constraint :math:`n^Tz \ge b` divided by the norm of
``C``'s row, so that one tolerance (:data:`PRIMAL_TOL`) reads alike for every row. The
solver does not answer (:data:`NOT_CONVERGED`) where the active rows become dependent to
rounding (a degenerate vertex) or its iterations run out, and says :data:`INFEASIBLE` where
the constraints admit no point; the caller then hands the QP to a backend.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.compiled import inlined, kernel
from rrc_pin.solvers.linalg import cholesky, max_abs, solve_factored

Array = npt.NDArray[np.float64]

SOLVED, INFEASIBLE, NOT_CONVERGED, NOT_DEFINITE = 0, 1, 2, 3
"""What :func:`solve` returns."""

PRIMAL_TOL = 1e-10
"""How far a constraint (its row of unit norm) may be broken, times (1 + its bound's size),
before it enters the active set."""

ROUNDING = 1e-13
"""The steps' rounding, relative to the unconstrained minimum's size (where P is small, far
from the answer): added to :data:`PRIMAL_TOL` (a vertex reached from 6e4 away was left 4e-10
short of a row through it)."""

DEPENDENT = 1e-12
"""A constraint whose primal step direction is this small relative to its own
(:math:`n_p^TP^{-1}n_p`) depends on the active ones."""

NAME = "active_set"
"""The name a tick's report gives for answers of this solver."""


@inlined
def one_sided(C: Array, lo: Array, hi: Array, lb: Array, ub: Array) -> tuple[Array, Array, bool]:
    """The constraints as rows ``N z >= b`` (m', nz), each C row of unit norm; and False
    where a row of zeros is broken (no point meets the constraints).
    """  # noqa: D205
    p, nz = C.shape
    count = 0
    for i in range(p):
        count += int(np.isfinite(lo[i])) + int(np.isfinite(hi[i]))
    for j in range(nz):
        count += int(np.isfinite(lb[j])) + int(np.isfinite(ub[j]))
    N, b = np.zeros((count, nz)), np.empty(count)
    k = 0
    for i in range(p):
        norm = 0.0
        for j in range(nz):
            norm += C[i, j] * C[i, j]
        norm = math.sqrt(norm)
        if norm == 0.0:
            if lo[i] > 0.0 or hi[i] < 0.0:
                return N[:0], b[:0], False
            continue
        for side, bound in ((1.0, lo[i]), (-1.0, hi[i])):
            if np.isfinite(bound):
                for j in range(nz):
                    N[k, j] = side * C[i, j] / norm
                b[k] = side * bound / norm
                k += 1
    for j in range(nz):
        for side, bound in ((1.0, lb[j]), (-1.0, ub[j])):
            if np.isfinite(bound):
                N[k, j] = side
                b[k] = side * bound
                k += 1
    return N[:k], b[:k], True


@inlined
def _gram(Pinv: Array, N: Array, active: npt.NDArray[np.int64], k: int
          ) -> tuple[Array, Array, bool]:  # fmt: skip
    r"""The active rows through :math:`P^{-1}`, rows :math:`P^{-1}n_j` (k, nz), and the
    Cholesky factor (k, k) of :math:`N_A^TP^{-1}N_A`; False where the rows are dependent to
    rounding (:data:`DEPENDENT`).
    """  # noqa: D205
    nz = Pinv.shape[0]
    PN = np.empty((k, nz))
    for a in range(k):
        for i in range(nz):
            s = 0.0
            for j in range(nz):
                s += Pinv[i, j] * N[active[a], j]
            PN[a, i] = s
    M = np.empty((k, k))
    for a in range(k):
        for c in range(a + 1):
            s = 0.0
            for i in range(nz):
                s += N[active[a], i] * PN[c, i]
            M[a, c] = s
            M[c, a] = s
    L = np.zeros((k, k))
    return PN, L, cholesky(M, DEPENDENT, L) if k else True


@inlined
def _directions(Pinv: Array, N: Array, active: npt.NDArray[np.int64], k: int, p: int,
                z: Array, r: Array) -> bool:  # fmt: skip
    r"""The primal step z (nz,) and the dual one r (k,) of constraint ``p`` on the active set.

    :math:`r = (N_A^TP^{-1}N_A)^{-1}N_A^TP^{-1}n_p`, :math:`z = P^{-1}(n_p - N_Ar)`. False where
    the active rows are dependent to rounding (:func:`_gram`).
    """
    nz = Pinv.shape[0]
    for i in range(nz):  # P^{-1} n_p
        s = 0.0
        for j in range(nz):
            s += Pinv[i, j] * N[p, j]
        z[i] = s
    if k == 0:
        return True
    PN, L, independent = _gram(Pinv, N, active, k)
    if not independent:
        return False
    rhs = np.empty(k)
    for a in range(k):
        s = 0.0
        for i in range(nz):
            s += N[active[a], i] * z[i]
        rhs[a] = s
    solve_factored(L, rhs, r[:k])
    for i in range(nz):
        for a in range(k):
            z[i] -= PN[a, i] * r[a]
    return True


@inlined
def _slack(N: Array, b: Array, i: int, x: Array) -> float:
    """``n_i^T x - b_i``: negative where constraint i is broken."""
    s = -float(b[i])
    for j in range(x.size):
        s += N[i, j] * x[j]
    return s


@inlined
def _most_broken(N: Array, b: Array, x: Array, is_active: npt.NDArray[np.bool_], tol: Array
                 ) -> int:  # fmt: skip
    """The inactive constraint broken the most beyond its ``tol``, or -1."""
    worst, p = 0.0, -1
    for i in range(b.size):
        if is_active[i]:
            continue
        s = _slack(N, b, i, x)
        if s < -tol[i] and s < worst:
            worst, p = s, i
    return p


@kernel
def solve(P: Array, q: Array, C: Array, lo: Array, hi: Array, lb: Array, ub: Array,
          x: Array) -> tuple[int, int]:  # fmt: skip
    """The QP of the module docstring: its code and steps; ``x`` the optimum where SOLVED.

    Args:
        P: Definite cost matrix (nz, nz).
        q: Cost vector (nz,).
        C: Rows (p, nz), p >= 0.
        lo: Lower bounds of ``C z`` (p,), -inf allowed.
        hi: Upper bounds of ``C z`` (p,), +inf allowed.
        lb: Lower bounds of z (nz,), -inf allowed.
        ub: Upper bounds of z (nz,), +inf allowed.
        x: Out (nz,).

    Returns:
        (SOLVED, INFEASIBLE, NOT_CONVERGED or NOT_DEFINITE (P's Cholesky failed), steps).
    """
    nz = q.size
    L = np.zeros((nz, nz))
    if not cholesky(P, 1e-14, L):
        return NOT_DEFINITE, 0
    Pinv = np.empty((nz, nz))
    e, column = np.zeros(nz), np.empty(nz)  # contiguous: one compiled signature of the solve
    for j in range(nz):
        e[j] = 1.0
        solve_factored(L, e, column)
        e[j] = 0.0
        for i in range(nz):
            Pinv[i, j] = column[i]
    for i in range(nz):  # the unconstrained minimum
        s = 0.0
        for j in range(nz):
            s -= Pinv[i, j] * q[j]
        x[i] = s
    N, b, possible = one_sided(C, lo, hi, lb, ub)
    if not possible:
        return INFEASIBLE, 0
    return _iterate(Pinv, N, b, x)


@inlined
def _iterate(Pinv: Array, N: Array, b: Array, x: Array) -> tuple[int, int]:
    """Goldfarb & Idnani's iterations from the unconstrained minimum ``x`` (in place)."""
    nz, m = x.size, b.size
    tol = np.empty(m)  # the steps' rounding grows with their length: from x's start
    far = ROUNDING * max_abs(x)
    for i in range(m):
        tol[i] = PRIMAL_TOL * (1.0 + abs(b[i])) + far
    active = np.empty(nz + 1, np.int64)
    is_active = np.zeros(m, np.bool_)
    u = np.zeros(nz + 1)  # the multipliers of the active constraints, then of p's
    z, r = np.empty(nz), np.empty(nz + 1)
    k, steps = 0 * nz, 0  # k not the literal 0: one compiled signature of _directions
    limit = 10 * (m + nz) + 10
    p = _most_broken(N, b, x, is_active, tol)
    while p >= 0:
        u[k] = 0.0
        while True:
            steps += 1
            if steps > limit or not _directions(Pinv, N, active, k, p, z, r):
                return NOT_CONVERGED, steps
            t1, drop = math.inf, -1  # the longest step keeping the multipliers >= 0
            for a in range(k):
                if r[a] > 0.0 and u[a] / r[a] < t1:
                    t1, drop = u[a] / r[a], a
            zn, own = 0.0, 0.0
            for j in range(nz):
                zn += z[j] * N[p, j]
            for i in range(nz):
                for j in range(nz):
                    own += N[p, i] * Pinv[i, j] * N[p, j]
            # with nz rows active no primal step is left: p depends on them
            t2 = -_slack(N, b, p, x) / zn if k < nz and zn > DEPENDENT * own else math.inf
            if t1 == math.inf and t2 == math.inf:
                return INFEASIBLE, steps
            t = min(t1, t2)
            if t2 < math.inf:
                for j in range(nz):
                    x[j] += t * z[j]
            for a in range(k):
                u[a] -= t * r[a]
            u[k] += t
            if t2 <= t1:  # p joins the active set
                active[k] = p
                is_active[p] = True
                k += 1
                break
            is_active[active[drop]] = False  # a multiplier reached zero: it leaves
            for a in range(drop, k):
                active[a] = active[a + 1]
                u[a] = u[a + 1]
            k -= 1
        p = _most_broken(N, b, x, is_active, tol)
    return SOLVED, steps
