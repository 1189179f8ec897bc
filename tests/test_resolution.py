"""The Resolution record: what it reports, computed from the problem it answered, immutable."""

from __future__ import annotations

import numpy as np
import pytest

from rrc_pin.solvers.qp_backends import make_backend
from rrc_pin.solvers.tick.joint_box import joint_box
from rrc_pin.solvers.tick.pipeline import METHODS, Options, scale_and_veer, solve
from rrc_pin.solvers.tick.problem import Box, Constraints, TaskRows, build
from rrc_pin.solvers.tick.resolution import (
    ACTIVE_TOL,
    ActiveLimit,
    ActiveRow,
    Resolution,
    active_limits,
)


def box(n: int = 3, v: float = 1.0, q: np.ndarray | None = None) -> Box:
    lb, ub, kind = np.empty(n), np.empty(n), np.empty((2, n), np.int8)
    q = np.zeros(n) if q is None else q
    zero, recovering = joint_box(
        q,
        -np.ones(n),
        np.ones(n),
        np.full(n, v),
        0.0,
        1.0,
        0.01,
        np.zeros(n),
        np.array([np.inf]),
        lb,
        ub,
        kind,
    )
    return Box(lb, ub, kind, zero, recovering, np.full(n, v))


def solved(command: np.ndarray, rows: Constraints | None = None) -> Resolution:
    J = np.array([[1.0, 0.5, 0.0], [0.0, 1.0, 0.5]])
    task = TaskRows(J, command, None, "hand", np.array([2.0, 1.0]))
    limits = [Constraints(box())] + ([] if rows is None else [rows])
    problem = build([[task]], limits, 3, 0.01)
    answer = solve(problem, make_backend("daqp"), Options())
    return Resolution.of(problem, answer, 1e-5, ("j1", "j2", "j3"))


def test_a_met_command_reports_exact() -> None:
    b = np.array([0.05, -0.02])
    r = solved(b)
    np.testing.assert_allclose(r.problem.levels[0][0].A @ r.qdot, b, atol=1e-15)
    assert r.scale == 1.0 and r.veer == 0.0 and r.residual < 1e-15 and r.status == "exact"
    assert r.method in METHODS and r.method == "qp" and r.active == () and r.levels == ("met",)
    (report,) = r.tasks
    assert report.name == "hand" and report.level == 0 and report.bound_by == ()
    assert report.scale == pytest.approx(1.0, abs=1e-15) and report.residual < 1e-15
    assert "status='exact'" in repr(r) and r.build_time == pytest.approx(1e-5)


def test_a_command_beyond_the_limits_is_scaled_along_its_direction() -> None:
    b = np.array([3.0, 1.0])
    r = solved(b)
    y = r.problem.levels[0][0].A @ r.qdot
    assert r.status == "scaled" and 0.0 < r.scale < 1.0 and r.veer == 0.0
    np.testing.assert_allclose(y, r.scale * b, atol=1e-12)
    assert r.residual == pytest.approx(np.linalg.norm(y - b), rel=1e-12)
    assert r.active and all(a.kind == "velocity" for a in r.active)
    assert {a.name for a in r.active} <= {"j1", "j2", "j3"}
    assert r.tasks[0].bound_by == r.active
    assert (r.qdot >= r.box.lb).all() and (r.qdot <= r.box.ub).all()


def test_the_old_name_of_the_box_warns_for_one_release() -> None:
    r = solved(np.array([3.0, 1.0]))
    with pytest.warns(DeprecationWarning, match=r"Resolution.bounds is deprecated.*\.box"):
        old = r.bounds
    assert old is r.box


def test_active_rows_by_name() -> None:
    g = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    r = solved(
        np.array([3.0, 1.0]), Constraints(G=g, h=np.array([0.2, 5.0]), names=("wall", "far wall"))
    )
    assert r.active_rows == (ActiveRow("wall", 0, pytest.approx(0.2), 0.2),)
    assert float(r.qdot[0]) <= 0.2


def test_the_resolution_is_immutable() -> None:
    r = solved(np.array([3.0, 1.0]))
    for name in ("qdot", "method", "status", "scale", "veer", "levels", "active", "problem"):
        with pytest.raises(AttributeError):
            setattr(r, name, None)
    with pytest.raises(ValueError, match="read-only"):
        r.qdot[0] = 1.0


def test_active_limits_kinds_names_and_sides() -> None:
    b = box(2, v=2.0, q=np.array([1.0, 0.0]))  # joint 0 on its upper limit
    qdot = np.array([0.0, -2.0])
    assert active_limits(qdot, b, ("a", "b")) == (
        ActiveLimit(0, "upper", "position", 0.0, "a"),
        ActiveLimit(1, "lower", "velocity", -2.0, "b"),
    )
    assert active_limits(qdot + 2 * ACTIVE_TOL * np.array([-1, 1]), b) == ()


def test_scale_and_veer(rng: np.random.Generator) -> None:
    for _ in range(300):
        b = rng.normal(size=4)
        u = float(rng.uniform(-0.5, 1.5))
        side = rng.normal(size=4)
        side -= (side @ b) / (b @ b) * b
        scale, veer = scale_and_veer(u * b + side, b)
        assert scale == pytest.approx(min(1.0, max(0.0, u)), abs=1e-12)
        y = u * b + side
        cos = (y @ b) / np.linalg.norm(y) / np.linalg.norm(b)
        assert veer == pytest.approx(np.arccos(np.clip(cos, -1, 1)), abs=1e-7)
    assert scale_and_veer(np.zeros(3), np.zeros(3)) == (1.0, 0.0)
    assert scale_and_veer(np.zeros(3), np.ones(3)) == (0.0, 0.0)
    huge = np.array([1.7e308, -1.7e308, 0.0])
    assert scale_and_veer(0.5 * huge, huge) == (pytest.approx(0.5), pytest.approx(0.0, abs=1e-7))
    assert scale_and_veer(np.array([1e-300, 0.0]), np.array([1e300, 0.0]))[0] == 0.0
