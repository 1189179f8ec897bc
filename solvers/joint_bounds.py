r"""Joint-rate bounds of one control step: velocity, position over the step, acceleration.

Three intervals are intersected by priority; where two are disjoint the one of higher
priority wins (the other is clipped into it), so that ``lb <= ub`` always holds:

1. velocity: :math:`-v_{max} \le \dot q \le v_{max}`, never violated;
2. position over one step, inside the range shrunk by the margin m (at most half the range):
   :math:`g\,(q_{min} + m - q)/dt \le \dot q \le g\,(q_{max} - m - q)/dt`, with the gain
   g in (0, 1] (pink's ``config_limit_gain``). The bound is exact in floating point: it is
   shrunk by :data:`SHRINK` so that ``q + qdot * dt`` computed in doubles (either order, with
   or without a fused multiply-add) never leaves the range for any rate within the bounds. A start
   outside the range makes the interval exclude zero: the joint must move back toward the
   range at the rate that reaches it in one step (times g), but never faster than
   :math:`v_{max}`, and may not move further out; a start outside by at most
   :data:`ON_LIMIT` counts as on the limit (the bound is zero, not negative). The problem
   stays feasible and recovers (where pink and mink raise, or their QP becomes infeasible);
3. acceleration, if given: :math:`|\dot q - \dot q_{prev}| \le a_{max} dt`; yields to the two
   above (stopping at a position limit, or returning under the velocity limit, may need more).
"""

from __future__ import annotations

import math
from typing import Literal, NamedTuple

import numpy as np
import numpy.typing as npt

from solvers.errors import InputError
from solvers.validation import as_vector, finite_number, real_array

Array = npt.NDArray[np.float64]

BoundKind = Literal["velocity", "position", "acceleration"]
KINDS: tuple[BoundKind, ...] = ("velocity", "position", "acceleration")
"""Names of the constraints a bound can come from."""

ON_LIMIT = 1e-12
"""[rad or m] A start at most this far outside the range counts as on its limit."""

SHRINK = 1.0 - 8.0 * float(np.finfo(np.float64).eps)
"""Factor on the position bounds that makes them exact in floating point (a relative change
of 1.8e-15: eight ulps against the six roundings of ``(high - q) * gain / dt * dt``)."""


class StepBounds(NamedTuple):
    """Joint-rate bounds of one step, and what sets each of them.

    Attributes:
        lb: Lower bounds (n,) [rad/s or m/s].
        ub: Upper bounds (n,), ``lb <= ub`` everywhere.
        contains_zero: True when standing still is allowed (no joint must move).
        recovering: True when a joint is outside its range and must move back (its position
            bounds exclude zero); zero can also be excluded by the acceleration limits alone
            (the arm cannot stop in one step), which is not recovering.
        velocity: The velocity limits (n,) the bounds were clipped into.
        position: The position bounds ``(lower, upper)`` (n,) before that clip.
        dt: The step [s].
        acceleration: The acceleration bounds ``(lower, upper)`` (n,) before they were clipped
            into the velocity and position bounds, or None without acceleration limits.
    """

    lb: Array
    ub: Array
    contains_zero: bool
    recovering: bool
    velocity: Array
    position: tuple[Array, Array]
    dt: float
    acceleration: tuple[Array, Array] | None = None

    def kind(self, joint: int, side: Literal["lower", "upper"]) -> BoundKind:
        """The constraint behind the ``side`` bound of ``joint``."""
        i = 0 if side == "lower" else 1
        bound = float((self.lb, self.ub)[i][joint])
        v = float(self.velocity[joint])
        if self.acceleration is not None:
            a = float(self.acceleration[i][joint])
            if bound == a and abs(a) < v:
                return "acceleration"
        position = float(self.position[i][joint])
        tighter = position > -v if i == 0 else position < v
        # neither its own position bound nor the velocity limit: clipped across to the
        # other side's position bound (an acceleration band beyond a position limit)
        return "position" if tighter or abs(bound) != v else "velocity"


class JointBounds:
    """An arm's joint limits, checked once, for the per-step :meth:`step`.

    Args:
        lower: Lower position limits (n,) [rad or m]; -inf allowed.
        upper: Upper position limits (n,), >= lower; +inf allowed.
        velocity: Velocity limits (n,) [rad/s or m/s], finite and > 0.
        margin: Distance kept from each position limit [rad or m], >= 0 (capped at half
            the range).
        acceleration: Acceleration limits (n,) or a scalar [rad/s^2 or m/s^2], > 0, or None.
        gain: Fraction in (0, 1] of the distance to a position bound allowed in one step.

    Raises:
        InputError: Wrong shapes, entries that are not real numbers (booleans, complex
            numbers, strings), NaN limits, lower > upper, velocity limits not finite and
            > 0, a negative margin, acceleration limits not > 0, a gain outside (0, 1].
    """

    def __init__(
        self,
        lower: npt.ArrayLike,
        upper: npt.ArrayLike,
        velocity: npt.ArrayLike,
        margin: float = 0.0,
        acceleration: npt.ArrayLike | None = None,
        gain: float = 1.0,
    ) -> None:
        v = as_vector(velocity, "velocity", np.size(velocity))
        n = v.size
        if np.any(v <= 0.0):
            raise InputError("velocity", f"expected velocity limits > 0, got {v}")
        lo, hi = _limits(lower, upper, n)
        m = finite_number(margin, "margin", 0.0)
        self.gain = finite_number(gain, "gain", 0.0, inclusive=False)
        if self.gain > 1.0:
            raise InputError("gain", f"expected a number in (0, 1], got {gain!r}")
        half = 0.5 * (hi - lo)
        self.n = n
        self.lower, self.upper, self.velocity, self.margin = lo, hi, v, m
        cut = np.minimum(m, half)
        self.low = lo + cut  # the range a step must stay in
        # capped at half the range: one point (rounding would leave low and high an ulp
        # apart, either way round, and an empty range cannot hold a step)
        self.high = np.where(m < half, np.maximum(hi - cut, self.low), self.low)
        self.acceleration: Array | None = None
        if acceleration is not None:
            a = real_array(acceleration, "acceleration")
            a = as_vector(np.full(n, a) if a.ndim == 0 else a, "acceleration", n)
            if np.any(a <= 0.0):
                raise InputError("acceleration", f"expected acceleration limits > 0, got {a}")
            self.acceleration = a
        self._minus_velocity = -v

    def step(self, q: Array, dt: float, qdot_prev: Array | None = None) -> StepBounds:
        """The bounds of one step of ``dt`` from ``q`` (module docstring); inputs not checked.

        Args:
            q: Joint positions (n,), finite.
            dt: Step [s], > 0.
            qdot_prev: Previous joint rates (n,) for the acceleration limits (zero if None).

        Returns:
            The :class:`StepBounds`.
        """
        # Exact in floating point: with k shrunk by SHRINK, fl(ub * dt) <= high - q for
        # high >= q (six roundings of at most eps each), so fl(q + qdot * dt) <= high for
        # every qdot <= ub, fused multiply-add or not; the same for lb.
        k = self.gain / dt * SHRINK
        lb, ub = (self.low - q) * k, (self.high - q) * k
        outside = excludes_zero(lb, ub)
        if outside:  # a joint outside its range: on its limit, or recovering
            on_limit = (q <= self.high + ON_LIMIT) & (q >= self.low - ON_LIMIT)
            lb[on_limit] = np.minimum(lb[on_limit], 0.0)
            ub[on_limit] = np.maximum(ub[on_limit], 0.0)
            outside = excludes_zero(lb, ub)
        position = (lb, ub)
        v, minus_v = self.velocity, self._minus_velocity
        if outside:  # the interval excludes zero: either side may lie beyond either limit
            lb, ub = np.minimum(np.maximum(lb, minus_v), v), np.minimum(np.maximum(ub, minus_v), v)
        else:  # lb <= 0 <= ub: one side each
            lb, ub = np.maximum(lb, minus_v), np.minimum(ub, v)
        if self.acceleration is None:
            return StepBounds(lb, ub, not outside, outside, self.velocity, position, dt)
        prev = np.zeros(self.n) if qdot_prev is None else qdot_prev
        reach = self.acceleration * dt
        wanted = (prev - reach, prev + reach)
        lb, ub = np.minimum(np.maximum(wanted, lb), ub)
        zero_ok = not excludes_zero(lb, ub)
        return StepBounds(lb, ub, zero_ok, outside, self.velocity, position, dt, wanted)


def excludes_zero(lb: Array, ub: Array) -> bool:
    """True when zero rates are outside ``lb <= qdot <= ub`` (lb > 0 or ub < 0 somewhere)."""
    # over Python lists: 8k instructions against 17k for numpy's reduction, at every tick
    return bool(max(lb.tolist()) > 0.0 or min(ub.tolist()) < 0.0)


def radius(lb: Array, ub: Array) -> float:
    """R, the norm of the largest joint rates within ``lb <= qdot <= ub`` [rad/s or m/s]."""
    return math.hypot(*np.maximum(-lb, ub).tolist())  # without overflow, as resolution.norm


def _limits(lower: npt.ArrayLike, upper: npt.ArrayLike, n: int) -> tuple[Array, Array]:
    lo = real_array(lower, "lower").copy()  # copies: later changes to the caller's arrays
    hi = real_array(upper, "upper").copy()  # do not count
    for name, arr in (("lower", lo), ("upper", hi)):
        if arr.shape != (n,):
            raise InputError(name, f"expected shape ({n},), got {arr.shape}")
        if np.any(np.isnan(arr)):
            raise InputError(name, "NaN entry")
    if np.any(lo > hi):
        raise InputError("lower", f"expected lower <= upper, got {lo} > {hi}")
    return lo, hi
