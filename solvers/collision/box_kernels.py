r"""A capsule inside a box: its separating axis and the rows of the features that realise it.

A capsule (segment :math:`a_0 a_1`, radius :math:`r`) against a box (centre :math:`t`, unit axes
:math:`R_c`, half sides :math:`h_c`) overlaps it exactly when no axis separates them. The
separation along a unit axis :math:`m` pointing from the box towards the capsule is

.. math:: F(m) = \min(m \cdot a_0,\ m \cdot a_1) - r
          - \Big(m \cdot t + \sum_c h_c |m \cdot R_c|\Big)

and, in penetration, the signed distance is its largest value over the twelve face normals of
the Minkowski difference of the segment and the box: the six box faces :math:`\pm R_c` and
the six :math:`\pm u \times R_c / \|u \times R_c\|` (:math:`u = a_1 - a_0`), less those of an
axis near parallel to the segment (Gilbert & Foo 1990; Ericson, *Real-Time Collision
Detection*, 4.4 and 5.2.1). So :math:`d = \max_m F(m) \ge F(m^*)` for the best axis
:math:`m^*`: a row holding each feature that realises :math:`F(m^*)` keeps :math:`d` from
decreasing to first order, however the best axis and the deepest feature change within the
step. coal's penetration witness alone is one point of the contact (EPA's), and where the
segment lies along a face its row follows the middle while an end sinks: a box 72 mm into
panda's hand came 0.33 mm closer in a tick.

The features, each a row with coal's conventions (``p_b - p_a = d n``, ``n`` from the capsule
to the box, :math:`n = -m^*`):

- a box face (:math:`m^* = \pm R_c`): each end :math:`e` of the segment against the face's
  plane, :math:`d_e = m^* \cdot e - r - (m^* \cdot t + h_c)`, :math:`p_a = e - r\,m^*`,
  :math:`p_b = p_a - d_e m^*` on the plane (the plane turns with the box and :math:`p_b - p_a`
  lies along :math:`m^*`, so the row's rate is the rate of :math:`d_e`); the deeper end is
  :math:`F(m^*)`, the other may become it within the step;
- a segment-edge axis: the common perpendicular of the segment's line and the box's edge along
  :math:`R_c` that supports the box along :math:`m^*` (the corner offset
  :math:`\sum_{k \ne c} h_k \operatorname{sign}(m^* \cdot R_k) R_k`), one row.

Outside the box (the largest separation positive) no row is given here: the pair's closest
points (coal's) and the end points' rows (:mod:`rrc_pin.solvers.collision.narrow_kernels`) are
the features there.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.collision.vectors import Vector, along, cross, dot, norm, sub
from rrc_pin.solvers.compiled import kernel

Array = npt.NDArray[np.float64]
Records = npt.NDArray[np.void]
Axes = tuple[Vector, Vector, Vector]
"""A rotation by its columns (each a box axis in the world)."""
Row = tuple[float, Vector, Vector, Vector]
"""A row's signed distance [m], witness points on A and B and unit normal from A to B."""

TIE = 0.01
"""[m] A face this close to a deepest segment-edge axis gets its rows too: the two are one
plane where the segment lies along the face, and the box's corner supporting the edge axis then
switches within a step."""

PARALLEL = 1e-6
r"""An axis :math:`u \times R_c` shorter than this times :math:`\|u\|` is left out: the segment
lies along the box's edge, and the box's faces separate there."""


@kernel
def turned(R: Axes, x: Vector) -> Vector:
    r""":math:`R\,x` for ``R`` given by its columns."""
    return (R[0][0] * x[0] + R[1][0] * x[1] + R[2][0] * x[2],
            R[0][1] * x[0] + R[1][1] * x[1] + R[2][1] * x[2],
            R[0][2] * x[0] + R[1][2] * x[1] + R[2][2] * x[2])  # fmt: skip


@kernel
def box_pose(poses: Array, bodies: Records, b: int) -> tuple[Axes, Vector]:
    """Box ``b``'s rotation, by its columns (each a box axis in the world), and centre [m]."""
    box = bodies["box"]
    j = bodies["joint"][b]
    M = ((poses[j, 0, 0], poses[j, 1, 0], poses[j, 2, 0]),
         (poses[j, 0, 1], poses[j, 1, 1], poses[j, 2, 1]),
         (poses[j, 0, 2], poses[j, 1, 2], poses[j, 2, 2]))  # fmt: skip
    R = (turned(M, (box[b, 0, 0], box[b, 1, 0], box[b, 2, 0])),
         turned(M, (box[b, 0, 1], box[b, 1, 1], box[b, 2, 1])),
         turned(M, (box[b, 0, 2], box[b, 1, 2], box[b, 2, 2])))  # fmt: skip
    x, y, z = box[b, 0, 3], box[b, 1, 3], box[b, 2, 3]
    centre = (poses[j, 0, 3] + poses[j, 0, 0] * x + poses[j, 0, 1] * y + poses[j, 0, 2] * z,
              poses[j, 1, 3] + poses[j, 1, 0] * x + poses[j, 1, 1] * y + poses[j, 1, 2] * z,
              poses[j, 2, 3] + poses[j, 2, 0] * x + poses[j, 2, 1] * y + poses[j, 2, 2] * z)
    return R, centre


@kernel
def separation(m: Vector, a0: Vector, a1: Vector, r: float, R: Axes, t: Vector,
               half: Vector) -> float:  # fmt: skip
    """:math:`F(m)` [m] (module docstring): the capsule beyond the box along unit ``m``."""
    reach = half[0] * abs(dot(m, R[0])) + half[1] * abs(dot(m, R[1])) + half[2] * abs(dot(m, R[2]))
    return min(dot(m, a0), dot(m, a1)) - r - dot(m, t) - reach


@kernel
def deepest_axis(a0: Vector, a1: Vector, r: float, R: Axes, t: Vector, half: Vector,
                 faces: bool = False) -> tuple[float, Vector, int]:  # fmt: skip
    r"""The largest separation [m] over the twelve axes (module docstring), or over the box's
    faces alone where ``faces``; its unit axis from the box towards the capsule, and the box
    axis ``c`` it is made of (``c`` for the face :math:`\pm R_c`, ``3 + c`` for
    :math:`\pm u \times R_c`)."""  # noqa: D205, D209
    u = sub(a1, a0)
    length = norm(u)
    best, axis, kind = -math.inf, R[0], 0
    for c in range(3 if faces else 6):
        if c < 3:
            m = R[c]
        else:
            w = cross(u, R[c - 3])
            size = norm(w)
            if size <= PARALLEL * length or size == 0.0:
                continue
            m = (w[0] / size, w[1] / size, w[2] / size)
        for sign in (1.0, -1.0):
            signed = (sign * m[0], sign * m[1], sign * m[2])
            F = separation(signed, a0, a1, r, R, t, half)
            if F > best:
                best, axis, kind = F, signed, c
    return best, axis, kind


@kernel
def inside_rows(a0: Vector, a1: Vector, r: float, R: Axes, t: Vector,
                half: Vector) -> tuple[int, Row, Row, Row]:  # fmt: skip
    """The rows of the features realising the deepest axis of a capsule inside a box.

    Where that axis is a segment-edge one, also the rows of the deepest face's when it is
    within :data:`TIE` of it (module docstring).

    Args:
        a0: The segment's first end [m], world frame.
        a1: Its other end [m] (``a0`` again for a sphere).
        r: The capsule's radius [m].
        R: The box's axes by columns (world frame).
        t: The box's centre [m].
        half: Its half sides [m].

    Returns:
        count: 0 where the segment is outside the box (the largest separation not below
        ``-r``), else 1 to 3; and that many rows (distance [m], point on the capsule, point on
        the box, unit normal from the capsule to the box), copies of the first after them.
    """
    F, m, kind = deepest_axis(a0, a1, r, R, t, half)
    if F >= -r:  # the segment outside the box: not the inside's distance (module docstring)
        empty = (F, a0, a0, (-m[0], -m[1], -m[2]))
        return 0, empty, empty, empty
    count = 0
    if kind >= 3:  # the common perpendicular of the segment and the supporting edge
        c = kind - 3
        corner = t
        for k in range(3):
            if k != c:
                corner = along(corner, math.copysign(half[k], dot(m, R[k])), R[k])
        s = _line_closest(a0, sub(a1, a0), corner, R[c])
        point_a = along(along(a0, s, sub(a1, a0)), -r, m)
        edge = (F, point_a, along(point_a, -F, m), (-m[0], -m[1], -m[2]))
        count = 1
        F, m, kind = deepest_axis(a0, a1, r, R, t, half, True)
        if edge[0] - F > TIE:
            return count, edge, edge, edge
    plane = dot(m, t) + half[kind]
    first, second = _face_row(a0, r, m, plane), _face_row(a1, r, m, plane)
    faces = 1 if a0 == a1 else 2
    if count == 0:
        return faces, first, second, first
    return 1 + faces, edge, first, second


@kernel
def _face_row(e: Vector, r: float, m: Vector, plane: float) -> Row:
    """The row of the segment's end ``e`` against the box's face ``m . x = plane``."""
    d = dot(m, e) - r - plane
    point_a = along(e, -r, m)
    return d, point_a, along(point_a, -d, m), (-m[0], -m[1], -m[2])


@kernel
def _line_closest(a0: Vector, u: Vector, b0: Vector, v: Vector) -> float:
    """The parameter s of the point ``a0 + s u`` of the line nearest the line ``b0 + t v``
    (not parallel)."""  # noqa: D205, D209
    w = sub(a0, b0)
    a, b, e = dot(u, u), dot(u, v), dot(v, v)
    c, f = dot(u, w), dot(v, w)
    return (b * f - c * e) / (a * e - b * b)
