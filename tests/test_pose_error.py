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


def test_a_stack_gives_the_rows_of_single_calls(rng):
    T = np.tile(np.eye(4), (5, 1, 1))
    T_d = np.tile(np.eye(4), (5, 1, 1))
    for k in range(5):
        T[k, :3, :3], T_d[k, :3, :3] = pin.exp3(rng.normal(size=3)), pin.exp3(rng.normal(size=3))
        T[k, :3, 3], T_d[k, :3, 3] = rng.normal(size=3), rng.normal(size=3)
    rows = pose_error(T, T_d)
    assert rows.shape == (5, 6)
    assert all(np.allclose(rows[k], pose_error(T[k], T_d[k])) for k in range(5))
