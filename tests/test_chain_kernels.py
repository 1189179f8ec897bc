"""The closed chains' compiled rows against plain references: Pinocchio's frame Jacobians, the
relative rows' formula (RelativeFrameTask's docstring) and the pose error with pinocchio.log3,
on seeded random configurations of the two cells."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from test_relative_frame_kernels import _pose, _reference

import rrc_pin
from rrc_pin.limits.chain_kernels import NO_POSES, UNMEASURED, contact_rows, grip_rows
from rrc_pin.limits.frame_columns import FrameColumns

CONFIGURATIONS = 2000


def _ticks(robot: rrc_pin.Robot, frames: list[int], seed: int):
    """Seeded configurations around the ready pose: the data placed, the frames' columns."""
    model = robot.model
    data = model.createData()
    columns = FrameColumns.of(model, data, frames)
    rng = np.random.default_rng(seed)
    q0 = robot.ready()
    for _ in range(CONFIGURATIONS):
        q = robot.integrate(q0, rng.normal(size=robot.nv) * rng.uniform(0.0, 1.0), 1.0)
        pin.computeJointJacobians(model, data, robot.positions(q)[2])
        pin.updateFramePlacements(model, data)
        yield rng, data, columns


def _jacobian(robot: rrc_pin.Robot, data: pin.Data, frame: int) -> np.ndarray:
    return pin.getFrameJacobian(robot.model, data, frame, pin.LOCAL_WORLD_ALIGNED)


def test_contact_rows_as_pinocchios_jacobians_and_the_anchors_errors(tripod) -> None:
    frames = [tripod.model.getFrameId(f) for f in tripod.tool_frames]
    k = len(frames)
    for rng, data, columns in _ticks(tripod, frames, 21):
        poses = columns.poses(data)
        turn = 1e-6 if rng.uniform() < 0.5 else rng.uniform(0.0, 2.5)
        anchors = np.array([T @ _pose(rng, turn) for T in poses])
        C, error = np.zeros((6 * k, tripod.nv)), np.empty(6 * k)
        contact_rows(data.J, columns.steps, columns.starts, poses, anchors, C, error)
        for i, f in enumerate(frames):
            np.testing.assert_array_equal(C[6 * i : 6 * i + 6], _jacobian(tripod, data, f))
            T, A = poses[i], anchors[i]
            want = np.concatenate([A[:3, 3] - T[:3, 3], pin.log3(A[:3, :3] @ T[:3, :3].T)])
            np.testing.assert_allclose(error[6 * i : 6 * i + 6], want, rtol=0.0, atol=1e-12)


def test_grip_rows_as_the_relative_formula_and_the_grips_errors() -> None:
    dual = rrc_pin.load("gsfc_dual")
    a, b = (dual.model.getFrameId(h) for h in dual.objects["object"].hands)
    frames = [a, b, b, a]  # two pairs: the grip and its reverse
    for rng, data, columns in _ticks(dual, frames, 22):
        poses = columns.poses(data)
        turn = 1e-6 if rng.uniform() < 0.5 else rng.uniform(0.0, 2.5)
        grips = np.array([np.linalg.inv(poses[2 * i]) @ poses[2 * i + 1] @ _pose(rng, turn)
                          for i in range(2)])  # fmt: skip
        C, error = np.full((12, dual.nv), np.nan), np.empty(12)
        grip_rows(data.J, columns.steps, columns.starts, poses, grips, C, error)
        for i, (fa, fb) in enumerate([(a, b), (b, a)]):
            want_J, want_error = _reference(_jacobian(dual, data, fa), _jacobian(dual, data, fb),
                                            poses[2 * i], poses[2 * i + 1], grips[i])  # fmt: skip
            np.testing.assert_allclose(C[6 * i : 6 * i + 6], want_J, rtol=0.0, atol=1e-12)
            np.testing.assert_allclose(error[6 * i : 6 * i + 6], want_error, rtol=0.0, atol=1e-12)


@pytest.mark.parametrize("kernel", [contact_rows, grip_rows])
def test_without_anchors_or_grips_no_error_is_written(kernel) -> None:
    dual = rrc_pin.load("gsfc_dual")
    hands = [dual.model.getFrameId(h) for h in dual.objects["object"].hands]
    _, data, columns = next(_ticks(dual, hands, 23))
    C = np.zeros((12 if kernel is contact_rows else 6, dual.nv))
    kernel(data.J, columns.steps, columns.starts, columns.poses(data), NO_POSES, C, UNMEASURED)
    assert np.isfinite(C).all() and np.abs(C).max() > 0.0
    assert UNMEASURED.size == 0 and NO_POSES.size == 0
