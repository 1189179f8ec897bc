"""The Pinocchio-backed Robot: shapes, frames, limits, continuous joints, threads, bad input."""

from __future__ import annotations

import subprocess
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


def test_a_serial_chain_built_in_code_is_called_a_chain():
    """Issue 40: Pinocchio's sample manipulator (its frames name no link as another's parent)
    was called "a tree with 9 end links"; its joints make a chain whose last joint carries
    two links."""
    model = pin.buildSampleModelManipulator()
    assert end_links(model) == ["wrist2_body", "effector_body"]
    with pytest.raises(ToolFrameRequired, match="^tool_frame: sample is a serial chain ending "
                       "in 2 end links; name one of: wrist2_body, effector_body$"):  # fmt: skip
        Robot(model, None, name="sample", source="sample")
    assert Robot(model, "effector_body", name="sample", source="sample").nq == 6


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


def _floating_ur5() -> Robot:
    path = robots_directory() / INSTALLED["ur5"].path
    model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    model.velocityLimit[:6] = 1.0
    return Robot(model, "tool0", name="ur5_floating", source=str(path))


def test_a_free_flyer_root_is_a_floating_base_with_nq_one_more_than_nv():
    arm = _floating_ur5()
    assert (arm.nq, arm.nv, arm.floating) == (13, 12, True)
    axes = ("vx", "vy", "vz", "wx", "wy", "wz")
    assert arm.dof_names[:6] == tuple(f"root_joint:{a}" for a in axes)
    assert list(arm.actuated) == [False] * 6 + [True] * 6
    assert np.isinf(arm.dof_lower[:6]).all() and arm.dof_lower.shape == (12,)
    np.testing.assert_array_equal(arm.neutral()[:7], [0, 0, 0, 0, 0, 0, 1])
    rng = np.random.default_rng(3)
    q = arm.random_q(rng)
    assert arm.jacobian(q).shape == (6, 12)
    np.testing.assert_array_equal(arm.dof_positions(q)[6:], q[7:])


def test_integrate_moves_a_floating_base_on_se3_and_matches_pinocchio():
    arm = _floating_ur5()
    rng = np.random.default_rng(4)
    q = arm.random_q(rng)
    q[:3] = rng.normal(size=3)
    q[3:7] = rng.normal(size=4)
    q[3:7] /= np.linalg.norm(q[3:7])
    v = rng.normal(size=12)
    moved = arm.integrate(q, v, 0.01)
    np.testing.assert_allclose(moved, pin.integrate(arm.model, q, v * 0.01), atol=1e-15)
    # The tool moves by the Jacobian's twist to first order (finite difference over dt)
    dt = 1e-6
    J = arm.jacobian(q, "world_aligned")
    p0, p1 = arm.fk(q)[:3, 3], arm.fk(arm.integrate(q, v, dt))[:3, 3]
    np.testing.assert_allclose((p1 - p0) / dt, J[:3] @ v, atol=1e-4)


def test_a_base_quaternion_of_zero_length_is_refused_naming_q():
    arm = _floating_ur5()
    q = arm.neutral()
    q[3:7] = 0.0
    with pytest.raises(InvalidInput, match="^q:.*quaternion"):
        arm.fk(q)


def test_a_free_flyer_below_the_root_is_refused_with_the_reason():
    arm = rrc_pin.load("barker6")
    model = pin.Model(arm.model)
    model.addJoint(1, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "loose")
    with pytest.raises(URDFError, match="JointModelFreeFlyer.*1-DOF joints only"):
        Robot(model, "tool", name="loose", source="test")


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


REDUCED = """
import pinocchio as pin
import rrc_pin
for name, joint in (("ur5", 6), ("panda", 7), ("baxter", 3), ("so101", 5), ("z1", 6)):
    model = rrc_pin.load(name).model
    reduced = pin.buildReducedModel(model, [joint], pin.neutral(model))
    try:
        robot = rrc_pin.Robot(reduced, None, name=name, source="reduced")
        print(name, robot.nq, robot.tool_frame)
    except rrc_pin.ToolFrameRequired as exc:
        print(name, reduced.nv, "ends:", ",".join(sorted(exc.candidates)))
"""


def test_a_reduced_model_with_a_locked_joint_loads():
    """Issue 28 item 3: with Pinocchio 4.1 a locked joint's frame is its own parent, and the
    search for end links never ended (a subprocess, so that a hang fails within a minute)."""
    done = subprocess.run([sys.executable, "-c", REDUCED], capture_output=True, text=True,
                          timeout=60)  # fmt: skip
    assert done.returncode == 0, done.stderr
    lines = dict(line.split(" ", 1) for line in done.stdout.splitlines())
    assert lines["ur5"] == "5 ends: ee_link,tool0"  # as the full ur5_robot.urdf
    assert lines["z1"] == "5 gripperMover"
    assert lines["panda"] == "6 ends: panda_hand_tcp,panda_rightfinger"
    model = rrc_pin.load("ur5").model
    reduced = pin.buildReducedModel(model, [6], pin.neutral(model))
    from rrc_pin.robot import parent_link

    assert parent_link(reduced, reduced.getFrameId("wrist_3_link")) == reduced.getFrameId(
        "wrist_2_link"
    )
    robot = Robot(reduced, "tool0", name="ur5_5", source="reduced")
    q = np.array([0.1, -1.2, 1.3, -1.6, -1.5])
    np.testing.assert_allclose(robot.fk(q), rrc_pin.load("ur5").fk([*q, 0.0]), atol=1e-12)


MIMIC = """<robot name="mimic">
  <link name="base"/><link name="l0"/><link name="l1"/><link name="l2"/>
  <joint name="j0" type="{kind}"><parent link="base"/><child link="l0"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" velocity="1" effort="1"/></joint>
  <joint name="j1" type="revolute"><parent link="l0"/><child link="l1"/><axis xyz="0 0 1"/>
    <limit lower="-2" upper="2" velocity="1" effort="1"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0.5 0 0"/>
    <axis xyz="0 0 1"/><limit lower="-2" upper="2" velocity="1" effort="1"/>
    <mimic joint="j1" multiplier="0.5" offset="0.1"/></joint>
</robot>"""


def test_a_mimic_joint_follows_its_primary(tmp_path):
    """Issue 28 item 7: the mimic joint loaded as an independent one (nq 2); honoured now."""
    path = tmp_path / "mimic.urdf"
    path.write_text(MIMIC.format(kind="prismatic"))
    arm = rrc_pin.load(path)
    assert arm.nq == 2 and arm.joint_names == ["j0", "j1"] and arm.mimic_joints == ("j2",)
    q = [0.2, 0.4]
    turn = q[1] + 0.5 * q[1] + 0.1  # j2 = 0.5 j1 + 0.1
    np.testing.assert_allclose(arm.fk(q)[:3, 3], [0.5 * np.cos(q[1]), 0.5 * np.sin(q[1]), 0.2],
                               atol=1e-12)  # fmt: skip
    np.testing.assert_allclose(arm.fk(q)[:2, 0], [np.cos(turn), np.sin(turn)], atol=1e-12)
    assert arm.jacobian(q).shape == (6, 2)
    assert arm.jacobian(q)[5, 1] == pytest.approx(1.5)  # the link turns 1.5 rad per rad of j1
    # two joints: the resolver commands the tool's position (j1 at 0.3 rad/s turns it)
    v = [-0.15 * np.sin(q[1]), 0.15 * np.cos(q[1]), 0.05, 0.0, 0.0, 0.0]
    r = rrc_pin.Resolver(arm, dt=0.01).solve(q, v)
    np.testing.assert_allclose(r.qdot, [0.05, 0.3], atol=1e-9)
    path.write_text(MIMIC.format(kind="continuous"))  # a continuous joint beside the mimic
    arm = rrc_pin.load(path)
    assert arm.nq == 2 and arm.continuous.tolist() == [True, False]
    posture = rrc_pin.PostureTask([3.0, 0.0], gain=1.0)  # the short way round: -3.28 rad
    r = rrc_pin.Resolver(arm, dt=0.01).solve([-3.0, 0.0], [posture])
    assert r.qdot[0] < 0.0 and r.qdot[1] == pytest.approx(0.0, abs=1e-12)


def test_without_mimic_support_a_mimic_joint_is_refused_by_name(tmp_path, monkeypatch):
    """A Pinocchio before 3.4 has no ``mimic=``: the joint is refused, not loaded free."""
    path = tmp_path / "mimic.urdf"
    path.write_text(MIMIC.format(kind="prismatic"))
    build = pin.buildModelFromUrdf

    def old_pinocchio(filename, *args, **kwargs):
        if "mimic" in kwargs:
            raise TypeError("unexpected keyword argument 'mimic'")
        return build(filename, *args)

    monkeypatch.setattr(pin, "buildModelFromUrdf", old_pinocchio)
    with pytest.raises(URDFError, match="joint 'j2' mimics 'j1': this Pinocchio"):
        rrc_pin.load(path)


def test_random_q_is_finite_where_the_limits_are_huge(tmp_path):
    """Issue 28 item 7: limits of +-1e308 made random_q raise OverflowError."""
    path = tmp_path / "huge.urdf"
    joints = "".join(
        f'<joint name="j{i}" type="{kind}"><parent link="l{i}"/><child link="l{i + 1}"/>'
        f'<axis xyz="0 0 1"/><limit lower="{lo}" upper="{hi}" velocity="1" effort="1"/></joint>'
        for i, (kind, lo, hi) in enumerate(
            [("revolute", -1e308, 1e308), ("prismatic", 0.0, 1e308), ("revolute", -1.0, 1.0)]
        )
    )
    links = "".join(f'<link name="l{i}"/>' for i in range(4))
    path.write_text(f'<robot name="huge">{links}{joints}</robot>')
    arm = rrc_pin.load(path)
    assert arm.upper[0] == 1e308
    Q = np.array([arm.random_q(seed) for seed in range(200)])
    assert np.isfinite(Q).all()
    assert -np.pi <= Q[:, 0].min() < -2.5 and 2.5 < Q[:, 0].max() <= np.pi
    assert 0.0 <= Q[:, 1].min() < 0.5 and 5.5 < Q[:, 1].max() <= 2 * np.pi
    assert -1.0 <= Q[:, 2].min() and Q[:, 2].max() <= 1.0
    np.testing.assert_allclose(arm.ready(), [0.0, 0.2 * np.pi, 0.0])  # 10 % inside


def test_ready_is_a_named_pose_away_from_the_limits():
    panda = rrc_pin.load("panda")
    ready = panda.ready()
    np.testing.assert_array_equal(ready, panda.poses["ready"])
    ready[0] = 9.0  # a copy: the pose stays
    assert panda.poses["ready"][0] == 0.0 and not panda.poses["ready"].flags.writeable
    model = panda.model  # a model without named poses: zero, 10 % of each range inside
    bare = Robot(model, "panda_hand_tcp", name="bare", source="here")
    span = panda.upper[3] - panda.lower[3]
    np.testing.assert_allclose(bare.ready()[3], panda.upper[3] - 0.1 * span)
    named = Robot(model, "panda_hand_tcp", name="n", source="here", poses=panda.poses)
    np.testing.assert_array_equal(named.ready(), panda.ready())
    with pytest.raises(InvalidInput, match=r"^poses\['ready'\]: joint 'panda_joint4' at 0 is "
                       "outside its limits"):  # fmt: skip
        Robot(model, "panda_hand_tcp", name="n", source="here", poses={"ready": np.zeros(7)})
    with pytest.raises(InvalidInput, match=r"^poses\['up'\]: expected shape \(7,\)"):
        Robot(model, "panda_hand_tcp", name="n", source="here", poses={"up": np.zeros(3)})


@pytest.mark.parametrize(
    ("call", "argument"),
    [
        (lambda m: Robot("panda", None, name="x", source="x"), "model"),
        (lambda m: Robot(None, None, name="x", source="x"), "model"),
        (lambda m: Robot(m, None, name=object(), source="x"), "name"),
        (lambda m: Robot(m, None, name="", source="x"), "name"),
        (lambda m: Robot(m, None, name="x", source=np.array(["a"])), "source"),
        (lambda m: Robot(m, None, name="x", source="x", spec="barker6"), "spec"),
        (lambda m: Robot(m, None, name="x", source="x", poses=[1, 2]), "poses"),
        (lambda m: Robot(m, None, name="x", source="x", poses={3: [0] * 3}), "poses"),
    ],
)
def test_what_is_not_a_model_or_a_name_is_refused_by_name(call, argument):
    """Issue 28 item 8: a non-model raised AttributeError; any object passed as a name."""
    model = rrc_pin.load("kr5_3r").model
    with pytest.raises(InvalidInput) as info:
        call(model)
    assert info.value.argument == argument


def test_arrays_and_booleans_where_names_and_numbers_go_are_refused():
    """Issue 28 item 8: an array as ``frame`` or ``ref`` (TypeError: unhashable), a boolean
    inside q (taken as 1.0)."""
    arm = rrc_pin.load("panda")
    q = arm.ready()
    for frame in (np.array(["panda_hand_tcp"]), ["panda_hand_tcp"], 3):
        for call in (arm.fk, arm.jacobian):
            with pytest.raises(InvalidInput, match="^frame: expected a frame name") as info:
                call(q, frame=frame)
            assert info.value.argument == "frame"
    with pytest.raises(InvalidInput, match="^ref: expected one of"):
        arm.jacobian(q, ref=np.array(["local"]))
    with pytest.raises(InvalidInput, match="^q: expected a real numeric array"):
        arm.fk([0.0, True, 0.0, -1.5, 0.0, 1.5, 0.0])


BAD = [None, object(), "x", np.array(["a", "b"]), [True, 0.0], 3 + 1j, {"a": 1}, float("nan"),
       np.zeros((2, 2)), [[0.0] * 7], np.full(7, np.inf), [0.0, True, 0, 0, 0, 0, 0]]  # fmt: skip


def test_bad_input_of_every_robot_method_raises_only_the_package_errors():
    """Issue 28 item 8: every bad-input class, at every Robot call site, raises an RrcPinError
    naming the argument, and changes nothing."""
    arm = rrc_pin.load("panda")
    q = arm.ready()
    calls = {
        "q": [lambda v: arm.fk(v), lambda v: arm.jacobian(v), lambda v: arm.check_q(v),
              lambda v: arm.to_pinocchio(v), lambda v: arm.frame_pose(v, "panda_hand_tcp")],
        "frame": [lambda v: arm.fk(q, v), lambda v: arm.jacobian(q, frame=v),
                  lambda v: arm.frame_pose(q, v)],
        "ref": [lambda v: arm.jacobian(q, ref=v)],
        "rng": [lambda v: arm.random_q(v)],
    }  # fmt: skip
    before = (arm.ready(), arm.fk(q), arm.lower.copy(), dict(arm.poses))
    for argument, sites in calls.items():
        for site in sites:
            for value in BAD:
                if value is None and argument in ("frame", "rng"):
                    continue  # None: the tool frame, fresh entropy
                with pytest.raises(rrc_pin.RrcPinError) as info:
                    site(value)
                assert getattr(info.value, "argument", argument) == argument, (argument, value)
    np.testing.assert_array_equal(before[0], arm.ready())
    np.testing.assert_array_equal(before[1], arm.fk(q))
    np.testing.assert_array_equal(before[2], arm.lower)
    assert before[3].keys() == arm.poses.keys()
