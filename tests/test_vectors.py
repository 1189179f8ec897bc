"""rrc_pin.solvers.collision.vectors: each formula on tuples against numpy (1e-15), on seeded
random vectors and placements."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from rrc_pin.solvers.collision.vectors import along, cross, dot, norm, placed, sub

TOL = 1e-15


def test_each_formula_matches_numpy(rng):
    for _ in range(200):
        a, b = rng.normal(size=3), rng.normal(size=3)
        s = float(rng.normal())
        ta, tb = tuple(a.tolist()), tuple(b.tolist())
        assert abs(dot(ta, tb) - a @ b) <= TOL * 10
        np.testing.assert_allclose(sub(ta, tb), a - b, atol=TOL)
        np.testing.assert_allclose(along(ta, s, tb), a + s * b, atol=TOL * 10)
        np.testing.assert_allclose(cross(ta, tb), np.cross(a, b), atol=TOL * 10)
        assert abs(norm(ta) - np.linalg.norm(a)) <= TOL * 10
        poses = np.array([pin.SE3(pin.exp3(rng.normal(size=3)), rng.normal(size=3)).homogeneous
                          for _ in range(3)])  # fmt: skip
        np.testing.assert_allclose(placed(poses, 1, ta), poses[1][:3, :3] @ a + poses[1][:3, 3],
                                   atol=TOL * 10)  # fmt: skip
