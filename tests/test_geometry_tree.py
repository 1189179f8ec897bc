"""rrc_pin.geometry.tree: the joints as arrays, or None where the kernel cannot follow them.

The kernel itself against Pinocchio: tests/test_proximity_kernels.py. Here: a model with a mimic
joint gets no tree, and its queries, which then read Pinocchio's placements, stay exact.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

import rrc_pin
from rrc_pin.geometry import CollisionModel
from rrc_pin.geometry.tree import tree_of

MIMIC = """<?xml version="1.0"?>
<robot name="pincer">
  <link name="base"><collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision></link>
  <link name="arm"><collision><origin xyz="0 0 0.25"/><geometry><cylinder radius="0.03"
    length="0.5"/></geometry></collision></link>
  <link name="finger"><collision><origin xyz="0 0 0.1"/><geometry><box size="0.02 0.02 0.2"/>
    </geometry></collision></link>
  <link name="thumb"><collision><origin xyz="0 0 0.1"/><geometry><box size="0.02 0.02 0.2"/>
    </geometry></collision></link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="arm"/>
    <origin xyz="0 0 0.05"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" velocity="1" effort="1"/></joint>
  <joint name="grip" type="revolute"><parent link="arm"/><child link="finger"/>
    <origin xyz="0 0.05 0.5"/><axis xyz="1 0 0"/>
    <limit lower="-1" upper="1" velocity="1" effort="1"/></joint>
  <joint name="thumb_joint" type="revolute"><parent link="arm"/><child link="thumb"/>
    <origin xyz="0 -0.05 0.5"/><axis xyz="1 0 0"/>
    <limit lower="-1" upper="1" velocity="1" effort="1"/>
    <mimic joint="grip" multiplier="-1" offset="0"/></joint>
</robot>
"""


def test_a_model_with_a_mimic_joint_gets_no_tree_and_still_answers_exactly(tmp_path, rng):
    path = tmp_path / "pincer.urdf"
    path.write_text(MIMIC)
    robot = rrc_pin.load(str(path), tool_frame="finger")
    assert robot.mimic_joints == ("thumb_joint",)
    assert tree_of(robot.model, robot.random_q(rng)) is None
    cm = CollisionModel(robot)
    assert cm.scene.tree is None
    cm.add_halfspace((0, 0, 1), 0.2, name="floor")
    for _ in range(20):
        q = robot.random_q(rng)
        prox = cm.proximity_at(q, 0.3)
        data = cm.scene.geometry.createData()
        pin.computeDistances(robot.model, robot.model.createData(), cm.scene.geometry, data,
                             robot.to_pinocchio(q))  # fmt: skip
        every = np.array([r.min_distance for r in data.distanceResults])
        assert set(prox.names) == {cm.pairs[k] for k in np.flatnonzero(every < 0.3)}


def test_every_loadable_robot_gets_a_tree(rng):
    for name in ("barker6", "nadkarni_c2", "panda", "kinova", "baxter", "pr2"):
        robot = rrc_pin.load(name)
        assert tree_of(robot.model, robot.random_q(rng)) is not None, name
