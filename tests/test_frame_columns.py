"""FrameColumns: a frame's Jacobian taken from the joint Jacobians as Pinocchio takes it."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from test_mimic import chain

import rrc_pin
from rrc_pin.limits.chain_kernels import frame_jacobian
from rrc_pin.limits.frame_columns import FrameColumns


def _configurations(robot: rrc_pin.Robot, rng: np.random.Generator, count: int):
    q0 = robot.ready()
    for _ in range(count):
        yield robot.integrate(q0, rng.normal(size=robot.nv), 1.0)


def _every_frame_as_pinocchio(robot: rrc_pin.Robot, seed: int, count: int) -> None:
    model = robot.model
    data = model.createData()
    columns = FrameColumns.of(model, data, list(range(model.nframes)))
    assert columns.frames == tuple(range(model.nframes))
    for q in _configurations(robot, np.random.default_rng(seed), count):
        q_pin = robot.positions(q)[2]
        pin.computeJointJacobians(model, data, q_pin)
        pin.updateFramePlacements(model, data)
        poses = columns.poses(data)
        for f in range(model.nframes):
            J = np.zeros((6, model.nv))
            frame_jacobian(data.J, columns.steps, columns.starts[f], columns.starts[f + 1],
                           poses[f, :3, 3], J)  # fmt: skip
            want = pin.getFrameJacobian(model, data, f, pin.LOCAL_WORLD_ALIGNED)
            np.testing.assert_array_equal(J, want, err_msg=f"{robot.name} {model.frames[f].name}")
            np.testing.assert_array_equal(poses[f], data.oMf[f].homogeneous)


@pytest.mark.parametrize("name", ["gsfc_dual", "yeh_tripod", "panda"])
def test_every_frame_as_pinocchios_frame_jacobian(name: str) -> None:
    """The same floats as ``getFrameJacobian(LOCAL_WORLD_ALIGNED)``: fixed and floating bases,
    the universe's frames (no columns)."""
    _every_frame_as_pinocchio(rrc_pin.load(name), 7, 20)


@pytest.mark.parametrize("k", [0.5, -3.0])
def test_a_mimic_joints_column_added_into_its_leaders(tmp_path, k: float) -> None:
    arm = chain(tmp_path, k)
    assert arm.model.nvExtended == arm.model.nv + 1
    columns = FrameColumns.of(arm.model, arm.model.createData(), [arm.model.nframes - 1])
    assert columns.steps[:, 2].any()  # the tool's chain holds the mimic joint's column
    _every_frame_as_pinocchio(arm, 11, 20)


def test_repeated_frames_and_none() -> None:
    dual = rrc_pin.load("gsfc_dual")
    data = dual.model.createData()
    f = dual.model.getFrameId(dual.objects["object"].hands[0])
    columns = FrameColumns.of(dual.model, data, [f, f])
    half = columns.starts[1]
    assert columns.starts.tolist() == [0, half, 2 * half]
    np.testing.assert_array_equal(columns.steps[:half], columns.steps[half:])
    empty = FrameColumns.of(dual.model, data, [])
    assert empty.steps.shape == (0, 3) and empty.starts.tolist() == [0]
    assert empty.poses(data).shape == (0, 4, 4)


class _Without:
    """``inner`` without the attributes Pinocchio 3.4 added for mimic joints."""

    def __init__(self, inner: object) -> None:
        self._inner = inner

    def __getattr__(self, name: str) -> object:
        if "Extended" in name or "mimic" in name:
            raise AttributeError(name)
        return getattr(self._inner, name)


@pytest.mark.parametrize("name", ["gsfc_dual", "yeh_tripod", "panda"])
def test_the_walk_of_a_pinocchio_without_mimic_columns(name: str) -> None:
    """Where the model has no extended columns (Pinocchio before 3.4), the walk over
    ``parents_fromRow`` gives the same steps on a model without mimic joints."""
    model = rrc_pin.load(name).model
    data = model.createData()
    frames = list(range(model.nframes))
    want = FrameColumns.of(model, data, frames)
    got = FrameColumns.of(_Without(model), _Without(data), frames)  # type: ignore[arg-type]
    np.testing.assert_array_equal(got.steps, want.steps)
    np.testing.assert_array_equal(got.starts, want.starts)

