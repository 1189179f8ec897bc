r"""The narrow phase of a proximity query for spheres, capsules and half-spaces, compiled.

A sphere is a capsule whose segment has zero length, so every pair of the two is the distance
between two segments less both radii. The segments' closest points :math:`c_a = a_0 + s\,u`,
:math:`c_b = b_0 + t\,v` (:math:`s, t \in [0, 1]`) are those of Lumelsky 1985 in the form of
Ericson, *Real-Time Collision Detection*, 5.1.9 (clamp ``s`` of the two lines' closest points,
solve ``t`` for it, clamp ``t`` and solve ``s`` again). Then, with coal's conventions
(:mod:`rrc_pin.geometry.proximity`):

.. math:: n = \frac{c_b - c_a}{\|c_b - c_a\|}, \quad d = \|c_b - c_a\| - r_a - r_b, \quad
          p_a = c_a + r_a n, \quad p_b = c_b - r_b n \quad (p_b - p_a = d\,n)

Where the segments meet (:math:`c_a = c_b`, deep penetration) the normal is the unit
:math:`u \times v`, else the direction between the segments' mid-points, else :math:`+z`,
each turned to point from A's mid-point towards B's, so a pair in penetration is always pushed
apart along one direction (coal returns a zero normal there).

A capsule against a half-space :math:`\{x : m \cdot x \le o\}` (always body B):
:math:`d = \min_{e \in \{a_0, a_1\}} (m \cdot e - o) - r_a`, :math:`n = -m`, :math:`p_b` the end
point projected onto the plane.

**End-point rows** (``ends``): for two near-parallel capsules the closest points jump from one
end to the other as the segments turn through parallel, and one row on the current closest
points does not see the other end approaching. With ``ends``, each end point of each segment
also gets a row against the other body (the distance from the end point to the other segment,
or to the plane), when within the detection distance and not the pair's closest points
already: at most four more rows a capsule pair, one more a capsule against a plane. The
distance of the pair is the minimum over the segments' points; every point whose distance may
become the minimum over one step is then constrained (the ends, and the current minimum).

A capsule against a box (body B) goes to coal for its closest points; its end-point rows are
each end against the box: in the box's frame the end point clamped to the box is the nearest
box point outside it; inside, the nearest face (the signed distance to a convex set).

Pairs of other shapes (cylinders, convex hulls, meshes) are returned for coal.
Compiled with numba through :func:`rrc_pin.solvers.tick.kernels.kernel`; plain arrays in and out.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.compiled import kernel

Array = npt.NDArray[np.float64]
Index = npt.NDArray[np.int64]

OTHER, SPHERE, CAPSULE, HALFSPACE, BOX = 0, 1, 2, 3, 4
"""Codes of a body's shape (:func:`narrow_phase`'s ``shape``); OTHER and BOX go to coal (a
capsule against a box gets its end-point rows here)."""

SAME = 1e-9
"""[m] An end-point row whose two points are both within this of the pair's closest points is
that row again, and is left out."""

MET = 1e-12
"""[m] Closest points nearer than this: the segments meet (the normal from their directions)."""


@kernel
def segment_closest(
    a0: Array, u: Array, b0: Array, v: Array, out: Array
) -> None:  # fmt: skip
    """Closest points of the segments ``a0 + s u`` and ``b0 + t v``, s, t in [0, 1] (5.1.9).

    Args:
        a0: Start (3,) of segment A [m].
        u: Its direction (3,) [m], end minus start.
        b0: Start (3,) of segment B [m].
        v: Its direction (3,) [m].
        out: (2, 3) written: the point on A, the point on B [m].
    """
    rx, ry, rz = a0[0] - b0[0], a0[1] - b0[1], a0[2] - b0[2]
    a = u[0] * u[0] + u[1] * u[1] + u[2] * u[2]
    e = v[0] * v[0] + v[1] * v[1] + v[2] * v[2]
    f = v[0] * rx + v[1] * ry + v[2] * rz
    if a <= 0.0 and e <= 0.0:
        s, t = 0.0, 0.0
    elif a <= 0.0:
        s, t = 0.0, min(max(f / e, 0.0), 1.0)
    else:
        c = u[0] * rx + u[1] * ry + u[2] * rz
        if e <= 0.0:
            s, t = min(max(-c / a, 0.0), 1.0), 0.0
        else:
            b = u[0] * v[0] + u[1] * v[1] + u[2] * v[2]
            denom = a * e - b * b
            s = min(max((b * f - c * e) / denom, 0.0), 1.0) if denom > 0.0 else 0.0
            t = (b * s + f) / e
            if t < 0.0:
                t, s = 0.0, min(max(-c / a, 0.0), 1.0)
            elif t > 1.0:
                t, s = 1.0, min(max((b - c) / a, 0.0), 1.0)
    for r in range(3):
        out[0, r] = a0[r] + s * u[r]
        out[1, r] = b0[r] + t * v[r]


@kernel
def narrow_phase(
    poses: Array,
    joint: Index,
    shape: Index,
    segment: Array,
    radius: Array,
    box_frame: Array,
    half: Array,
    plane: Array,
    offset: Array,
    first: Index,
    second: Index,
    candidates: Index,
    count: int,
    keep: npt.NDArray[np.bool_],
    detection: float,
    ends: bool,
    pair: Index,
    distance: Array,
    point_a: Array,
    point_b: Array,
    normal: Array,
    end: npt.NDArray[np.int8],
    other: Index,
) -> tuple[int, int]:
    """The rows of the candidate pairs below ``detection`` (module docstring), in one pass.

    Args:
        poses: Joint placements (nj, 4, 4) in the world frame.
        joint: The joint (ng,) each body moves with.
        shape: :data:`SPHERE`, :data:`CAPSULE`, :data:`HALFSPACE` or :data:`OTHER` (ng,).
        segment: Each sphere's or capsule's segment end points (ng, 2, 3) in its joint's
            frame [m] (a sphere: its centre twice).
        radius: Sphere and capsule radii (ng,) [m].
        box_frame: Each box's placement (ng, 3, 4) ``[R | t]`` in its joint's frame.
        half: Each box's half sides (ng, 3) [m].
        plane: Unit outward normals (ng, 3) of the half-spaces, world frame.
        offset: Offsets (ng,) [m] of the half-spaces (the solid ``plane . x <= offset``).
        first: First body (npairs,) of each pair.
        second: Second body (npairs,).
        candidates: Pair indices from the broad phase.
        count: How many of ``candidates`` to read.
        keep: Whether each pair (npairs,) is asked for (the others are skipped).
        detection: Detection distance [m].
        ends: Add the end-point rows.
        pair: Out (>= 5 count,): the pair index of each row.
        distance: Out (>= 5 count,): signed distances [m].
        point_a: Out (>= 5 count, 3): witness points on A, world frame [m].
        point_b: Out (>= 5 count, 3): witness points on B [m].
        normal: Out (>= 5 count, 3): unit normals from A to B.
        end: Out (>= 5 count,): 1 for an end point's row, 0 for a pair's closest points'.
        other: Out (>= count,): the candidates of other shapes, for coal.

    Returns:
        rows: The number of rows written; ``others``: the number of pairs left for coal.
    """
    rows = 0
    others = 0
    seg = np.empty((2, 2, 3))  # the two bodies' segments in the world
    close = np.empty((2, 3))
    main = np.empty((2, 3))
    swap = np.empty((2, 3))
    still = np.zeros(3)
    direction = np.empty((2, 3))
    for i in range(count):
        k = candidates[i]
        if not keep[k]:
            continue
        ab = (first[k], second[k])
        sa, sb = shape[ab[0]], shape[ab[1]]
        if sa == OTHER or sb == OTHER or sa == HALFSPACE or sa == BOX:
            other[others] = k
            others += 1
            continue
        if sb == BOX:
            other[others] = k
            others += 1
            if ends and sa == CAPSULE:
                rows = _box_ends(poses, joint, segment, radius, box_frame, half, ab[0], ab[1],
                                 k, detection, pair, distance, point_a, point_b, normal, end,
                                 rows)  # fmt: skip
            continue
        for side in range(2):
            g = ab[side]
            M = poses[joint[g]]
            for e in range(2):
                for r in range(3):
                    seg[side, e, r] = (
                        M[r, 0] * segment[g, e, 0] + M[r, 1] * segment[g, e, 1]
                        + M[r, 2] * segment[g, e, 2] + M[r, 3]
                    )  # fmt: skip
            for r in range(3):
                direction[side, r] = seg[side, 1, r] - seg[side, 0, r]
        ra = radius[ab[0]]
        if shape[ab[1]] == HALFSPACE:
            h = ab[1]
            height0 = (
                plane[h, 0] * seg[0, 0, 0] + plane[h, 1] * seg[0, 0, 1] + plane[h, 2] * seg[0, 0, 2]
            )
            height1 = (
                plane[h, 0] * seg[0, 1, 0] + plane[h, 1] * seg[0, 1, 1] + plane[h, 2] * seg[0, 1, 2]
            )
            lowest = 0 if height0 <= height1 else 1
            for e in (lowest, 1 - lowest):  # the pair's own row (its lowest end) first
                if e != lowest and not ends:
                    continue
                height = (height0 if e == 0 else height1) - offset[h]
                if height - ra >= detection:
                    continue
                if (
                    e != lowest
                    and direction[0, 0] ** 2 + direction[0, 1] ** 2 + direction[0, 2] ** 2 <= 0.0
                ):
                    continue
                pair[rows] = k
                end[rows] = 0 if e == lowest else 1
                distance[rows] = height - ra
                for r in range(3):
                    normal[rows, r] = -plane[h, r]
                    point_a[rows, r] = seg[0, e, r] - ra * plane[h, r]
                    point_b[rows, r] = seg[0, e, r] - height * plane[h, r]
                rows += 1
            continue
        rb = radius[ab[1]]
        segment_closest(seg[0, 0], direction[0], seg[1, 0], direction[1], close)
        if not _row(close, ra, rb, seg, direction, detection, distance, point_a, point_b,
                    normal, rows):  # fmt: skip
            continue  # the ends are no nearer than the closest points
        pair[rows] = k
        end[rows] = 0
        rows += 1
        if not ends:
            continue
        main[:] = close
        for side in range(2):
            if direction[side, 0] ** 2 + direction[side, 1] ** 2 + direction[side, 2] ** 2 <= 0.0:
                continue  # a sphere has no ends of its own
            o = 1 - side
            for e in range(2):  # the end point against the other body's segment
                segment_closest(seg[side, e], still, seg[o, 0], direction[o], swap)
                for r in range(3):
                    close[side, r] = swap[0, r]
                    close[o, r] = swap[1, r]
                gap = 0.0
                for r in range(3):
                    gap = max(gap, abs(close[0, r] - main[0, r]), abs(close[1, r] - main[1, r]))
                if gap <= SAME:
                    continue
                if _row(close, ra, rb, seg, direction, detection, distance, point_a, point_b,
                        normal, rows):  # fmt: skip
                    pair[rows] = k
                    end[rows] = 1
                    rows += 1
    return rows, others


@kernel
def _box_ends(
    poses: Array,
    joint: Index,
    segment: Array,
    radius: Array,
    box_frame: Array,
    half: Array,
    a: int,
    b: int,
    k: int,
    detection: float,
    pair: Index,
    distance: Array,
    point_a: Array,
    point_b: Array,
    normal: Array,
    end: npt.NDArray[np.int8],
    rows: int,
) -> int:
    """Append the end-point rows of capsule ``a`` against box ``b`` (module docstring).

    Returns:
        The number of rows now written.
    """
    Ma = poses[joint[a]]
    Mj = poses[joint[b]]
    R = np.empty((3, 3))  # the box's rotation and centre in the world
    t = np.empty(3)
    for r in range(3):
        t[r] = Mj[r, 3]
        for c in range(3):
            R[r, c] = Mj[r, 0] * box_frame[b, 0, c] + Mj[r, 1] * box_frame[b, 1, c] + (
                Mj[r, 2] * box_frame[b, 2, c])  # fmt: skip
            t[r] += Mj[r, c] * box_frame[b, c, 3]
    p = np.empty(3)
    local = np.empty(3)
    near = np.empty(3)
    ra = radius[a]
    for e in range(2):
        if e == 1 and segment[a, 0, 0] == segment[a, 1, 0] and segment[a, 0, 1] == segment[
                a, 1, 1] and segment[a, 0, 2] == segment[a, 1, 2]:  # fmt: skip
            break  # a sphere: one point
        for r in range(3):
            p[r] = (Ma[r, 0] * segment[a, e, 0] + Ma[r, 1] * segment[a, e, 1]
                    + Ma[r, 2] * segment[a, e, 2] + Ma[r, 3])  # fmt: skip
        for c in range(3):  # R^T (p - t)
            local[c] = R[0, c] * (p[0] - t[0]) + R[1, c] * (p[1] - t[1]) + R[2, c] * (p[2] - t[2])
            near[c] = min(max(local[c], -half[b, c]), half[b, c])
        gap = math.sqrt((local[0] - near[0]) ** 2 + (local[1] - near[1]) ** 2
                        + (local[2] - near[2]) ** 2)  # fmt: skip
        n0, n1, n2 = 0.0, 0.0, 0.0  # from the end point towards the box, box frame
        if gap > MET:
            sd = gap
            n0, n1, n2 = (near[0] - local[0]) / gap, (near[1] - local[1]) / gap, (
                near[2] - local[2]) / gap  # fmt: skip
        else:  # inside (or on the surface): the nearest face
            axis, depth = 0, half[b, 0] - abs(local[0])
            for c in range(1, 3):
                if half[b, c] - abs(local[c]) < depth:
                    axis, depth = c, half[b, c] - abs(local[c])
            sd = -depth
            face = 1.0 if local[axis] >= 0.0 else -1.0
            near[axis] = face * half[b, axis]
            if axis == 0:
                n0 = -face
            elif axis == 1:
                n1 = -face
            else:
                n2 = -face
        d = sd - ra
        if d >= detection:
            continue
        pair[rows] = k
        end[rows] = 1
        distance[rows] = d
        for r in range(3):
            n = R[r, 0] * n0 + R[r, 1] * n1 + R[r, 2] * n2
            normal[rows, r] = n
            point_a[rows, r] = p[r] + ra * n
            point_b[rows, r] = t[r] + R[r, 0] * near[0] + R[r, 1] * near[1] + R[r, 2] * near[2]
        rows += 1
    return rows


@kernel
def _row(
    close: Array,
    ra: float,
    rb: float,
    seg: Array,
    direction: Array,
    detection: float,
    distance: Array,
    point_a: Array,
    point_b: Array,
    normal: Array,
    row: int,
) -> bool:
    """Write row ``row`` from the segment points ``close`` (2, 3) if below ``detection``."""
    nx = close[1, 0] - close[0, 0]
    ny = close[1, 1] - close[0, 1]
    nz = close[1, 2] - close[0, 2]
    length = math.sqrt(nx * nx + ny * ny + nz * nz)
    d = length - ra - rb
    if d >= detection:
        return False
    if length > MET:
        nx, ny, nz = nx / length, ny / length, nz / length
    else:  # the segments meet (module docstring)
        mx = 0.5 * (seg[1, 0, 0] + seg[1, 1, 0] - seg[0, 0, 0] - seg[0, 1, 0])
        my = 0.5 * (seg[1, 0, 1] + seg[1, 1, 1] - seg[0, 0, 1] - seg[0, 1, 1])
        mz = 0.5 * (seg[1, 0, 2] + seg[1, 1, 2] - seg[0, 0, 2] - seg[0, 1, 2])
        u, v = direction[0], direction[1]
        nx = u[1] * v[2] - u[2] * v[1]
        ny = u[2] * v[0] - u[0] * v[2]
        nz = u[0] * v[1] - u[1] * v[0]
        size = math.sqrt(nx * nx + ny * ny + nz * nz)
        scale = math.sqrt(u[0] ** 2 + u[1] ** 2 + u[2] ** 2) * math.sqrt(
            v[0] ** 2 + v[1] ** 2 + v[2] ** 2
        )
        if size <= 1e-9 * scale or size == 0.0:
            nx, ny, nz = mx, my, mz
            size = math.sqrt(nx * nx + ny * ny + nz * nz)
        if size <= MET:
            nx, ny, nz, size = 0.0, 0.0, 1.0, 1.0
        sign = 1.0 if nx * mx + ny * my + nz * mz >= 0.0 else -1.0
        nx, ny, nz = sign * nx / size, sign * ny / size, sign * nz / size
    distance[row] = d
    normal[row, 0], normal[row, 1], normal[row, 2] = nx, ny, nz
    point_a[row, 0] = close[0, 0] + ra * nx
    point_a[row, 1] = close[0, 1] + ra * ny
    point_a[row, 2] = close[0, 2] + ra * nz
    point_b[row, 0] = close[1, 0] - rb * nx
    point_b[row, 1] = close[1, 1] - rb * ny
    point_b[row, 2] = close[1, 2] - rb * nz
    return True
