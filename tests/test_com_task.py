"""ComTask: the centre of mass moved on the upper bodies and the tripod."""

from __future__ import annotations

import numpy as np
import pytest

import rrc_pin
from rrc_pin.center_of_mass import center_of_mass
from rrc_pin.kinematics import Kinematics, Layout
from rrc_pin.tasks.com_task import ComTask


def kinematics(robot, q):
    q, dof, q_pin = robot.positions(q)
    return Kinematics(robot.model, robot.model.createData(), Layout.of(robot), dof, q_pin)


def test_rows_are_the_com_jacobian_and_the_feedback():
    robot = rrc_pin.load("g1_upper")
    q = robot.ready()
    kin = kinematics(robot, q)
    com = center_of_mass(kin)
    target = com.position[:2] + np.array([0.1, 0.0])
    task = ComTask([0.01, -0.02], target=target, axes="xy", gain=3.0)
    task.check(Layout.of(robot))
    rows = task.rows(kin)
    np.testing.assert_array_equal(rows.A, com.jacobian[:2])
    np.testing.assert_allclose(rows.b, [0.01 + 0.3, -0.02], atol=1e-12)
    assert rows.unit is not None and rows.unit[0] == max(Layout.of(robot).reach.values())
    z = ComTask([0.05], axes="z").rows(kin)
    np.testing.assert_array_equal(z.A, com.jacobian[2:])


@pytest.mark.parametrize("name", ["talos_upper", "g1_upper", "romeo_upper", "yeh_tripod"])
def test_the_com_reaches_a_target_2_cm_away(name):
    """The upper bodies (pelvis fixed) lean with their torso and arms; the tripod moves its
    body over its three feet (contacts held). Below the CoM task, the posture."""
    robot = rrc_pin.load(name)
    limits = [rrc_pin.JointLimits()]
    if robot.floating:
        limits.append(rrc_pin.ContactLimit(robot.tool_frames))
    resolver = rrc_pin.Resolver(robot, dt=0.01, limits=limits)
    q = robot.ready()
    start = center_of_mass(kinematics(robot, q)).position
    target = start[:2] + np.array([0.02, 0.0])
    task = ComTask(axes="xy", target=target, gain=2.0)
    posture = rrc_pin.PostureTask(robot.dof_positions(robot.ready()), gain=0.1, weight=1e-3)
    for _ in range(400):
        r = resolver.solve(q, [[task], [posture]], priority="strict")
        q = robot.integrate(q, r.qdot, 0.01)
    reached = center_of_mass(kinematics(robot, q)).position
    assert np.linalg.norm(reached[:2] - target) < 1e-4, (name, reached[:2] - target)


def test_bad_arguments_are_refused_by_name():
    for kwargs, argument in [({"axes": "xx"}, "axes"), ({"axes": "w"}, "axes"),
                             ({"velocity": [1.0]}, "velocity"), ({"target": [0, 0, np.nan]},
                             "target"), ({"gain": 0.0}, "gain"), ({"weight": -1.0}, "weight"),
                             ({"name": ""}, "name")]:  # fmt: skip
        with pytest.raises(rrc_pin.InvalidInput) as info:
            ComTask(**kwargs)
        assert info.value.argument == argument
    task = ComTask(axes="xy", target=[0.0, 0.0])
    with pytest.raises(rrc_pin.InvalidInput):
        task.set_target([1.0, 2.0, 3.0])
    np.testing.assert_array_equal(task.target, [0.0, 0.0])
