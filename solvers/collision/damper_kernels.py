r"""The velocity-damper rows of collision pairs, one compiled pass over every pair.

The damper is Kanehiro, Lamiraux, Kanoun, Yoshida & Laumond 2008.

A pair at signed distance :math:`d` (negative in penetration) with witness points
:math:`p_a` on body A, :math:`p_b` on body B and unit normal :math:`n` from A to B
(:math:`p_b - p_a = d\,n`) changes its distance at :math:`\dot d = n^T (v_b - v_a)`, the
witness points' velocities :math:`v = J_p \dot q`. The damper keeps

.. math:: \dot d \ge -\xi \frac{d - d_s}{d_i - d_s}
   \iff -n^T (J_b - J_a)\,\dot q \le \xi \frac{d - d_s}{d_i - d_s}

with :math:`d_s` the safety distance, :math:`d_i` the detection distance and :math:`\xi`
[m/s] the approach speed allowed at :math:`d_i`. Below :math:`d_s` (in penetration too) the
row asks that the distance not decrease, :math:`\dot d \ge -\epsilon` (:data:`SLACK`), so that
standing still meets it and the problem stays feasible whatever the start: any motion that does
not bring the pair closer is free, and a command away from it is met as it is. Asked to
separate at a rate instead (mink's rows in penetration), a start the user did not choose locked
the arm: the rate could not be met within the joints' velocity limits, or two pairs asked for
opposite motions (100 of 119 starting placements of panda against obstacles held, every tick,
even commanded away). A pair just below :math:`d_s`, at most ``band`` (the one-step
linearisation's error: the witness points' second-order motion over the step), is pushed back
out, at

.. math:: \dot d \ge \rho \min(d_s - d,\ 2\beta - (d_s - d)) / \Delta t

(:func:`damper_bound`, at most :math:`\xi`): the fraction :math:`\rho` of its shortfall a step
up to :math:`\beta`, falling linearly to nothing at :math:`2\beta` (continuous in the
distance). Without it, the second-order losses of a pair sliding at :math:`d_s` add up tick
after tick (baxter's fingers 0.4 mm below it in 8 s). Where no rates restore every such pair
(:mod:`rrc_pin.solvers.tick.pipeline`, ``_damped_within``), their rows ask only that they not
approach.

A point's linear Jacobian from its joint's Jacobian in Pinocchio's WORLD convention (the
spatial velocity at the world origin, :math:`[v_O; \omega]`, what
``pinocchio.getJointJacobian(model, data, j, WORLD)`` returns): :math:`v_p = v_O + \omega
\times p`, so

.. math:: n^T J_p = n^T J_v + (p \times n)^T J_\omega

over the joint's supporting columns (every other column zero). The WORLD Jacobians of all
joints are one (6, nv) matrix (``data.J``), masked per joint by its support.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.compiled import kernel

Array = npt.NDArray[np.float64]
Index = npt.NDArray[np.int64]

SLACK = 1e-9
"""[m/s] The least bound of a row not pushing its pair out (module docstring): a pair held at
d_s (bound 0) met by rates that cross it by rounding (1e-17) had the whole answer shrunk to zero by
the pipeline's last step (``rrc_pin.solvers.tick.pipeline._within_rows`` scales the rates back
into every row, and 0 / 1e-17 is 0): two hands held side by side stopped sliding. 1e-9 m/s is
6e-7 m in ten minutes."""


HELD = 1e-6
"""[m] A pair less than this below d_s is held (the bound :data:`SLACK`), not pushed back: the
damper brings pairs to d_s exponentially, and rounding leaves them a hair below it (a bound of
-1e-18 would turn every such tick into a recovery, the whole problem a least-squares one)."""


@kernel
def damper_bound(
    gap: float, span: float, gain: float, band: float, recovery: float
) -> float:  # fmt: skip
    r"""The bound [m/s] of a pair's row at ``gap`` = :math:`d - d_s` [m] (module docstring).

    Args:
        gap: The pair's distance less the safety distance [m].
        span: :math:`d_i - d_s` [m], > 0.
        gain: :math:`\xi` [m/s], the approach speed allowed at ``span``.
        band: :math:`\beta` [m] >= 0, the shortfall below d_s pushed back out.
        recovery: :math:`\rho / \Delta t` [1/s].
    """
    if gap > -HELD:
        return max(gain * gap / span, SLACK)
    shortfall = min(-gap, 2.0 * band + gap)
    if shortfall <= 0.0:
        return SLACK
    return max(-recovery * shortfall, -gain)


@kernel
def damper_rows(
    J: Array,
    support: npt.NDArray[np.bool_],
    joint_a: Index,
    joint_b: Index,
    point_a: Array,
    point_b: Array,
    normal: Array,
    distance: Array,
    pair: Index,
    safety: float,
    detection: float,
    xi: float,
    xi_end: float,
    blend: float,
    band: float,
    recovery: float,
    still: float,
    G: Array,
    h: Array,
    moved: npt.NDArray[np.bool_],
) -> int:
    """Fill the damper rows ``G qdot <= h`` of k pairs (module docstring).

    Args:
        J: Every joint's Jacobian in the WORLD convention (6, nv), rows [v_O; w].
        support: (njoints, nv) whether column c moves joint j (row 0, the world: none).
        joint_a: The joint of body A per pair (k,).
        joint_b: The joint of body B per pair (k,).
        point_a: Witness points on A (k, 3), world frame [m].
        point_b: Witness points on B (k, 3) [m].
        normal: Unit normals from A to B (k, 3).
        distance: Signed distances (k,) [m].
        pair: The pair of each row (k,): a pair's own row first, then its end points' rows.
        safety: d_s [m].
        detection: d_i [m], > d_s.
        xi: Approach speed allowed at d_i [m/s] of a pair's own row.
        xi_end: That of an end point's row ``blend`` [m] farther than its pair's own row, >=
            ``xi``; an end point's row as close as its pair's has ``xi``, linearly between.
        blend: See xi_end, > 0.
        band: beta [m], the shortfall below d_s pushed back out (:func:`damper_bound`).
        recovery: rho / dt [1/s], the rate of that push.
        still: A row whose every entry is at most this in size is not ``moved``.
        G: Out (k, nv).
        h: Out (k,) [m/s].
        moved: Out (k,), whether a row has an entry above ``still``.

    Returns:
        The number of rows not ``moved``.
    """
    k = distance.size
    nv = J.shape[1]
    span = detection - safety
    unmoved = 0
    own = 0.0  # the distance of the current pair's own row
    for r in range(k):
        gain = xi
        if r > 0 and pair[r] == pair[r - 1]:
            excess = min(max((distance[r] - own) / blend, 0.0), 1.0)
            gain = xi + (xi_end - xi) * excess
        else:
            own = distance[r]
        n0, n1, n2 = normal[r, 0], normal[r, 1], normal[r, 2]
        # p x n for each witness point
        a0 = point_a[r, 1] * n2 - point_a[r, 2] * n1
        a1 = point_a[r, 2] * n0 - point_a[r, 0] * n2
        a2 = point_a[r, 0] * n1 - point_a[r, 1] * n0
        b0 = point_b[r, 1] * n2 - point_b[r, 2] * n1
        b1 = point_b[r, 2] * n0 - point_b[r, 0] * n2
        b2 = point_b[r, 0] * n1 - point_b[r, 1] * n0
        ja, jb = joint_a[r], joint_b[r]
        largest = 0.0
        for c in range(nv):
            linear = n0 * J[0, c] + n1 * J[1, c] + n2 * J[2, c]
            value = 0.0
            if support[jb, c]:
                value -= linear + b0 * J[3, c] + b1 * J[4, c] + b2 * J[5, c]
            if support[ja, c]:
                value += linear + a0 * J[3, c] + a1 * J[4, c] + a2 * J[5, c]
            G[r, c] = value
            largest = max(largest, abs(value))
        moved[r] = largest > still
        if not moved[r]:
            unmoved += 1
        h[r] = damper_bound(distance[r] - safety, span, gain, band, recovery)
    return unmoved
