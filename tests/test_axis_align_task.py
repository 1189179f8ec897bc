"""AxisAlignTask: rows against finite differences; an axis turned onto a direction."""

from __future__ import annotations

import numpy as np
import pytest

import rrc_pin
from rrc_pin.kinematics import Kinematics, Layout
from rrc_pin.tasks.axis_align_task import AxisAlignTask, across, unit

SEEDS = [20261206, int(np.random.SeedSequence().entropy % 2**63)]


def kinematics(robot, q):
    q, dof, q_pin = robot.positions(q)
    return Kinematics(robot.model, robot.model.createData(), Layout.of(robot), dof, q_pin)


def relative_rates(robot, q, task, h=1e-6):
    """E^T (a x da/dq_j - d x dd/dq_j) by central differences (module docstring of the task)."""
    kin = kinematics(robot, q)
    R = kin.pose(task.frame)[:3, :3]
    a, E = R @ task.axis, R @ task.across
    d = task.aim(kin)[0]
    out = np.empty((2, robot.nv))
    for j in range(robot.nv):
        e = np.zeros(robot.nv)
        e[j] = h
        ends = []
        for sign in (1.0, -1.0):
            k = kinematics(robot, robot.integrate(q, sign * e, 1.0))
            ends.append((k.pose(task.frame)[:3, :3] @ task.axis, task.aim(k)[0]))
        da = (ends[0][0] - ends[1][0]) / (2 * h)
        dd = (ends[0][1] - ends[1][1]) / (2 * h)
        out[:, j] = E.T @ (np.cross(a, da) - np.cross(d, dd))
    return out


@pytest.mark.parametrize("seed", SEEDS, ids=["fixed", "fresh"])
@pytest.mark.parametrize("name", ["panda", "ur5", "yeh_tripod"])
def test_rows_are_the_finite_differences(name, seed):
    robot = rrc_pin.load(name)
    rng = np.random.default_rng(seed)
    q = robot.random_q(rng)
    task = AxisAlignTask(robot.tool_frames[0], rng.normal(size=3), rng.normal(size=3))
    rows = task.rows(kinematics(robot, q))
    assert rows.A.shape == (2, robot.nv)
    assert np.abs(rows.A - relative_rates(robot, q, task)).max() < 1e-8, seed


def test_the_axis_turns_onto_the_direction_and_spins_about_itself_freely():
    arm = rrc_pin.load("panda")
    tool = arm.tool_frame
    task = AxisAlignTask(tool, [0, 0, 1], [0.3, -0.2, -1.0], gain=5.0)
    spin = rrc_pin.FrameTask(tool, [0, 0, 0, 0, 0, 0.3], rows="orientation")
    resolver = rrc_pin.Resolver(arm, dt=0.01)
    q = arm.ready()
    hold = rrc_pin.FrameTask(tool, rows="position", target=arm.fk(q))
    start = task.angle(kinematics(arm, q))
    for _ in range(150):
        r = resolver.solve(q, [[hold, task], [spin]], priority="strict")
        q = arm.integrate(q, r.qdot, 0.01)
    kin = kinematics(arm, q)
    assert start > 0.3 and task.angle(kin) < 1e-3
    assert np.linalg.norm(arm.fk(q)[:3, 3] - hold.target[:3, 3]) < 1e-4
    z = kin.pose(tool)[:3, 2]
    x0, x = arm.fk(arm.ready())[:3, 0], kin.pose(tool)[:3, 0]
    assert np.arccos(np.clip(x0 @ x, -1, 1)) > 0.3  # the spin below it was followed
    np.testing.assert_allclose(z, unit([0.3, -0.2, -1.0], "d"), atol=2e-3)


def test_opposite_and_aligned_axes():
    """At the opposite direction the task still asks a turn (of pi, about e1); aligned, none."""
    arm = rrc_pin.load("panda")
    q = arm.ready()
    kin = kinematics(arm, q)
    z = kin.pose(arm.tool_frame)[:3, 2]
    assert np.linalg.norm(AxisAlignTask(arm.tool_frame, direction=-z, gain=2.0).rows(kin).b) \
        == pytest.approx(2.0 * np.pi)  # fmt: skip
    np.testing.assert_allclose(AxisAlignTask(arm.tool_frame, direction=z).rows(kin).b, 0.0,
                               atol=1e-12)  # fmt: skip


def test_across_is_a_right_handed_basis():
    rng = np.random.default_rng(3)
    for _ in range(20):
        a = unit(rng.normal(size=3), "a")
        E = across(a)
        np.testing.assert_allclose(E.T @ E, np.eye(2), atol=1e-15)
        np.testing.assert_allclose(np.cross(E[:, 0], E[:, 1]), a, atol=1e-15)


def test_bad_arguments_are_refused_by_name():
    for kwargs, argument in [({"axis": [0, 0, 0]}, "axis"), ({"direction": [np.nan, 0, 1]},
                             "direction"), ({"gain": -1.0}, "gain"), ({"weight": 0.0}, "weight"),
                             ({"name": ""}, "name")]:  # fmt: skip
        with pytest.raises(rrc_pin.InvalidInput) as info:
            AxisAlignTask("tool", **kwargs)
        assert info.value.argument == argument
    task = AxisAlignTask("tool")
    with pytest.raises(rrc_pin.InvalidInput):
        task.set_direction([0, 0, 0])
    np.testing.assert_array_equal(task.direction, [0, 0, -1])
