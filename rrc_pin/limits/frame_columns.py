"""Some frames' Jacobian columns and poses, as the closed chains' compiled rows read them.

After ``computeJointJacobians``, ``data.J`` (6, nv_ext) holds every joint's motion subspace in
the world frame, one column per extended rate (a mimic joint has its own). Pinocchio's
``getFrameJacobian`` (``details::translateJointJacobian``, algorithm/jacobian.hxx) takes a
frame's Jacobian from the columns that support the frame's parent joint, following
``data.non_mimic_parents_fromRow`` from the joint's last column (from its first non-mimic
parent's, for a mimic joint), then adds the mimic joints' columns, following
``data.mimic_parents_fromRow``, into the columns of the joints they follow
(``data.idx_vExtended_to_idx_v_fromRow``); every other column is zero. :class:`FrameColumns`
is that walk, made once per model and frames.

The frames' poses are read in place (:func:`placed_frames`): Pinocchio keeps ``data.oMf`` in
one array of SE3 (each its column-major rotation, then its translation, at a fixed stride), a
read-only view of which gives every frame's ``[R | p]`` without a Python call per frame.
:class:`FrameReader` holds both for one layout and Data, and the view's Data with it.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
import numpy.typing as npt
import pinocchio as pin

if TYPE_CHECKING:
    from rrc_pin.kinematics import Kinematics, Layout

Array = npt.NDArray[np.float64]
Ints = npt.NDArray[np.int64]


class FrameColumns(NamedTuple):
    """The steps that make each of ``frames``' Jacobians from ``data.J`` (module docstring).

    Attributes:
        frames: (k,) Pinocchio frame indices (repeats allowed).
        steps: (s, 3) each step's column of ``data.J``, its column in the frame's Jacobian
            (nv), and 1 where it adds to that column (a mimic joint's), else 0 (sets it).
        starts: (k + 1,) frame i's steps are ``steps[starts[i]:starts[i + 1]]``, in
            Pinocchio's order.
    """

    frames: Ints
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
        return cls(np.array(frames, dtype=np.int64), np.array(steps, dtype=np.int64).reshape(-1, 3),
                   np.array(starts, dtype=np.int64))  # fmt: skip


def _walk(model: pin.Model, data: pin.Data, joint: int) -> list[tuple[int, int, int]]:
    """The steps of a frame on ``joint``: Pinocchio's two passes (module docstring)."""
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


def placed_frames(data: pin.Data) -> Array | None:
    """Every frame's pose ``[R | p]`` (nframes, 3, 4) [m], a read-only view of ``data.oMf``.

    Or None where Pinocchio's array is not laid out as one (module docstring): each frame's
    rotation and translation at a fixed stride, the view equal to each frame's pose now. The
    view holds no reference to ``data``: whoever keeps it keeps ``data`` (:class:`FrameReader`).
    """
    oMf = data.oMf
    n = len(oMf)
    if n == 0:
        return None
    R, t = oMf[0].rotation, oMf[0].translation
    row, col = R.strides
    base = _address(R)
    stride = _address(oMf[1].rotation) - base if n > 1 else 0
    if _address(t) != base + 3 * col or t.strides != (row,):
        return None
    if any(_address(oMf[i].rotation) != base + i * stride for i in range(n)):
        return None
    view: Array = np.lib.stride_tricks.as_strided(R, shape=(n, 3, 4), strides=(stride, row, col),
                                                  writeable=False)  # fmt: skip
    if not all(np.array_equal(view[i], oMf[i].homogeneous[:3]) for i in range(n)):
        return None
    return view


def _address(a: Array) -> int:
    """Where ``a``'s first entry is in memory."""
    address: int = a.__array_interface__["data"][0]
    return address


class FrameReader:
    """What the closed chains' rows read of a tick for ``frames``: their columns and poses.

    Made for one layout and one Data (the tick's :class:`~rrc_pin.kinematics.Kinematics`'),
    kept while the ticks' are the same (:meth:`fits`).

    Args:
        kin: A tick's kinematics.
        frames: Pinocchio frame indices (k,).
    """

    __slots__ = ("_copied", "_view", "columns", "data", "layout")

    def __init__(self, kin: Kinematics, frames: Sequence[int]) -> None:
        self.layout: Layout = kin.layout
        self.data: pin.Data = kin.data
        self.columns = FrameColumns.of(kin.model, self.data, frames)
        self._view = placed_frames(self.data)
        self._copied = np.arange(len(frames), dtype=np.int64)

    def fits(self, kin: Kinematics) -> bool:
        """Whether ``kin`` is on this reader's layout and Data."""
        return kin.layout is self.layout and kin.data is self.data

    def poses(self) -> tuple[Array, Ints]:
        """The frames' poses now: ``[R | p]`` (m, 3, 4) [m] and frame i's row in them (k,).

        Every frame's, read in place; where Pinocchio's array cannot be (:func:`placed_frames`),
        a copy of these frames'.
        """
        if self._view is not None:
            return self._view, self.columns.frames
        oMf = self.data.oMf
        poses = np.array([oMf[f].homogeneous[:3] for f in self.columns.frames.tolist()])
        return poses.reshape(-1, 3, 4), self._copied
