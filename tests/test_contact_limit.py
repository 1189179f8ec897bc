"""ContactLimit: feet in support as equality rows, and how far each foot is from its anchor."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import rrc_pin
from rrc_pin.errors import FrameNotFound, InvalidInput
from rrc_pin.kinematics import Kinematics
from rrc_pin.limits import ContactLimit, JointLimits
from rrc_pin.solvers.exp_log import pose_error


def test_the_feet_are_held_and_their_anchors_errors_measured(tripod):
    """The rows keep every foot still; the error is each foot's [p* - p; log(R* R^T)] at the
    tick's configuration (world axes), in the resolver's metric units (the reach)."""
    q0 = tripod.ready()
    feet = list(tripod.tool_frames)
    anchors = [tripod.fk(q0, f) for f in feet]
    limit = ContactLimit(feet, anchors=anchors)
    resolver = rrc_pin.Resolver(tripod, 0.01, limits=[JointLimits(), limit])
    q = tripod.integrate(q0, np.random.default_rng(3).normal(size=tripod.nv) * 0.1, 0.01)
    r = resolver.solve(q, [rrc_pin.FrameTask("body", [0.02, 0, 0, 0, 0, 0])], priority="strict")
    for k, (f, T) in enumerate(zip(feet, anchors, strict=True)):
        now = tripod.fk(q, f)
        J = tripod.jacobian(q, "world_aligned", f)
        np.testing.assert_allclose(J @ r.qdot, 0.0, atol=1e-10)
        want = np.concatenate([T[:3, 3] - now[:3, 3], pin.log3(T[:3, :3] @ now[:3, :3].T)])
        np.testing.assert_allclose(limit.last.error[6 * k : 6 * k + 6], want, atol=1e-12)
        np.testing.assert_allclose(limit.last.C[6 * k : 6 * k + 6], J, atol=1e-12)
    np.testing.assert_allclose(limit.last.unit.reshape(3, 6)[:, 3:], 1.0)
    np.testing.assert_allclose(limit.last.unit.reshape(3, 6)[:, :3], 1.987, atol=1e-3)


def test_without_anchors_nothing_is_measured_and_bad_anchors_are_named(tripod):
    limit = ContactLimit(["leg1/flange"])
    rrc_pin.Resolver(tripod, 0.01, limits=[limit]).solve(
        tripod.ready(), [rrc_pin.FrameTask("body")], priority="strict")
    assert limit.last is None
    with pytest.raises(InvalidInput, match="anchors: expected 1 poses, got 2"):
        limit.set_frames(["leg1/flange"], [np.eye(4), np.eye(4)])
    with pytest.raises(InvalidInput, match=r"anchors\[0\]"):
        limit.set_frames(["leg1/flange"], [np.ones((4, 4))])
    assert limit.frames == ("leg1/flange",)
    with pytest.raises(FrameNotFound):
        limit.set_frames(["nope"], [np.eye(4)])


@pytest.mark.parametrize("measured", [True, False])
def test_the_rows_and_errors_are_pinocchios_jacobians_and_pose_errors(tripod, measured) -> None:
    """On seeded random configurations: the rows are each foot's world_aligned Jacobian (the
    tick's kinematics), the errors its pose error to its anchor, within 1e-12; ``last`` holds
    the rows the tick is given, or stays None without anchors."""
    q0 = tripod.ready()
    feet = list(tripod.tool_frames)
    anchors = np.array([tripod.fk(q0, f) for f in feet])
    limit = ContactLimit(feet, anchors=anchors if measured else None)
    resolver = rrc_pin.Resolver(tripod, 0.01, limits=[JointLimits(), limit])
    rng = np.random.default_rng(33)

    def kinematics(q: np.ndarray) -> Kinematics:
        _, dof, q_pin = tripod.positions(q)
        return Kinematics(tripod.model, tripod.model.createData(), resolver.layout, dof, q_pin)

    for _ in range(1000):
        q = tripod.integrate(q0, rng.normal(size=tripod.nv) * rng.uniform(0.0, 1.0), 1.0)
        c = limit.constraints(kinematics(q), 0.01, np.zeros(tripod.nv))
        kin = kinematics(q)
        np.testing.assert_allclose(c.C, np.vstack([kin.jacobian(f) for f in feet]), rtol=0.0,
                                   atol=1e-12)  # fmt: skip
        np.testing.assert_array_equal(c.d, 0.0)
        if not measured:
            assert limit.last is None
            continue
        assert limit.last.C is c.C
        want = np.empty(6 * len(feet))
        for i, f in enumerate(feet):
            pose_error(anchors[i], kin.pose(f), want[6 * i : 6 * i + 6])
        np.testing.assert_allclose(limit.last.error, want, rtol=0.0, atol=1e-12)
        reach = [resolver.layout.reach[f] for f in feet]
        unit = np.ravel([[r] * 3 + [1.0] * 3 for r in reach])
        np.testing.assert_array_equal(limit.last.unit, unit)
