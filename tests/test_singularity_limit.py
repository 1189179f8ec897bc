"""SingularityLimit: the smallest singular values held above a threshold (issue 41)."""

from __future__ import annotations

import numpy as np
import pytest

import rrc_pin
from rrc_pin.dexterity import dexterity
from rrc_pin.kinematics import Kinematics, Layout
from rrc_pin.limits.singularity_limit import SingularityLimit


def kinematics(robot, q):
    q, dof, q_pin = robot.positions(q)
    return Kinematics(robot.model, robot.model.createData(), Layout.of(robot), dof, q_pin)


def drive(name: str, twist, limit: SingularityLimit | None, ticks: int = 600):
    """The tool driven by a constant twist from ready; the smallest singular value after each
    tick and the statuses."""
    arm = rrc_pin.load(name)
    limits = [rrc_pin.JointLimits()] + ([] if limit is None else [limit])
    resolver = rrc_pin.Resolver(arm, dt=0.01, limits=limits)
    q, sigma, statuses = arm.ready(), [], set()
    for _ in range(ticks):
        r = resolver.solve(q, twist)
        statuses.add(r.status)
        q = arm.integrate(q, r.qdot, 0.01)
        sigma.append(dexterity(kinematics(arm, q), arm.tool_frame).sigma[-1])
    return np.array(sigma), statuses, r


@pytest.mark.parametrize(("name", "twist"), [("panda", [0.15, 0, 0, 0, 0, 0]),
                                             ("rrc_k1607", [0.15, 0, 0, 0, 0, 0]),
                                             ("ur5", [0, 0.3, 0, 0, 0, 0])])  # fmt: skip
def test_a_command_into_a_singularity_stops_at_the_threshold(name, twist):
    """Stretching the arm out: without the limit the smallest singular value reaches 0 (the
    resolver damps); with it, it stays at the threshold to 1e-4 (second order in the step)
    and the command is scaled, its row named in the report."""
    free, _, _ = drive(name, twist, None)
    arm = rrc_pin.load(name)
    limit = SingularityLimit(arm.tool_frame, threshold=0.03, detection=0.08)
    held, statuses, last = drive(name, twist, limit)
    assert free.min() < 1e-3
    assert held.min() > 0.03 - 1e-4, held.min()
    assert abs(held[-1] - 0.03) < 1e-3  # it got there: the command pushed all along
    assert "damped" not in statuses
    assert last.scale < 0.05
    prefix = f"singularity:{arm.tool_frame}:sigma"
    assert any(row.name.startswith(prefix) for row in last.active_rows)


def test_rows_are_the_damper_of_the_exact_gradient():
    arm = rrc_pin.load("panda")
    q = arm.ready()
    q[3] = -0.6  # elbow nearly stretched
    kin = kinematics(arm, q)
    d = dexterity(kin, arm.tool_frame)
    limit = SingularityLimit(arm.tool_frame, threshold=0.01, detection=d.sigma[-1] + 0.01, gain=0.2)
    c = limit.constraints(kin, 0.01, np.zeros(7))
    assert c.G is not None and c.h is not None and c.G.shape == (1, 7)
    np.testing.assert_allclose(c.G[0], -d.gradients[-1], atol=1e-15)
    assert c.h[0] == pytest.approx(0.2 * (d.sigma[-1] - 0.01) / (d.sigma[-1] + 0.01 - 0.01))
    assert c.names == ("singularity:panda_hand_tcp:sigma6",)
    far = SingularityLimit(arm.tool_frame, threshold=0.001, detection=0.002)
    assert far.constraints(kin, 0.01, np.zeros(7)).G is None  # nothing near: no rows
    fast = SingularityLimit(arm.tool_frame, threshold=0.01, detection=d.sigma[-1] + 0.01,
                            gain=100.0).constraints(kin, 0.01, np.zeros(7))  # fmt: skip
    assert fast.h is not None and fast.h[0] == pytest.approx((d.sigma[-1] - 0.01) / 0.01)


def test_bad_arguments_are_refused_by_name():
    for kwargs, argument in [({"threshold": -0.1}, "threshold"),
                             ({"threshold": 0.1, "detection": 0.05}, "detection"),
                             ({"gain": 0.0}, "gain"), ({"rows": "up"}, "rows"),
                             ({"name": ""}, "name")]:  # fmt: skip
        with pytest.raises(rrc_pin.InvalidInput) as info:
            SingularityLimit("tool", **kwargs)
        assert info.value.argument == argument
    with pytest.raises(rrc_pin.FrameNotFound):
        rrc_pin.Resolver("panda", limits=[SingularityLimit("nowhere")])
