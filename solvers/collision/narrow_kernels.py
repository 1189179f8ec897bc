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
box point outside it; inside, the nearest face (the signed distance to a convex set). coal's
witness is one point of the contact, and where the contact is a line or a patch (the segment
along a face or an edge) its row follows that point while another comes closer, at first
order. So the features that may take over within the step get rows too: with the segment
inside the box, those of its deepest separating axis
(:func:`~rrc_pin.solvers.collision.box_kernels.inside_rows`); outside, the three box edges
nearest the segment, those meeting at its nearest corner counted once (the distance of a
segment to a box is the least of its ends' and of the box's edges' to it).

Pairs of other shapes (cylinders, convex hulls, meshes) are returned for coal, only where they
may be within the detection distance: besides the broad phase's bounding spheres, a sphere or
capsule is measured exactly against the other body's bounding sphere (the distance from its
segment to that sphere's centre, less both radii), a lower bound of the pair's signed distance
(the other body lies inside its sphere).

Bodies are :data:`~rrc_pin.solvers.collision.records.BODY` records, rows
:data:`~rrc_pin.solvers.collision.records.FOUND` records.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.collision.box_kernels import box_pose, inside_rows, turned
from rrc_pin.solvers.collision.vectors import Vector, along, dot, norm, placed, sub
from rrc_pin.solvers.compiled import kernel

Array = npt.NDArray[np.float64]
Index = npt.NDArray[np.int64]
Records = npt.NDArray[np.void]
Row = tuple[float, Vector, Vector, Vector]
"""A row's signed distance [m], witness points on A and B and unit normal from A to B."""

OTHER, SPHERE, CAPSULE, HALFSPACE, BOX = 0, 1, 2, 3, 4
"""Codes of a body's shape (:data:`~rrc_pin.solvers.collision.records.BODY`'s ``shape``); OTHER
and BOX go to coal (a capsule against a box gets its end-point rows here)."""

FEATURE = 2
"""``end`` of a box feature's row (:data:`~rrc_pin.solvers.collision.records.FOUND`)."""

SAME = 1e-9
"""[m] An end-point row whose two points are both within this of the pair's closest points is
that row again, and is left out."""

MET = 1e-12
"""[m] Closest points nearer than this: the segments meet (the normal from their directions)."""

ZERO: Vector = (0.0, 0.0, 0.0)


@kernel
def segment_closest(a0: Vector, u: Vector, b0: Vector, v: Vector) -> tuple[float, float]:
    """Parameters (s, t) of the closest points of ``a0 + s u`` and ``b0 + t v``, s, t in [0, 1].

    Ericson 5.1.9. ``u`` or ``v`` zero: a point against a segment (or a point).
    """
    r = sub(a0, b0)
    a = dot(u, u)
    e = dot(v, v)
    f = dot(v, r)
    if a <= 0.0 and e <= 0.0:
        return 0.0, 0.0
    if a <= 0.0:
        return 0.0, min(max(f / e, 0.0), 1.0)
    c = dot(u, r)
    if e <= 0.0:
        return min(max(-c / a, 0.0), 1.0), 0.0
    b = dot(u, v)
    denom = a * e - b * b
    s = min(max((b * f - c * e) / denom, 0.0), 1.0) if denom > 0.0 else 0.0
    t = (b * s + f) / e
    if t < 0.0:
        return min(max(-c / a, 0.0), 1.0), 0.0
    if t > 1.0:
        return min(max((b - c) / a, 0.0), 1.0), 1.0
    return s, t


@kernel
def narrow_phase(
    poses: Array,
    bodies: Records,
    world: Array,
    first: Index,
    second: Index,
    candidates: Index,
    count: int,
    keep: npt.NDArray[np.bool_],
    detection: float,
    ends: bool,
    found: Records,
    other: Index,
) -> tuple[int, int]:
    """The rows of the candidate pairs below ``detection`` (module docstring), in one pass.

    Args:
        poses: Joint placements (nj, 4, 4) in the world frame.
        bodies: The bodies (ng,), :data:`~rrc_pin.solvers.collision.records.BODY` records.
        world: Bounding-sphere centres (ng, 3) in the world frame [m].
        first: First body (npairs,) of each pair.
        second: Second body (npairs,).
        candidates: Pair indices from the broad phase.
        count: How many of ``candidates`` to read.
        keep: Whether each pair (npairs,) is asked for (the others are skipped).
        detection: Detection distance [m].
        ends: Add the end-point rows.
        found: Out (>= 5 count,) rows (``pair``, ``end``, ``distance``, ``point_a``,
            ``point_b``, ``normal`` written).
        other: Out (>= count,): the candidates of other shapes, for coal.

    Returns:
        rows: The number of rows written; ``others``: the number of pairs left for coal.
    """
    shape = bodies["shape"]
    rows = 0
    others = 0
    for i in range(count):
        k = candidates[i]
        if not keep[k]:
            continue
        a, b = first[k], second[k]
        sa, sb = shape[a], shape[b]
        if sa == OTHER or sb == OTHER or sa == HALFSPACE or sa == BOX or sb == BOX:
            if _apart(poses, bodies, world, a, b) >= detection:
                continue
            other[others] = k
            others += 1
            if ends and sa == CAPSULE and sb == BOX:
                rows = _box_ends(poses, bodies, a, b, k, detection, found, rows)
        elif sb == HALFSPACE:
            rows = _plane_rows(poses, bodies, a, b, k, detection, ends, found, rows)
        else:
            rows = _segment_rows(poses, bodies, a, b, k, detection, ends, found, rows)
    return rows, others


@kernel
def _segment(poses: Array, bodies: Records, g: int) -> tuple[Vector, Vector]:
    """The end points of body ``g``'s segment in the world frame [m]."""
    segment = bodies["segment"]
    j = bodies["joint"][g]
    start = placed(poses, j, (segment[g, 0, 0], segment[g, 0, 1], segment[g, 0, 2]))
    end = placed(poses, j, (segment[g, 1, 0], segment[g, 1, 1], segment[g, 1, 2]))
    return start, end


@kernel
def _apart(poses: Array, bodies: Records, world: Array, a: int, b: int) -> float:
    """A lower bound [m] of the signed distance of a pair coal measures (module docstring).

    A sphere or capsule against the other body's bounding sphere, else ``-inf`` (no bound
    beyond the broad phase's).
    """
    shape = bodies["shape"]
    for g, o in ((a, b), (b, a)):
        if shape[g] == SPHERE or shape[g] == CAPSULE:
            start, end = _segment(poses, bodies, g)
            centre = (world[o, 0], world[o, 1], world[o, 2])
            s, _ = segment_closest(start, sub(end, start), centre, ZERO)
            gap = norm(sub(centre, along(start, s, sub(end, start))))
            bound: float = gap - bodies["radius"][g] - bodies["bounding"][o]
            return bound
    return -math.inf


@kernel
def _write(found: Records, row: int, k: int, end: int, measured: Row) -> int:
    """Write ``measured`` as row ``row`` of pair ``k`` (``end``: 1, :data:`FEATURE`)."""
    d, pa, pb, n = measured
    record = found[row]
    record["pair"] = k
    record["end"] = end
    record["distance"] = d
    point_a, point_b, normal = record["point_a"], record["point_b"], record["normal"]
    for r in range(3):
        point_a[r] = pa[r]
        point_b[r] = pb[r]
        normal[r] = n[r]
    return row + 1


@kernel
def _plane_rows(
    poses: Array, bodies: Records, a: int, h: int, k: int, detection: float, ends: bool,
    found: Records, rows: int,
) -> int:  # fmt: skip
    """Append the rows of sphere or capsule ``a`` against half-space ``h`` (pair ``k``).

    The pair's own row (its lower end) first, then, with ``ends``, the other end's.
    """
    start, end = _segment(poses, bodies, a)
    m = (bodies["normal"][h, 0], bodies["normal"][h, 1], bodies["normal"][h, 2])
    ra = bodies["radius"][a]
    heights = (dot(m, start), dot(m, end))
    lowest = 0 if heights[0] <= heights[1] else 1
    u = sub(end, start)
    for e in (lowest, 1 - lowest):
        if e != lowest and (not ends or dot(u, u) <= 0.0):
            continue
        height = heights[e] - bodies["offset"][h]
        if height - ra >= detection:
            continue
        p = start if e == 0 else end
        inward = (-m[0], -m[1], -m[2])
        row = (height - ra, along(p, -ra, m), along(p, -height, m), inward)
        rows = _write(found, rows, k, 0 if e == lowest else 1, row)
    return rows


@kernel
def _segment_rows(
    poses: Array, bodies: Records, a: int, b: int, k: int, detection: float, ends: bool,
    found: Records, rows: int,
) -> int:  # fmt: skip
    """Append the rows of two spheres or capsules ``a``, ``b`` (pair ``k``).

    The closest points' row first; with ``ends``, then each end point's against the other
    segment (module docstring), unless it is the closest points' row again.
    """
    a0, a1 = _segment(poses, bodies, a)
    b0, b1 = _segment(poses, bodies, b)
    u, v = sub(a1, a0), sub(b1, b0)
    ra, rb = bodies["radius"][a], bodies["radius"][b]
    s, t = segment_closest(a0, u, b0, v)
    ca, cb = along(a0, s, u), along(b0, t, v)
    row = _between(ca, cb, ra, rb, a0, a1, b0, b1)
    if row[0] >= detection:
        return rows  # the ends are no nearer than the closest points
    rows = _write(found, rows, k, 0, row)
    if not ends:
        return rows
    for side in range(2):
        p0, p1, w = (a0, a1, u) if side == 0 else (b0, b1, v)
        q0, z = (b0, v) if side == 0 else (a0, u)
        if dot(w, w) <= 0.0:
            continue  # a sphere has no ends of its own
        for e in range(2):  # the end point against the other body's segment
            p = p0 if e == 0 else p1
            _, t_end = segment_closest(p, ZERO, q0, z)
            c = along(q0, t_end, z)
            xa, xb = (p, c) if side == 0 else (c, p)
            gap = max(abs(xa[0] - ca[0]), abs(xa[1] - ca[1]), abs(xa[2] - ca[2]),
                      abs(xb[0] - cb[0]), abs(xb[1] - cb[1]), abs(xb[2] - cb[2]))  # fmt: skip
            if gap <= SAME:
                continue
            row = _between(xa, xb, ra, rb, a0, a1, b0, b1)
            if row[0] < detection:
                rows = _write(found, rows, k, 1, row)
    return rows


@kernel
def _between(
    ca: Vector, cb: Vector, ra: float, rb: float, a0: Vector, a1: Vector, b0: Vector, b1: Vector
) -> Row:  # fmt: skip
    """The row of the points ``ca`` on segment A, ``cb`` on B, inflated by ``ra``, ``rb``.

    The segments ``a0``-``a1`` and ``b0``-``b1`` give the normal where the points meet (module
    docstring).
    """
    gap = sub(cb, ca)
    length = norm(gap)
    d = length - ra - rb
    if length > MET:
        n = (gap[0] / length, gap[1] / length, gap[2] / length)
    else:
        n = _meeting_normal(a0, a1, b0, b1)
    return d, along(ca, ra, n), along(cb, -rb, n), n


@kernel
def _meeting_normal(a0: Vector, a1: Vector, b0: Vector, b1: Vector) -> Vector:
    r"""The unit normal of two segments that meet (:math:`u \times v`, module docstring).

    Else the direction between their mid-points, else +z; from A's mid-point towards B's.
    """
    mid = (0.5 * (b0[0] + b1[0] - a0[0] - a1[0]), 0.5 * (b0[1] + b1[1] - a0[1] - a1[1]),
           0.5 * (b0[2] + b1[2] - a0[2] - a1[2]))  # fmt: skip
    u, v = sub(a1, a0), sub(b1, b0)
    n = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
    size = norm(n)
    if size <= 1e-9 * (norm(u) * norm(v)) or size == 0.0:
        n = mid
        size = norm(n)
    if size <= MET:
        n, size = (0.0, 0.0, 1.0), 1.0
    sign = 1.0 if dot(n, mid) >= 0.0 else -1.0
    return (sign * n[0] / size, sign * n[1] / size, sign * n[2] / size)


@kernel
def _box_ends(
    poses: Array, bodies: Records, a: int, b: int, k: int, detection: float, found: Records,
    rows: int,
) -> int:  # fmt: skip
    """Append the end-point rows of capsule ``a`` against box ``b``, then its features'.

    The features (module docstring): with the segment inside the box, those of its deepest axis
    (:func:`~rrc_pin.solvers.collision.box_kernels.inside_rows`), else the nearest edges
    (:func:`_box_edges`); those that no end-point row repeats.

    Returns:
        The number of rows now written.
    """
    R, t = box_pose(poses, bodies, b)
    half = (bodies["half"][b, 0], bodies["half"][b, 1], bodies["half"][b, 2])
    ra = bodies["radius"][a]
    start, end = _segment(poses, bodies, a)
    count = 1 if start == end else 2  # a sphere: one point
    begin = rows
    for e in range(count):
        p = start if e == 0 else end
        rel = sub(p, t)
        local = (dot(R[0], rel), dot(R[1], rel), dot(R[2], rel))  # R^T (p - t)
        near = (min(max(local[0], -half[0]), half[0]), min(max(local[1], -half[1]), half[1]),
                min(max(local[2], -half[2]), half[2]))  # fmt: skip
        gap = norm(sub(local, near))
        if gap > MET:  # n from the end point towards the box, box frame
            sd = gap
            n = ((near[0] - local[0]) / gap, (near[1] - local[1]) / gap,
                 (near[2] - local[2]) / gap)  # fmt: skip
        else:  # inside (or on the surface): the nearest face
            axis, depth = 0, half[0] - abs(local[0])
            for c in range(1, 3):
                if half[c] - abs(local[c]) < depth:
                    axis, depth = c, half[c] - abs(local[c])
            sd = -depth
            face = 1.0 if local[axis] >= 0.0 else -1.0
            near = (face * half[0] if axis == 0 else near[0],
                    face * half[1] if axis == 1 else near[1],
                    face * half[2] if axis == 2 else near[2])  # fmt: skip
            n = (-face if axis == 0 else 0.0, -face if axis == 1 else 0.0,
                 -face if axis == 2 else 0.0)  # fmt: skip
        d = sd - ra
        if d >= detection:
            continue
        normal = turned(R, n)
        point_b = (t[0] + R[0][0] * near[0] + R[1][0] * near[1] + R[2][0] * near[2],
                   t[1] + R[0][1] * near[0] + R[1][1] * near[1] + R[2][1] * near[2],
                   t[2] + R[0][2] * near[0] + R[1][2] * near[1] + R[2][2] * near[2])  # fmt: skip
        rows = _write(found, rows, k, 1, (d, along(p, ra, normal), point_b, normal))
    inside, first, second, third = inside_rows(start, end, ra, R, t, half)
    if inside == 0:  # outside: the box's edges nearest the segment
        inside, first, second, third = _box_edges(start, end, ra, R, t, half)
    for i in range(inside):
        row = first if i == 0 else second if i == 1 else third
        if row[0] < detection and not _repeats(found, begin, rows, row):
            rows = _write(found, rows, k, FEATURE, row)
    return rows


@kernel
def _box_edges(a0: Vector, a1: Vector, r: float, R: tuple[Vector, Vector, Vector], t: Vector,
               half: Vector) -> tuple[int, Row, Row, Row]:  # fmt: skip
    """The rows of the three box edges nearest a segment outside the box (module docstring).

    Edges whose closest points are those of a nearer one (the edges of a corner closest to the
    segment) are one row.

    Args:
        a0: The segment's first end [m], world frame.
        a1: Its other end [m].
        r: The capsule's radius [m].
        R: The box's axes by columns (world frame).
        t: The box's centre [m].
        half: Its half sides [m].

    Returns:
        count: 0 where an edge meets the segment, else 3; the rows of the nearest edges,
        nearest first (distance [m], point on the capsule, point on the box, unit normal from
        the capsule to the box; an infinite distance where the box has fewer).
    """
    u = sub(a1, a0)
    first = second = third = (math.inf, a0, a0, ZERO)
    for c in range(3):
        k1, k2 = (c + 1) % 3, (c + 2) % 3
        e = along(ZERO, 2.0 * half[c], R[c])
        for corner in range(4):
            v0 = along(along(along(t, -half[c], R[c]), (1.0 if corner & 1 else -1.0) * half[k1],
                             R[k1]), (1.0 if corner & 2 else -1.0) * half[k2], R[k2])  # fmt: skip
            s, edge = segment_closest(a0, u, v0, e)
            ca, cb = along(a0, s, u), along(v0, edge, e)
            gap = sub(cb, ca)
            length = norm(gap)
            if length <= MET:
                return 0, first, second, third
            n = (gap[0] / length, gap[1] / length, gap[2] / length)
            row = (length - r, along(ca, r, n), cb, n)
            if _same(row, first) or _same(row, second) or _same(row, third):
                continue
            if row[0] < first[0]:
                first, second, third = row, first, second
            elif row[0] < second[0]:
                second, third = row, second
            elif row[0] < third[0]:
                third = row
    return 3, first, second, third


@kernel
def _same(row: Row, other: Row) -> bool:
    """Whether the witness points of two rows are both within :data:`SAME` of each other."""
    _, pa, pb, _ = row
    _, qa, qb, _ = other
    return max(abs(pa[0] - qa[0]), abs(pa[1] - qa[1]), abs(pa[2] - qa[2]), abs(pb[0] - qb[0]),
               abs(pb[1] - qb[1]), abs(pb[2] - qb[2])) <= SAME  # fmt: skip


@kernel
def _repeats(found: Records, begin: int, rows: int, row: Row) -> bool:
    """Whether ``row``'s witness points are both within :data:`SAME` of those of one of the
    rows ``begin`` to ``rows`` of ``found``."""  # noqa: D205, D209
    for r in range(begin, rows):
        record = found[r]
        point_a, point_b = record["point_a"], record["point_b"]
        written = (record["distance"], (point_a[0], point_a[1], point_a[2]),
                   (point_b[0], point_b[1], point_b[2]), ZERO)  # fmt: skip
        if _same(row, written):
            return True
    return False
