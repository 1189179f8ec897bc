"""rrc_pin.geometry.walls: the six walls of a box and a single wall, normals outward."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from rrc_pin.geometry.walls import FACES, box_walls, plane_wall


def test_a_box_gives_six_outward_unit_walls_through_its_faces(rng):
    T = pin.SE3(pin.exp3(rng.normal(size=3)), rng.normal(size=3)).homogeneous
    size = np.array([0.2, 0.5, 0.9])
    walls = box_walls("box", "tool", T, size)
    assert [w.name for w in walls] == [f"box/{f}" for f in FACES]
    for k, wall in enumerate(walls):
        axis, sign = k // 2, 1.0 if k % 2 == 0 else -1.0
        np.testing.assert_allclose(wall.normal, sign * T[:3, axis], atol=1e-15)
        face_centre = T[:3, 3] + sign * T[:3, axis] * size[axis] / 2
        assert abs(wall.normal @ face_centre - wall.offset) < 1e-12
        assert wall.normal @ T[:3, 3] < wall.offset  # the centre is inside
        assert not wall.normal.flags.writeable


def test_a_wall_is_normalised():
    wall = plane_wall("w", "tool", np.array([3.0, 0.0, 4.0]), 10.0)
    np.testing.assert_allclose(wall.normal, (0.6, 0.0, 0.8))
    assert wall.offset == 2.0
