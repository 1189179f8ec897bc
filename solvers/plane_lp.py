r"""Exact direction-preserving step with one null-space direction: a linear program in the plane.

The 7-joint arm with a 6-row task has one null-space direction ``a`` (n,). The
direction-preserving problem (:func:`solvers.qp_problem.direction_problem`) then has two
variables, :math:`\dot q = z\,a + u\,w`, and its priority order is lexicographic: the
largest scale u first, then the null-space coordinate z nearest a target. Both steps are
solved exactly here, with no iteration:

1. :math:`\max u` s.t. :math:`lb \le z\,a + u\,w \le ub`, :math:`0 \le u \le 1`. Joint by
   joint, the feasible z form an interval :math:`[L_i(u), U_i(u)]` whose ends move linearly
   with u (joints with :math:`a_i = 0` bound u directly); the largest u is the first
   crossing :math:`L_i(u) = U_j(u)` over all pairs, O(n^2) numbers;
2. at that u, z is the target clipped into :math:`[\max_i L_i, \min_j U_j]`.

Feasible whenever the bounds contain zero (z = u = 0).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

Array = npt.NDArray[np.float64]

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
    moving = np.abs(a) > 1e-12
    u_max = 1.0
    fixed = ~moving  # joints the null direction does not move: u w_i in [lb_i, ub_i]
    if fixed.any():
        wf = w[fixed]
        with np.errstate(divide="ignore", invalid="ignore"):
            caps = np.where(wf > 0.0, ub[fixed] / wf, np.where(wf < 0.0, lb[fixed] / wf, np.inf))
        u_max = min(u_max, float(caps.min()))
    inv = 1.0 / a[moving]
    p, r = lb[moving] * inv, ub[moving] * inv
    lo0, hi0 = np.minimum(p, r), np.maximum(p, r)  # z interval of each joint at u = 0
    slope = -w[moving] * inv  # both ends move by slope * u
    c1 = slope[:, None] - slope[None, :]  # L_i - U_j grows at this rate ...
    c0 = lo0[:, None] - hi0[None, :]  # ... from this value (<= 0: z = 0 fits at u = 0)
    binding = c1 > 1e-15 * (1.0 + np.abs(slope).max(initial=0.0))
    if binding.any():
        u_max = min(u_max, float((-c0[binding] / c1[binding]).min()))
    u = min(max(u_max, 0.0), 1.0)
    z_lo = float((lo0 + slope * u).max(initial=-np.inf))
    z_hi = float((hi0 + slope * u).min(initial=np.inf))
    if z_lo > z_hi:  # rounding at a degenerate vertex: the interval is a point
        z_lo = z_hi = 0.5 * (z_lo + z_hi)
    return min(max(z_target, z_lo), z_hi), u
