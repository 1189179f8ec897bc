"""LookAtTask: rows against finite differences; a camera axis kept on a point."""

from __future__ import annotations

import numpy as np
import pytest
from test_axis_align_task import SEEDS, kinematics, relative_rates

import rrc_pin
from rrc_pin.tasks.look_at_task import LookAtTask


@pytest.mark.parametrize("seed", SEEDS, ids=["fixed", "fresh"])
@pytest.mark.parametrize("name", ["panda", "rrc_k1607", "yeh_tripod"])
def test_rows_are_the_finite_differences(name, seed):
    """The direction to the point turns as the frame moves: its rate is in the rows."""
    robot = rrc_pin.load(name)
    rng = np.random.default_rng(seed)
    q = robot.random_q(rng)
    task = LookAtTask(robot.tool_frames[0], rng.normal(size=3), rng.normal(size=3))
    rows = task.rows(kinematics(robot, q))
    assert np.abs(rows.A - relative_rates(robot, q, task)).max() < 1e-8, seed


def test_the_axis_stays_on_the_point_while_the_hand_moves():
    """The hand carried 0.2 m sideways at 0.1 m/s (top level, position), the look-at beside
    it: once aimed, the angle to the point stays below 1 mrad; the hand's path is followed."""
    arm = rrc_pin.load("panda")
    tool = arm.tool_frame
    q = arm.ready()
    point = arm.fk(q)[:3, 3] + [0.1, 0.05, -0.4]
    look = LookAtTask(tool, point, gain=10.0)
    resolver = rrc_pin.Resolver(arm, dt=0.01)
    start = look.angle(kinematics(arm, q))
    angles, p0 = [], arm.fk(q)[:3, 3]
    for k in range(300):
        target = arm.fk(arm.ready())
        target[1, 3] += 0.1 * 0.01 * min(k, 200)  # the hand's path, its pose error fed back
        move = rrc_pin.FrameTask(tool, [0, 0.1 if k < 200 else 0.0, 0], rows="position",
                                 target=target)  # fmt: skip
        r = resolver.solve(q, [[move, look]], priority="strict")
        q = arm.integrate(q, r.qdot, 0.01)
        angles.append(look.angle(kinematics(arm, q)))
    assert start > 0.2
    assert max(angles[100:]) < 1e-3, max(angles[100:])
    np.testing.assert_allclose(arm.fk(q)[:3, 3] - p0, [0, 0.2, 0], atol=1e-5)


def test_a_point_at_the_origin_holds_the_axis_and_bad_points_are_refused():
    arm = rrc_pin.load("panda")
    q = arm.ready()
    kin = kinematics(arm, q)
    task = LookAtTask(arm.tool_frame, kin.pose(arm.tool_frame)[:3, 3])
    np.testing.assert_allclose(task.rows(kin).b, 0.0, atol=1e-12)
    with pytest.raises(rrc_pin.InvalidInput) as info:
        LookAtTask("tool", [0, np.inf, 0])
    assert info.value.argument == "point"
    with pytest.raises(rrc_pin.InvalidInput):
        task.set_point([1, 2])
