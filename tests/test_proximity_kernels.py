"""rrc_pin.solvers.collision.proximity_kernels: the compiled forward kinematics, joint Jacobians
and bounding-sphere test, against numpy references (1e-12) and Pinocchio."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import rrc_pin
from rrc_pin.geometry.tree import tree_of
from rrc_pin.solvers.collision.proximity_kernels import (
    joint_jacobians,
    joint_poses,
    near_pairs,
    world_centres,
)


def rodrigues(axis, theta):
    K = pin.skew(axis)
    return np.eye(3) + np.sin(theta) * K + (1 - np.cos(theta)) * K @ K


@pytest.mark.parametrize("name", ["barker6", "nadkarni_c2", "panda", "kinova", "baxter"])
def test_joint_poses_match_pinocchio_and_a_numpy_product(name, rng):
    """Revolute, prismatic (nadkarni_c2), continuous (kinova) joints, a tree (baxter)."""
    robot = rrc_pin.load(name)
    model = robot.model
    tree = tree_of(model, robot.random_q(rng))
    assert tree is not None
    out = np.zeros((model.njoints, 4, 4))
    for _ in range(20):
        q = robot.random_q(rng)
        joint_poses(q, tree.parent, tree.rotation, tree.translation, tree.kind, tree.axis,
                    tree.coordinate, out)  # fmt: skip
        data = model.createData()
        pin.forwardKinematics(model, data, robot.to_pinocchio(q))
        reference = np.zeros_like(out)
        reference[0] = np.eye(4)
        for j in range(1, model.njoints):
            M = np.eye(4)
            M[:3, :3], M[:3, 3] = tree.rotation[j], tree.translation[j]
            motion = np.eye(4)
            theta = q[tree.coordinate[j]]
            if tree.kind[j] == 0:
                motion[:3, :3] = rodrigues(tree.axis[j], theta)
            else:
                motion[:3, 3] = tree.axis[j] * theta
            reference[j] = reference[tree.parent[j]] @ M @ motion
            np.testing.assert_allclose(out[j], data.oMi[j].homogeneous, atol=1e-12)
        np.testing.assert_allclose(out, reference, atol=1e-12)


SEEDS = (41, int(np.random.SeedSequence().entropy % 2**63))
"""A fixed seed and one drawn fresh each run (named in every failure's message)."""


@pytest.mark.parametrize("seed", SEEDS, ids=("fixed", "fresh"))
@pytest.mark.parametrize("name", ["barker6", "nadkarni_c2", "panda", "kinova", "baxter"])
def test_joint_jacobians_match_pinocchio(name, seed):
    """Every column of ``data.J`` after ``computeJointJacobians`` (WORLD: [v_O; w]), from the
    compiled placements: revolute, prismatic (nadkarni_c2), continuous (kinova), a tree."""
    robot = rrc_pin.load(name)
    model = robot.model
    rng = np.random.default_rng(seed)
    tree = tree_of(model, robot.random_q(rng))
    poses = np.zeros((model.njoints, 4, 4))
    J = np.full((6, model.nv), np.nan)
    for _ in range(20):
        q = robot.random_q(rng)
        joint_poses(q, tree.parent, tree.rotation, tree.translation, tree.kind, tree.axis,
                    tree.coordinate, poses)  # fmt: skip
        joint_jacobians(poses, tree.kind, tree.axis, tree.coordinate, J)
        data = model.createData()
        pin.computeJointJacobians(model, data, robot.to_pinocchio(q))
        np.testing.assert_allclose(J, data.J, atol=1e-12, err_msg=f"seed {seed}")


def test_world_centres_and_near_pairs_against_numpy(rng):
    nj, ng = 4, 9
    poses = np.array([pin.SE3(pin.exp3(rng.normal(size=3)), rng.normal(size=3)).homogeneous
                      for _ in range(nj)])  # fmt: skip
    joint = rng.integers(0, nj, size=ng).astype(np.int64)
    centre = rng.normal(size=(ng, 3)) * 0.1
    world = np.zeros((ng, 3))
    world_centres(poses, joint, centre, world)
    expected = np.einsum("gij,gj->gi", poses[joint, :3, :3], centre) + poses[joint, :3, 3]
    np.testing.assert_allclose(world, expected, atol=1e-12)

    radius = rng.uniform(0.05, 0.5, size=ng)
    radius[-1] = np.inf  # a half-space
    normal = np.zeros((ng, 3))
    normal[-1] = (0.0, 0.0, 1.0)
    offset = np.zeros(ng)
    offset[-1] = -0.5
    pairs = np.array([(a, b) for a in range(ng) for b in range(a + 1, ng)], dtype=np.int64)
    first, second = pairs[:, 0].copy(), pairs[:, 1].copy()
    bound = np.where(
        second == ng - 1,
        world[first] @ normal[-1] - offset[-1] - radius[first],
        np.linalg.norm(world[first] - world[second], axis=1) - radius[first] - radius[second],
    )
    out = np.zeros(len(first), dtype=np.int64)
    every = np.ones(len(first), dtype=np.bool_)
    some = rng.random(len(first)) < 0.5
    for detection in (-1.0, 0.0, 0.3, 10.0):
        count = near_pairs(first, second, world, radius, normal, offset, detection, every, out)
        np.testing.assert_array_equal(out[:count], np.flatnonzero(bound < detection))
        count = near_pairs(first, second, world, radius, normal, offset, detection, some, out)
        np.testing.assert_array_equal(out[:count], np.flatnonzero((bound < detection) & some))
