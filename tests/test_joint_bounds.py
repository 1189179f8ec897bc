"""Joint-rate bounds of one step: never lb > ub, never past a velocity limit, recovery."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from solvers.errors import InputError
from solvers.joint_bounds import (
    ACCELERATION,
    POSITION,
    ROUNDING,
    VELOCITY,
    JointLimits,
    joint_velocity_bounds,
)

N = 5
finite = st.floats(-10.0, 10.0, allow_nan=False)


@st.composite
def cases(draw: st.DrawFn) -> dict:
    lower = np.array(draw(st.lists(finite, min_size=N, max_size=N)))
    width = np.array(draw(st.lists(st.floats(0.0, 6.0), min_size=N, max_size=N)))
    upper = lower + width
    # q: anywhere, including far outside the limits and exactly on them
    q = np.array(draw(st.lists(st.floats(-30.0, 30.0), min_size=N, max_size=N)))
    for i, pick in enumerate(draw(st.lists(st.integers(0, 3), min_size=N, max_size=N))):
        q[i] = (lower[i], upper[i], q[i], q[i])[pick]
    v = np.array(draw(st.lists(st.floats(1e-3, 10.0), min_size=N, max_size=N)))
    dt = draw(st.floats(1e-4, 0.5))
    margin = draw(st.floats(0.0, 1.0))
    with_acc = draw(st.booleans())
    a = np.array(draw(st.lists(st.floats(1e-2, 100.0), min_size=N, max_size=N)))
    prev = np.array(draw(st.lists(st.floats(-20.0, 20.0), min_size=N, max_size=N)))
    gain = draw(st.floats(0.05, 1.0))
    return dict(q=q, lower=lower, upper=upper, v_max=v, dt=dt, margin=margin,
                a_max=a if with_acc else None, qdot_prev=prev if with_acc else None, gain=gain)


@settings(max_examples=400, deadline=None, derandomize=True)
@given(cases())
def test_bounds_are_consistent(c: dict) -> None:
    b = joint_velocity_bounds(**c)
    lower, upper, q, v, dt = c["lower"], c["upper"], c["q"], c["v_max"], c["dt"]
    assert np.all(b.lb <= b.ub)
    assert np.all(b.lb >= -v) and np.all(b.ub <= v)
    m = np.minimum(c["margin"], 0.5 * (upper - lower))
    lo, hi = lower + m, upper - m
    inside = (q >= lo - ROUNDING) & (q <= hi + ROUNDING)
    # inside the range: every rate in [lb, ub] keeps the step inside it
    for rate in (b.lb, b.ub):
        step = q + rate * dt
        assert np.all(step[inside] >= lo[inside] - ROUNDING - 1e-12)
        assert np.all(step[inside] <= hi[inside] + ROUNDING + 1e-12)
    # outside: no rate in [lb, ub] moves further out, and standing still is excluded
    below, above = q < lo - ROUNDING, q > hi + ROUNDING
    assert np.all(b.lb[below] > 0.0) and np.all(b.ub[above] < 0.0)
    if c["a_max"] is None:
        # the return is at the rate that reaches the range in one step, capped by v_max
        want = np.minimum((lo - ROUNDING - q) * c["gain"] / dt, v)
        assert np.allclose(b.lb[below], want[below], rtol=1e-12, atol=1e-12)
    else:
        # the acceleration band, clipped into the position/velocity interval (its priority)
        pv = joint_velocity_bounds(**{**c, "a_max": None, "qdot_prev": None})
        lo_a = np.clip(c["qdot_prev"] - c["a_max"] * dt, pv.lb, pv.ub)
        hi_a = np.clip(c["qdot_prev"] + c["a_max"] * dt, pv.lb, pv.ub)
        assert np.array_equal(b.lb, lo_a) and np.array_equal(b.ub, hi_a)
        assert np.array_equal(b.lower_kind == ACCELERATION, lo_a > pv.lb)
        assert np.array_equal(b.upper_kind == ACCELERATION, hi_a < pv.ub)


def test_kinds_of_bounds() -> None:
    limits = JointLimits([-1.0] * 3, [1.0] * 3, [1.0] * 3, a_max=[1e3, 1e3, 50.0])
    # joint 0: mid-range (velocity both sides); joint 1: 0.005 from the upper limit
    # (position above); joint 2: moving fast (acceleration both sides)
    b = limits.bounds(np.array([0.0, 0.995, 0.0]), 0.01, 1.0, np.array([0.0, 0.0, 0.9]))
    assert b.lower_kind.tolist() == [VELOCITY, VELOCITY, ACCELERATION]
    assert b.upper_kind.tolist() == [VELOCITY, POSITION, VELOCITY]
    assert b.ub[1] == pytest.approx((1.0 + ROUNDING - 0.995) / 0.01, rel=1e-12)
    assert b.lb[2] == pytest.approx(0.4, rel=1e-12)


def test_start_outside_moves_back_within_velocity_limit() -> None:
    b = joint_velocity_bounds([1.5, -1.001, 0.2], [-1.0] * 3, [1.0] * 3, [2.0] * 3, 0.01)
    assert b.ub[0] == -2.0 and b.lb[0] == -2.0  # far above: back at full speed
    assert b.lb[1] == pytest.approx((0.001 - ROUNDING) / 0.01, rel=1e-9)
    assert b.ub[1] == 2.0
    assert not b.contains_zero
    assert b.lower_kind[1] == POSITION and b.upper_kind[0] == POSITION


def test_rounding_at_the_boundary_keeps_zero_feasible() -> None:
    """Integrating up to a bound lands a few ulp past it: still "inside"."""
    q = np.array([1.0 + 4e-16])
    b = joint_velocity_bounds(q, [-1.0], [1.0], [1.0], 0.01)
    assert b.contains_zero


def test_margin_is_capped_at_half_the_range() -> None:
    b = joint_velocity_bounds([0.0], [-0.1], [0.1], [1.0], 0.01, margin=5.0)
    assert b.lb[0] <= 0.0 <= b.ub[0]
    assert abs(b.lb[0]) < 1e-10 and abs(b.ub[0]) < 1e-10


def test_infinite_position_limits() -> None:
    b = joint_velocity_bounds([3.0], [-np.inf], [np.inf], [2.0], 0.01, margin=0.1)
    assert b.lb[0] == -2.0 and b.ub[0] == 2.0


@pytest.mark.parametrize(
    ("kwargs", "argument"),
    [
        ({"q": [np.nan, 0.0]}, "q"),
        ({"v_max": [1.0, 0.0]}, "v_max"),
        ({"v_max": [1.0, np.inf]}, "v_max"),
        ({"dt": 0.0}, "dt"),
        ({"dt": -0.01}, "dt"),
        ({"lower": [2.0, 0.0]}, "lower"),
        ({"margin": -1.0}, "margin"),
        ({"gain": 1.5}, "gain"),
        ({"a_max": [1.0, 1.0]}, "qdot_prev"),
        ({"a_max": [1.0, -1.0], "qdot_prev": [0.0, 0.0]}, "a_max"),
    ],
)
def test_bad_input_names_the_argument(kwargs: dict, argument: str) -> None:
    args = dict(q=[0.0, 0.0], lower=[-1.0, -1.0], upper=[1.0, 0.5], v_max=[1.0, 1.0], dt=0.01)
    args.update(kwargs)
    with pytest.raises(InputError) as info:
        joint_velocity_bounds(**args)
    assert info.value.argument == argument


def test_bounds_from_python_floats_equal_the_numpy_formula() -> None:
    """The per-step bounds are computed on Python floats; the same numbers as numpy's."""
    rng = np.random.default_rng(7)
    for _ in range(200):
        lower = rng.uniform(-3.0, 0.0, N)
        upper = lower + rng.uniform(0.0, 4.0, N)
        lower[0], upper[0] = -np.inf, np.inf  # a continuous joint
        v = rng.uniform(0.1, 3.0, N)
        limits = JointLimits(lower, upper, v, margin=0.01)
        q = rng.uniform(-4.0, 4.0, N)
        dt, gain = float(rng.uniform(1e-3, 0.1)), float(rng.uniform(0.1, 1.0))
        b = limits.bounds(q, dt, gain)
        reference = np.clip((limits._range - q) * (gain / dt), -v, v)
        assert np.array_equal(b.lb, reference[0]) and np.array_equal(b.ub, reference[1])
        assert b.lists() == (reference[0].tolist(), reference[1].tolist())
        position = (reference[0] > -v, reference[1] < v)
        assert np.array_equal(b.lower_kind == POSITION, position[0])
        assert np.array_equal(b.upper_kind == POSITION, position[1])
        assert np.all((b.lower_kind == POSITION) | (b.lower_kind == VELOCITY))
        assert b.contains_zero == bool(np.all(b.lb <= 0.0) and np.all(b.ub >= 0.0))
