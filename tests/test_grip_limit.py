"""GripLimit: two hands held together as equality rows, and how far each pair is from its
grip."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import rrc_pin
from rrc_pin.errors import InvalidInput
from rrc_pin.kinematics import Kinematics
from rrc_pin.limits import GripLimit, JointLimits
from rrc_pin.tasks import RelativeFrameTask


def test_the_grip_is_held_and_its_error_measured_in_the_first_hands_axes():
    dual = rrc_pin.load("gsfc_dual")
    a, b = dual.objects["object"].hands
    q0 = dual.ready()
    grip = np.linalg.inv(dual.fk(q0, a)) @ dual.fk(q0, b)
    limit = GripLimit([(a, b)], grips=[grip])
    resolver = rrc_pin.Resolver(dual, 0.01, limits=[JointLimits(), limit])
    q = q0 + np.random.default_rng(5).normal(size=dual.nq) * 0.01
    resolver.solve(q, [rrc_pin.FrameTask("object", [0.02, 0, 0, 0, 0, 0.1])], priority="strict")
    rel = np.linalg.inv(dual.fk(q, a)) @ dual.fk(q, b)
    want = np.concatenate([grip[:3, 3] - rel[:3, 3], pin.log3(grip[:3, :3] @ rel[:3, :3].T)])
    np.testing.assert_allclose(limit.last.error, want, atol=1e-12)
    assert limit.last.C.shape == (6, dual.nv)
    np.testing.assert_allclose(limit.last.unit[3:], 1.0)
    assert limit.last.unit[0] > 1.0  # the longer hand's chain [m]


def test_bad_grips_are_named_and_change_nothing():
    limit = GripLimit([("a", "b")])
    assert limit.last is None
    with pytest.raises(InvalidInput, match="grips: expected 1 poses, got 0"):
        limit.set_pairs([("a", "b")], [])
    with pytest.raises(InvalidInput, match=r"grips\[0\]"):
        limit.set_pairs([("a", "b")], [np.zeros((4, 4))])
    assert limit.pairs == (("a", "b"),)


def _kinematics(resolver: rrc_pin.Resolver, robot: rrc_pin.Robot, q: np.ndarray) -> Kinematics:
    _, dof, q_pin = robot.positions(q)
    return Kinematics(robot.model, robot.model.createData(), resolver.layout, dof, q_pin)


@pytest.mark.parametrize("measured", [True, False])
def test_the_rows_errors_and_units_are_the_relative_tasks(measured: bool) -> None:
    """On seeded random configurations: each pair's rows, grip error and units are those of a
    RelativeFrameTask holding the grip at gain 1 (its rates are then the error), within 1e-12;
    ``last`` holds the rows the tick is given, or stays None without grips."""
    dual = rrc_pin.load("gsfc_dual")
    a, b = dual.objects["object"].hands
    q0 = dual.ready()
    pairs = [(a, b), (b, a)]
    grips = [np.linalg.inv(dual.fk(q0, x)) @ dual.fk(q0, y) for x, y in pairs]
    limit = GripLimit(pairs, grips=grips if measured else None)
    resolver = rrc_pin.Resolver(dual, 0.01, limits=[JointLimits(), limit])
    tasks = [RelativeFrameTask(x, y, target=T, gain=1.0)
             for (x, y), T in zip(pairs, grips, strict=True)]  # fmt: skip
    rng = np.random.default_rng(31)
    for _ in range(1000):
        q = q0 + rng.normal(size=dual.nq) * rng.uniform(0.0, 0.5)
        c = limit.constraints(_kinematics(resolver, dual, q), 0.01, np.zeros(dual.nv))
        kin = _kinematics(resolver, dual, q)
        rows = [t.rows(kin) for t in tasks]
        np.testing.assert_allclose(c.C, np.vstack([r.A for r in rows]), rtol=0.0, atol=1e-12)
        np.testing.assert_array_equal(c.d, 0.0)
        assert c.names[0] == f"grip:{b}/{a}:vx" and len(c.names) == 12
        if not measured:
            assert limit.last is None
            continue
        assert limit.last.C is c.C
        want = np.concatenate([r.b for r in rows])
        np.testing.assert_allclose(limit.last.error, want, rtol=0.0, atol=1e-12)
        np.testing.assert_array_equal(limit.last.unit, np.concatenate([r.unit for r in rows]))


def test_the_rows_follow_the_robot_and_pairs_of_the_tick() -> None:
    """One limit on two resolvers (two layouts, two models), and after its pairs change: each
    tick's rows are those of its robot and pairs."""
    duals = [rrc_pin.load("gsfc_dual") for _ in range(2)]
    a, b = duals[0].objects["object"].hands
    limit = GripLimit([(a, b)])
    resolvers = [rrc_pin.Resolver(d, 0.01, limits=[limit]) for d in duals]
    rng = np.random.default_rng(32)
    for k in range(6):
        if k == 3:
            limit.set_pairs([(b, a)])
        robot, resolver = duals[k % 2], resolvers[k % 2]
        q = robot.ready() + rng.normal(size=robot.nq) * 0.3
        task = RelativeFrameTask(*limit.pairs[0])
        want = task.rows(_kinematics(resolver, robot, q)).A
        C = limit.constraints(_kinematics(resolver, robot, q), 0.01, None).C
        np.testing.assert_allclose(C, want, rtol=0.0, atol=1e-12)
