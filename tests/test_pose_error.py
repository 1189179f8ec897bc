"""The Cartesian error: position difference and Nguyen's quaternion orientation error."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from rrc_pin.dynamics.pose_error import pose_error


def test_orientation_error_is_the_rotation_vector_to_third_order(rng):
    """2 delta s of R_d R^T equals log(R_d R^T) up to theta^3 / 24 (Nguyen eq. (37))."""
    for angle in (1e-3, 0.05, 0.3):
        T, T_d = np.eye(4), np.eye(4)
        T[:3, :3] = pin.exp3(rng.normal(size=3))
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        T_d[:3, :3] = pin.exp3(angle * axis) @ T[:3, :3]
        T[:3, 3], T_d[:3, 3] = rng.normal(size=3), rng.normal(size=3)
        e = pose_error(T, T_d)
        assert np.allclose(e[:3], T_d[:3, 3] - T[:3, 3])
        assert np.linalg.norm(e[3:] - angle * axis) <= angle**3 / 24 * 1.01 + 1e-15
