"""rrc_pin.load and rrc_pin.arms: catalogue, example-robot-data (offline), files, errors."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

import rrc_pin
from rrc_pin.cross_check import finite_difference_jacobians
from rrc_pin.errors import (
    FrameNotFound,
    InvalidInput,
    RrcPinError,
    ToolFrameRequired,
    UnknownArm,
    URDFError,
)
from rrc_pin.loading import INSTALLED, parameters_of, robots_directory
from rrc_pin.models import CATALOGUE, barker6
from rrc_pin.urdf_export import COMMITTED_DIR, to_urdf

EXPECTED_DOF = {
    "panda": 7,
    "ur3": 6,
    "ur5": 6,
    "ur10": 6,
    "kinova": 6,
    "xarm7": 7,
    "z1": 6,
    "so101": 5,
    "baxter_left": 7,
    "baxter_right": 7,
    "baxter": 15,
    "pr2": 15,
    "tiago_pro": 15,
    "tiago_dual": 15,
    "talos_upper": 16,
    "g1_upper": 17,
    "centauro_upper": 13,
    "romeo_upper": 15,
}
MULTI_ARM = [name for name in EXPECTED_DOF if len(INSTALLED[name].tool_frames) > 1]


def test_arms_lists_catalogue_then_installed():
    names = rrc_pin.arms()
    assert names[:5] == ["barker6", "rrc_k1607", "kr5_3r", "nadkarni_c1", "nadkarni_c2"]
    assert set(EXPECTED_DOF) <= set(names)


@pytest.mark.parametrize("name", sorted(EXPECTED_DOF))
def test_installed_arms_load_from_the_package(name):
    arm = rrc_pin.load(name)
    assert arm.nq == EXPECTED_DOF[name]
    assert arm.tool_frames == INSTALLED[name].tool_frames
    assert "example-robot-data" in arm.source
    assert np.all(np.isfinite(arm.velocity_limit)) and np.all(arm.velocity_limit > 0)
    for frame in arm.tool_frames:
        assert np.isfinite(arm.jacobian(arm.neutral(), frame=frame)).all()


def test_baxter_arms_lock_everything_else():
    left, right = rrc_pin.load("baxter_left"), rrc_pin.load("baxter_right")
    assert all(n.startswith("left_") for n in left.joint_names)
    assert all(n.startswith("right_") for n in right.joint_names)
    both = rrc_pin.load("baxter")
    assert both.joint_names == ["head_pan", *left.joint_names, *right.joint_names]
    assert both.tool_frame is None and both.tool_frames == ("left_gripper", "right_gripper")


def test_pr2_arms_share_the_torso_lift(rng):
    pr2 = rrc_pin.load("pr2")
    assert pr2.joint_names[0] == "torso_lift_joint" and pr2.lower[0] == 0.0
    assert not any("gripper" in n or "head" in n for n in pr2.joint_names)
    assert np.sum(np.isinf(pr2.upper)) == 4  # forearm and wrist rolls are continuous
    q = pr2.random_q(rng)
    left = pr2.jacobian(q, frame="l_gripper_tool_frame")
    right = pr2.jacobian(q, frame="r_gripper_tool_frame")
    np.testing.assert_allclose(left[:3, 0], [0, 0, 1], atol=1e-12)  # the lift moves both hands
    np.testing.assert_allclose(right[:3, 0], [0, 0, 1], atol=1e-12)
    is_left = np.array([n.startswith("l_") for n in pr2.joint_names])
    assert np.all(left[:, ~is_left][:, 1:] == 0.0) and np.all(right[:, is_left] == 0.0)
    assert np.abs(left[:, is_left]).min(axis=0).max() >= 0.0 and np.linalg.matrix_rank(left) == 6


@pytest.mark.parametrize("name", MULTI_ARM)
def test_robots_with_several_arms_have_exact_jacobians_at_every_hand(name, rng):
    robot = rrc_pin.load(name)
    assert len(robot.tool_frames) == 2 and robot.tool_frame is None
    for _ in range(5):
        q = robot.random_q(rng)
        for frame in robot.tool_frames:
            fd = finite_difference_jacobians(robot, q, frame=frame)
            for ref, J_fd in fd.items():
                np.testing.assert_allclose(robot.jacobian(q, ref, frame), J_fd, atol=1e-6)


def test_a_chain_urdf_keeps_its_one_end_link_as_tool(tmp_path):
    path = tmp_path / "my_arm.urdf"
    path.write_text(to_urdf(CATALOGUE["kr5_3r"]).replace('name="kr5_3r"', 'name="my_arm"'))
    arm = rrc_pin.load(path)
    assert arm.name == "my_arm" and arm.tool_frame == "tool" and arm.nq == 3
    assert arm.spec is None and arm.closed_form is None


def test_a_committed_catalogue_urdf_loads_as_the_catalogue_arm(rng):
    """Issue 18 item 13: by path as by name: tool frame "tool", the spec, the closed form."""
    for name in CATALOGUE:
        by_path, by_name = rrc_pin.load(COMMITTED_DIR / f"{name}.urdf"), rrc_pin.load(name)
        assert by_path.name == name and by_path.spec is CATALOGUE[name]
        assert by_path.tool_frames == by_name.tool_frames == ("tool",)
        assert (by_path.closed_form is None) == (by_name.closed_form is None)
        q = by_name.random_q(rng)
        np.testing.assert_allclose(by_path.fk(q), by_name.fk(q), atol=1e-12)
    arm = rrc_pin.load(str(COMMITTED_DIR / "barker6.urdf"), tool_frame="flange")
    assert arm.tool_frame == "flange" and arm.closed_form is None


def test_a_changed_catalogue_urdf_is_a_generic_arm(tmp_path):
    text = (COMMITTED_DIR / "barker6.urdf").read_text()
    path = tmp_path / "barker6.urdf"
    path.write_text(text.replace('xyz="0 0 0.6718"', 'xyz="0 0 0.6719"', 1))
    assert path.read_text() != text
    arm = rrc_pin.load(path)
    assert arm.spec is None and arm.closed_form is None
    assert arm.tool_frame == "flange"  # the chain's one end link: flange hangs from tool


def test_a_tree_urdf_needs_its_tool_frames(tmp_path):
    """Issue 18 item 13 / 19: baxter.urdf is a tree; its last link is no tool."""
    path = robots_directory() / INSTALLED["baxter"].path
    with pytest.raises(
        ToolFrameRequired,
        match="^tool_frame: .*baxter.urdf is a tree with "
        r"\d+ end links; name one of: .*left_gripper",
    ) as info:
        rrc_pin.load(path)
    assert {"left_gripper", "right_gripper"} <= set(info.value.candidates)
    assert "sonar_ring" not in info.value.candidates
    robot = rrc_pin.load(path, tool_frame=("left_gripper", "right_gripper"))
    # 15 arm and head joints, 2 fingers; each finger's second joint mimics its first (issue 28)
    assert robot.nq == 17 and robot.tool_frames == ("left_gripper", "right_gripper")
    assert robot.mimic_joints == ("l_gripper_r_finger_joint", "r_gripper_r_finger_joint")
    ur5 = robots_directory() / INSTALLED["ur5"].path
    with pytest.raises(ToolFrameRequired) as info:
        rrc_pin.load(ur5)
    assert sorted(info.value.candidates) == ["ee_link", "tool0"]


def test_catalogue_parameters_build_a_variant():
    arm = rrc_pin.load("barker6", alpha3=np.deg2rad(88))
    assert arm.spec.parameters["alpha3"] == pytest.approx(np.deg2rad(88))
    assert arm.spec.chain.rows[2].alpha == pytest.approx(np.deg2rad(88))


def test_unknown_name_lists_the_available_ones():
    with pytest.raises(UnknownArm, match="puma.*available: barker6, rrc_k1607.*panda"):
        rrc_pin.load("puma")


def test_missing_urdf_names_the_path(tmp_path):
    path = tmp_path / "missing.urdf"
    with pytest.raises(URDFError, match=f"{path}: no such file"):
        rrc_pin.load(path)


def test_malformed_urdf_gives_path_and_parser_message(tmp_path):
    path = tmp_path / "broken.urdf"
    path.write_text('<robot name="x"><link name="a"/><joint name="j" type="revolute">')
    with pytest.raises(URDFError, match=f"{path}: not XML: .+"):
        rrc_pin.load(path)
    path.write_text('<robot name="x"><link name="a"/><joint name="j" type="revolute"/></robot>')
    with pytest.raises(URDFError, match=f"{path}: joint 'j': its parent link has none"):
        rrc_pin.load(path)
    path.write_text("<launch/>")
    with pytest.raises(URDFError, match=f"{path}: not a URDF: the root element is <launch>"):
        rrc_pin.load(path)


JOINT = ('<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
         '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>')


def urdf(*joints: dict[str, str], links: tuple[str, ...] = ("base", "l1")) -> str:
    body = "".join(f'<link name="{n}"/>' for n in links)
    return f'<robot name="x">{body}{"".join(JOINT.format(**j) for j in joints)}</robot>'


@pytest.mark.parametrize(
    ("joints", "said"),
    [
        # issue 40: urdfdom printed "child link [nowhere] of joint [j2] not found" on stderr,
        # the exception said only "does not contain a valid URDF model"
        ([{"name": "j1", "kind": "revolute", "parent": "base", "child": "l1"},
          {"name": "j2", "kind": "revolute", "parent": "l1", "child": "nowhere"}],
         "joint 'j2': its child link 'nowhere' is not a link of the file"),
        ([{"name": "j1", "kind": "revolute", "parent": "base", "child": "l1"},
          {"name": "j2", "kind": "revolute", "parent": "base", "child": "l1"}],
         r"link 'l1' is the child of two joints \('j1' and 'j2'\)"),
        ([{"name": "j1", "kind": "revolute", "parent": "l1", "child": "base"},
          {"name": "j2", "kind": "revolute", "parent": "base", "child": "l1"}],
         "the links hang from 0 roots"),
        # what only the parser knows: its own words, captured from its stderr
        ([{"name": "j1", "kind": "revolut", "parent": "base", "child": "l1"}],
         r"Pinocchio could not parse it: Joint \[j1\] has no known type \[revolut\]"),
    ],
)
def test_a_broken_tree_is_named_in_the_error_and_nothing_is_printed(tmp_path, capfd, joints,
                                                                     said):
    path = tmp_path / "broken.urdf"
    path.write_text(urdf(*joints))
    with pytest.raises(URDFError, match=f"^URDF {path}: {said}"):
        rrc_pin.load(path)
    out, err = capfd.readouterr()
    assert out == "" and err == ""


def test_an_empty_name_or_a_folder_is_named_as_such(tmp_path):
    """Issue 40: ``load("")`` said "URDF .: cannot read it: Is a directory"."""
    with pytest.raises(InvalidInput, match=r"^name_or_path: empty \(''\): expected an arm's "
                       "name .*barker6.*or a URDF file's path"):  # fmt: skip
        rrc_pin.load("")
    with pytest.raises(URDFError, match=f"^URDF {tmp_path}: name_or_path is a folder, not a URDF"):
        rrc_pin.load(tmp_path)


def test_unknown_tool_frame():
    with pytest.raises(FrameNotFound, match="^tool_frame: no frame 'hand'"):
        rrc_pin.load("ur5", tool_frame="hand")


def test_parameters_for_non_catalogue_arms_are_refused():
    """Issue 7 item 4: an argument mistake, not a URDF error."""
    for name in ("ur5", "panda"):
        with pytest.raises(
            InvalidInput,
            match="^alpha3: geometry parameters apply to "
            "catalogue names only .*not to 'panda'|'ur5'",
        ):
            rrc_pin.load(name, alpha3=1.0)


def test_parameters_with_an_arm_spec_are_refused():
    """Issue 18 item 9: they were ignored silently."""
    with pytest.raises(
        InvalidInput,
        match="^a3: geometry parameters apply to catalogue names only .*not to an ArmSpec",
    ):
        rrc_pin.load(barker6.build(), a3=0.1)


@pytest.mark.parametrize("value", [np.nan, np.inf, "x", "0.1", None, [0.1], True])
def test_a_bad_parameter_value_is_named_without_parser_noise(value, capfd):
    """Issue 18 item 9: no urdfdom output, no bare ValueError or UFuncTypeError."""
    with pytest.raises(InvalidInput, match="^a3: expected a finite number"):
        rrc_pin.load("barker6", a3=value)
    assert capfd.readouterr().err == ""


def test_an_unknown_parameter_lists_those_the_builder_takes():
    """Issue 7 item 4: it was a bare TypeError."""
    with pytest.raises(
        InvalidInput,
        match="^alpha4: not a parameter of barker6; it takes: no, es, sn, we, a3, r3, alpha3, hw$",
    ):
        rrc_pin.load("barker6", alpha4=1)
    with pytest.raises(InvalidInput, match="^a: not a parameter of rrc_k1607; it takes: none$"):
        rrc_pin.load("rrc_k1607", a=1)
    assert parameters_of("kr5_3r") == ["a1", "a2", "a3"]
    with pytest.raises(InvalidInput, match="^name: 'panda' is not a catalogue arm"):
        parameters_of("panda")
    arm = rrc_pin.load("kr5_3r", a2=0.6)
    np.testing.assert_allclose(arm.fk(np.zeros(3))[:3, 3], [1.3, 0, 0], atol=1e-12)


def test_every_loading_error_is_an_rrc_pin_error(tmp_path):
    calls = [
        lambda: rrc_pin.load("puma"),
        lambda: rrc_pin.load(3.5),
        lambda: rrc_pin.load(tmp_path / "missing.urdf"),
        lambda: rrc_pin.load(tmp_path),
        lambda: rrc_pin.load("barker6", tool_frame=3),
        lambda: rrc_pin.load("barker6", a3=1j),
        lambda: rrc_pin.load("panda", tool_frame=()),
    ]
    for call in calls:
        with pytest.raises(RrcPinError):
            call()


READY_MARGIN = 0.1
"""[rad or m] The least distance of a ready pose from a joint limit (or 10 % of a shorter
range)."""
READY_SIGMA = 0.05
"""The least smallest singular value of a ready pose's task Jacobian: where the slowdown
strategy starts and the controller's log starts naming singularities."""


@pytest.mark.parametrize("name", rrc_pin.arms())
def test_every_robot_has_a_ready_pose_away_from_limits_and_singularities(name):
    """Issue 33 item 2: panda's start pose sat on joint 4's limit, baxter's arms were straight."""
    robot = rrc_pin.load(name)
    q = robot.ready()
    np.testing.assert_array_equal(q, robot.poses["ready"])
    span = np.minimum(robot.upper - robot.lower, 2 * np.pi)
    margin = np.minimum(q - robot.lower, robot.upper - q)
    assert np.all(margin >= np.minimum(READY_MARGIN, 0.1 * span)), (name, margin)
    rows = 3 if robot.nq < 6 else 6  # the controller's task rows
    for frame in robot.tool_frames:
        sigma = np.linalg.svd(robot.jacobian(q, frame=frame)[:rows], compute_uv=False)[-1]
        assert sigma >= READY_SIGMA, (name, frame, sigma)
    reason = (
        "; ".join(CATALOGUE[name].assumed) if name in CATALOGUE else INSTALLED[name].ready.reason
    )
    assert "ready" in reason or "SRDF" in reason or "chosen" in reason


def test_ready_poses_come_from_the_srdf_where_it_gives_one():
    panda = rrc_pin.load("panda")  # panda.srdf's "default"
    np.testing.assert_allclose(panda.ready(), [0, -0.785398, 0, -2.35619, 0, 1.5707, 0.785398])
    kinova = rrc_pin.load("kinova")  # kinova.srdf's "arm_up", joint 3 turned into its limits
    np.testing.assert_allclose(kinova.ready(), [1.5707, 2.618, 2 * np.pi - 1.5707, 3.1415,
                                                2.618, 0.0])  # fmt: skip
    talos = rrc_pin.load("talos_upper")
    assert talos.ready()[talos.joint_names.index("arm_left_4_joint")] == -0.525366
    assert INSTALLED["talos_upper"].ready.srdf == "talos_data/srdf/talos.srdf"
    barker = rrc_pin.load("barker6")  # a catalogue arm: chosen, stated in its ArmSpec
    np.testing.assert_allclose(barker.ready(), np.deg2rad([0, 0, 90, 0, 45, 0]))
    assert barker.poses["paper_start"].tolist() == [0.0] * 6


MJCF = Path(__file__).resolve().parent / "data" / "mjcf"
"""MJCF files MuJoCo wrote from the committed URDFs (tests/data/mjcf/generate.py)."""


def test_the_committed_mjcf_is_what_mujoco_writes_from_the_urdfs():
    spec = importlib.util.spec_from_file_location("generate", MJCF / "generate.py")
    generate = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(generate)
    assert generate.main(check=True) == 0
    assert sorted(p.stem for p in MJCF.glob("*.xml")) == sorted(CATALOGUE)


@pytest.mark.parametrize("name", sorted(CATALOGUE))
def test_an_mjcf_loads_with_the_urdfs_kinematics_and_mujocos(name):
    """Same joints, limits to the 6 digits MuJoCo prints, tool frame by the same rule; fk and
    Jacobians equal MuJoCo's own of the same file (1e-12) and the URDF's (1e-12, but
    nadkarni_c1: its -70 deg base turn is a quaternion MuJoCo prints to 6 digits, 7e-7)."""
    import mujoco  # the test extra

    frame = "tool"
    robot = rrc_pin.load(MJCF / f"{name}.xml", tool_frame=frame)
    urdf = rrc_pin.load(name, tool_frame=frame)
    assert robot.name == name and robot.joint_names == urdf.joint_names
    np.testing.assert_allclose(robot.lower, urdf.lower, atol=5e-6)
    assert np.isinf(robot.velocity_limit).all()  # MJCF has none: the caller gives them
    m = mujoco.MjModel.from_xml_path(str(MJCF / f"{name}.xml"))
    d = mujoco.MjData(m)
    body = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, frame)
    tol = 1e-6 if name == "nadkarni_c1" else 1e-12
    rng = np.random.default_rng(41)
    for _ in range(50):
        q = np.clip(urdf.random_q(rng), robot.lower, robot.upper)
        T, J = robot.fk(q), robot.jacobian(q)
        assert np.abs(T - urdf.fk(q)).max() < tol and np.abs(J - urdf.jacobian(q)).max() < tol
        d.qpos[:] = q
        mujoco.mj_kinematics(m, d)
        mujoco.mj_comPos(m, d)
        jp, jr = np.zeros((3, m.nv)), np.zeros((3, m.nv))
        mujoco.mj_jacBody(m, d, jp, jr, body)
        assert np.abs(T[:3, 3] - d.xpos[body]).max() < 1e-12
        assert np.abs(T[:3, :3] - d.xmat[body].reshape(3, 3)).max() < 1e-12
        assert np.abs(J - np.vstack([jp, jr])).max() < 1e-12


def test_an_mjcf_arm_solves_as_its_urdf():
    robot = rrc_pin.load(MJCF / "rrc_k1607.xml")
    urdf = rrc_pin.load("rrc_k1607")
    assert robot.tool_frame == "tool"  # the one end link, as for a URDF
    with pytest.raises(InvalidInput) as info:
        rrc_pin.Resolver(robot)  # no velocity limits in MJCF: refused by name
    assert info.value.argument == "velocity"
    limits = rrc_pin.JointLimits(velocity=urdf.velocity_limit)
    mine, theirs = rrc_pin.Resolver(robot, limits=limits), rrc_pin.Resolver(urdf)
    q, twist = urdf.ready(), [0.1, -0.05, 0.02, 0.1, 0.0, -0.2]
    for _ in range(50):
        a, b = mine.solve(q, twist), theirs.solve(q, twist)
        assert a.status == b.status and np.abs(a.qdot - b.qdot).max() < 1e-9
        q = q + a.qdot * 0.01


def test_an_xml_that_is_neither_urdf_nor_mjcf_is_refused(tmp_path):
    path = tmp_path / "scene.xml"
    path.write_text("<sdf version='1.7'/>")
    with pytest.raises(URDFError) as info:
        rrc_pin.load(path)
    assert "MJCF" in str(info.value) and "<sdf>" in str(info.value)


def test_a_malformed_mjcf_gives_path_and_parser_message(tmp_path):
    path = tmp_path / "broken.xml"
    path.write_text('<mujoco><worldbody><body><joint type="warp"/></body></worldbody></mujoco>')
    with pytest.raises(URDFError) as info:
        rrc_pin.load(path)
    assert str(path) in str(info.value) and "Pinocchio could not parse it" in str(info.value)
