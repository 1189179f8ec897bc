"""JointLimits: the step's box (rrc_pin.solvers.tick.joint_box.joint_box), exact in floating point,
recovery,
priorities, kinds; its fields checked at construction and against the robot."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest

import rrc_pin
from rrc_pin import InvalidInput, JointLimits, Resolver
from rrc_pin.solvers.tick.joint_box import ON_LIMIT, SHRINK, joint_box
from rrc_pin.solvers.tick.resolution import KIND_NAMES

KINDS = ("velocity", "position", "acceleration")


class Step:
    """One step's box from the kernel, read as the tests read it."""

    def __init__(self, lb, ub, kind, zero, recovering) -> None:
        self.lb, self.ub, self._kind = lb, ub, kind
        self.contains_zero, self.recovering = zero, recovering

    def kind(self, joint: int, side: str) -> str:
        return KIND_NAMES.get(int(self._kind[0 if side == "lower" else 1, joint]), "velocity")


class JointBounds:
    """The kernel's arguments for one arm, and the range it keeps (the reference for margins)."""

    def __init__(self, lower, upper, velocity, margin=0.0, acceleration=None, gain=1.0) -> None:
        self.lower, self.upper = np.asarray(lower, float), np.asarray(upper, float)
        self.velocity = np.asarray(velocity, float)
        self.margin, self.gain = float(margin), float(gain)
        self.acceleration = (np.array([np.inf]) if acceleration is None
                             else np.asarray(acceleration, float).reshape(-1))  # fmt: skip
        half = 0.5 * (self.upper - self.lower)
        cut = np.minimum(self.margin, half)
        self.low = self.lower + cut
        self.high = np.where(self.margin < half, np.maximum(self.upper - cut, self.low), self.low)

    def step(self, q, dt, prev=None) -> Step:
        n = q.size
        lb, ub, kind = np.empty(n), np.empty(n), np.empty((2, n), np.int8)
        prev = np.zeros(n) if prev is None else prev
        zero, recovering = joint_box(
            np.asarray(q, float), self.lower, self.upper, self.velocity, self.margin, self.gain,
            dt, prev, self.acceleration, lb, ub, kind)  # fmt: skip
        return Step(lb, ub, kind, zero, recovering)


EPS = float(np.finfo(np.float64).eps)


def exact_fma(x: float, y: float, z: float) -> float:
    """``x * y + z`` computed exactly and rounded once, as a fused multiply-add does.

    Integers are exact and ``int / int`` is correctly rounded in CPython; the denominators
    of ``as_integer_ratio`` are powers of two, so the common denominator is exact too.
    """
    n1, d1 = x.as_integer_ratio()
    n2, d2 = y.as_integer_ratio()
    n3, d3 = z.as_integer_ratio()
    d = d1 * d2
    if d >= d3:
        return (n1 * n2 + n3 * (d // d3)) / d
    return (n1 * n2 * (d3 // d) + n3) / d3


def test_exact_fma_reference_is_a_fused_multiply_add() -> None:
    # 1 + 2^-30 squared minus its rounded square: only a fused operation keeps 2^-60
    a = 1.0 + 2.0**-30
    assert exact_fma(a, a, -(a * a)) == 2.0**-60
    assert a * a - a * a == 0.0
    assert exact_fma(0.1, 0.2, 0.3) == float(Fraction(0.1) * Fraction(0.2) + Fraction(0.3))
    if hasattr(math, "fma"):
        rng = np.random.default_rng(3)
        for x, y, z in rng.standard_normal((1000, 3)).tolist():
            assert exact_fma(x, y, z) == math.fma(x, y, z)


def _starts(rng: np.random.Generator, low: np.ndarray, high: np.ndarray) -> np.ndarray:
    """Positions in [low, high]: exactly on a limit, within 1e-3 or a few ulps of one."""
    n = low.size
    pick = rng.integers(0, 7, n)
    q = rng.uniform(low, high)
    q = np.where(pick == 0, low, q)
    q = np.where(pick == 1, high, q)
    q = np.where(pick == 2, high - rng.uniform(0.0, 1e-3, n), q)
    q = np.where(pick == 3, low + rng.uniform(0.0, 1e-3, n), q)
    ulps = rng.integers(1, 6, n)
    near_high, near_low = high.copy(), low.copy()
    for k in range(5):
        near_high = np.where(ulps > k, np.nextafter(near_high, -np.inf), near_high)
        near_low = np.where(ulps > k, np.nextafter(near_low, np.inf), near_low)
    q = np.where(pick == 4, near_high, q)
    q = np.where(pick == 5, near_low, q)
    return np.clip(q, low, high)  # narrow ranges: the offsets may cross them


def test_one_step_position_bound_is_exact_in_floating_point(rng: np.random.Generator) -> None:
    """q + qdot dt, in any order, fused or not, never leaves [low, high]: no tolerance."""
    calls, n = 220, 500  # 110,000 joint-steps, each checked at both bounds
    has_fma = hasattr(math, "fma")
    position_limited = 0
    for _ in range(calls):
        scale = rng.choice([1e-2, 1.0, 1e2], n)  # different ulps: small to large magnitudes
        lower = rng.uniform(-3.0, 1.0, n) * scale
        upper = lower + rng.uniform(1e-6, 6.0, n) * scale
        velocity = np.where(rng.random(n) < 0.7, 1e6, rng.uniform(0.1, 10.0, n))
        margin = float(rng.choice([0.0, 1e-3, 0.1]))
        gain = float(rng.choice([1.0, rng.uniform(0.05, 1.0)]))
        dt = float(rng.choice([1e-3, 1e-2, 5e-2]) * rng.uniform(0.3, 3.0))
        limits = JointBounds(lower, upper, velocity, margin, gain=gain)
        low, high = limits.low, limits.high
        q = _starts(rng, low, high)
        b = limits.step(q, dt)
        assert b.contains_zero
        assert (b.lb <= 0.0).all() and (b.ub >= 0.0).all() and (b.lb <= b.ub).all()
        for qdot in (b.lb, b.ub):
            for after in (q + qdot * dt, q + dt * qdot):
                assert (after >= low).all() and (after <= high).all()
            fused = [exact_fma(x, dt, p) for x, p in zip(qdot.tolist(), q.tolist(), strict=True)]
            assert min(f - lo for f, lo in zip(fused, low.tolist(), strict=True)) >= 0.0
            assert max(f - hi for f, hi in zip(fused, high.tolist(), strict=True)) <= 0.0
            if has_fma:  # Python >= 3.13: the platform's own fused multiply-add
                fused = [math.fma(x, dt, p) for x, p in zip(qdot.tolist(), q.tolist(), strict=True)]
                assert all(lo <= f <= hi for f, lo, hi in zip(fused, low, high, strict=True))
        # and the bound is tight: it gives up at most 16 ulps of the distance to the limit
        free = b.ub < velocity
        position_limited += int(free.sum())
        reach = (high - q)[free] * gain
        assert (b.ub[free] * dt >= reach * (1.0 - 16.0 * EPS) - 4 * np.spacing(reach)).all()
        free = b.lb > -velocity
        reach = (low - q)[free] * gain
        assert (b.lb[free] * dt <= reach * (1.0 - 16.0 * EPS) + 4 * np.spacing(-reach)).all()
    assert position_limited > calls * n // 4  # the position bound was the one tested


def test_shrink_is_eight_ulps() -> None:
    assert SHRINK == 1.0 - 8.0 * EPS
    assert SHRINK < 1.0 and 1.0 - SHRINK < 2e-15


def test_on_the_limit_standing_still_is_the_only_rate_outward() -> None:
    limits = JointBounds([-1.0, -1.0], [1.0, 1.0], [2.0, 2.0])
    b = limits.step(np.array([1.0, -1.0]), 0.01)
    assert b.contains_zero
    assert b.ub[0] == 0.0 and b.lb[0] == -2.0  # at the upper limit: may only come back
    assert b.lb[1] == 0.0 and b.ub[1] == 2.0
    assert b.kind(0, "upper") == "position" and b.kind(0, "lower") == "velocity"
    assert b.kind(1, "lower") == "position" and b.kind(1, "upper") == "velocity"


@pytest.mark.parametrize("distance", [3e-12, 1e-9, 1e-4, 0.05, 1.0, 10.0])
def test_a_start_outside_moves_back_in_one_step(distance: float) -> None:
    dt = 0.01
    limits = JointBounds([-1.0, -1.0], [1.0, 1.0], [1e6, 1e6])
    q = np.array([1.0 + distance, -1.0 - distance])  # above joint 0's range, below joint 1's
    b = limits.step(q, dt)
    assert not b.contains_zero
    assert b.ub[0] < 0.0 and b.lb[1] > 0.0  # every allowed rate moves back
    assert (b.lb <= b.ub).all()
    # gain 1: the rate that reaches the range in one step (short of it by the 8-ulp shrink)
    np.testing.assert_allclose([-b.ub[0], b.lb[1]], (q[0] - 1.0) / dt, rtol=1e-14)
    after = q + np.array([b.ub[0], b.lb[1]]) * dt
    assert 0.0 <= after[0] - 1.0 <= ON_LIMIT and 0.0 <= -1.0 - after[1] <= ON_LIMIT
    assert limits.step(after, dt).contains_zero  # on the limit at the next step
    # the fastest rate back does not cross the range: it stops at the other limit
    assert q[0] + b.lb[0] * dt >= -1.0 and q[1] + b.ub[1] * dt <= 1.0


def test_recovery_is_never_faster_than_the_velocity_limit() -> None:
    limits = JointBounds([-1.0, -1.0], [1.0, 1.0], [0.5, 0.5])
    b = limits.step(np.array([1.3, -1.3]), 0.01)  # 30 rad/s would reach the range
    assert not b.contains_zero
    assert b.lb[0] == b.ub[0] == -0.5 and b.lb[1] == b.ub[1] == 0.5
    # the side that forces the motion is the position limit's, the other the velocity's
    assert b.kind(0, "upper") == "position" and b.kind(0, "lower") == "velocity"
    assert b.kind(1, "lower") == "position" and b.kind(1, "upper") == "velocity"


def test_recovery_with_a_gain_moves_that_fraction_of_the_way() -> None:
    limits = JointBounds([-1.0], [1.0], [1e3], gain=0.25)
    b = limits.step(np.array([1.2]), 0.01)
    np.testing.assert_allclose(b.ub, [-0.25 * 0.2 / 0.01], rtol=1e-14)
    np.testing.assert_allclose(b.lb, [-0.25 * 2.2 / 0.01], rtol=1e-14)


def test_a_start_outside_by_at_most_on_limit_counts_as_on_the_limit() -> None:
    limits = JointBounds([-1.0] * 4, [1.0] * 4, [1.0] * 4)
    q = np.array([1.0 + ON_LIMIT, -1.0 - ON_LIMIT, 1.0 + 0.5 * ON_LIMIT, 0.0])
    b = limits.step(q, 0.01)
    assert b.contains_zero
    np.testing.assert_array_equal(b.ub[:3], [0.0, 1.0, 0.0])
    np.testing.assert_array_equal(b.lb[:3], [-1.0, 0.0, -1.0])
    assert b.kind(0, "upper") == "position" and b.kind(1, "lower") == "position"
    for q0 in (1.0 + 3.0 * ON_LIMIT, -1.0 - 3.0 * ON_LIMIT):  # beyond: it must move back
        b = limits.step(np.array([q0, 0.0, 0.0, 0.0]), 0.01)
        assert not b.contains_zero
        assert b.ub[0] < 0.0 if q0 > 0 else b.lb[0] > 0.0


def test_margin_shrinks_the_range_and_is_capped_at_half_of_it() -> None:
    limits = JointBounds([-1.0, 0.0, 2.0], [1.0, 0.1, 2.0], [10.0] * 3, margin=0.2)
    np.testing.assert_array_equal(limits.low, [-0.8, 0.05, 2.0])  # capped: the midpoint
    np.testing.assert_array_equal(limits.high, [0.8, 0.05, 2.0])
    b = limits.step(np.array([0.79, 0.05, 2.0]), 0.01)
    assert b.contains_zero
    np.testing.assert_allclose(b.ub[0], 0.01 / 0.01, rtol=1e-12)  # 0.01 to the margin
    assert b.lb[1] == b.ub[1] == 0.0 and b.lb[2] == b.ub[2] == 0.0  # no range left
    b = limits.step(np.array([0.0, 0.06, 2.0]), 0.01)  # off the midpoint: moves back to it
    assert not b.contains_zero
    np.testing.assert_allclose([b.lb[1], b.ub[1]], [-1.0, -1.0], rtol=1e-12)  # in one step
    b = limits.step(np.array([0.0, 0.5, 2.0]), 0.01)  # 0.45 away: at the velocity limit
    assert b.lb[1] == b.ub[1] == -10.0
    b = limits.step(np.array([0.9, 0.05, 2.0]), 0.01)  # inside the limits, inside the margin
    assert not b.contains_zero and b.ub[0] < 0.0


def test_a_range_capped_by_the_margin_is_one_point(rng: np.random.Generator) -> None:
    """Rounding must not make the range empty (low > high by an ulp): it is the midpoint."""
    lower = rng.uniform(-3.0, 1.0, 20000)
    upper = lower + rng.uniform(1e-6, 6.0, lower.size)
    limits = JointBounds(lower, upper, np.ones(lower.size), margin=10.0)
    assert (limits.low == limits.high).all()
    np.testing.assert_allclose(limits.low, 0.5 * (lower + upper), rtol=0, atol=1e-15)
    b = limits.step(limits.low.copy(), 0.01)
    assert b.contains_zero and (b.lb == 0.0).all() and (b.ub == 0.0).all()


def test_infinite_limits_leave_the_velocity_limits() -> None:
    inf = np.inf
    limits = JointBounds([-inf, -inf, -1.0], [inf, 0.5, inf], [1.0, 2.0, 3.0], margin=0.1)
    assert limits.low[0] == -inf and limits.high[0] == inf
    b = limits.step(np.array([1e6, 0.0, 0.0]), 0.01)
    np.testing.assert_array_equal(b.lb, [-1.0, -2.0, -3.0])
    np.testing.assert_array_equal(b.ub, [1.0, 2.0, 3.0])
    assert b.contains_zero
    assert [b.kind(j, s) for j in range(3) for s in ("lower", "upper")] == ["velocity"] * 6
    b = limits.step(np.array([0.0, 0.395, -0.895]), 0.01)  # 5e-3 from the finite sides
    np.testing.assert_allclose([b.ub[1], b.lb[2]], [0.5, -0.5], rtol=1e-12)
    assert b.lb[1] == -2.0 and b.ub[2] == 3.0
    assert b.kind(1, "upper") == "position" and b.kind(2, "upper") == "velocity"


def test_kinds_of_bounds() -> None:
    limits = JointBounds([-1.0] * 3, [1.0] * 3, [1.0] * 3, acceleration=[1e3, 1e3, 50.0])
    # joint 0 mid-range: velocity; joint 1 5e-3 from its upper limit: position above;
    # joint 2 moving at 0.9 rad/s with 0.5 rad/s of acceleration per step: acceleration
    b = limits.step(np.array([0.0, 0.995, 0.0]), 0.01, np.array([0.0, 0.0, 0.9]))
    assert b.kind(0, "lower") == "velocity" and b.kind(0, "upper") == "velocity"
    assert b.kind(1, "upper") == "position" and b.kind(1, "lower") == "velocity"
    assert b.kind(2, "lower") == "acceleration" and b.kind(2, "upper") == "velocity"
    np.testing.assert_allclose(b.ub[1], 0.5, rtol=1e-12)
    np.testing.assert_allclose(b.lb[2], 0.4, rtol=1e-12)
    assert set(KINDS) == {"velocity", "position", "acceleration"}


def test_acceleration_bounds_around_the_previous_rate() -> None:
    limits = JointBounds([-1.0] * 2, [1.0] * 2, [1.0] * 2, acceleration=20.0)  # a scalar
    b = limits.step(np.zeros(2), 0.01, np.array([0.0, -0.3]))
    np.testing.assert_allclose(b.lb, [-0.2, -0.5], rtol=1e-12)
    np.testing.assert_allclose(b.ub, [0.2, -0.1], rtol=1e-12)
    assert not b.contains_zero  # joint 1 cannot stop within one step
    assert all(b.kind(j, s) == "acceleration" for j in range(2) for s in ("lower", "upper"))
    b = limits.step(np.zeros(2), 0.01)  # no previous rate: zero
    np.testing.assert_allclose(b.ub, [0.2, 0.2], rtol=1e-12)
    assert b.contains_zero


def test_acceleration_yields_to_velocity_and_position() -> None:
    limits = JointBounds([-1.0] * 3, [1.0] * 3, [1.0] * 3, acceleration=[10.0] * 3)
    dt = 0.01
    # joint 0 at 1.5 rad/s (beyond its velocity limit): back under it at once, at 1 rad/s;
    # joint 1 racing to its upper limit 1e-3 away: the position bound wins
    # (0.1 rad/s); joint 2 away from everything: acceleration both sides
    q = np.array([0.0, 0.999, 0.0])
    b = limits.step(q, dt, np.array([1.5, 0.95, 0.0]))
    assert b.lb[0] == b.ub[0] == 1.0
    assert b.kind(0, "lower") == "velocity" and b.kind(0, "upper") == "velocity"
    np.testing.assert_allclose([b.lb[1], b.ub[1]], [0.1, 0.1], rtol=1e-9)
    assert b.kind(1, "upper") == "position" and b.kind(1, "lower") == "position"
    assert (q + b.ub * dt <= 1.0).all()  # still exact in floating point
    np.testing.assert_allclose([b.lb[2], b.ub[2]], [-0.1, 0.1], rtol=1e-12)
    assert b.kind(2, "lower") == "acceleration" and b.kind(2, "upper") == "acceleration"
    assert b.lb[0] > 0.0 and not b.contains_zero


def test_bounds_are_ordered_and_within_the_velocity_limits(rng: np.random.Generator) -> None:
    """Random starts anywhere (far outside included), margins, gains, accelerations."""
    n = 6
    for _ in range(400):
        lower = rng.uniform(-3.0, 1.0, n)
        upper = lower + rng.uniform(0.0, 4.0, n)
        v = rng.uniform(1e-3, 10.0, n)
        q = rng.uniform(-6.0, 6.0, n)
        q = np.where(rng.random(n) < 0.3, np.where(rng.random(n) < 0.5, lower, upper), q)
        acc = rng.uniform(1e-2, 100.0, n) if rng.random() < 0.5 else None
        prev = rng.uniform(-20.0, 20.0, n)
        limits = JointBounds(lower, upper, v, rng.uniform(0.0, 1.0), acc, rng.uniform(0.05, 1.0))
        b = limits.step(q, float(rng.uniform(1e-4, 0.5)), prev)
        assert (b.lb <= b.ub).all()
        assert (b.lb >= -v).all() and (b.ub <= v).all()
        assert b.contains_zero == bool((b.lb <= 0.0).all() and (b.ub >= 0.0).all())
        below = q < limits.low - ON_LIMIT
        above = q > limits.high + ON_LIMIT
        assert (b.lb[below] > 0.0).all() and (b.ub[above] < 0.0).all()
        for j in range(n):
            for side in ("lower", "upper"):
                assert b.kind(j, side) in KINDS


@pytest.mark.parametrize(
    ("kwargs", "argument"),
    [({"margin": -0.1}, "margin"), ({"margin": np.nan}, "margin"), ({"margin": True}, "margin"),
     ({"margin": "0.1"}, "margin"), ({"position_gain": 0.0}, "position_gain"),
     ({"position_gain": 1.5}, "position_gain"), ({"position_gain": "0.5"}, "position_gain"),
     ({"acceleration": [1.0, 0.0]}, "acceleration"), ({"acceleration": -1.0}, "acceleration"),
     ({"acceleration": np.nan}, "acceleration"), ({"acceleration": "x"}, "acceleration"),
     ({"acceleration": True}, "acceleration"), ({"acceleration": [1j, 1.0]}, "acceleration"),
     ({"acceleration": [[1.0]]}, "acceleration"), ({"velocity": [1.0, 0.0]}, "velocity"),
     ({"velocity": [1.0, np.inf]}, "velocity"), ({"velocity": [True, True]}, "velocity"),
     ({"velocity": [[1.0, 1.0]]}, "velocity"), ({"name": 3}, "name")],
)  # fmt: skip
def test_bad_fields_are_refused_at_construction(kwargs: dict, argument: str) -> None:
    """Issue 33 item 3: a margin of -1 or NaN was accepted until a Resolver was built."""
    with pytest.raises(InvalidInput) as info:
        JointLimits(**kwargs)
    assert info.value.argument == argument
    assert str(info.value).startswith(f"{argument}: ")


@pytest.mark.parametrize(
    ("limits", "argument"),
    [(JointLimits(margin=5.0), "margin"), (JointLimits(margin=1.51), "margin"),
     (JointLimits(velocity=np.ones(6)), "velocity"),
     (JointLimits(acceleration=np.ones(3)), "acceleration")],
)  # fmt: skip
def test_limits_that_do_not_fit_the_robot_are_refused(limits: JointLimits, argument: str) -> None:
    """Issue 33 item 3: panda with a margin of 5 rad answered 'recovering' forever; joint 4's
    half range is 1.501 rad, so no margin of that size can hold."""
    with pytest.raises(InvalidInput) as info:
        Resolver(rrc_pin.load("panda"), limits=limits)
    assert info.value.argument == argument
    Resolver(rrc_pin.load("panda"), limits=JointLimits(margin=1.5))  # just inside: accepted


def test_the_fields_are_copies_and_frozen() -> None:
    velocity = np.ones(7)
    limits = JointLimits(velocity=velocity)
    velocity[:] = 5.0
    assert (np.asarray(limits.velocity) == 1.0).all()
    with pytest.raises(AttributeError):
        limits.margin = 0.1  # type: ignore[misc]


def test_recovering_is_a_position_outside_the_range_not_an_arm_that_cannot_stop() -> None:
    """Zero excluded by the acceleration limits alone (moving too fast to stop in one step)
    is not recovering; a joint outside its range is, with or without acceleration limits."""
    limits = JointBounds([-1.0] * 2, [1.0] * 2, [1.0] * 2, acceleration=[1.0, 1.0])
    fast = limits.step(np.zeros(2), 0.01, np.array([0.5, 0.0]))
    assert not fast.contains_zero and not fast.recovering
    assert fast.lb[0] == pytest.approx(0.49) and fast.ub[0] == pytest.approx(0.51)
    outside = limits.step(np.array([1.5, 0.0]), 0.01, np.zeros(2))
    assert outside.recovering and not outside.contains_zero
    plain = JointBounds([-1.0] * 2, [1.0] * 2, [1.0] * 2)
    assert plain.step(np.array([1.5, 0.0]), 0.01).recovering
    assert not plain.step(np.array([1.0, 0.0]), 0.01).recovering  # on the limit
