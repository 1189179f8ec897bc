r"""The step's joint box: each joint's rate bounds over one step, and what sets them.

:func:`joint_box` intersects the velocity limits, the position limits reached over the step and
the acceleration limits, by priority, exactly in floating point (:data:`SHRINK`). It is
:class:`~rrc_pin.limits.joint_limits.JointLimits`' kernel, called by the compiled tick too;
compiled by numba (``@njit(cache=True)``, through :func:`~rrc_pin.solvers.compiled.kernel`),
the same source runs as plain Python under ``NUMBA_DISABLE_JIT=1``. Its tests are
tests/test_joint_limits.py's.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.compiled import kernel

Array = npt.NDArray[np.float64]

ON_LIMIT = 1e-12
"""[rad or m] A start at most this far outside the range counts as on its limit."""

SHRINK = 1.0 - 8.0 * float(np.finfo(np.float64).eps)
"""Factor on the one-step position bounds that makes them exact in floating point (eight
ulps against the six roundings of ``(high - q) * gain / dt * dt``)."""

VELOCITY, POSITION, ACCELERATION = 0, 1, 2
"""Codes of what sets a joint-rate bound (:func:`joint_box`'s ``kind``)."""


@kernel
def joint_box(
    q: Array,
    lower: Array,
    upper: Array,
    velocity: Array,
    margin: float,
    gain: float,
    dt: float,
    previous: Array,
    acceleration: Array,
    lb: Array,
    ub: Array,
    kind: npt.NDArray[np.int8],
) -> tuple[bool, bool]:
    r"""Joint-rate bounds of one step: velocity, position over the step, acceleration.

    Three intervals intersected by priority (where two are disjoint the higher one wins):

    1. velocity :math:`|\dot q| \le v_{max}`, never violated;
    2. position over one step inside the range shrunk by the margin m (at most half of it):
       :math:`g\,(q_{min} + m - q)/dt \le \dot q \le g\,(q_{max} - m - q)/dt`, shrunk by
       :data:`SHRINK` so that ``q + qdot * dt`` in doubles (either order, fused or not) never
       leaves the range. A start outside the range makes the interval exclude zero: the joint
       moves back (at most at :math:`v_{max}`); one outside by at most :data:`ON_LIMIT` is on
       its limit (bound zero);
    3. acceleration :math:`|\dot q - \dot q_{prev}| \le a_{max}\,dt` (``inf`` for none), which
       yields to the two above.

    Args:
        q: Joint positions (n,) [rad or m].
        lower: Lower position limits (n,); -inf allowed.
        upper: Upper position limits (n,); +inf allowed.
        velocity: Velocity limits (n,) > 0 [rad/s or m/s].
        margin: Distance kept from each position limit [rad or m], >= 0.
        gain: Fraction in (0, 1] of the distance to a position bound allowed in one step.
        dt: Step [s] > 0.
        previous: Previous joint rates (n,) (for the acceleration bounds).
        acceleration: Acceleration limits (n,), or one for all (1,) [rad/s^2 or m/s^2];
            ``inf`` for none.
        lb: Out: lower bounds (n,).
        ub: Out: upper bounds (n,).
        kind: Out (2, n): what sets each bound, :data:`VELOCITY`, :data:`POSITION` or
            :data:`ACCELERATION` (row 0 the lower bounds, row 1 the upper).

    Returns:
        (contains_zero, recovering): whether standing still is allowed, and whether a joint
        is outside its range and must move back.
    """
    n = q.size
    k = gain / dt * SHRINK
    recovering = False
    for i in range(n):
        half = 0.5 * (upper[i] - lower[i])
        cut = min(margin, half)
        low = lower[i] + cut
        high = max(upper[i] - cut, low) if margin < half else low
        lo = (low - q[i]) * k
        hi = (high - q[i]) * k
        if (lo > 0.0 or hi < 0.0) and low - ON_LIMIT <= q[i] <= high + ON_LIMIT:
            lo, hi = min(lo, 0.0), max(hi, 0.0)  # on the limit: standing still allowed
        if lo > 0.0 or hi < 0.0:
            recovering = True
        v = velocity[i]
        kind[0, i] = POSITION if lo > -v else VELOCITY
        kind[1, i] = POSITION if hi < v else VELOCITY
        lb[i] = min(max(lo, -v), v)
        ub[i] = min(max(hi, -v), v)
        a = acceleration[i if acceleration.size > 1 else 0] * dt
        if a < math.inf:
            want_lo, want_hi = previous[i] - a, previous[i] + a
            if lb[i] < want_lo <= ub[i]:
                lb[i], kind[0, i] = want_lo, ACCELERATION
            elif want_lo > ub[i]:  # clipped across: the upper bound's constraint sets both
                lb[i], kind[0, i] = ub[i], kind[1, i]
            if lb[i] <= want_hi < ub[i]:
                ub[i], kind[1, i] = want_hi, ACCELERATION
            elif want_hi < lb[i]:
                ub[i], kind[1, i] = lb[i], kind[0, i]
    contains_zero = True
    for i in range(n):
        if lb[i] > 0.0 or ub[i] < 0.0:
            contains_zero = False
    return contains_zero, recovering
