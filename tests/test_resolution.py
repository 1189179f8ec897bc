"""The Resolution record: scale along the command, norm, active limits, an immutable snapshot."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from solvers.joint_bounds import JointBounds
from solvers.qp_backends import make_backend
from solvers.resolution import (
    ACTIVE_TOL,
    METHODS,
    ActiveLimit,
    Resolution,
    TaskRows,
    active_limits,
    norm,
    scale_along,
)
from solvers.resolve import ResolveOptions, resolve

# -- scale_along ---------------------------------------------------------------------------


def test_scale_along_is_the_fraction_along_the_command(rng: np.random.Generator) -> None:
    for _ in range(500):
        m = int(rng.integers(1, 7))
        b = rng.standard_normal(m)
        u = float(rng.uniform(-0.5, 1.5))
        side = rng.standard_normal(m)
        side -= (side @ b) / (b @ b) * b  # orthogonal to the command
        y = u * b + side
        want = min(1.0, max(0.0, u))
        assert scale_along(y, b) == pytest.approx(want, abs=1e-12)
        assert 0.0 <= scale_along(rng.standard_normal(m) * 1e3, b) <= 1.0


def test_scale_along_weights(rng: np.random.Generator) -> None:
    b = np.array([1.0, 2.0, -1.0])
    w = np.array([4.0, 0.25, 1.0])
    y = np.array([0.5, 0.0, 0.0])
    assert scale_along(y, b, w) == pytest.approx((y @ (w * b)) / (b @ (w * b)), rel=1e-15)
    assert scale_along(y, b, w) == pytest.approx(2.0 / 6.0, rel=1e-15)
    assert scale_along(y, b) == pytest.approx(0.5 / 6.0, rel=1e-15)
    assert scale_along(0.3 * b, b, w) == pytest.approx(0.3, rel=1e-15)  # along: any weights
    assert scale_along(b, b, rng.uniform(0.1, 10.0, 3)) == 1.0


def test_scale_along_edge_values() -> None:
    b = np.array([0.1, -0.2, 0.3])
    assert scale_along(np.zeros(3), np.zeros(3)) == 1.0  # a zero command is met
    assert scale_along(np.ones(3), np.zeros(3)) == 1.0
    assert scale_along(np.zeros(3), b) == 0.0
    assert scale_along(b, b) == 1.0
    assert scale_along(3.0 * b, b) == 1.0  # clipped
    assert scale_along(-b, b) == 0.0  # clipped
    assert scale_along(np.zeros(0), np.zeros(0)) == 1.0


@pytest.mark.parametrize(
    ("achieved", "commanded", "want"),
    [([0.5e300, -0.5e300, 0.0], [1e300, -1e300, 0.0], 0.5),  # |b|^2 overflows
     ([1e308, 1e308], [1e308, 1e308], 1.0),
     ([0.25e308, 0.0], [1e308, 1e308], 0.125),
     ([-1e300, 0.0], [1e300, 0.0], 0.0),
     ([2.5e-301, 0.0, 0.0], [1e-300, 0.0, 0.0], 0.25),  # |b|^2 underflows
     ([1e-300, 1e-300], [1e-300, -1e-300], 0.0),
     ([0.75e-320, 0.0], [1e-320, 0.0], 0.75),  # subnormal
     ([1.0, 0.0], [1e-300, 0.0], 1.0),  # a tiny command, far more achieved
     ([1.0, 0.0], [1e-310, 0.0], 1.0),
     ([0.3, 0.1], [1e-320, 0.0], 1.0),
     ([1e200, 0.0], [1e-200, 0.0], 1.0),
     ([-1e200, 0.0], [1e-200, 0.0], 0.0),
     ([1e-300, 0.0], [1e300, 0.0], 0.0),  # a huge command, nothing achieved
     ([1e300, 1e300], [1e10, 1e10], 1.0)],
)  # fmt: skip
def test_scale_along_never_overflows_or_underflows(
    achieved: list[float], commanded: list[float], want: float
) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no overflow or invalid-value warning either
        got = scale_along(np.array(achieved), np.array(commanded))
    assert got == pytest.approx(want, rel=1e-12, abs=1e-300)
    assert 0.0 <= got <= 1.0


def test_scale_along_with_huge_and_tiny_weighted_commands() -> None:
    w = np.array([2.0, 0.5])
    b = np.array([1e300, 1e300])
    assert scale_along(0.4 * b, b, w) == pytest.approx(0.4, rel=1e-12)
    tiny = np.array([1e-305, -1e-305])  # |b|_W^2 underflows
    assert scale_along(0.4 * tiny, tiny, w) == pytest.approx(0.4, rel=1e-12)


# -- norm --------------------------------------------------------------------------------------


def test_norm(rng: np.random.Generator) -> None:
    for _ in range(100):
        x = rng.standard_normal(int(rng.integers(0, 9)))
        assert norm(x) == pytest.approx(float(np.linalg.norm(x)), rel=1e-15)
    assert norm(np.array([3.0, -4.0])) == 5.0
    assert norm(np.zeros(0)) == 0.0
    assert norm(np.array([1e300, 1e300])) == pytest.approx(math.sqrt(2.0) * 1e300, rel=1e-15)
    assert norm(np.array([1e-300, 1e-300])) == pytest.approx(math.sqrt(2.0) * 1e-300, rel=1e-15)
    assert norm(np.array([1e308, 1e308, 1e308])) == pytest.approx(math.sqrt(3) * 1e308, rel=1e-15)
    assert type(norm(np.ones(3))) is float


# -- active limits ------------------------------------------------------------------------------


def test_active_limits_kinds_names_and_sides() -> None:
    limits = JointBounds([-1.0] * 5, [1.0] * 5, [1.0, 2.0, 1.0, 1.0, 1.0],
                         acceleration=[1e3, 1e3, 1e3, 1e3, 20.0])  # fmt: skip
    # joint 1 5e-3 from its upper limit; joint 3 on its lower limit; joint 4 accelerating
    q = np.array([0.0, 0.995, 0.0, -1.0, 0.0])
    b = limits.step(q, 0.01, np.array([0.0, 0.0, 0.0, 0.0, 0.5]))
    qdot = np.array([
        b.lb[0],  # velocity, lower
        b.ub[1],  # position, upper
        0.3,  # free
        b.lb[3] + 0.5 * ACTIVE_TOL,  # position (zero: on the limit), within the tolerance
        b.ub[4] - 2.0 * ACTIVE_TOL,  # acceleration, just beyond the tolerance: not active
    ])  # fmt: skip
    active = active_limits(qdot, b)
    assert active == (
        ActiveLimit(0, "lower", "velocity", -1.0, None),
        ActiveLimit(1, "upper", "position", float(b.ub[1]), None),
        ActiveLimit(3, "lower", "position", 0.0, None),
    )
    names = ("a", "b", "c", "d", "e")
    assert [a.name for a in active_limits(qdot, b, names)] == ["a", "b", "d"]
    qdot[4] = b.ub[4]
    last = active_limits(qdot, b, names)[-1]
    assert last == ActiveLimit(4, "upper", "acceleration", float(b.ub[4]), "e")
    np.testing.assert_allclose(last.bound, 0.7, rtol=1e-12)
    assert active_limits(0.5 * (b.lb + b.ub), b) == ()


def test_a_fixed_joint_touches_both_sides() -> None:
    limits = JointBounds([0.0, -1.0], [0.0, 1.0], [1.0, 1.0])  # joint 0 has no range
    b = limits.step(np.zeros(2), 0.01)
    active = active_limits(np.zeros(2), b, ("fixed", "free"))
    assert [(a.joint, a.side, a.kind, a.name) for a in active] == [
        (0, "lower", "position", "fixed"), (0, "upper", "position", "fixed")]  # fmt: skip


# -- the record ---------------------------------------------------------------------------------


def small_problem(command: np.ndarray, q: np.ndarray | None = None) -> tuple:
    """A planar three-link position task: J (2, 3), one null direction."""
    l1, l2, l3 = 0.4, 0.3, 0.2
    q = np.array([0.3, 0.5, -0.4]) if q is None else q
    c = np.cumsum(q)
    J = np.array([
        [-(l1 * np.sin(c[0]) + l2 * np.sin(c[1]) + l3 * np.sin(c[2])),
         -(l2 * np.sin(c[1]) + l3 * np.sin(c[2])), -l3 * np.sin(c[2])],
        [l1 * np.cos(c[0]) + l2 * np.cos(c[1]) + l3 * np.cos(c[2]),
         l2 * np.cos(c[1]) + l3 * np.cos(c[2]), l3 * np.cos(c[2])],
    ])  # fmt: skip
    limits = JointBounds([-2.5] * 3, [2.5] * 3, [1.0, 1.0, 1.5])
    bounds = limits.step(q, 0.01)
    levels = [[TaskRows(J, command, None, "hand")]]
    return levels, bounds


def solved(command: np.ndarray, q: np.ndarray | None = None) -> Resolution:
    levels, bounds = small_problem(command, q)
    return resolve(levels, bounds, make_backend("daqp"), ResolveOptions(),
                   joint_names=("j1", "j2", "j3"))  # fmt: skip


def test_a_met_command_reports_exact() -> None:
    b = np.array([0.05, -0.02])
    r = solved(b)
    J = r.levels[0][0].A
    np.testing.assert_allclose(J @ r.qdot, b, atol=1e-14)
    assert r.scale == 1.0 and r.residual < 1e-14 and r.status == "exact"
    assert r.method in METHODS and r.method == "qp" and r.active == ()
    (report,) = r.tasks
    assert report.name == "hand" and report.level == 0 and report.bound_by == ()
    assert "status='exact'" in repr(r)


def test_a_command_beyond_the_limits_is_scaled_along_its_direction() -> None:
    b = np.array([3.0, 1.0])
    r = solved(b)
    J = r.levels[0][0].A
    y = J @ r.qdot
    assert 0.0 < r.scale < 1.0
    assert r.scale == pytest.approx((y @ b) / (b @ b), rel=1e-12)
    np.testing.assert_allclose(y, r.scale * b, atol=1e-9)  # along the command
    assert r.residual == pytest.approx(norm(y - b), rel=1e-12)
    assert r.status == "scaled"
    assert r.active and all(a.kind == "velocity" for a in r.active)
    assert {a.name for a in r.active} <= {"j1", "j2", "j3"}
    assert (r.qdot >= r.bounds.lb).all() and (r.qdot <= r.bounds.ub).all()


def test_the_resolution_is_immutable() -> None:
    r = solved(np.array([3.0, 1.0]))
    scale = r.scale
    for field in ("qdot", "method", "backend", "iterations", "attempts", "clip", "lambda_sq",
                  "bounds", "levels", "known_status", "scale", "status", "active"):  # fmt: skip
        with pytest.raises(AttributeError):
            setattr(r, field, None)
    with pytest.raises(AttributeError):
        del r.method
    with pytest.raises(ValueError, match="read-only"):
        r.qdot[0] = 1.0
    assert r.scale == scale  # computed once, cached
    assert isinstance(r.levels, tuple) and all(isinstance(lv, tuple) for lv in r.levels)
    assert isinstance(r.attempts, tuple)


def test_the_resolution_is_a_snapshot_of_the_command() -> None:
    """Changing the caller's arrays afterwards changes nothing in it (module docstring)."""
    b = np.array([3.0, 1.0])
    levels, bounds = small_problem(b)
    r = resolve(levels, bounds, make_backend("daqp"), ResolveOptions())
    want = solved(np.array([3.0, 1.0]))
    b[:] = [0.0, -0.5]  # before anything was read
    levels[0][0].A[:] = 0.0
    assert r.scale == pytest.approx(want.scale, rel=1e-12)
    assert r.residual == pytest.approx(want.residual, rel=1e-12)
    assert r.status == want.status
    np.testing.assert_array_equal(r.tasks[0].commanded, [3.0, 1.0])


def test_a_resolution_built_directly() -> None:
    bounds = JointBounds([-1.0] * 2, [1.0] * 2, [1.0] * 2).step(np.zeros(2), 0.01)
    rows = TaskRows(np.eye(2), np.array([2.0, 0.0]), None, "joint")
    r = Resolution(np.array([1.0, 0.0]), "scaling", "", 0, (("qp", "daqp: exitflag -1"),),
                   0.0, 0.0, 1e-6, 0.0, bounds, ((rows,),), None, "fallback")  # fmt: skip
    assert r.scale == 0.5 and r.residual == 1.0 and r.status == "fallback"
    assert r.active == (ActiveLimit(0, "upper", "velocity", 1.0, None),)
    assert r.tasks[0].bound_by == r.active
    unknown = r._replace(known_status=None)
    assert unknown.status == "scaled"
    missed = unknown._replace(qdot=np.array([0.5, 0.5]))
    assert missed.status == "least_squares" and missed.scale == 0.25
