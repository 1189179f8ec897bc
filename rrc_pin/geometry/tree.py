"""A robot's joints as plain arrays, for the compiled collision pass's forward kinematics.

A proximity query needs every joint's placement at the tick, and the collision limit every
joint's Jacobian. Pinocchio's ``data.oMi`` is read by a Python loop over the joints, and its
``data.J`` needs a ``computeJointJacobians`` call that a tick may not otherwise make;
:func:`rrc_pin.solvers.collision.proximity_kernels.joint_poses` and
:func:`~rrc_pin.solvers.collision.proximity_kernels.joint_jacobians` compute them from q inside
the pass. :func:`tree_of` checks the kernel against Pinocchio (1e-9 m) before it is used.

Each joint is revolute or prismatic about one axis of its own frame, found from Pinocchio's
motion subspace (the joint's LOCAL Jacobian column); a model with any other joint (a URDF
mimic joint, whose motion Pinocchio's Python API does not expose) gets None, and the query
reads ``data.oMi`` instead.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.solvers.collision.proximity_kernels import PRISMATIC, REVOLUTE, joint_poses

Array = npt.NDArray[np.float64]
Index = npt.NDArray[np.int64]

CHECK_TOL = 1e-9
"""[m] Largest disagreement with Pinocchio's joint placements that :func:`tree_of` accepts."""


class KinematicTree(NamedTuple):
    """The joints of a model as arrays (index 0: the world).

    Attributes:
        parent: Parent joint (nj,).
        rotation: Joint placement rotations (nj, 3, 3) in the parent joint's frame.
        translation: Joint placement translations (nj, 3) [m].
        kind: :data:`~rrc_pin.solvers.collision.proximity_kernels.REVOLUTE` or
            :data:`~rrc_pin.solvers.collision.proximity_kernels.PRISMATIC`.
        axis: Unit axes (nj, 3) in the joint's frame.
        coordinate: The coordinate of q (one per joint, the API's) that moves the joint.
    """

    parent: Index
    rotation: Array
    translation: Array
    kind: Index
    axis: Array
    coordinate: Index


def tree_of(model: pin.Model, q_check: Array) -> KinematicTree | None:
    """The tree of ``model``, or None if a joint is not one axis or the check fails.

    Args:
        model: A model of 1-DOF joints (and perhaps mimic joints).
        q_check: A configuration (nv,) [rad or m], one coordinate per joint, at which the
            kernel is compared with Pinocchio.
    """
    nj = model.njoints
    parent = np.array(model.parents, dtype=np.int64)
    rotation = np.zeros((nj, 3, 3))
    translation = np.zeros((nj, 3))
    kind = np.zeros(nj, dtype=np.int64)
    axis = np.zeros((nj, 3))
    index = np.zeros(nj, dtype=np.int64)
    rotation[0] = np.eye(3)
    data = model.createData()
    pin.computeJointJacobians(model, data, pin.neutral(model))
    for j in range(1, nj):
        joint = model.joints[j]
        if joint.nv != 1 or joint.shortname() == "JointModelMimic":
            return None
        S = pin.getJointJacobian(model, data, j, pin.ReferenceFrame.LOCAL).reshape(6, -1)
        v, w = S[:3, joint.idx_v], S[3:, joint.idx_v]
        if np.linalg.norm(v) < 1e-12 and abs(np.linalg.norm(w) - 1.0) < 1e-12:
            kind[j], axis[j] = REVOLUTE, w
        elif np.linalg.norm(w) < 1e-12 and abs(np.linalg.norm(v) - 1.0) < 1e-12:
            kind[j], axis[j] = PRISMATIC, v
        else:
            return None
        M = model.jointPlacements[j]
        rotation[j], translation[j], index[j] = M.rotation, M.translation, joint.idx_v
    tree = KinematicTree(parent, rotation, translation, kind, axis, index)
    return tree if _agrees(model, tree, q_check) else None


def _agrees(model: pin.Model, tree: KinematicTree, q: Array) -> bool:
    """Whether the kernel's placements at ``q`` match Pinocchio's within :data:`CHECK_TOL`."""
    q_pin = np.empty(model.nq)
    for j in range(1, model.njoints):
        joint = model.joints[j]
        if joint.nq == 2:  # continuous: (cos, sin)
            q_pin[joint.idx_q : joint.idx_q + 2] = np.cos(q[joint.idx_v]), np.sin(q[joint.idx_v])
        else:
            q_pin[joint.idx_q] = q[joint.idx_v]
    data = model.createData()
    pin.forwardKinematics(model, data, q_pin)
    poses = np.zeros((model.njoints, 4, 4))
    joint_poses(q, tree.parent, tree.rotation, tree.translation, tree.kind, tree.axis,
                tree.coordinate, poses)  # fmt: skip
    expected = np.array([M.homogeneous for M in data.oMi.tolist()])
    return bool(np.abs(poses - expected).max() <= CHECK_TOL)
