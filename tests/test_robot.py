"""The Pinocchio-backed Robot: shapes, frames, limits, continuous joints, threads, bad input."""

from __future__ import annotations

import sys
import threading

import numpy as np
import pinocchio as pin
import pytest

import rrc_pin
from rrc_pin.errors import FrameNotFound, InvalidInput, ToolFrameRequired, URDFError
from rrc_pin.loading import INSTALLED, robots_directory
from rrc_pin.models import CATALOGUE
from rrc_pin.robot import Robot, end_links


def test_api_shapes_and_limits(rng):
    arm = rrc_pin.load("rrc_k1607")
    assert arm.nq == 7 and len(arm.joint_names) == 7 and arm.tool_frame == "tool"
    assert arm.lower.shape == arm.upper.shape == arm.velocity_limit.shape == (7,)
    for _ in range(100):
        q = arm.random_q(rng)
        assert np.all(arm.lower <= q) and np.all(q <= arm.upper)
    assert arm.fk(arm.neutral()).shape == (4, 4)
    assert arm.jacobian(arm.neutral()).shape == (6, 7)


def test_to_pinocchio_returns_q_itself_or_a_new_array(rng):
    """Never a buffer shared between calls: two configurations converted one after the other
    keep their own values."""
    panda = rrc_pin.load("panda")
    q = panda.random_q(rng)
    assert panda.to_pinocchio(q) is q
    kinova = rrc_pin.load("kinova")  # three continuous joints: (cos, sin) in Pinocchio
    q1, q2 = kinova.random_q(rng), kinova.random_q(rng)
    p1 = kinova.to_pinocchio(q1)
    p1_values = p1.copy()
    p2 = kinova.to_pinocchio(q2)
    assert p1 is not p2 and p1.shape == (9,)
    np.testing.assert_array_equal(p1, p1_values)
    assert np.abs(p1 - p2).max() > 1e-3


def test_random_q_takes_a_generator_a_seed_or_none():
    arm = rrc_pin.load("panda")
    np.testing.assert_array_equal(arm.random_q(0), arm.random_q(0))
    np.testing.assert_array_equal(arm.random_q(np.int64(3)), arm.random_q(3))
    assert np.abs(arm.random_q(0) - arm.random_q(1)).max() > 1e-3
    g = np.random.default_rng(0)
    first, second = arm.random_q(g), arm.random_q(g)  # a Generator advances
    np.testing.assert_array_equal(first, arm.random_q(0))
    assert np.abs(first - second).max() > 1e-3
    for q in (arm.random_q(None), arm.random_q()):
        assert np.all(arm.lower <= q) and np.all(q <= arm.upper)
    for bad in ("x", -1, True, 1.5):
        with pytest.raises(InvalidInput, match="^rng: expected a numpy Generator"):
            arm.random_q(bad)


def test_no_moving_joint_is_refused(tmp_path):
    path = tmp_path / "statue.urdf"
    path.write_text(
        '<robot name="statue"><link name="base"/><link name="head"/>'
        '<joint name="neck" type="fixed"><parent link="base"/><child link="head"/></joint>'
        "</robot>"
    )
    with pytest.raises(URDFError, match=f"{path}: no moving joint"):
        rrc_pin.load(path)
    model = pin.buildModelFromUrdf(str(path))
    with pytest.raises(URDFError, match="no moving joint"):
        Robot(model, "head", name="statue", source="here")


def test_several_tool_frames_and_the_frame_argument(rng):
    arm = rrc_pin.load("baxter")
    assert arm.tool_frames == ("left_gripper", "right_gripper") and arm.tool_frame is None
    q = arm.random_q(rng)
    left = rrc_pin.load("baxter", tool_frame="left_gripper")
    assert left.tool_frame == "left_gripper" and left.tool_frames == ("left_gripper",)
    np.testing.assert_array_equal(arm.fk(q, "left_gripper"), left.fk(q))
    np.testing.assert_array_equal(
        arm.jacobian(q, "local", "left_gripper"), left.jacobian(q, "local")
    )
    for call in (arm.fk, arm.jacobian):
        with pytest.raises(
            ToolFrameRequired,
            match="^frame: baxter has several tool frames; "
            "name one of: left_gripper, right_gripper$",
        ) as info:
            call(q)
        assert info.value.candidates == ["left_gripper", "right_gripper"]
        with pytest.raises(
            FrameNotFound, match="^frame: no frame 'left_hand'; frames: .*left_gripper"
        ):
            call(q, frame="left_hand")
    assert isinstance(ToolFrameRequired("frame", "x", []), InvalidInput)


def test_tool_frames_are_checked():
    model = rrc_pin.load("kr5_3r").model
    with pytest.raises(FrameNotFound, match="^tool_frame: no frame 'hand'"):
        Robot(model, ("tool", "hand"), name="x", source="x")
    for bad in ((), ("tool", "tool")):
        with pytest.raises(InvalidInput, match="^tool_frame: expected distinct frame names"):
            Robot(model, bad, name="x", source="x")


def test_end_links_are_the_moving_leaves_of_the_tree():
    chain = rrc_pin.load("kr5_3r").model
    assert end_links(chain) == ["tool"]
    baxter = pin.buildModelFromUrdf(str(robots_directory() / INSTALLED["baxter"].path))
    ends = end_links(baxter)
    assert {"left_gripper", "right_gripper", "l_gripper_l_finger_tip"} <= set(ends)
    assert "sonar_ring" not in ends and "pedestal" not in ends  # fixed to the base


def test_shared_robot_gives_every_thread_its_own_answers():
    """Issue 15: threads calling fk and jacobian on one Robot, with another thread churning
    frame_pose, jacobian and to_pinocchio on it, get the single-threaded answers."""
    arm = rrc_pin.load("panda")
    rng = np.random.default_rng(0)
    Q = [arm.random_q(rng) for _ in range(100)]
    ref_T = [arm.fk(q).copy() for q in Q]
    ref_J = [arm.jacobian(q).copy() for q in Q]
    stop = threading.Event()
    bad: list[int] = []
    calls: list[int] = []

    def churn() -> None:
        g = np.random.default_rng(1)
        while not stop.is_set():
            arm.frame_pose(arm.random_q(g), "panda_link4")
            arm.jacobian(arm.random_q(g), "local")
            arm.to_pinocchio(arm.random_q(g))

    def check() -> None:
        mismatches = n = 0
        for _ in range(20):
            for q, T, J in zip(Q, ref_T, ref_J, strict=True):
                mismatches += np.abs(arm.fk(q) - T).max() > 1e-12
                mismatches += np.abs(arm.jacobian(q) - J).max() > 1e-12
                n += 2
        bad.append(mismatches)
        calls.append(n)

    interval = sys.getswitchinterval()
    sys.setswitchinterval(1e-6)
    try:
        churner = threading.Thread(target=churn)
        checkers = [threading.Thread(target=check) for _ in range(3)]
        churner.start()
        for t in checkers:
            t.start()
        for t in checkers:
            t.join()
    finally:
        stop.set()
        churner.join()
        sys.setswitchinterval(interval)
    assert sum(calls) >= 10**4 and len(calls) == 3
    assert sum(bad) == 0, f"{sum(bad)} of {sum(calls)} calls answered for another configuration"


@pytest.mark.parametrize("name", list(CATALOGUE))
def test_closed_form_only_for_the_frame_it_answers_for(name, rng):
    """Issue 7 item 7: a closed form answers for its own frame ("tool"); on any other tool
    frame ``closed_form`` is None; where it is given, its rates realise the twist at the tool
    frame (Pinocchio's Jacobian)."""
    model = rrc_pin.load(name).model
    frames = [f.name for f in model.frames if f.type == pin.FrameType.BODY]
    assert "tool" in frames and len(frames) >= 4
    has_closed_form = CATALOGUE[name].closed_form is not None
    for frame in frames:
        arm = rrc_pin.load(name, tool_frame=frame)
        cf = arm.closed_form
        if frame != "tool" or not has_closed_form:
            assert cf is None, (name, frame)
            continue
        assert cf is not None
        for _ in range(20):
            q = arm.random_q(rng)
            J = arm.jacobian(q)[: cf.task_dim]
            if np.linalg.cond(J) > 1e4:
                continue
            x = rng.normal(size=cf.task_dim)
            np.testing.assert_allclose(J @ cf.joint_rates(q, x), x, atol=1e-9)
    flange = rrc_pin.load("barker6", tool_frame="flange")
    assert flange.closed_form is None
    assert rrc_pin.load("barker6").closed_form is not None
    # another frame is None before the geometry is asked for a closed form it has not
    assert rrc_pin.load("kr5_3r", a2=0.0, tool_frame="link2").closed_form is None
    with pytest.raises(InvalidInput, match="a2"):
        _ = rrc_pin.load("kr5_3r", a2=0.0).closed_form


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


def test_a_geometry_without_closed_form_is_an_rrc_pin_error():
    arm = rrc_pin.load("kr5_3r", a2=0.0)  # Pinocchio takes it; the 3R closed form divides by a2
    assert arm.fk(np.zeros(3))[0, 3] == pytest.approx(0.7)
    with pytest.raises(InvalidInput, match="^a2: kr5_3r has no closed form for this geometry"):
        _ = arm.closed_form


def test_closed_form_is_none_for_non_paper_arms():
    assert rrc_pin.load("ur5").closed_form is None
    assert rrc_pin.load("nadkarni_c1").closed_form is None
    assert rrc_pin.load("barker6", tool_frame=("tool", "flange")).closed_form is None
