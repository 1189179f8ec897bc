"""Which columns of Pinocchio's joint Jacobians make some frames' Jacobians, and their poses.

After ``computeJointJacobians``, ``data.J`` (6, nv_ext) holds every joint's motion subspace in
the world frame, one column per extended rate (a mimic joint has its own). Pinocchio's
``getFrameJacobian`` (``details::translateJointJacobian``, algorithm/jacobian.hxx) takes a
frame's Jacobian from the columns that support the frame's parent joint, following
``data.non_mimic_parents_fromRow`` from the joint's last column (from its first non-mimic
parent's, for a mimic joint), then adds the mimic joints' columns, following
``data.mimic_parents_fromRow``, into the columns of the joints they follow
(``data.idx_vExtended_to_idx_v_fromRow``); every other column is zero. Before Pinocchio 3.4's
mimic joints (no ``model.nvExtended``) one column per rate, the walk ``data.parents_fromRow``
from the joint's last column. :class:`FrameColumns` is that walk, made once per model and
frames, as the compiled rows (:mod:`rrc_pin.limits.chain_kernels`) read it at every tick.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

import numpy as np
import numpy.typing as npt
import pinocchio as pin

Array = npt.NDArray[np.float64]
Ints = npt.NDArray[np.int64]


class FrameColumns(NamedTuple):
    """The steps that make each of ``frames``' Jacobians from ``data.J`` (module docstring).

    Attributes:
        frames: Pinocchio frame indices, k of them (repeats allowed).
        steps: (s, 3) each step's column of ``data.J``, its column in the frame's Jacobian
            (nv), and 1 where it adds to that column (a mimic joint's), else 0 (sets it).
        starts: (k + 1,) frame i's steps are ``steps[starts[i]:starts[i + 1]]``, in
            Pinocchio's order.
    """

    frames: tuple[int, ...]
    steps: Ints
    starts: Ints

    @classmethod
    def of(cls, model: pin.Model, data: pin.Data, frames: Sequence[int]) -> FrameColumns:
        """The steps of ``frames`` on ``model`` (``data``: any Data of it)."""
        steps: list[tuple[int, int, int]] = []
        starts = [0]
        for frame in frames:
            steps += _walk(model, data, model.frames[frame].parentJoint)
            starts.append(len(steps))
        return cls(tuple(frames), np.array(steps, dtype=np.int64).reshape(-1, 3),
                   np.array(starts, dtype=np.int64))  # fmt: skip

    def poses(self, data: pin.Data) -> Array:
        """The frames' poses (k, 4, 4) in the base frame [m], from ``data.oMf`` (placed)."""
        return frame_poses(data, self.frames)


def frame_poses(data: pin.Data, frames: Sequence[int]) -> Array:
    """The poses (k, 4, 4) in the base frame [m] of Pinocchio's ``frames``, from ``data.oMf``
    (placed: ``updateFramePlacements``)."""  # noqa: D205, D209
    oMf = data.oMf
    poses = np.empty((len(frames), 4, 4))
    for i, f in enumerate(frames):
        poses[i] = oMf[f].homogeneous
    return poses


def _walk(model: pin.Model, data: pin.Data, joint: int) -> list[tuple[int, int, int]]:
    """The steps of a frame on ``joint``: Pinocchio's two passes (module docstring)."""
    if not hasattr(model, "nvExtended"):  # a Pinocchio without extended (mimic) columns
        column = model.joints[joint].idx_v + model.joints[joint].nv - 1
        plain = []
        while column >= 0:
            plain.append((column, column, 0))
            column = data.parents_fromRow[column]
        return plain
    if model.nvExtended == 0:
        return []
    first = model.idx_vExtendeds[joint]
    last = first + model.nvExtendeds[joint] - 1
    mimic = model.mimic_joint_supports[joint][-1] == joint
    to_v = data.idx_vExtended_to_idx_v_fromRow
    steps = []
    for add, parents, column in (
        (0, data.non_mimic_parents_fromRow, data.non_mimic_parents_fromRow[first] if mimic
         else last),
        (1, data.mimic_parents_fromRow, last if mimic else data.mimic_parents_fromRow[first]),
    ):  # fmt: skip
        while column >= 0:
            steps.append((column, to_v[column], add))
            column = parents[column]
    return steps
