"""The kinematics of one control tick: frame Jacobians and poses, computed once for all tasks.

:class:`Kinematics` runs ``pinocchio.computeJointJacobians`` (which includes the forward
kinematics) and ``updateFramePlacements`` once at a configuration, in a ``pinocchio.Data``
that belongs to its caller (a resolver's own: never a Data shared between threads); the tasks
then read frame Jacobians (``getFrameJacobian``, no recomputation) and poses from it.
:class:`Layout` is what the tasks may name on a robot, prepared once.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.robot import PIN_REFERENCE, frame_index
from solvers.spatial import Reference

Array = npt.NDArray[np.float64]


class Layout(NamedTuple):
    """The names a task may use on one robot, and its continuous joints.

    Attributes:
        nv: Number of joints (one rate each).
        frames: Frame name to Pinocchio frame index.
        joints: Joint name to index in q.
        continuous: Mask (nv,) of the continuous (unbounded revolute) joints.
    """

    nv: int
    frames: dict[str, int]
    joints: dict[str, int]
    continuous: npt.NDArray[np.bool_]

    @classmethod
    def of(cls, model: pin.Model, joint_names: list[str]) -> Layout:
        """The layout of ``model`` whose joints (in q's order) are ``joint_names``."""
        continuous = np.array([model.joints[j].nq == 2 for j in range(1, model.njoints)])
        joints = {n: i for i, n in enumerate(joint_names)}
        return cls(model.nv, frame_index(model), joints, continuous)


class Kinematics:
    """Frame Jacobians (6, nv) and poses of one configuration.

    Args:
        model: The ``pinocchio.Model``.
        data: A ``pinocchio.Data`` of ``model`` owned by the caller (overwritten).
        layout: The robot's :class:`Layout`.
        q: Joint positions at the API (nv,) [rad or m], one coordinate per joint.
        q_pin: The same configuration as Pinocchio's vector (model.nq,).

    Attributes:
        q: Joint positions (nv,).
        q_pin: Pinocchio configuration (model.nq,).
        continuous: Mask (nv,) of the continuous joints.
    """

    def __init__(
        self, model: pin.Model, data: pin.Data, layout: Layout, q: Array, q_pin: Array
    ) -> None:
        self.q, self.q_pin, self.continuous = q, q_pin, layout.continuous
        self._model, self._data, self._layout = model, data, layout
        pin.computeJointJacobians(model, data, q_pin)
        pin.updateFramePlacements(model, data)

    def jacobian(self, frame: str, ref: Reference = "world_aligned") -> Array:
        """Geometric Jacobian (6, nv) of ``frame``, rows [v; w], in frame ``ref``."""
        fid = self._layout.frames[frame]
        J: Array = pin.getFrameJacobian(self._model, self._data, fid, PIN_REFERENCE[ref])
        return J

    def joint_index(self, joint: str) -> int:
        """Index in q of the joint named ``joint``."""
        return self._layout.joints[joint]

    def pose(self, frame: str) -> Array:
        """Pose (4, 4) of ``frame`` in the base frame [m] (a copy)."""
        return np.array(self._data.oMf[self._layout.frames[frame]].homogeneous)
