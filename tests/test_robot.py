"""The Pinocchio-backed Robot: shapes, frames, limits, continuous joints, bad input."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import rrc_pin
from rrc_pin.errors import FrameNotFound, InvalidInput, URDFError
from rrc_pin.loading import INSTALLED, robots_directory
from rrc_pin.robot import Robot


def test_api_shapes_and_limits(rng):
    arm = rrc_pin.load("rrc_k1607")
    assert arm.nq == 7 and len(arm.joint_names) == 7 and arm.tool_frame == "tool"
    assert arm.lower.shape == arm.upper.shape == arm.velocity_limit.shape == (7,)
    for _ in range(100):
        q = arm.random_q(rng)
        assert np.all(arm.lower <= q) and np.all(q <= arm.upper)
    assert arm.fk(arm.neutral()).shape == (4, 4)
    assert arm.jacobian(arm.neutral()).shape == (6, 7)


def test_one_data_per_robot_is_reused():
    arm = rrc_pin.load("barker6")
    data = arm.data
    arm.fk(np.zeros(6))
    arm.jacobian(np.ones(6), "local")
    assert arm.data is data


def test_neutral_is_zero_clipped_into_the_limits():
    arm = rrc_pin.load("panda")
    q = arm.neutral()
    assert np.all(arm.lower <= q) and np.all(q <= arm.upper)
    assert q[3] == pytest.approx(arm.upper[3])  # panda joint 4 cannot reach zero


def test_continuous_joints_take_one_angle_each(rng):
    """kinova's continuous joints are (cos, sin) in Pinocchio, one angle at this API."""
    arm = rrc_pin.load("kinova")
    assert arm.model.nq == 9 and arm.nq == 6
    assert np.sum(np.isinf(arm.upper)) == 3
    q = arm.random_q(rng)
    T = arm.fk(q)
    q_wrapped = q.copy()
    q_wrapped[np.isinf(arm.upper)] += 2 * np.pi
    np.testing.assert_allclose(arm.fk(q_wrapped), T, atol=1e-12)


def test_free_flyer_is_refused_with_the_reason():
    path = robots_directory() / INSTALLED["ur5"].path
    model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    with pytest.raises(URDFError, match="JointModelFreeFlyer.*1-DOF joints only"):
        Robot(model, "tool0", name="ur5_floating", source=str(path))


@pytest.mark.parametrize(
    "q",
    [np.zeros(5), np.zeros(7), [0, 0, np.nan, 0, 0, 0], [np.inf, 0, 0, 0, 0, 0], "abc", [[0] * 6]],
)
def test_bad_q_names_q(q):
    arm = rrc_pin.load("barker6")
    for call in (arm.fk, arm.jacobian):
        with pytest.raises(ValueError, match="^q:"):
            call(q)


def test_bad_ref_and_frame():
    arm = rrc_pin.load("barker6")
    with pytest.raises(InvalidInput, match="^ref:.*world_aligned"):
        arm.jacobian(np.zeros(6), ref="base")
    with pytest.raises(FrameNotFound, match="nowhere.*flange"):
        arm.frame_pose(np.zeros(6), "nowhere")


def test_closed_form_is_none_for_non_paper_arms():
    assert rrc_pin.load("ur5").closed_form is None
    assert rrc_pin.load("nadkarni_c1").closed_form is None
