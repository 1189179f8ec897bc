"""Collision shapes from checked dimensions, and the bounding sphere of any shape.

Every shape is a coal geometry in its own frame, as coal defines it:

- box: centred, sides ``size`` (3,) along its x, y, z [m];
- sphere: centred, ``radius``;
- capsule: the points within ``radius`` of the segment from ``(0, 0, -length/2)`` to
  ``(0, 0, length/2)`` (``length`` is the axis between the two sphere centres, not the total);
- cylinder: ``radius``, ``length`` the total height along z, centred;
- convex: the convex hull of ``points`` (N, 3) [m] (qhull, through coal);
- half-space: the solid ``{x : normal . x <= offset}`` (coal's ``Halfspace``): a table top at
  height h is ``normal = (0, 0, 1)``, ``offset = h``; the robot stays where ``normal . x > offset``.

Bad dimensions raise :class:`~rrc_pin.errors.InvalidInput` naming the argument.
"""

from __future__ import annotations

from typing import Literal

import coal
import numpy as np
import numpy.typing as npt

from rrc_pin.errors import InvalidInput
from rrc_pin.solvers import checks
from rrc_pin.solvers.checks import MAX_LENGTH, as_array, as_vector, direction, within_length

Array = npt.NDArray[np.float64]
Kind = Literal["box", "sphere", "capsule", "cylinder", "convex", "halfspace"]
KINDS: tuple[str, ...] = ("box", "capsule", "convex", "cylinder", "halfspace", "sphere")
ATTACHABLE: tuple[str, ...] = ("box", "capsule", "convex", "cylinder", "sphere")
"""Kinds a link can hold (a half-space is unbounded: only the world has one)."""
DIMENSIONS: dict[str, tuple[str, ...]] = {
    "box": ("size",),
    "sphere": ("radius",),
    "capsule": ("radius", "length"),
    "cylinder": ("radius", "length"),
    "convex": ("points",),
}
"""The keyword dimensions of each attachable kind (:meth:`CollisionModel.attach`)."""
HALFSPACE_RADIUS = np.inf
"""The bounding radius of a half-space: unbounded (the broad phase tests its plane)."""


def box(size: npt.ArrayLike, name: str = "size") -> coal.Box:
    """A box of sides ``size`` (3,) [m], each > 0."""
    sides = within_length(as_vector(size, name, 3), name)
    if np.any(sides <= 0.0):
        raise InvalidInput(name, f"expected three sides > 0 [m], got {sides.tolist()}")
    return coal.Box(float(sides[0]), float(sides[1]), float(sides[2]))


def sphere(radius: float) -> coal.Sphere:
    """A sphere of ``radius`` [m] > 0."""
    return coal.Sphere(checks.length(radius, "radius"))


def capsule(radius: float, length: float) -> coal.Capsule:
    """A capsule of ``radius`` > 0 about an axis of ``length`` >= 0 [m] along z."""
    r = checks.length(radius, "radius")
    return coal.Capsule(r, checks.length(length, "length", 0.0, inclusive=True))


def cylinder(radius: float, length: float) -> coal.Cylinder:
    """A cylinder of ``radius`` and height ``length`` [m] along z, both > 0."""
    return coal.Cylinder(checks.length(radius, "radius"), checks.length(length, "length"))


def convex(points: npt.ArrayLike) -> coal.ConvexBase:
    """The convex hull of ``points`` (N, 3) [m]: at least four, not all in one plane."""
    P = within_length(as_array(points, "points", (None, 3)), "points")
    centred = P - P.mean(axis=0) if len(P) else P
    if len(P) < 4 or np.linalg.matrix_rank(centred, tol=1e-9 * max(1.0, np.abs(P).max())) < 3:
        raise InvalidInput("points", f"expected >= 4 points (N, 3) spanning a volume, got {len(P)}")
    vertices = coal.StdVec_Vec3s()
    vertices.extend(list(P))
    hull: coal.ConvexBase = coal.ConvexBase.convexHull(vertices, False, "")
    return hull


def halfspace(normal: npt.ArrayLike, offset: float) -> tuple[coal.Halfspace, Array, float]:
    """The solid ``normal . x <= offset`` (module docstring), with its unit normal and offset.

    ``normal`` need not be unit: both are divided by its norm.

    Returns:
        The coal shape, the unit normal (3,) and the offset [m].
    """
    unit, norm = direction(normal, "normal")
    d = checks.length(offset, "offset", -MAX_LENGTH) / norm
    return coal.Halfspace(unit, d), unit, d


def bounding_sphere(geometry: coal.CollisionGeometry) -> tuple[Array, float]:
    """Centre (3,) in the shape's frame and radius [m] of a sphere holding ``geometry``.

    The smallest for a sphere, a capsule, a cylinder and a box (about their centre); for a
    convex hull, the farthest vertex from the centre of its bounding box; for anything else
    (a mesh), the sphere around coal's axis-aligned bounding box. A half-space gets
    :data:`HALFSPACE_RADIUS`.
    """
    centre: Array = np.zeros(3)
    if isinstance(geometry, coal.Halfspace):
        return centre, HALFSPACE_RADIUS
    if isinstance(geometry, coal.Sphere):
        return centre, float(geometry.radius)
    if isinstance(geometry, coal.Capsule):
        return centre, float(geometry.radius + geometry.halfLength)
    if isinstance(geometry, coal.Cylinder):
        return centre, float(np.hypot(geometry.radius, geometry.halfLength))
    if isinstance(geometry, coal.Box):
        return centre, float(np.linalg.norm(geometry.halfSide))
    geometry.computeLocalAABB()
    centre = np.array(geometry.aabb_center, dtype=float)
    if isinstance(geometry, coal.ConvexBase):
        points = np.asarray(geometry.points())
        return centre, float(np.max(np.linalg.norm(points - centre, axis=1)))
    return centre, float(geometry.aabb_radius)
