r"""The broad phase of a proximity query: which pairs may be within the detection distance.

Every body has a bounding sphere (a centre fixed in its joint's frame, a radius); a half-space
has its plane instead. A lower bound of the signed distance of a pair, also in penetration
(the penetration depth of two bodies is at most that of spheres holding them):

.. math:: d(A, B) \ge \|c_A - c_B\| - r_A - r_B, \qquad
          d(A, H) \ge n \cdot c_A - o - r_A \quad (H = \{x : n \cdot x \le o\})

A pair whose bound is below the detection distance is a candidate; only candidates go to the
narrow phase (coal), so no pair within the detection distance is ever dropped.

Compiled with numba (:func:`rrc_pin.solvers.compiled.kernel`); plain arrays in and out.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.collision.vectors import cross
from rrc_pin.solvers.compiled import kernel

Array = npt.NDArray[np.float64]
Index = npt.NDArray[np.int64]

REVOLUTE, PRISMATIC = 0, 1
"""Codes of a joint's kind in :func:`joint_poses`."""


@kernel
def joint_poses(
    q: Array,
    parent: Index,
    rotation: Array,
    translation: Array,
    kind: Index,
    axis: Array,
    index: Index,
    out: Array,
) -> None:
    r"""Placements of every joint of a tree in the world frame (forward kinematics).

    .. math:: {}^0M_j = {}^0M_{\lambda(j)}\, M^{\text{placement}}_j\, \exp(a_j \theta_j)

    with the rotation of a revolute joint by Rodrigues' formula
    :math:`R = I + \sin\theta\, K + (1 - \cos\theta) K^2` (K the cross-product matrix of
    its unit axis a) and the translation :math:`a \theta` of a prismatic one. Joints are in
    Pinocchio's order (every parent before its children); joint 0 is the world.

    Args:
        q: Joint positions (nv,) [rad or m], one coordinate per joint.
        parent: Parent joint (nj,).
        rotation: Placement rotations (nj, 3, 3) in the parent joint's frame.
        translation: Placement translations (nj, 3) [m].
        kind: :data:`REVOLUTE` or :data:`PRISMATIC` (nj,).
        axis: Unit axes (nj, 3) in each joint's frame.
        index: Coordinate of q (nj,) moving each joint.
        out: Placements (nj, 4, 4) (written; row 0 set to the identity).
    """
    out[0] = 0.0
    for r in range(4):
        out[0, r, r] = 1.0
    local = np.empty((3, 3))
    offset = np.empty(3)
    for j in range(1, parent.shape[0]):
        theta = q[index[j]]
        x, y, z = axis[j, 0], axis[j, 1], axis[j, 2]
        if kind[j] == REVOLUTE:
            s, c = math.sin(theta), math.cos(theta)
            t = 1.0 - c
            motion = (
                (c + t * x * x, t * x * y - s * z, t * x * z + s * y),
                (t * x * y + s * z, c + t * y * y, t * y * z - s * x),
                (t * x * z - s * y, t * y * z + s * x, c + t * z * z),
            )
            shift = (0.0, 0.0, 0.0)
        else:
            motion = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
            shift = (x * theta, y * theta, z * theta)
        for r in range(3):  # local = rotation_j @ motion, offset = rotation_j @ shift + t_j
            offset[r] = translation[j, r]
            for k in range(3):
                local[r, k] = 0.0
                offset[r] += rotation[j, r, k] * shift[k]
                for m in range(3):
                    local[r, k] += rotation[j, r, m] * motion[m][k]
        p = parent[j]
        for r in range(3):
            for k in range(3):
                out[j, r, k] = (
                    out[p, r, 0] * local[0, k] + out[p, r, 1] * local[1, k]
                    + out[p, r, 2] * local[2, k]
                )  # fmt: skip
            out[j, r, 3] = (
                out[p, r, 0] * offset[0] + out[p, r, 1] * offset[1] + out[p, r, 2] * offset[2]
                + out[p, r, 3]
            )  # fmt: skip
            out[j, 3, r] = 0.0
        out[j, 3, 3] = 1.0


@kernel
def joint_jacobians(poses: Array, kind: Index, axis: Array, index: Index, J: Array) -> None:
    r"""Every joint's Jacobian column in Pinocchio's WORLD convention, from its placement.

    The spatial velocity at the world origin, :math:`[v_O; \omega]`, that a unit rate of joint
    :math:`j` gives: with its axis in the world :math:`w_j = R_j a_j` and its origin
    :math:`p_j`,

    .. math:: J_{c(j)} = \begin{bmatrix} p_j \times w_j \\ w_j \end{bmatrix} \text{ (revolute)},
              \qquad J_{c(j)} = \begin{bmatrix} w_j \\ 0 \end{bmatrix} \text{ (prismatic)}

    (:math:`v_O = \omega \times (0 - p_j)`), what ``pinocchio.computeJointJacobians`` writes
    into ``data.J``.

    Args:
        poses: Placements (nj, 4, 4) of the joints in the world frame (:func:`joint_poses`).
        kind: :data:`REVOLUTE` or :data:`PRISMATIC` (nj,).
        axis: Unit axes (nj, 3) in each joint's frame.
        index: Coordinate (nj,) of q, and column of J, moving each joint.
        J: (6, nv), rows [v_O; w] (written: every column, one a joint).
    """
    for j in range(1, kind.shape[0]):
        w = (
            poses[j, 0, 0] * axis[j, 0] + poses[j, 0, 1] * axis[j, 1] + poses[j, 0, 2] * axis[j, 2],
            poses[j, 1, 0] * axis[j, 0] + poses[j, 1, 1] * axis[j, 1] + poses[j, 1, 2] * axis[j, 2],
            poses[j, 2, 0] * axis[j, 0] + poses[j, 2, 1] * axis[j, 1] + poses[j, 2, 2] * axis[j, 2],
        )
        c = index[j]
        if kind[j] == REVOLUTE:
            linear = cross((poses[j, 0, 3], poses[j, 1, 3], poses[j, 2, 3]), w)
            angular = w
        else:
            linear, angular = w, (0.0, 0.0, 0.0)
        for r in range(3):
            J[r, c] = linear[r]
            J[3 + r, c] = angular[r]


@kernel
def world_centres(poses: Array, joint: Index, centre: Array, out: Array) -> None:
    """Bounding-sphere centres in the world frame: ``out[g] = R_j centre[g] + p_j``.

    Args:
        poses: Placements (nj, 4, 4) of the joints in the world frame.
        joint: The joint (ng,) each body moves with (an index into ``poses``).
        centre: Centres (ng, 3) in the frames of their joints [m].
        out: Centres (ng, 3) in the world frame [m] (written).
    """
    for g in range(joint.shape[0]):
        j = joint[g]
        for r in range(3):
            out[g, r] = (
                poses[j, r, 0] * centre[g, 0]
                + poses[j, r, 1] * centre[g, 1]
                + poses[j, r, 2] * centre[g, 2]
                + poses[j, r, 3]
            )


@kernel
def near_pairs(
    first: Index,
    second: Index,
    world: Array,
    radius: Array,
    normal: Array,
    offset: Array,
    detection: float,
    keep: npt.NDArray[np.bool_],
    out: Index,
) -> int:
    """Indices of the pairs asked for whose distance bound is below ``detection``.

    Args:
        first: First body (npairs,) of each pair.
        second: Second body (npairs,).
        world: Bounding-sphere centres (ng, 3) in the world frame [m].
        radius: Bounding radii (ng,) [m]; ``inf`` marks a half-space.
        normal: Unit outward normals (ng, 3) of the half-spaces (world frame; unused rows for
            other bodies).
        offset: Offsets (ng,) [m] of the half-spaces: the solid is ``normal . x <= offset``.
        detection: Detection distance [m].
        keep: Whether each pair (npairs,) is asked for (the others are not candidates).
        out: Pair indices (npairs,), the first ``count`` written.

    Returns:
        count: The number of candidates.
    """
    count = 0
    for k in range(first.shape[0]):
        if not keep[k]:
            continue
        a = first[k]
        b = second[k]
        if math.isinf(radius[a]) or math.isinf(radius[b]):
            h, s = (a, b) if math.isinf(radius[a]) else (b, a)
            bound = (
                normal[h, 0] * world[s, 0]
                + normal[h, 1] * world[s, 1]
                + normal[h, 2] * world[s, 2]
                - offset[h]
                - radius[s]
            )
        else:
            dx = world[a, 0] - world[b, 0]
            dy = world[a, 1] - world[b, 1]
            dz = world[a, 2] - world[b, 2]
            bound = math.sqrt(dx * dx + dy * dy + dz * dz) - radius[a] - radius[b]
        if bound < detection:
            out[count] = k
            count += 1
    return count

