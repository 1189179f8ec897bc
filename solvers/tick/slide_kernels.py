r"""The sliding stage's QP, solved by hand: a projection in a definite metric onto a polytope.

.. math:: \min_{\dot q}\ (\dot q - w)^T M (\dot q - w) \quad \text{s.t.}\quad
   lb \le \dot q \le ub,\ G\dot q \le h

with :math:`M = B^TB` definite, B the rows of the metric (:func:`slide_metric`: :math:`A^TA`
damped on A's null space and past the damping threshold; n of a few tens at most, a few tens
of rows). With
:math:`M = LL^T` and :math:`y = L^T(\dot q - w)` it is the least-distance problem
:math:`\min \|y\|` s.t. :math:`E^T y \ge f` (Lawson & Hanson 1974, chapter 23), whose answer
comes from the non-negative least squares :math:`\min_{u \ge 0} \|[E; f^T] u - e_{n+1}\|`
(their algorithm NNLS, chapter 23.3): with :math:`r` its residual,
:math:`y = -r_{1..n} / r_{n+1}`, and :math:`r = 0` where the constraints admit no point.

Each constraint's column is divided by the norm of its part in y (a constraint times a
positive number is the same constraint), so that NNLS's tolerances read alike for every row.
Only the constraints that ``w`` breaks enter first; those the answer then breaks are added and
the problem solved again (the optimum over fewer constraints that meets them all is the
optimum over all): the answer rarely meets more than a few of a collision limit's rows.
The caller checks the answer against the constraints (the kernel's only failure mode left is
rounding, which that check catches) and falls back to a QP backend where it is refused.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.compiled import inlined, kernel
from rrc_pin.solvers.linalg import cholesky, solve_factored

Array = npt.NDArray[np.float64]
Ints = npt.NDArray[np.int64]

SOLVED, NOT_DEFINITE, INFEASIBLE, NOT_CONVERGED = 0, 1, 2, 3
"""What :func:`project` returns."""

TINY = 2.2250738585072014e-308
"""The smallest normal double: the least damping of :func:`project`'s metric."""

MARGIN = 1e-12
"""[relative above 1] How far inside its rows :func:`project`'s answer is sought: an answer on a
row at 0 must not cross it by 1e-17 (the pipeline's last step would shrink the whole answer to
zero)."""

CHECK = 1e-9
"""Relative violation of a constraint beyond which :func:`project`'s answer is refused
(INFEASIBLE: constraints that admit no point leave a residual of rounding in NNLS)."""


@kernel
def _damped_gram(A: Array, damping: float) -> tuple[Array, float]:
    r""":math:`M = A^TA + \mu I` (n, n) and :math:`\mu` of rows A (m, n), as in :func:`project`."""
    rows, n = A.shape
    M = np.empty((n, n))
    trace = 0.0
    for i in range(n):
        for j in range(i + 1):
            t = 0.0
            for r in range(rows):
                t += A[r, i] * A[r, j]
            M[i, j] = t
            M[j, i] = t
        trace += M[i, i]
    mu = max(damping * trace / max(rows, 1), TINY)
    for i in range(n):
        M[i, i] += mu
    return M, mu


@kernel
def project(
    A: Array, damping: float, w: Array, lb: Array, ub: Array, G: Array, h: Array, margin: float,
    x: Array,
) -> int:  # fmt: skip
    r"""``x`` the point of the box and rows nearest to ``w`` in the metric M (module docstring).

    Args:
        A: Rows (m, n) of the metric :math:`M = A^TA + \mu I`, :math:`\mu` = ``damping``
            times :math:`\operatorname{tr}(A^TA) / m` (the mean squared singular value of A,
            for m <= n), or at least the smallest normal double.
        damping: See A, >= 0 (0: the least squares of A alone, M definite).
        w: The point projected (n,).
        lb: Lower bounds (n,), -inf allowed.
        ub: Upper bounds (n,), +inf allowed.
        G: Rows (p, n).
        h: Their bounds (p,), met with ``margin * (1 + |h|)`` to spare.
        margin: See h (rounding: an answer on a row at 0 must not cross it by 1e-17).
        x: Out (n,), set when SOLVED.

    Returns:
        SOLVED, NOT_DEFINITE (M's Cholesky failed), INFEASIBLE (no point meets the
        constraints, or a row with no entries is broken at w) or NOT_CONVERGED (an iteration
        limit, or a degenerate passive set).
    """
    n = w.size
    M = _damped_gram(A, damping)[0]
    L = np.zeros((n, n))
    if not cholesky(M, 1e-13, L):
        return NOT_DEFINITE
    return project_factored(L, w, lb, ub, G, h, margin, x)


@kernel
def project_factored(L: Array, w: Array, lb: Array, ub: Array, G: Array, h: Array,
                     margin: float, x: Array) -> int:  # fmt: skip
    r""":func:`project` in the metric :math:`M = LL^T` of its Cholesky factor ``L`` (n, n)
    (lower triangular, zeros above), for a caller that has factorised M already; the other
    arguments and the codes are :func:`project`'s (NOT_DEFINITE never).
    """  # noqa: D205
    n = w.size
    p = h.size
    tight = np.empty(p)
    for r in range(p):
        tight[r] = h[r] - margin * (1.0 + abs(h[r]))
    h = tight
    total = 2 * n + p
    E = np.empty((n + 1, total))  # the columns of the constraints taken in, in order
    taken = np.zeros(total, dtype=np.bool_)
    m = 0
    for _ in range(total + 1):
        # the constraints the current point (w, then the last answer) breaks
        added = 0
        point = w if m == 0 else x
        for r in range(total):
            if taken[r]:
                continue
            if _value(r, n, point, lb, ub, G, h) > 0.0:
                taken[r] = True
                code = _column(r, n, L, w, lb, ub, G, h, E, m)
                if code == INFEASIBLE:
                    return INFEASIBLE
                if code == SOLVED:
                    m += 1
                added += 1
        if added == 0:
            if m == 0:  # w meets every constraint
                for i in range(n):
                    x[i] = w[i]
            return _checked(n, x, lb, ub, G, h)
        code = _least_distance(E, m, n, L, w, x)
        if code != SOLVED:
            return code
    return NOT_CONVERGED


@kernel
def _value(r: int, n: int, x: Array, lb: Array, ub: Array, G: Array, h: Array) -> float:
    """How far constraint ``r`` (upper bounds, lower bounds, rows) is broken at ``x``."""
    if r < n:
        return float(x[r] - ub[r]) if ub[r] < math.inf else -math.inf
    if r < 2 * n:
        return float(lb[r - n] - x[r - n]) if lb[r - n] > -math.inf else -math.inf
    t = -float(h[r - 2 * n])
    for i in range(n):
        t += G[r - 2 * n, i] * x[i]
    return t


@kernel
def _column(
    r: int, n: int, L: Array, w: Array, lb: Array, ub: Array, G: Array, h: Array, E: Array,
    m: int,
) -> int:  # fmt: skip
    """Write constraint ``r``'s column ``[-L^{-1} c; c^T w - d] / |L^{-1} c|`` as E's ``m``-th.

    Returns SOLVED, INFEASIBLE (a row of zeros broken at w) or NOT_DEFINITE (a row of zeros
    kept: no column written).
    """
    c = np.zeros(n)
    if r < 2 * n:
        i = r % n
        c[i] = 1.0 if r < n else -1.0
        d = ub[i] if r < n else -lb[i]
    else:
        d = h[r - 2 * n]
        for k in range(n):
            c[k] = G[r - 2 * n, k]
    a = np.empty(n)
    norm = 0.0
    value = -d
    for i in range(n):
        s = c[i]
        for k in range(i):
            s -= L[i, k] * a[k]
        a[i] = s / L[i, i]
        norm += a[i] * a[i]
        value += c[i] * w[i]
    norm = math.sqrt(norm)
    if norm == 0.0:
        return INFEASIBLE if value > 0.0 else NOT_DEFINITE
    for i in range(n):
        E[i, m] = -a[i] / norm
    E[n, m] = value / norm
    return SOLVED


@kernel
def _checked(n: int, x: Array, lb: Array, ub: Array, G: Array, h: Array) -> int:
    """SOLVED where ``x`` meets every constraint to :data:`CHECK` (rounding), else INFEASIBLE."""
    for i in range(n):
        if x[i] > ub[i] + CHECK * (1.0 + abs(ub[i])) or x[i] < lb[i] - CHECK * (1.0 + abs(lb[i])):
            return INFEASIBLE
    for r in range(h.size):
        t = 0.0
        for i in range(n):
            t += G[r, i] * x[i]
        if not t <= h[r] + CHECK * (1.0 + abs(h[r])):
            return INFEASIBLE
    return SOLVED


@inlined
def _entering(E: Array, m: int, n: int, passive: npt.NDArray[np.bool_], resid: Array,
              tol: float) -> int:  # fmt: skip
    """NNLS's most promising inactive column (its gradient ``E^T resid`` above ``tol``), or -1."""
    best, entering = tol, -1
    for j in range(m):
        if passive[j]:
            continue
        t = 0.0
        for i in range(n + 1):
            t += E[i, j] * resid[i]
        if t > best:
            best, entering = t, j
    return entering


@inlined
def _passive_solve(E: Array, m: int, n: int, passive: npt.NDArray[np.bool_], index: Ints,
                   H: Array, g: Array, z: Array, s: Array) -> int:  # fmt: skip
    """The least squares on the k passive columns into ``s`` (zero elsewhere), by the normal
    equations' Cholesky factor (in ``H``), their indices into ``index``: k, or -1 where more
    columns are passive than E has rows or the factor fails.
    """  # noqa: D205
    k = 0
    for j in range(m):
        if passive[j]:
            if k == n + 1:
                return -1
            index[k] = j
            k += 1
    for i in range(k):
        ci = index[i]
        for j in range(i + 1):
            cj = index[j]
            t = 0.0
            for r in range(n + 1):
                t += E[r, ci] * E[r, cj]
            H[i, j] = t
        g[i] = E[n, ci]
    # in place; the columns' unit parts make every diagonal entry at least 1
    if not cholesky(H[:k, :k], 0.0, H[:k, :k], 1e-14):
        return -1
    solve_factored(H[:k, :k], g[:k], z[:k])
    for j in range(m):
        s[j] = 0.0
    for i in range(k):
        s[index[i]] = z[i]
    return k


@inlined
def _step_back(u: Array, s: Array, passive: npt.NDArray[np.bool_], index: Ints, k: int) -> None:
    """``u`` stepped toward ``s`` until a passive coefficient reaches zero, which is dropped."""
    alpha = 1.0
    for i in range(k):
        j = index[i]
        if not s[j] > 0.0:
            t = u[j] / (u[j] - s[j])
            if t < alpha:
                alpha = t
    for i in range(k):
        j = index[i]
        u[j] += alpha * (s[j] - u[j])
        if not u[j] > 1e-300 or (not s[j] > 0.0 and u[j] <= 1e-15 * (1.0 + abs(s[j]))):
            u[j] = 0.0
            passive[j] = False


@inlined
def _nnls(E: Array, m: int, n: int, resid: Array, z: Array) -> bool:
    """Lawson & Hanson's NNLS on E's first ``m`` columns (module docstring): its residual
    ``e_n - E u`` into ``resid``; False where it did not converge. ``z`` is scratch (n + 1,).
    """  # noqa: D205
    u, s = np.zeros(m), np.zeros(m)
    passive = np.zeros(m, dtype=np.bool_)
    resid[:] = 0.0
    resid[n] = 1.0
    index = np.empty(n + 1, dtype=np.int64)
    H, g = np.empty((n + 1, n + 1)), np.empty(n + 1)
    scale_f = 0.0
    for j in range(m):
        scale_f = max(scale_f, abs(E[n, j]))
    tol = 1e-12 * (1.0 + scale_f)
    for _ in range(3 * (m + n + 1)):
        entering = _entering(E, m, n, passive, resid, tol)
        if entering < 0:
            return True
        passive[entering] = True
        converged = False
        for _inner in range(3 * (m + n + 1)):
            k = _passive_solve(E, m, n, passive, index, H, g, z, s)
            if k < 0:
                return False
            positive = True
            for i in range(k):
                if not s[index[i]] > 0.0:
                    positive = False
            if positive:
                u[:] = s
                converged = True
                break
            _step_back(u, s, passive, index, k)
        if not converged:
            return False
        for i in range(n + 1):
            t = 1.0 if i == n else 0.0
            for j in range(m):
                t -= E[i, j] * u[j]
            resid[i] = t
    return False


@kernel
def _least_distance(E: Array, m: int, n: int, L: Array, w: Array, x: Array) -> int:
    """``x = w + L^{-T} y``, y the least-distance answer of E's first ``m`` columns (NNLS)."""
    resid, z = np.empty(n + 1), np.empty(n + 1)
    if not _nnls(E, m, n, resid, z):
        return NOT_CONVERGED
    # r = E u - e_n = -resid; y = -r[:n] / r[n] = -resid[:n] / resid[n]
    norm_sq = 0.0
    for i in range(n + 1):
        norm_sq += resid[i] * resid[i]
    if not resid[n] > 1e-14 or not norm_sq > 1e-28:
        return INFEASIBLE
    # x = w + L^{-T} y (back substitution)
    for i in range(n - 1, -1, -1):
        t = -resid[i] / resid[n]
        for k in range(i + 1, n):
            t -= L[k, i] * z[k]
        z[i] = t / L[i, i]
    for i in range(n):
        x[i] = w[i] + z[i]
    return SOLVED


@kernel
def slide_metric(
    A: Array, US: Array, sigma: Array, right: Array, rank: int, null: Array, b: Array,
    damping: float, threshold: float, B: Array, target: Array,
) -> int:  # fmt: skip
    r"""The sliding stage's metric as rows B (:math:`M = B^TB`) and the point it pulls toward.

    .. math:: M = A^TA + \sum_{i<r} f_i v_iv_i^T + \mu N^TN, \qquad
       f_i = \mu\,\max\big(0,\ 1 - (\sigma_i/\sigma_{on})^2\big)

    with :math:`A = U\Sigma V^T` of rank r, N (d, n) orthonormal rows spanning its null space,
    :math:`\mu` = ``damping`` times the mean squared singular value
    :math:`\operatorname{tr}(A^TA)/m` (at least the smallest normal double) and the onset
    :math:`\sigma_{on} = \sigma_1/\kappa` of the top level's damping
    (:mod:`rrc_pin.solvers.tick.damping`, ``threshold`` :math:`\kappa`; inf: none). A direction
    A moves well (:math:`\sigma_i \ge \sigma_{on}`) is not damped; one below the onset is,
    smoothly from zero at the onset (Maciejewski & Klein 1988's onset) to :math:`\mu` at a
    singularity; the null space costs :math:`\mu`, which makes the answer one point.

    The target minimises :math:`\|A\dot q - b\|^2 + (\dot q - t)^TD(\dot q - t)` (D the
    damping terms of M, t :math:`= M^{-1}A^Tb` the damped least squares): along
    :math:`v_i`, :math:`\beta_i\sigma_i(\sigma_i^2 + 2f_i)/(\sigma_i^2 + f_i)^2` with
    :math:`\beta_i = u_i^Tb`, the exact :math:`\beta_i/\sigma_i` where undamped, bounded
    through a singularity; zero in the null space (t has none).

    Args:
        A: The rows (m, n).
        US: :math:`U\Sigma` (m, k) of A's SVD, k = min(m, n).
        sigma: Singular values (k,), descending.
        right: Right singular vectors (n, k).
        rank: How many singular values count.
        null: Orthonormal rows (d, n), d = n - rank, spanning A's null space.
        b: The command (m,).
        damping: See :math:`\mu`, > 0.
        threshold: :math:`\kappa` >= 1, or inf for no damping of A's range.
        B: Out: the metric's rows, the first returned count of its (m + n, n) written.
        target: Out (n,).

    Returns:
        The number of rows of B written: m, the damped directions, then d.
    """
    m, n = A.shape
    trace = 0.0
    for i in range(sigma.size):
        trace += sigma[i] * sigma[i]
    mu = max(damping * trace / max(m, 1), TINY)
    onset = sigma[0] / threshold if sigma.size and rank > 0 else 0.0
    for i in range(m):
        for j in range(n):
            B[i, j] = A[i, j]
    rows: int = m
    for j in range(n):
        target[j] = 0.0
    for i in range(rank):
        s = sigma[i]
        f = 0.0
        if s < onset:
            ratio = s / onset
            f = mu * (1.0 - ratio * ratio)
        beta = 0.0
        for r in range(m):
            beta += US[r, i] * b[r]
        beta /= s  # u_i^T b
        coefficient = beta * s * (s * s + 2.0 * f) / ((s * s + f) * (s * s + f))
        root = math.sqrt(f)
        for j in range(n):
            target[j] += coefficient * right[j, i]
            if f > 0.0:
                B[rows, j] = root * right[j, i]
        if f > 0.0:
            rows += 1
    root = math.sqrt(mu)
    for i in range(null.shape[0]):
        for j in range(n):
            B[rows, j] = root * null[i, j]
        rows += 1
    return rows
