"""The kinematics of one control tick, computed once for every task and limit that reads it.

:class:`Kinematics` answers frame Jacobians and poses at one configuration from a
``pinocchio.Data`` that belongs to its caller (a resolver's own: never a Data shared between
threads). It computes lazily: the first Jacobian asked for comes from one
``computeFrameJacobian`` call (what a one-frame tick needs); a second frame runs
``computeJointJacobians`` once (every joint's Jacobian, which ``getFrameJacobian`` reads for
every later frame), and a pose of another frame ``updateFramePlacements`` once (every frame's
pose: the Jacobians do not read them). :class:`Layout` is what tasks and limits may name on a
robot, prepared once.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.robot import PIN_REFERENCE, Robot, frame_index
from rrc_pin.solvers.spatial import Reference

Array = npt.NDArray[np.float64]

MIN_REACH = 0.01
"""[m] The smallest reach a frame's linear rows are normalised by (a frame at the base)."""


class Layout(NamedTuple):
    """The names a task or limit may use on one robot, and its joints' limits.

    Attributes:
        nv: Number of joint rates (a floating base's six, then one per joint).
        frames: Frame name to Pinocchio frame index.
        joints: Joint name to index in qdot (a floating base's rates are named
            ``base:vx`` ... ``base:wz``, :attr:`Robot.dof_names`).
        continuous: Mask (nv,) of the continuous (unbounded revolute) joints.
        lower: Lower position limits (nv,) [rad or m].
        upper: Upper position limits (nv,).
        velocity: Velocity limits (nv,) [rad/s or m/s].
        reach: Frame name to its reach [m] (:func:`reach`), the unit of its linear rows.
        closed_form: A closed form answering the tool frame's world_aligned Jacobian, or None.
        tool_frame: The frame the closed form answers for, or None.
        actuated: Mask (nv,) of the rates a joint drives (False for a floating base's), or
            None when every rate is.
        mimic_velocity: Speed limits (nv,) that mimic joints put on the joints they follow
            (:attr:`Robot.mimic_velocity`), or None where there are none.
    """

    nv: int
    frames: dict[str, int]
    joints: dict[str, int]
    continuous: npt.NDArray[np.bool_]
    lower: Array
    upper: Array
    velocity: Array
    reach: dict[str, float]
    closed_form: Any = None
    tool_frame: str | None = None
    actuated: npt.NDArray[np.bool_] | None = None
    mimic_velocity: Array | None = None

    @classmethod
    def of(cls, robot: Robot, closed_form: Any = None) -> Layout:
        """The layout of ``robot`` (with ``closed_form`` for its tool frame, if given)."""
        model = robot.model
        continuous = robot.continuous
        if robot.floating:  # per rate: the base's six are not continuous joints
            continuous = np.concatenate([np.zeros(6, dtype=bool), continuous[7:]])
        joints = {n: i for i, n in enumerate(robot.dof_names)}
        frames = frame_index(model)
        reaches = {name: reach(model, fid) for name, fid in frames.items()}
        if robot.floating:  # every frame at least the longest chain's (:func:`reach`)
            extent = max(reaches.values())
            reaches = {name: max(length, extent) for name, length in reaches.items()}
        return cls(
            model.nv, frames, joints, continuous, robot.dof_lower, robot.dof_upper,
            robot.velocity_limit, reaches, closed_form,
            robot.tool_frame if closed_form is not None else None,
            robot.actuated if robot.floating else None,
            robot.mimic_velocity if np.isfinite(robot.mimic_velocity).any() else None,
        )  # fmt: skip


def reach(model: pin.Model, frame: int) -> float:
    """The length [m] of the chain from the base to ``frame``: the sum of its links' offsets.

    An upper bound of how far the frame can be from the base (for revolute chains): the
    scale at which a frame's linear velocity compares with an angular one (1 m/s at this
    distance is 1 rad/s), so that the resolver's metric does not mix metres and radians. At
    least :data:`MIN_REACH`.

    On a floating base (:meth:`Layout.of`) every frame's reach is at least the robot's longest
    chain: the free-flyer's own chain has no length, so the body's frame would be normalised
    by :data:`MIN_REACH`, its linear rows 100 times its angular ones (the tripod's body rows
    over its feet in support read a condition number of 284 at the ready pose, 5-6 in metres,
    and every body command the contacts limit was damped instead of scaled). A floating body
    moves by its limbs: 1 rad/s of the body moves their ends at their length.
    """
    f = model.frames[frame]
    length = float(np.linalg.norm(f.placement.translation))
    for j in model.supports[f.parentJoint][1:]:
        length += float(np.linalg.norm(model.jointPlacements[j].translation))
    return max(length, MIN_REACH) if math.isfinite(length) else 1.0


class Kinematics:
    """Frame Jacobians (6, nv) and poses of one configuration (module docstring).

    Args:
        model: The ``pinocchio.Model``.
        data: A ``pinocchio.Data`` of ``model`` owned by the caller (overwritten).
        layout: The robot's :class:`Layout`.
        q: Each rate's position (nv,) [rad or m] (:meth:`Robot.dof_positions`: the joints'
            coordinates, 0 for a floating base's six rates).
        q_pin: The configuration as Pinocchio's vector (model.nq,).

    Attributes:
        q: Each rate's position (nv,).
        q_pin: Pinocchio configuration (model.nq,).
        layout: The robot's layout.
    """

    __slots__ = ("_data", "_first", "_framed", "_jacobians", "_joints", "_model", "_placed",
                 "layout", "q", "q_pin")  # fmt: skip

    def __init__(
        self, model: pin.Model, data: pin.Data, layout: Layout, q: Array, q_pin: Array
    ) -> None:
        self.q, self.q_pin, self.layout = q, q_pin, layout
        self._model, self._data = model, data
        self._first: str | None = None  # the one frame whose Jacobian computeFrameJacobian gave
        self._joints = False  # every joint's placement and Jacobian computed
        self._framed = False  # every frame's pose computed
        self._placed = False  # the joints supporting _first placed (a world_aligned or world
        # Jacobian of it: Pinocchio's local one does not place them)
        self._jacobians: dict[tuple[str, str], Array] = {}

    @property
    def model(self) -> pin.Model:
        """The Pinocchio model."""
        return self._model

    @property
    def data(self) -> pin.Data:
        """The Data with every joint's placement and Jacobian and every frame's pose at q
        (computed on first use)."""  # noqa: D205, D209
        self._compute_frames()
        return self._data

    def jacobian(self, frame: str, ref: Reference = "world_aligned") -> Array:
        """Geometric Jacobian (6, nv) of ``frame``, rows [v; w], in frame ``ref``.

        Computed once per frame and ref, then shared by every reader of this tick (read only).
        """
        J = self._jacobians.get((frame, ref))
        if J is None:
            J = self._jacobians[frame, ref] = self._computed(frame, ref)
        return J

    def _computed(self, frame: str, ref: Reference) -> Array:
        layout = self.layout
        if frame == layout.tool_frame and ref == "world_aligned":
            return np.asarray(layout.closed_form.jacobian(self.q), dtype=np.float64)
        fid = layout.frames[frame]
        J: Array
        if not self._joints and (self._first is None or self._first == frame):
            self._first = frame
            self._placed = self._placed or ref != "local"
            J = pin.computeFrameJacobian(
                self._model, self._data, self.q_pin, fid, PIN_REFERENCE[ref]
            )
        else:
            self._compute_joints()
            J = pin.getFrameJacobian(self._model, self._data, fid, PIN_REFERENCE[ref])
        return J if J.ndim == 2 else J.reshape(6, 1)  # one joint: Pinocchio gives (6,)

    def joint_index(self, joint: str) -> int:
        """Index in q of the joint named ``joint``."""
        return self.layout.joints[joint]

    def pose(self, frame: str) -> Array:
        """Pose (4, 4) of ``frame`` in the base frame [m] (a new array, :meth:`placement`'s)."""
        pose: Array = self._placed_in(frame).homogeneous
        return pose

    def placement(self, frame: str) -> pin.SE3:
        """Pose of ``frame`` in the base frame (a copy).

        Where the frame's world_aligned Jacobian was computed alone (``computeFrameJacobian``),
        its parent joint is placed already: the pose is that placement times the frame's
        (Pinocchio's ``updateFramePlacement``, the same floats as a forward pass), without a
        second pass.
        """
        return pin.SE3(self._placed_in(frame))

    def _placed_in(self, frame: str) -> pin.SE3:
        """The Data's placement of ``frame`` (:meth:`placement`), not a copy."""
        fid = self.layout.frames[frame]
        if frame != self._first or not self._placed or self._joints:
            self._compute_frames()
            return self._data.oMf[fid]
        return pin.updateFramePlacement(self._model, self._data, fid)

    def _compute_joints(self) -> None:
        if not self._joints:
            pin.computeJointJacobians(self._model, self._data, self.q_pin)
            self._joints = True

    def _compute_frames(self) -> None:
        if not self._framed:
            self._compute_joints()
            pin.updateFramePlacements(self._model, self._data)
            self._framed = True
