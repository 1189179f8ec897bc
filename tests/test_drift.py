"""The controller's drift correction: Nguyen's pose error (eqs. (32)-(34), (37)) by Pinocchio,
the clipped twist, the reference's advance by the fraction of the command followed."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import rrc_pin
from rrc_pin.control import Controller
from rrc_pin.control.controller import REANCHOR, _followed
from rrc_pin.control.drift import DriftCorrection, advance, pose_error
from rrc_pin.solvers.closed_form.quaternion import (
    differential_rotation,
    quaternion_difference,
    quaternion_from_matrix,
)


@pytest.fixture(scope="module")
def panda_arm():
    return rrc_pin.load("panda")


def test_pose_error_is_nguyens_in_hand_axes(rng):
    """R^T times 2 delta s of Q{R_ref} * conj(Q{R}), and R^T (p_ref - p), to 1e-12.

    From small angles to near 180 deg apart (where the product of the two quaternions may
    have delta eta < 0 and the sign of eq. (37) matters).
    """
    for angle in (1e-9, 1e-4, 0.05, 0.5, 2.0, 3.1, np.pi - 1e-9):
        pose = pin.SE3(pin.exp3(rng.normal(size=3)), rng.normal(size=3))
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        reference = pin.SE3(pin.exp3(angle * axis) @ pose.rotation, rng.normal(size=3))
        R, R_ref = pose.rotation, reference.rotation
        quats = quaternion_from_matrix(np.stack([R, R_ref]))
        nguyen = differential_rotation(quaternion_difference(quats[0], quats[1]))  # base axes
        error = pose_error(pose, reference)
        assert np.max(np.abs(error[3:] - R.T @ nguyen)) <= 1e-12, angle
        linear = R.T @ (reference.translation - pose.translation)
        assert np.max(np.abs(error[:3] - linear)) <= 1e-12


def test_correction_is_clipped_part_by_part():
    drift = DriftCorrection(gain=2.0, max_linear=0.01, max_angular=0.05)
    small = np.array([1e-3, -2e-3, 0.0, 1e-3, 0.0, 0.0])
    assert np.allclose(drift.twist(small), 2.0 * small, rtol=0, atol=1e-15)
    large = np.array([0.3, 0.4, 0.0, 0.0, 0.0, -1.0])
    twist = drift.twist(large)
    assert abs(np.linalg.norm(twist[:3]) - 0.01) <= 1e-15
    assert np.allclose(twist[:3] / 0.01, [0.6, 0.8, 0.0], rtol=0, atol=1e-15)
    assert np.allclose(twist[3:], [0.0, 0.0, -0.05], rtol=0, atol=1e-15)


def test_the_reference_advances_along_the_twist():
    reference = pin.SE3(pin.exp3(np.array([0.3, -0.2, 0.1])), np.array([0.5, 0.1, 0.2]))
    twist = np.array([0.1, 0.0, -0.2, 0.0, 0.5, 0.3])
    local = advance(reference, twist, 0.01, "local")
    assert np.allclose(pin.log6(reference.actInv(local)).vector, 0.01 * twist, atol=1e-15)
    world = advance(reference, twist, 0.01, "world")  # the spatial twist at the base origin
    assert np.allclose(pin.log6(world * reference.inverse()).vector, 0.01 * twist, atol=1e-15)
    base = advance(reference, twist, 0.01, "world_aligned")
    assert np.allclose(base.translation - reference.translation, 0.01 * twist[:3], atol=1e-15)
    turn = pin.log3(base.rotation @ reference.rotation.T)
    assert np.allclose(turn, 0.01 * twist[3:], atol=1e-15)


def test_the_followed_fraction_is_the_resolutions_scale(panda_arm):
    """The controller's shortcut (no bound touched: the whole command) agrees with ``scale``.

    Every third command beyond the velocity limits, so that the answers are exact (100 of 150)
    and scaled (50, all below 1).
    """
    ctl = Controller(panda_arm, q0=np.array([0.0, -0.5, 0.0, -2.0, 0.0, 1.8, 0.7]))
    rng = np.random.default_rng(3)
    seen = set()
    for k in range(150):
        twist = rng.normal(size=6) * (0.05 if k % 3 else 2.0)
        r = ctl.step(twist, ref="local").resolution
        expected = None if r.status in REANCHOR else r.scale
        got = _followed(r)
        seen.add(r.status)
        if expected is None:
            assert got is None
        else:
            assert got is not None and abs(got - expected) <= 1e-12, (r.status, got, expected)
    assert {"exact", "scaled"} <= seen
