r"""The direction-preserving problem: the largest scale of a command within the bounds.

With w the joint rates of the (damped) command and :math:`V_n` (d, n) an orthonormal basis
of the Jacobian's null space, every

.. math::

    \dot q = u\,w + V_n^T y \quad\Rightarrow\quad J\dot q = u\,Jw

moves the hand along the command at the fraction u of its speed, whatever y. The problem is

.. math::

    \max_{u, y}\ u \quad \text{s.t.} \quad lb \le u\,w + V_n^T y \le ub,\ 0 \le u \le 1

(Drake's differential IK formulation, with the null space parametrised so that there are
no rank-deficient equality rows), then the least-norm y. Solved here:

- no null space (d = 0): the largest u of uniform scaling (:func:`uniform_scale`);
- a null space of one dimension (d = 1: a 7-joint arm's six rows): exactly, by eliminating
  y (:func:`line_scale`);
- otherwise as a QP (:func:`direction_qp`) for the backend, or as an LP by scipy's HiGHS
  (:func:`direction_lp`, exact: the fallback when the backend fails).
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from solvers.errors import ProblemError
from solvers.joint_bounds import radius
from solvers.qp import QP, Decoding
from solvers.resolution import norm

Array = npt.NDArray[np.float64]

REGULARIZATION = 1e-4
r"""Weight :math:`\epsilon` of :math:`\tfrac12 u^2 + \tfrac12\|y\|^2/R^2` in the direction QP
(R the radius of the bounds). Measured on panda's benchmark trajectory (1,500 QPs, one null
direction, before :func:`line_scale` took those): the scale within 1.3e-10 of the exact LP
maximum; below 1e-6 DAQP declared up to 12% of these (feasible) problems infeasible."""


def uniform_scale(x: Array, lb: Array, ub: Array) -> float:
    """Largest s in [0, 1] with ``lb <= s x <= ub``, for bounds with ``lb <= 0 <= ub``.

    Args:
        x: Rates (n,).
        lb: Lower bounds (n,) <= 0 (not checked).
        ub: Upper bounds (n,) >= 0 (not checked).
    """
    s = 1.0
    for xi, low, high in zip(x.tolist(), lb.tolist(), ub.tolist(), strict=True):
        if xi > 0.0:
            s = min(s, high / xi)
        elif xi < 0.0:
            s = min(s, low / xi)
    return s


def line_scale(w: Array, v: Array, lb: Array, ub: Array) -> tuple[float, float]:
    r"""The direction problem with a null space of one dimension, exactly: u and y.

    Every row :math:`lb_i \le u w_i + y v_i \le ub_i` is two half-planes
    :math:`\alpha u + \beta y \le \gamma` (:math:`\gamma \ge 0`: u = y = 0 is feasible).
    Eliminating y (Fourier-Motzkin) between each half-plane bounding y from above
    (:math:`\beta > 0`) and each bounding it from below leaves bounds on u alone; the largest
    u in [0, 1] meets them all, and y is the value nearest zero that it allows (the
    lexicographic answer the QP's small regularisation approximates: where the largest u
    leaves one y, the QP may give up some 1e-6 of u for a smaller y). n rows make at most
    n^2 pairs: 49 for seven joints, over Python floats.

    Args:
        w: Rates of the command (n,).
        v: Null-space direction (n,).
        lb: Lower joint-rate bounds (n,) <= 0 (not checked).
        ub: Upper joint-rate bounds (n,) >= 0 (not checked).

    Returns:
        u in [0, 1] and y; the rates are ``u w + y v``.
    """
    above, below = [], []  # half-planes (alpha, beta, gamma) bounding y from above / below
    without_y = []  # rows that bound u alone: the uniform scale of their rates
    rows = zip(w.tolist(), v.tolist(), lb.tolist(), ub.tolist(), strict=True)
    for i, (wi, vi, lo, hi) in enumerate(rows):
        if vi > 0.0:
            above.append((wi, vi, hi))
            below.append((-wi, -vi, -lo))
        elif vi < 0.0:
            above.append((-wi, -vi, -lo))
            below.append((wi, vi, hi))
        else:
            without_y.append(i)
    u = uniform_scale(w[without_y], lb[without_y], ub[without_y]) if without_y else 1.0
    for a1, b1, g1 in above:
        for a2, b2, g2 in below:  # -b2 * (plane 1) + b1 * (plane 2): y eliminated
            coefficient = b1 * a2 - b2 * a1
            if coefficient > 0.0 and b1 * g2 - b2 * g1 < u * coefficient:
                u = (b1 * g2 - b2 * g1) / coefficient
    u = max(u, 0.0)
    y_hi, v_hi = min([((g - a * u) / b, b) for a, b, g in above], default=(math.inf, 1.0))
    y_lo, v_lo = max([((g - a * u) / b, -b) for a, b, g in below], default=(-math.inf, 1.0))
    if y_lo <= y_hi:
        return u, min(max(0.0, y_lo), y_hi)
    # Rounding at a vertex: the y that leaves both rows by the same rate. A row with a tiny
    # v_i (the SVD leaves 1e-15 where a joint is outside the null space) pins u, and its y
    # bound, rounding over v_i, is off by up to 0.1: min(y_lo, y_hi) took it and left the
    # other row 0.02 rad/s outside its bound (rrc_k1607 at q = 0, commands of 1e6).
    return u, (v_lo * y_lo + v_hi * y_hi) / (v_lo + v_hi)


def direction_qp(w: Array, null: Array, lb: Array, ub: Array, key: str) -> tuple[QP, Decoding]:
    """The direction problem as a QP in z = (y, u) for the backend (module docstring).

    w is first capped to the radius R of the bounds (no feasible rates are longer, and w is
    orthogonal to the null space), so that u is of order one for any command.

    Args:
        w: Rates of the command (n,), in the row space.
        null: Null-space basis (d, n).
        lb: Lower joint-rate bounds (n,) <= 0.
        ub: Upper joint-rate bounds (n,) >= 0.
        key: Warm-start key of the problem.

    Returns:
        The QP (its rows are the joint-rate bounds) and its decoding ``qdot = M z``.
    """
    d, n = null.shape
    R = radius(lb, ub)
    length = norm(w)
    M = np.empty((n, d + 1))
    M[:, :d] = null.T
    M[:, d] = w * (R / length) if length > R else w
    eps = REGULARIZATION
    P = np.zeros((d + 1, d + 1))
    P.flat[:: d + 2] = eps / (R * R or 1.0)
    P[d, d] = eps
    q = np.array([0.0] * d + [-1.0])
    z_lb = np.array([-np.inf] * d + [0.0])
    z_ub = np.array([np.inf] * d + [1.0])
    return QP(P, q, M, lb, ub, z_lb, z_ub, key), Decoding(None, M)


def direction_lp(M: Array, C: Array, lo: Array, hi: Array) -> Array:
    """The largest u of a direction problem by scipy's HiGHS (exact, any y).

    Args:
        M: Decoding (n, d + 1) of z = (y, u) into joint rates.
        C: Constraint rows (nc, d + 1) of z.
        lo: Their lower bounds (nc,), -inf allowed.
        hi: Their upper bounds (nc,).

    Returns:
        The joint rates ``M z`` (n,).

    Raises:
        ProblemError: HiGHS found no solution (one exists when the bounds contain zero).
    """
    from scipy.optimize import linprog

    d = M.shape[1] - 1
    cost = np.zeros(d + 1)
    cost[d] = -1.0
    finite = np.isfinite(lo)
    try:
        result = linprog(
            cost,
            A_ub=np.vstack([C, -C[finite]]),
            b_ub=np.concatenate([hi, -lo[finite]]),
            bounds=[(None, None)] * d + [(0.0, 1.0)],
            method="highs",
        )
    except ValueError as exc:  # data linprog refuses (non-finite entries)
        raise ProblemError(f"linprog: {exc}") from exc
    if result.status != 0 or result.x is None:
        raise ProblemError(f"linprog: {result.message}")
    return np.asarray(M @ result.x, dtype=np.float64)
