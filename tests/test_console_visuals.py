"""The shapes of a robot: its URDF's visuals, or a skeleton from its kinematics."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import rrc_pin
from rrc_pin.console.visuals import PACKAGE, PAPER_COLOR, _filename, skeleton, visuals_of
from rrc_pin.loading import robots_directory


def world_points(robot, shapes, q):
    """Every shape's vertices in the base frame at q."""
    model, data = robot.model, robot.model.createData()
    pin.forwardKinematics(model, data, robot.to_pinocchio(q))
    out = []
    for s in shapes:
        M = data.oMi[s.joint]
        out.append(np.asarray(s.mesh.vertices) @ M.rotation.T + M.translation)
    return out


def test_a_paper_arm_is_drawn_from_its_generated_urdf_in_its_colour():
    arm = rrc_pin.load("barker6")
    v = visuals_of(arm)
    assert v.source == "urdf" and len(v.shapes) == 10
    assert {s.color for s in v.shapes} == {PAPER_COLOR}
    assert 1.0 < v.reach < 2.0
    # the link cylinders reach the wrist centre (the tool frame) wherever the arm is
    q = np.array([0.3, -0.4, 0.8, 0.2, 0.5, 0.1])
    points = np.vstack(world_points(arm, v.shapes, q))
    hand = arm.fk(q)[:3, 3]
    assert np.min(np.linalg.norm(points - hand, axis=1)) < 0.05


def test_an_example_robot_data_arm_has_its_meshes_and_own_materials():
    v = visuals_of(rrc_pin.load("panda"))
    assert v.source == "urdf" and len(v.shapes) > 10
    assert any(s.color is None for s in v.shapes)


def test_a_combination_of_arms_is_drawn_as_a_skeleton():
    cell = rrc_pin.combine({"a": (rrc_pin.load("kr5_3r"), np.eye(4))})
    v = visuals_of(cell)
    assert v.source == "skeleton"
    assert len(v.shapes) == len(skeleton(cell))


def test_skeleton_rods_join_each_joint_to_the_next():
    arm = rrc_pin.load("kr5_3r")
    shapes = skeleton(arm, radius=0.01)
    q = np.array([0.2, 0.7, -0.5])
    for s, points in zip(shapes, world_points(arm, shapes, q), strict=True):
        if s.name.startswith("tool:"):
            hand = arm.fk(q)[:3, 3]
            assert np.min(np.linalg.norm(points - hand, axis=1)) < 0.011


def test_package_paths_map_to_the_installed_share_folder(tmp_path):
    robots = robots_directory()
    name = PACKAGE + "robots/panda_description/meshes/visual/link0.dae"
    assert _filename(name, directory=tmp_path) == str(robots.parent / name[len(PACKAGE) :])
    assert (robots.parent / name[len(PACKAGE) :]).is_file()


def test_a_urdf_whose_meshes_are_missing_falls_back_to_the_skeleton(tmp_path):
    urdf = tmp_path / "arm.urdf"
    urdf.write_text(
        '<robot name="arm"><link name="base"/><link name="l1"><visual><geometry>'
        '<mesh filename="package://nowhere/missing.stl"/></geometry></visual></link>'
        '<joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>'
        '<origin xyz="0 0 0.3"/><axis xyz="0 0 1"/>'
        '<limit lower="-1" upper="1" velocity="1" effort="1"/></joint></robot>'
    )
    v = visuals_of(rrc_pin.load(str(urdf)))
    assert v.source == "skeleton" and v.reach == pytest.approx(0.3)
