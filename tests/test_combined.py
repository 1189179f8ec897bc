"""rrc_pin.combined: several arms at their base placements as one model, equal to the arms apart."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import rrc_pin
from rrc_pin.combined import Combined, combine
from rrc_pin.cross_check import finite_difference_jacobians
from rrc_pin.errors import InvalidInput, ToolFrameRequired


def placement(rng: np.random.Generator) -> np.ndarray:
    return pin.SE3(pin.exp3(rng.normal(size=3)), rng.normal(size=3)).homogeneous


def adjoint(T: np.ndarray) -> np.ndarray:
    """Maps a spatial velocity [v; w] at the origin of the frame T to the origin T is in."""
    R, p = T[:3, :3], T[:3, 3]
    out = np.zeros((6, 6))
    out[:3, :3] = out[3:, 3:] = R
    out[:3, 3:] = pin.skew(p) @ R
    return out


@pytest.fixture
def cell(rng):
    arms = {
        "left": (rrc_pin.load("panda"), placement(rng)),
        "right": (rrc_pin.load("kinova"), placement(rng)),  # continuous joints too
        "third": (rrc_pin.load("barker6", tool_frame=("tool", "flange")), placement(rng)),
    }
    return arms, combine(arms)


def test_names_limits_and_tool_frames_are_the_arms_prefixed(cell):
    arms, robot = cell
    assert robot.name == "left+right+third"
    assert robot.tool_frames == (
        "left/panda_hand_tcp",
        "right/j2s6s200_end_effector",
        "third/tool",
        "third/flange",
    )
    assert robot.tool_frame is None and robot.nq == 7 + 6 + 6
    assert robot.joint_names == [
        f"{key}/{name}" for key, (arm, _) in arms.items() for name in arm.joint_names
    ]
    for attribute in ("lower", "upper", "velocity_limit"):
        np.testing.assert_array_equal(
            getattr(robot, attribute),
            np.concatenate([getattr(arm, attribute) for arm, _ in arms.values()]),
        )
    assert robot.closed_form is None and robot.spec is None


def test_poses_and_jacobians_equal_the_placed_arms(cell, rng):
    arms, robot = cell
    for _ in range(20):
        parts = [arm.random_q(rng) for arm, _ in arms.values()]
        q = np.concatenate(parts)
        start = 0
        for (key, (arm, T)), q_arm in zip(arms.items(), parts, strict=True):
            columns = slice(start, start + arm.nq)
            start += arm.nq
            R6 = np.kron(np.eye(2), T[:3, :3])
            for frame in arm.tool_frames:
                name = f"{key}/{frame}"
                np.testing.assert_allclose(robot.fk(q, name), T @ arm.fk(q_arm, frame), atol=1e-12)
                J = {
                    ref: robot.jacobian(q, ref, name) for ref in ("world_aligned", "local", "world")
                }
                expected = {
                    "world_aligned": R6 @ arm.jacobian(q_arm, "world_aligned", frame),
                    "local": arm.jacobian(q_arm, "local", frame),
                    "world": adjoint(T) @ arm.jacobian(q_arm, "world", frame),
                }
                for ref, J_ref in J.items():
                    np.testing.assert_allclose(J_ref[:, columns], expected[ref], atol=1e-12)
                    # block-sparse: the other arms' joints do not move this frame, exactly
                    others = np.ones(robot.nq, dtype=bool)
                    others[columns] = False
                    assert np.all(J_ref[:, others] == 0.0), (name, ref)


def test_jacobians_match_finite_differences(cell, rng):
    _, robot = cell
    q = robot.random_q(rng)
    for frame in robot.tool_frames:
        for ref, J_fd in finite_difference_jacobians(robot, q, frame=frame).items():
            np.testing.assert_allclose(robot.jacobian(q, ref, frame), J_fd, atol=1e-6)


def test_a_robot_with_several_tool_frames_needs_the_frame(cell):
    _, robot = cell
    with pytest.raises(ToolFrameRequired, match="^frame: left\\+right\\+third has several"):
        robot.fk(robot.neutral())


def test_the_inputs_are_not_changed(rng):
    arm = rrc_pin.load("ur5")
    names = list(arm.model.names)
    combine({"a": (arm, np.eye(4)), "b": (arm, placement(rng))}, name="pair")
    assert list(arm.model.names) == names and arm.fk(arm.neutral()).shape == (4, 4)


@pytest.mark.parametrize(
    ("arms", "message"),
    [
        ({}, "^arms: expected a non-empty mapping"),
        ([("a", None)], "^arms: expected a non-empty mapping"),
        ({"a/b": "x"}, "^arms: keys must be non-empty names without '/'"),
        ({"": "x"}, "^arms: keys must be non-empty names"),
        ({"a": "ur5"}, r"^arms\['a'\]: expected \(Robot, T_base \(4, 4\)\)"),
        ({"a": ("UR5", np.eye(4))}, r"^arms\['a'\]: expected \(Robot, T_base"),
        ({"a": ("ROBOT", np.eye(3))}, r"^arms\['a'\]: expected .*shape \(4, 4\)"),
        ({"a": ("ROBOT", 2 * np.eye(4))}, r"^arms\['a'\]: not a rigid transform"),
        ({"a": ("ROBOT", np.diag([1.0, 1, -1, 1]))}, r"^arms\['a'\]: not a rigid"),
        ({"a": ("ROBOT", np.full((4, 4), np.nan))}, r"^arms\['a'\]: non-finite entry"),
    ],
)
def test_bad_arms_are_refused_naming_the_entry(arms, message):
    robot = rrc_pin.load("kr5_3r")
    if isinstance(arms, dict):
        arms = {
            k: (robot, v[1]) if isinstance(v, tuple) and v[0] == "ROBOT" else v
            for k, v in arms.items()
        }
    with pytest.raises(InvalidInput, match=message):
        combine(arms)


def test_a_bad_name_is_refused():
    with pytest.raises(InvalidInput, match="^name: expected a string"):
        combine({"a": (rrc_pin.load("kr5_3r"), np.eye(4))}, name=3)


def test_the_ready_pose_is_the_arms_side_by_side(cell):
    """Issue 33 item 2: a cell starts where each of its arms would."""
    arms, robot = cell
    want = np.concatenate([arm.ready() for arm, _ in arms.values()])
    np.testing.assert_array_equal(robot.ready(), want)
    np.testing.assert_array_equal(robot.poses["ready"], want)


def test_the_result_keeps_its_arms_and_their_placements(cell):
    arms, robot = cell
    assert isinstance(robot, Combined)
    assert [p.key for p in robot.parts] == list(arms)
    for part, (arm, T) in zip(robot.parts, arms.values(), strict=True):
        assert part.robot is arm
        np.testing.assert_allclose(part.T_base, T, atol=1e-15)


def test_a_fixed_joint_named_after_its_link_joins_a_cell(rng):
    """z1's URDF names a fixed joint after its child link (two frames ``gripperStator``, a
    fixed joint's and a body's): the joint's frame is ``<name>_joint`` in the cell, the arm's
    kinematics unchanged."""
    z1 = rrc_pin.load("z1")
    pair = combine({"a": (z1, np.eye(4)), "b": (z1, placement(rng))})
    names = [f.name for f in pair.model.frames]
    assert names.count("a/gripperStator") == 1 and "a/gripperStator_joint" in names
    q = z1.random_q(rng)
    assert np.allclose(pair.fk(np.concatenate([q, q]), pair.tool_frames[0]), z1.fk(q), atol=1e-12)
