"""Collision meshes as convex hulls, built once per process.

coal measures a mesh (a BVH of triangles) against another shape by its triangles: in
penetration it returns a distance of 0, with no sign and no useful normal, and it is slow. The
convex hull of the same mesh gets GJK and EPA: a signed distance, witness points and a normal in
penetration as well, in about a microsecond. A hull holds its mesh, so it is conservative (it
fills concavities).

Hulls are built by qhull through coal (``BVHModel.buildConvexHull``) the first time a mesh is
met, and kept in memory for the process, keyed by the mesh file and scale: a second robot (the
other panda of a cell), a second :class:`~rrc_pin.geometry.CollisionModel` or another thread
reuses them. :func:`hull_statistics` says how many were built and what they cost.
"""

from __future__ import annotations

import threading
import time
from typing import NamedTuple

import coal
import pinocchio as pin

from rrc_pin.errors import URDFError

_LOCK = threading.Lock()
_HULLS: dict[tuple[str, tuple[float, ...]], coal.ConvexBase] = {}
_SECONDS = [0.0]
_BUILT = [0]

QHULL_OPTIONS = ("Qt", "QJ")
"""qhull options tried in turn: triangulated output (coal's default), then joggled input (a
hull of the vertices moved by about 1e-11 of the mesh's size: centauro's pelvis mesh, whose
triangulated hull gives a vertex more neighbours than coal stores)."""


class HullStatistics(NamedTuple):
    """The hulls built in this process so far.

    Attributes:
        built: Number of hulls built (and cached).
        seconds: Their total build time [s] (qhull; the meshes were already loaded).
    """

    built: int
    seconds: float


def hull_statistics() -> HullStatistics:
    """How many hulls this process has built and their total build time."""
    with _LOCK:
        return HullStatistics(_BUILT[0], _SECONDS[0])


def convex_hull(obj: pin.GeometryObject) -> coal.ConvexBase:
    """The convex hull of ``obj``'s mesh (a coal BVH), built once per mesh file and scale.

    A mesh read from no file (built in code) gets its hull built at every call.
    """
    key = (str(obj.meshPath), tuple(float(s) for s in obj.meshScale))
    with _LOCK:
        hull = _HULLS.get(key) if obj.meshPath else None
        if hull is None:
            start = time.perf_counter()
            hull = _build(obj)
            _SECONDS[0] += time.perf_counter() - start
            _BUILT[0] += 1
            if obj.meshPath:
                _HULLS[key] = hull
    return hull


def _build(obj: pin.GeometryObject) -> coal.ConvexBase:
    """Build the hull of ``obj``'s mesh with the first of :data:`QHULL_OPTIONS` that works.

    Raises:
        URDFError: qhull failed with every option (naming the mesh file).
    """
    failures = []
    for options in QHULL_OPTIONS:
        try:
            obj.geometry.buildConvexHull(True, options)
        except RuntimeError as exc:
            failures.append(f"{options}: {str(exc).strip().splitlines()[-1]}")
            continue
        hull: coal.ConvexBase = obj.geometry.convex
        return hull
    raise URDFError(
        str(obj.meshPath) or str(obj.name),
        "qhull could not build its convex hull (" + "; ".join(failures) + "); use "
        "geometry='urdf' to keep the mesh",
    )


def is_mesh(geometry: coal.CollisionGeometry) -> bool:
    """Whether ``geometry`` is a triangle mesh (a coal BVH model)."""
    return isinstance(geometry, coal.BVHModelBase)


def with_hulls(geometry: pin.GeometryModel) -> pin.GeometryModel:
    """A copy of ``geometry`` with every mesh replaced by its convex hull (primitives kept)."""
    out = pin.GeometryModel()
    for obj in geometry.geometryObjects:
        shape = convex_hull(obj) if is_mesh(obj.geometry) else obj.geometry
        out.addGeometryObject(
            pin.GeometryObject(obj.name, obj.parentJoint, obj.parentFrame, obj.placement, shape)
        )
    return out
