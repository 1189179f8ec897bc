"""An arm's batch kinematics for a map: its serial chain read off the Pinocchio model.

:func:`chain_of` builds the :class:`~rrc_pin.solvers.maps.batch.Chain` of a tool frame from the
model's joint placements and axes; :func:`arm_kinematics` picks the evaluator
(:mod:`rrc_pin.solvers.maps.kinematics`): Barker's batch closed form for ``barker6``, the compiled
chain for every other arm. The task rows are those of the resolver's default task
(:func:`~rrc_pin.solvers.maps.kinematics.task_rows`).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.errors import FrameNotFound, InvalidInput, ToolFrameRequired
from rrc_pin.robot import Robot, frame_index
from rrc_pin.solvers.closed_form.barker import BarkerClosedForm
from rrc_pin.solvers.maps.batch import PRISMATIC, REVOLUTE, Chain
from rrc_pin.solvers.maps.kinematics import (
    ArmKinematics,
    BarkerKinematics,
    ChainKinematics,
    task_rows,
)

Array = npt.NDArray[np.float64]

_AXES = {"X": (1.0, 0.0, 0.0), "Y": (0.0, 1.0, 0.0), "Z": (0.0, 0.0, 1.0)}
_REVOLUTE = {"JointModelR": "axis", "JointModelRUB": "axis", "JointModelRevoluteUnaligned": None,
             "JointModelRevoluteUnboundedUnaligned": None}  # fmt: skip
_PRISMATIC = {"JointModelP": "axis", "JointModelPrismaticUnaligned": None}


def z_to(axis: npt.ArrayLike) -> Array:
    """A rotation (3, 3) taking the z axis to the unit vector ``axis`` (its third column).

    The rotation about ``z x axis`` by the angle between them (Rodrigues); a half turn about
    x when ``axis`` is -z.
    """
    a = np.asarray(axis, dtype=float)
    a = a / np.linalg.norm(a)
    c = a[2]
    if c < -1.0 + 1e-12:
        return np.diag([1.0, -1.0, -1.0])
    k = np.array([-a[1], a[0], 0.0])  # z x a, |k| = sin
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    out: Array = np.eye(3) + K + K @ K / (1.0 + c)
    return out


def _joint_axis(joint: pin.JointModel) -> tuple[int, Array] | None:
    """(kind, unit axis in the joint frame) of a 1-DOF joint, None for any other."""
    name = joint.shortname()
    for table, kind in ((_REVOLUTE, REVOLUTE), (_PRISMATIC, PRISMATIC)):
        for prefix, how in table.items():
            if how is None and name == prefix:
                return kind, np.array(joint.extract().axis, dtype=float)
            if how == "axis" and name.startswith(prefix) and name[len(prefix) :] in _AXES:
                return kind, np.array(_AXES[name[len(prefix) :]])
    return None


def chain_of(robot: Robot, frame: str | None = None) -> tuple[Chain, npt.NDArray[np.int64]]:
    """The serial chain from the base to ``frame``, and the index in q of each of its joints.

    The joints supporting the frame (Pinocchio's ``model.supports``), in order; each joint
    frame turned so that its axis is z (:func:`z_to`: ``M_k A_k``, and ``A_k^T`` moved into
    the next placement), which leaves every pose unchanged. Continuous joints take
    [-pi, pi] and count in no margin.

    Args:
        robot: Any robot of 1-DOF joints (an arm, a cell, a robot with several hands).
        frame: The tool frame; default: the robot's (required when it has several).

    Raises:
        ToolFrameRequired: No ``frame`` on a robot with several tool frames.
        FrameNotFound: ``frame`` is not a frame of the model.
        InvalidInput: No joint moves ``frame``, or a supporting joint is not revolute or
            prismatic about one axis.
    """
    if frame is None:
        if robot.tool_frame is None:
            raise ToolFrameRequired(
                "frame", f"{robot.name} has several tool frames", list(robot.tool_frames)
            )
        frame = robot.tool_frame
    model = robot.model
    frames = frame_index(model)
    if not isinstance(frame, str) or frame not in frames:
        raise FrameNotFound(str(frame), sorted(frames), "frame")
    fid = frames[frame]
    f = model.frames[fid]
    joints = list(model.supports[f.parentJoint])[1:]
    if not joints:
        raise InvalidInput("frame", f"{model.frames[fid].name!r} is fixed to the base")
    n = len(joints)
    rot, trans = np.empty((n + 1, 3, 3)), np.empty((n + 1, 3))
    kind, index = np.empty(n, np.int64), np.empty(n, np.int64)
    lower, upper, bounded = np.empty(n), np.empty(n), np.empty(n, bool)
    turn = np.eye(3)  # A_{k-1}^T, carried into placement k
    for k, j in enumerate(joints):
        joint = model.joints[j]
        found = _joint_axis(joint)
        if found is None:
            raise InvalidInput(
                "robot", f"joint {model.names[j]!r} is a {joint.shortname()}, not one axis"
            )
        kind[k], axis = found
        A = z_to(axis)
        M = model.jointPlacements[j]
        rot[k] = turn @ M.rotation @ A
        trans[k] = turn @ M.translation
        turn = A.T
        index[k] = joint.idx_v
        lo, hi = robot.lower[joint.idx_v], robot.upper[joint.idx_v]
        bounded[k] = bool(np.isfinite(lo) and np.isfinite(hi))
        lower[k], upper[k] = (lo, hi) if bounded[k] else (-np.pi, np.pi)
    rot[n] = turn @ f.placement.rotation
    trans[n] = turn @ f.placement.translation
    return Chain(rot, trans, kind, lower, upper, bounded), index


def placed(chain: Chain, T: npt.ArrayLike) -> Chain:
    """``chain`` with its base at the pose ``T`` (4, 4) [m] of another frame."""
    T = np.asarray(T, dtype=float)
    rot, trans = chain.rot.copy(), chain.trans.copy()
    rot[0] = T[:3, :3] @ chain.rot[0]
    trans[0] = T[:3, :3] @ chain.trans[0] + T[:3, 3]
    return replace(chain, rot=rot, trans=trans)


def arm_kinematics(robot: Robot, frame: str | None = None) -> ArmKinematics:
    """The batch kinematics of ``robot``'s tool frame (or ``frame``).

    Barker's closed form where the robot has it for that frame (``barker6`` and its variants,
    tool frame ``tool``), else the compiled chain.

    Raises:
        ToolFrameRequired, FrameNotFound, InvalidInput: As :func:`chain_of`.
    """
    chain, _ = chain_of(robot, frame)
    cf = robot.closed_form if frame in (None, robot.tool_frame) else None
    if isinstance(cf, BarkerClosedForm):
        return BarkerKinematics(cf, chain)
    return ChainKinematics(chain, task_rows(chain.n))
