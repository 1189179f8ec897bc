r"""Exact direction-preserving step with one null-space direction: a linear program in the plane.

The 7-joint arm with a 6-row task has one null-space direction ``a`` (n,). The
direction-preserving problem (:func:`solvers.qp_problem.direction_problem`) then has two
variables, :math:`\dot q = z\,a + u\,w`, and its priority order is lexicographic: the
largest scale u first, then the null-space coordinate z nearest a target. Both steps are
solved exactly here, with no iteration over a tolerance:

1. :math:`\max u` s.t. :math:`lb \le z\,a + u\,w \le ub`, :math:`0 \le u \le 1`. Joint by
   joint, the feasible z form an interval :math:`[L_i(u), U_i(u)]` whose ends move linearly
   with u (joints with :math:`a_i = 0` bound u directly by a cap). The gap
   :math:`F(u) = \max_i L_i(u) - \min_j U_j(u)` is convex and piecewise linear with
   :math:`F(0) \le 0` (zero is feasible), so the largest feasible u is the root of F below
   the caps. Newton's method from the caps, on the pair (i, j) that attains F, moves down
   monotonically onto that root and stops after finitely many pairs (one to three in
   practice): each step's line lies below F and crosses zero at or above the root;
2. at that u, z is the target clipped into :math:`[\max_i L_i, \min_j U_j]`.

Feasible whenever the bounds contain zero (z = u = 0). n is small (the joints of one arm):
the arithmetic is done on Python floats, cheaper than numpy calls at this size.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

Array = npt.NDArray[np.float64]

MOVING = 1e-12
"""Joints with ``|a_i|`` at most this are not moved by the null direction (they cap u)."""


def max_scale_one_null(
    a: Array, w: Array, lb: Array, ub: Array, z_target: float = 0.0
) -> tuple[float, float]:
    r"""Lexicographic solution ``(z, u)`` of the plane LP (module docstring).

    Args:
        a: Null-space direction (n,), unit norm.
        w: Joint rates per unit of scale (n,).
        lb: Lower joint-rate bounds (n,), <= 0.
        ub: Upper joint-rate bounds (n,), >= 0.
        z_target: Preferred null-space coordinate.

    Returns:
        ``(z, u)`` with u in [0, 1] maximal and z nearest ``z_target`` at that u.
    """
    return plane_lp(a.tolist(), w.tolist(), lb.tolist(), ub.tolist(), z_target)


def plane_lp(
    a: list[float], w: list[float], lb: list[float], ub: list[float], z_target: float = 0.0
) -> tuple[float, float]:
    """:func:`max_scale_one_null` on lists of Python floats (the resolver's hot path)."""
    lo0: list[float] = []  # z interval of each moving joint at u = 0 ...
    hi0: list[float] = []
    slope: list[float] = []  # ... and the rate at which both of its ends move with u
    u = 1.0
    for ai, wi, li, ui in zip(a, w, lb, ub):  # noqa: B905
        if ai > MOVING or ai < -MOVING:
            p, r = li / ai, ui / ai
            if p > r:
                p, r = r, p
            lo0.append(p)
            hi0.append(r)
            slope.append(-wi / ai)
        elif wi > 0.0 and ui < u * wi:  # u w_i <= ub_i
            u = ui / wi
        elif wi < 0.0 and li > u * wi:
            u = li / wi
    u = max(u, 0.0)
    if not lo0:
        return z_target, u
    z_lo = z_hi = 0.0
    for _ in range(len(lo0) ** 2 + 1):  # at most one step per pair (i, j)
        low = [l0 + s * u for l0, s in zip(lo0, slope)]  # noqa: B905
        high = [h0 + s * u for h0, s in zip(hi0, slope)]  # noqa: B905
        z_lo, z_hi = max(low), min(high)
        if z_lo <= z_hi:
            break
        i, j = low.index(z_lo), high.index(z_hi)
        rate = slope[i] - slope[j]  # > 0: F(0) <= 0 < F(u)
        step = (hi0[j] - lo0[i]) / rate if rate > 0.0 else 0.0
        if not step < u:  # rounding at the root: u is the root
            break
        u = max(step, 0.0)
    if z_lo > z_hi:  # rounding at a degenerate vertex: the interval is a point
        z_lo = z_hi = 0.5 * (z_lo + z_hi)
    return min(max(z_target, z_lo), z_hi), u
