r"""Joint-rate bounds of one control step: velocity, position over the step, acceleration.

:func:`joint_velocity_bounds` is the one definition; :class:`JointLimits` holds an arm's
limits prepared once so that a control loop pays only a handful of vector operations per
step. Three intervals are intersected by priority (velocity, then position, then
acceleration); where two are disjoint the one of higher priority wins (the other is clipped
into it), so that ``lb <= ub`` always holds:

1. velocity: :math:`-v_{max} \le \dot q \le v_{max}`, never violated;
2. position over one step, inside the range shrunk by the margin m (at most half the range)
   and widened by :data:`ROUNDING`:
   :math:`g\,(q_{min} + m - q)/dt \le \dot q \le g\,(q_{max} - m - q)/dt`. A start outside
   that range makes the interval exclude zero: the joint must move back toward the range at
   the rate that reaches it in one step (times the gain g), but never faster than
   :math:`v_{max}`, and may not move further out. The problem stays feasible and recovers
   (where pink and mink raise, or their QP becomes infeasible);
3. acceleration, if given: :math:`|\dot q - \dot q_{prev}| \le a_{max} dt`; yields to the two
   above (stopping at a position limit, or returning under the velocity limit, may need more).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from solvers.errors import InputError
from solvers.validation import as_vector, positive

Array = npt.NDArray[np.float64]

VELOCITY, POSITION, ACCELERATION = 0, 1, 2
BOUND_KINDS: tuple[str, ...] = ("velocity", "position", "acceleration")
"""Names of the constraints a bound can come from, indexed by the codes above."""

ROUNDING = 1e-13
"""[rad or m] The range a step must stay in is widened by this much on each side.

Integrating ``q + qdot dt`` up to a bound lands within a few ulp of it; without this
tolerance the next step would see a start "outside" the range by 1e-16 and ask to move back
(and the direction-preserving problem, which needs zero within the bounds, would be skipped).
A step may therefore end up to ROUNDING outside the (margin-shrunk) range.
"""


class VelocityBounds:
    """Joint-rate bounds of one step and the constraint each bound comes from.

    Args:
        lb: Lower bounds (n,) [rad/s or m/s].
        ub: Upper bounds (n,), ``lb <= ub`` everywhere.
        lower_kind: Codes of the constraints behind ``lb`` (see below), or None.
        upper_kind: Same for ``ub``.
        velocity_limit: The velocity limits v the bounds were clipped into: without codes,
            a bound strictly inside [-v, v] is a position bound, one at -v or v a velocity
            bound (computed on first access). Neither: every bound is a velocity bound.

    Attributes:
        lb: Lower bounds (n,) [rad/s or m/s] (built on first access when the bounds were
            made by :meth:`from_lists`).
        ub: Upper bounds (n,), ``lb <= ub`` everywhere.
        lower_kind: Code (n,) of the constraint setting ``lb``: an index of
            :data:`BOUND_KINDS`.
        upper_kind: Same for ``ub``.
    """

    __slots__ = ("_kinds", "_lb", "_lists", "_ub", "_v_max")

    def __init__(
        self,
        lb: Array,
        ub: Array,
        lower_kind: npt.NDArray[np.int8] | None = None,
        upper_kind: npt.NDArray[np.int8] | None = None,
        *,
        velocity_limit: Array | None = None,
    ) -> None:
        self._lb: Array | None = lb
        self._ub: Array | None = ub
        self._lists: tuple[list[float], list[float]] | None = None
        both = lower_kind is not None and upper_kind is not None
        self._kinds = (lower_kind, upper_kind) if both else None
        self._v_max = velocity_limit

    @classmethod
    def from_lists(
        cls, lb: list[float], ub: list[float], velocity_limit: Array | None = None
    ) -> VelocityBounds:
        """Bounds given as Python floats; the arrays are built only if asked for.

        The resolver's hot path compares a handful of rates with the bounds: on lists of
        floats that costs less than a numpy call.
        """
        bounds = cls.__new__(cls)
        bounds._lb = bounds._ub = None
        bounds._lists = (lb, ub)
        bounds._kinds = None
        bounds._v_max = velocity_limit
        return bounds

    @property
    def lb(self) -> Array:
        """See the class docstring."""
        if self._lb is None:
            self._lb = np.array(self._lists[0])  # type: ignore[index]
        return self._lb

    @property
    def ub(self) -> Array:
        """See the class docstring."""
        if self._ub is None:
            self._ub = np.array(self._lists[1])  # type: ignore[index]
        return self._ub

    def lists(self) -> tuple[list[float], list[float]]:
        """``(lb, ub)`` as lists of Python floats (made once)."""
        if self._lists is None:
            self._lists = (self.lb.tolist(), self.ub.tolist())
        return self._lists

    def _kind(self) -> tuple[npt.NDArray[np.int8], npt.NDArray[np.int8]]:
        if self._kinds is None:
            if self._v_max is None:
                zeros = np.zeros(self.lb.size, dtype=np.int8)
                self._kinds = (zeros, zeros)
            else:
                # POSITION (1) where the position bound is tighter than the velocity limit v:
                # after clipping into [-v, v] that is lb > -v (and ub < v)
                v = self._v_max
                self._kinds = ((self.lb > -v).astype(np.int8), (self.ub < v).astype(np.int8))
        return self._kinds  # type: ignore[return-value]

    @property
    def lower_kind(self) -> npt.NDArray[np.int8]:
        """See the class docstring."""
        return self._kind()[0]

    @property
    def upper_kind(self) -> npt.NDArray[np.int8]:
        """See the class docstring."""
        return self._kind()[1]

    @property
    def contains_zero(self) -> bool:
        """True when standing still is allowed (no joint is asked to recover)."""
        lb, ub = self.lists()
        return max(lb, default=0.0) <= 0.0 <= min(ub, default=0.0)

    def __repr__(self) -> str:
        return f"VelocityBounds(lb={self.lb!r}, ub={self.ub!r})"


class JointLimits:
    """An arm's joint limits, prepared once for the per-step :meth:`bounds`.

    Args:
        lower: Lower position limits (n,) [rad or m]; -inf allowed.
        upper: Upper position limits (n,), >= lower; +inf allowed.
        v_max: Velocity limits (n,) [rad/s or m/s], finite and > 0.
        margin: Distance kept from each position limit [rad or m], >= 0 (capped at half
            the range).
        a_max: Acceleration limits (n,) or a scalar [rad/s^2 or m/s^2], > 0; None for none.

    Raises:
        InputError: Wrong shapes, NaN limits, lower > upper, non-positive or non-finite
            velocity limits, negative margin, non-positive acceleration limits.
    """

    def __init__(
        self,
        lower: npt.ArrayLike,
        upper: npt.ArrayLike,
        v_max: npt.ArrayLike,
        margin: float = 0.0,
        a_max: npt.ArrayLike | None = None,
    ) -> None:
        v = as_vector(v_max, "v_max", np.size(v_max))
        n = v.size
        if np.any(v <= 0.0):
            raise InputError("v_max", f"expected velocity limits > 0, got {v}")
        lo, hi = _limits(lower, upper, n)
        if not (np.isfinite(margin) and margin >= 0.0):
            raise InputError("margin", f"expected a finite number >= 0, got {margin!r}")
        m = np.minimum(margin, 0.5 * (hi - lo))
        self.n = n
        self.lower, self.upper, self.v_max, self.margin = lo, hi, v, float(margin)
        self._range = np.stack([lo + m - ROUNDING, hi - m + ROUNDING])  # (2, n)
        self._range_lists = self._range.tolist()
        self._v_list = v.tolist()
        # (2, n) copies of -v and v: a ufunc without broadcasting is faster on these sizes
        self._clip_lo, self._clip_hi = np.stack([-v, -v]), np.stack([v, v])
        self.a_max: Array | None = None
        if a_max is not None:
            a = as_vector(np.broadcast_to(np.asarray(a_max, dtype=float), (n,)), "a_max", n)
            if np.any(a <= 0.0):
                raise InputError("a_max", f"expected acceleration limits > 0, got {a}")
            self.a_max = a
            self._a_stack = np.stack([-a, a])

    def bounds(
        self, q: Array, dt: float, gain: float = 1.0, qdot_prev: Array | None = None
    ) -> VelocityBounds:
        """The bounds of one step (see the module docstring); inputs are not checked.

        Args:
            q: Joint positions (n,), finite.
            dt: Step [s], > 0.
            gain: Fraction in (0, 1] of the distance to a position bound allowed in one step
                (pink's ``config_limit_gain``).
            qdot_prev: Previous joint rates (n,) for the acceleration limits (zero if None).

        Returns:
            The :class:`VelocityBounds`.
        """
        if self.a_max is None:  # n is small: Python floats, no numpy call
            k = gain / dt
            lows, highs = self._range_lists
            lb: list[float] = []
            ub: list[float] = []
            for low, high, x, v_i in zip(lows, highs, q.tolist(), self._v_list):  # noqa: B905
                p = (low - x) * k
                lb.append(v_i if p > v_i else (-v_i if p < -v_i else p))
                p = (high - x) * k
                ub.append(v_i if p > v_i else (-v_i if p < -v_i else p))
            return VelocityBounds.from_lists(lb, ub, self.v_max)
        v = self.v_max
        b = np.subtract(self._range, q)  # rows: position bounds p_lo, p_hi ...
        b *= gain / dt
        np.maximum(b, self._clip_lo, out=b)  # ... clipped into the velocity interval
        np.minimum(b, self._clip_hi, out=b)
        lb, ub = b[0], b[1]
        lower_kind = (lb > -v).astype(np.int8)
        upper_kind = (ub < v).astype(np.int8)
        prev = np.zeros(self.n) if qdot_prev is None else qdot_prev
        a = np.minimum(np.maximum(prev + self._a_stack * dt, lb), ub)
        lower_kind[a[0] > lb] = ACCELERATION
        upper_kind[a[1] < ub] = ACCELERATION
        return VelocityBounds(a[0], a[1], lower_kind, upper_kind)


def joint_velocity_bounds(
    q: npt.ArrayLike,
    lower: npt.ArrayLike,
    upper: npt.ArrayLike,
    v_max: npt.ArrayLike,
    dt: float,
    margin: float = 0.0,
    qdot_prev: npt.ArrayLike | None = None,
    a_max: npt.ArrayLike | None = None,
    gain: float = 1.0,
) -> VelocityBounds:
    """Bounds on the joint rates of one step of length ``dt`` (module docstring).

    Args:
        q: Joint positions (n,) [rad or m].
        lower: Lower position limits (n,); -inf allowed.
        upper: Upper position limits (n,), >= lower; +inf allowed.
        v_max: Velocity limits (n,) [rad/s or m/s], finite and > 0.
        dt: Step [s], > 0.
        margin: Distance kept from each position limit [rad or m], >= 0.
        qdot_prev: Previous joint rates (n,), required with ``a_max``.
        a_max: Acceleration limits (n,) or scalar [rad/s^2 or m/s^2], > 0; None for none.
        gain: Fraction in (0, 1] of the distance to a position bound allowed in one step.

    Returns:
        The :class:`VelocityBounds`, ``lb <= ub`` everywhere.

    Raises:
        InputError: Wrong shapes, non-finite q, v_max, dt or qdot_prev, lower > upper,
            negative margin, gain outside (0, 1], or ``a_max`` without ``qdot_prev``.
    """
    limits = JointLimits(lower, upper, v_max, margin, a_max)
    q = as_vector(q, "q", limits.n)
    dt = positive(dt, "dt")
    if not 0.0 < gain <= 1.0:
        raise InputError("gain", f"expected a number in (0, 1], got {gain!r}")
    prev = None
    if a_max is not None:
        if qdot_prev is None:
            raise InputError("qdot_prev", "required with a_max")
        prev = as_vector(qdot_prev, "qdot_prev", limits.n)
    return limits.bounds(q, dt, gain, prev)


def _limits(lower: npt.ArrayLike, upper: npt.ArrayLike, n: int) -> tuple[Array, Array]:
    lo = np.array(lower, dtype=np.float64)
    hi = np.array(upper, dtype=np.float64)
    for name, arr in (("lower", lo), ("upper", hi)):
        if arr.shape != (n,):
            raise InputError(name, f"expected shape ({n},), got {arr.shape}")
        if np.any(np.isnan(arr)):
            raise InputError(name, "NaN entry")
    if np.any(lo > hi):
        raise InputError("lower", f"expected lower <= upper, got {lo} > {hi}")
    return lo, hi
