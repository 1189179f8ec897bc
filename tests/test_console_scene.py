"""The scene: a node per joint, nested as the joints are, and the hands' axes under them."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import rrc_pin
from rrc_pin.console.scene import ARROW, Scene, pose_of, wxyz
from rrc_pin.console.visuals import visuals_of

viser = pytest.importorskip("viser")


@pytest.fixture(scope="module")
def server():
    s = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
    yield s
    s.stop()


def se3(handle) -> pin.SE3:
    w, x, y, z = handle.wxyz
    return pin.SE3(pin.Quaternion(w, x, y, z).matrix(), np.array(handle.position))


def two_arms():
    T = np.eye(4)
    T[:3, 3] = [0.0, 0.8, 0.0]
    return rrc_pin.combine(
        {"a": (rrc_pin.load("kr5_3r"), np.eye(4)), "b": (rrc_pin.load("barker6"), T)}
    )


@pytest.mark.parametrize(
    "make", [lambda: rrc_pin.load("barker6"), two_arms, lambda: rrc_pin.load("kinova")]
)
def test_nested_joint_nodes_put_every_hand_where_the_kinematics_does(server, make):
    robot = make()
    scene = Scene(server, robot, visuals_of(robot))
    rng = np.random.default_rng(3)
    scene.update(robot.random_q(rng))
    q = robot.random_q(rng)
    pose = scene.update(q)  # the second: only what a joint's motion changes is sent
    model = robot.model
    for tool, handle in scene.hands.items():
        frame = model.frames[model.getFrameId(tool)]
        chain, j = [], int(frame.parentJoint)
        while j > 0:
            chain.append(j)
            j = model.parents[j]
        M = pin.SE3.Identity()
        for j in reversed(chain):
            M = M * se3(scene._nodes[j])
        M = M * se3(handle)
        np.testing.assert_allclose(M.homogeneous, robot.fk(q, tool), atol=1e-6)
    np.testing.assert_allclose(pose, robot.fk(q, scene.hand), atol=1e-12)
    np.testing.assert_allclose(scene.gizmo.position, pose[:3, 3], atol=1e-6)  # it follows


def test_arrows_start_at_the_hand_and_scale_with_the_twist(server):
    robot = rrc_pin.load("kr5_3r")
    scene = Scene(server, robot, visuals_of(robot))
    origin = np.array([0.5, 0.1, 0.3])
    scene.set_arrows(origin, np.array([0.1, 0, 0, 0, 0, 0.25]), None)  # full, half full
    points = np.asarray(scene.arrows.points)
    np.testing.assert_allclose(points[:, 0], np.tile(origin, (4, 1)), atol=1e-6)
    np.testing.assert_allclose(points[0, 1] - origin, [ARROW * scene.reach, 0, 0], atol=1e-6)
    np.testing.assert_allclose(points[1, 1] - origin, [0, 0, ARROW * scene.reach / 2], atol=1e-6)
    np.testing.assert_allclose(points[2:, 1], points[2:, 0])  # nothing achieved


def test_obstacles_and_pairs_can_be_drawn_and_cleared(server):
    robot = rrc_pin.load("kr5_3r")
    scene = Scene(server, robot, visuals_of(robot))
    scene.set_obstacles([(np.eye(4), np.array([0.1, 0.2, 0.3]))])
    scene.set_pairs(np.zeros((1, 2, 3)))
    assert len(scene._obstacles) == 1 and scene._pairs is not None
    scene.set_obstacles([])
    scene.set_pairs(np.zeros((0, 2, 3)))
    assert scene._obstacles == [] and scene._pairs is None


def test_wxyz_is_the_rotation():
    R = pin.rpy.rpyToMatrix(0.3, -1.0, 2.0)
    w, x, y, z = wxyz(R)
    np.testing.assert_allclose(pin.Quaternion(w, x, y, z).matrix(), R, atol=1e-12)


def test_pose_of_refuses_what_is_not_a_pose():
    T = pose_of([0.1, 0.2, 0.3], [2.0, 0.0, 0.0, 0.0])  # normalised
    np.testing.assert_allclose(T, np.r_[np.c_[np.eye(3), [0.1, 0.2, 0.3]], [[0, 0, 0, 1]]])
    assert pose_of([0, 0, np.nan], [1, 0, 0, 0]) is None
    assert pose_of([0, 0, 0], [0, 0, 0, 0]) is None
    assert pose_of([0, 0], [1, 0, 0, 0]) is None
    assert pose_of("abc", [1, 0, 0, 0]) is None
