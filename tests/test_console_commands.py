"""The page's requests: every bad value refused where it arrives, naming the field."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rrc_pin.console import commands as cmd
from rrc_pin.errors import InvalidInput


@pytest.mark.parametrize(
    "value", [math.nan, math.inf, -math.inf, "0.1", None, True, [0.1], 1.5, -0.2]
)
def test_bounded_refuses_what_is_not_a_number_in_range(value):
    with pytest.raises(InvalidInput, match="speed"):
        cmd.Speed(value)


def test_bounded_takes_ints_floats_and_numpy_numbers():
    assert cmd.Speed(1).value == 1.0
    assert cmd.Speed(np.float32(0.5)).value == 0.5
    assert cmd.Speed(np.int64(0)).value == 0.0


def test_velocity_from_page_checks_each_component_against_its_range():
    v = cmd.velocity_from_page([0.1, 0, -0.1, 0.5, 0, -0.5], "world_aligned", 0.1, 0.5)
    assert v.frame == "world_aligned"
    np.testing.assert_array_equal(v.twist, [0.1, 0, -0.1, 0.5, 0, -0.5])
    assert not v.twist.flags.writeable
    with pytest.raises(InvalidInput, match="vy"):
        cmd.velocity_from_page([0, 0.2, 0, 0, 0, 0], "local", 0.1, 0.5)
    with pytest.raises(InvalidInput, match="wz"):
        cmd.velocity_from_page([0, 0, 0, 0, 0, math.nan], "local", 0.1, 0.5)
    with pytest.raises(InvalidInput, match="vx"):
        cmd.velocity_from_page(["garbage", 0, 0, 0, 0, 0], "local", 0.1, 0.5)
    with pytest.raises(InvalidInput, match="frame"):
        cmd.velocity_from_page([0] * 6, "world", 0.1, 0.5)
    with pytest.raises(InvalidInput, match="twist"):
        cmd.velocity_from_page([0] * 5, "local", 0.1, 0.5)


def test_velocity_refuses_non_finite_twists():
    with pytest.raises(InvalidInput, match="twist"):
        cmd.Velocity(np.array([0, 0, math.inf, 0, 0, 0]))
    with pytest.raises(InvalidInput, match="twist"):
        cmd.Velocity(np.zeros(5))


@pytest.mark.parametrize(
    ("axis", "sign", "name"),
    [
        (6, 1, "axis"),
        (-1, 1, "axis"),
        (True, 1, "axis"),
        (0, 0, "sign"),
        (0, 2, "sign"),
        (0, True, "sign"),
    ],
)
def test_jog_checks_axis_and_sign(axis, sign, name):
    with pytest.raises(InvalidInput, match=name):
        cmd.Jog(axis, sign)


def test_target_takes_rigid_transforms_only():
    T = np.eye(4)
    T[:3, 3] = [0.1, 0.2, 0.3]
    assert cmd.Target(T).pose[0, 3] == 0.1
    assert cmd.Target(None).pose is None
    bad = np.eye(4)
    bad[0, 0] = 2.0
    for pose in (bad, np.full((4, 4), math.nan), np.eye(3), -np.eye(4)):
        with pytest.raises(InvalidInput, match="pose"):
            cmd.Target(pose)


def test_names_and_paths_are_checked():
    with pytest.raises(InvalidInput, match="strategy"):
        cmd.Strategy("")
    with pytest.raises(InvalidInput, match="backend"):
        cmd.Backend(3)  # type: ignore[arg-type]
    with pytest.raises(InvalidInput, match="hand"):
        cmd.Hand(None)  # type: ignore[arg-type]
    with pytest.raises(InvalidInput, match="path"):
        cmd.Save("run.txt")
    with pytest.raises(InvalidInput, match="path"):
        cmd.Load("run")
    with pytest.raises(InvalidInput, match="on"):
        cmd.Latch("yes")  # type: ignore[arg-type]
    with pytest.raises(InvalidInput, match="seconds"):
        cmd.Reverse(0.0)


def test_a_device_pose_from_the_page_is_seven_or_eight_numbers_with_a_unit_quaternion():
    """``x y z qw qx qy qz [clutch]``: a quarter turn about z at (0.1, 0, 0.2), the clutch
    pressed; a quaternion within 1e-3 of unit length normalised; empty ends the stream."""
    c = cmd.pose_from_page("0.1 0 0.2 0.70710678 0 0 0.70710678 1")
    want = np.array([[0.0, -1.0, 0.0, 0.1], [1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.2],
                     [0.0, 0.0, 0.0, 1.0]])  # fmt: skip
    np.testing.assert_allclose(c.pose, want, atol=1e-8)
    assert c.clutch and not c.pose.flags.writeable
    loose = cmd.pose_from_page("0, 0, 0, 1.0005, 0, 0, 0")
    np.testing.assert_allclose(loose.pose, np.eye(4), atol=1e-12)
    assert not loose.clutch
    assert cmd.pose_from_page("  ").pose is None
    for text, name in (("1 2 3", "pose"), ("0 0 0 1 0 0 0 2", "pose"), ("0 0 nan 1 0 0 0", "pose"),
                       ("0 0 0 1 0 0 x", "pose"), ("0 0 0 2 0 0 0", "quaternion"),
                       (None, "pose")):  # fmt: skip
        with pytest.raises(InvalidInput, match=name):
            cmd.pose_from_page(text)  # type: ignore[arg-type]
    with pytest.raises(InvalidInput, match="clutch"):
        cmd.Pose(np.eye(4), clutch=1)  # type: ignore[arg-type]
    with pytest.raises(InvalidInput, match="pose"):
        cmd.Pose(-np.eye(4))
