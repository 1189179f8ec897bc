"""Shared transcription of Nadkarni's manipulator tables (M.S. thesis, U. Houston, 1977).

A table row is ``(r_i, alpha_i, a_i, theta_i, kind)`` in the thesis's own units (lengths in
"units", taken here as inches: assumed) and degrees. The seventh row is not a joint: the hand
frame is x*(7) (origin on axis 7, z along it, x along the normal a_7), which is how the thesis's
Illustrations 4-7 give the hand by three points (origin, origin + z, origin + a_7 x). Joint zero
and sign are the thesis's theta_i (revolute) or r_i (prismatic), so the table's initial
configuration is a named pose.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from rrc_pin.dh import DHChain, DHRow, JointKind, pose, rot_z, translation
from rrc_pin.errors import InvalidInput
from rrc_pin.models.arm_spec import INCH
from rrc_pin.solvers.checks import as_array

Row = tuple[float, float, float, float, JointKind | None]


def frame_from_points(points: npt.ArrayLike) -> npt.NDArray[np.float64]:
    """Pose (4, 4) of a frame given by three points, as the thesis gives frames and hands.

    Args:
        points: (3, 3) rows: the origin, a point on the +z axis, a point in the x-z plane on
            the +x side. Any length unit; the pose keeps it.

    Raises:
        InvalidInput: Wrong shape, non-finite, or the three points are (nearly) collinear.
    """
    P = as_array(points, "points", (3, 3))
    z = P[1] - P[0]
    x = P[2] - P[0]
    if np.linalg.norm(z) < 1e-12 or np.linalg.norm(np.cross(z, x)) < 1e-12 * np.linalg.norm(z):
        raise InvalidInput("points", "the three points must be distinct and not collinear")
    z = z / np.linalg.norm(z)
    x = x - (x @ z) * z
    x = x / np.linalg.norm(x)
    T = np.eye(4)
    T[:3, :3] = np.column_stack([x, np.cross(z, x), z])
    T[:3, 3] = P[0]
    return T


def chain_and_initial_pose(
    table: tuple[Row, ...], first_frame_points: npt.ArrayLike
) -> tuple[DHChain, tuple[float, ...]]:
    """Build the DH chain of a Nadkarni table and its initial configuration (SI).

    Args:
        table: Seven rows, the last one placing the hand.
        first_frame_points: (3, 3) points giving x*(1) in the global frame in the initial
            configuration (the thesis's data set five), in thesis units.

    Returns:
        The chain (base frame = the thesis's global frame, tool = hand x*(7)) and the initial
        configuration.
    """
    rows: list[DHRow] = []
    q0: list[float] = []
    for r, alpha, a, theta, kind in table[:-1]:
        if kind == "prismatic":
            rows.append(
                DHRow(
                    a=a * INCH,
                    alpha=np.deg2rad(alpha),
                    d=0.0,
                    theta=np.deg2rad(theta),
                    kind="prismatic",
                )
            )
            q0.append(r * INCH)
        else:
            rows.append(DHRow(a=a * INCH, alpha=np.deg2rad(alpha), d=r * INCH, theta=0.0))
            q0.append(np.deg2rad(theta))
    r7, _alpha7, _a7, theta7, _ = table[-1]
    hand = rot_z(np.deg2rad(theta7)) @ translation(z=r7 * INCH)  # x*(7), eq. (2-3)
    first_star = frame_from_points(np.asarray(first_frame_points, dtype=float) * INCH)
    theta1, r1 = rows[0].joint_values(q0[0])
    base = first_star @ np.linalg.inv(rot_z(theta1) @ translation(z=r1))  # eq. (2-13)
    chain = DHChain(convention="nadkarni", rows=tuple(rows), base=pose(base), tool=pose(hand))
    return chain, tuple(q0)
