"""The Resolution record: active limits with their constraint, lazy fields, repr."""

from __future__ import annotations

import numpy as np
import pytest

from solvers.joint_bounds import JointLimits
from solvers.resolution import ResolutionChain
from solvers.resolution_record import ActiveLimit, Resolution, along


def test_active_limits_name_joint_side_and_kind() -> None:
    J = np.eye(3)
    limits = JointLimits([-1.0] * 3, [1.0, 0.999, 1.0], [0.5, 2.0, 2.0])
    bounds = limits.bounds(np.array([0.0, 0.99, 0.0]), 0.01)
    r = ResolutionChain().resolve(J, np.array([-10.0, 10.0, 0.1]), bounds,
                                  joint_names=["a", "b", "c"])
    assert r.active == (
        ActiveLimit(0, "lower", "velocity", -0.5, "a"),
        ActiveLimit(1, "upper", "position", pytest.approx(0.9 + 1e-11, rel=1e-9), "b"),
    )
    assert "Resolution(" in repr(r) and isinstance(r, Resolution)


def test_lazy_fields_match_their_definitions(rng: np.random.Generator) -> None:
    J = rng.standard_normal((6, 7))
    limits = JointLimits(-np.ones(7), np.ones(7), np.full(7, 0.3))
    x = rng.standard_normal(6)
    r = ResolutionChain().resolve(J, x, limits.bounds(np.zeros(7), 0.01))
    assert r.residual == pytest.approx(np.linalg.norm(J @ r.qdot - x), rel=1e-12)
    assert r.scale == pytest.approx((J @ r.qdot) @ x / (x @ x), rel=1e-12)
    assert along(np.zeros(6), np.zeros(6), None) == 1.0
