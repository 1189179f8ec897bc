"""The compiled log3 and exp3 against Pinocchio's, over seeded random rotations and poses and
the cases near an angle of 0 and of pi (each branch of Pinocchio's ``log3_impl``)."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from rrc_pin.solvers.exp_log import PREC, PREC3, displaced, exp3, log3, pose_error

ANGLES = (0.0, 1e-12, 1e-9, 1e-6, 0.5 * PREC, 2.0 * PREC, 1e-3, 1e-2, 1.0, np.pi - 5e-2,
          np.pi - 1e-2, np.pi - 1e-3, np.pi - 2e-3, np.pi - 1e-6, np.pi - 1e-9, np.pi - 1e-12,
          np.pi)  # fmt: skip
"""Angles [rad] at and around each branch: the series near 0, the arc cosine, the arc cosine's
expansion and the axis from the diagonal near pi."""


def _poses(seed: int, count: int) -> list[pin.SE3]:
    rng = np.random.default_rng(seed)
    poses = []
    for k in range(count):
        M = pin.SE3(pin.exp3(rng.normal(size=3)), rng.normal(size=3))
        if k % 2:  # not quite orthonormal: the renormalisation's branch too
            M.rotation = M.rotation + 1e-10 * rng.normal(size=(3, 3))
        poses.append(M)
    return poses


def _near(angle: float, seed: int, count: int) -> list[pin.SE3]:
    rng = np.random.default_rng(seed)
    out = []
    for k in range(count):
        axis = rng.normal(size=3)
        R = pin.exp3(axis / np.linalg.norm(axis) * angle)
        if k % 3 == 0:
            R = R + 1e-12 * rng.normal(size=(3, 3))
        out.append(pin.SE3(R, rng.normal(size=3)))
    return out


def _check(poses: list[pin.SE3]) -> None:
    for M in poses:
        R = np.array(M.rotation)
        w = np.empty(3)
        theta = log3(R, w)
        angle = np.zeros((1, 1))
        np.testing.assert_allclose(w, pin.log3(R, angle), rtol=0.0, atol=1e-12)
        assert abs(theta - angle[0, 0]) <= 1e-12


def test_random_poses_as_pinocchio() -> None:
    _check(_poses(2030, 4000))


@pytest.mark.parametrize("angle", ANGLES)
def test_near_zero_and_pi_as_pinocchio(angle: float) -> None:
    _check(_near(angle, 7, 200))


def test_axes_exactly_at_pi() -> None:
    for R in (np.diag([1.0, -1.0, -1.0]), np.diag([-1.0, 1.0, -1.0]), np.diag([-1.0, -1.0, 1.0])):
        _check([pin.SE3(R, np.array([0.1, -0.2, 0.3]))])


def test_pose_error_as_the_formula() -> None:
    """Turns up to 2.5 rad: nearer pi the logarithm's conditioning turns the product's last
    bits into 1e-12 (log3 itself is tested to pi above)."""
    rng = np.random.default_rng(5)
    targets = np.array([M.homogeneous for M in _poses(6, 300)])
    axes = [a / np.linalg.norm(a) for a in rng.normal(size=(300, 3))]
    turns = [pin.exp3(a * (1e-7 if k % 3 == 0 else rng.uniform(0.0, 2.5)))
             for k, a in enumerate(axes)]  # fmt: skip
    poses = targets.copy()
    for k, E in enumerate(turns):
        poses[k, :3, :3] = E @ targets[k, :3, :3]
        poses[k, :3, 3] = rng.normal(size=3)
    out = np.empty(6)
    for T, P in zip(targets, poses, strict=True):
        pose_error(T, P, out)
        want = np.concatenate([T[:3, 3] - P[:3, 3], pin.log3(T[:3, :3] @ P[:3, :3].T)])
        np.testing.assert_allclose(out, want, rtol=0.0, atol=1e-12)


def test_exp3_as_pinocchio() -> None:
    rng = np.random.default_rng(3)
    for size in (0.0, 1e-12, 1e-8, 1e-5, 0.5 * PREC3, 2.0 * PREC3, 1e-3, 0.1, 1.0, 3.0, 10.0):
        for _ in range(200):
            v = rng.normal(size=3) * size
            out = np.empty((3, 3))
            exp3(v, out)
            np.testing.assert_allclose(out, pin.exp3(v), rtol=0.0, atol=1e-12)


def test_displaced_as_the_formula() -> None:
    rng = np.random.default_rng(4)
    for k in range(1000):
        T = pin.SE3.Random().homogeneous
        delta = rng.normal(size=6) * 10.0 ** (-k % 9)
        out = np.empty((4, 4))
        displaced(T, delta, out)
        want = T.copy()
        want[:3, 3] += delta[:3]
        want[:3, :3] = pin.exp3(delta[3:]) @ T[:3, :3]
        np.testing.assert_allclose(out, want, rtol=0.0, atol=1e-12)
