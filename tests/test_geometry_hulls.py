"""rrc_pin.geometry.hulls: meshes become convex hulls once per process."""

from __future__ import annotations

import coal
import numpy as np
import pinocchio as pin

import rrc_pin
from rrc_pin.geometry import CollisionModel
from rrc_pin.geometry.hulls import convex_hull, hull_statistics, with_hulls
from rrc_pin.loading import robots_directory


def panda_meshes():
    folder = robots_directory()
    path = str(folder / "panda_description/urdf/panda.urdf")
    model = pin.buildModelFromUrdf(path)
    return pin.buildGeomFromUrdf(model, path, pin.GeometryType.COLLISION,
                                 package_dirs=[str(folder.parent.parent)])  # fmt: skip


def test_every_mesh_becomes_a_hull_that_holds_its_vertices():
    meshes = panda_meshes()
    hulls = with_hulls(meshes)
    assert hulls.ngeoms == meshes.ngeoms
    for mesh, hull in zip(meshes.geometryObjects, hulls.geometryObjects, strict=True):
        assert hull.name == mesh.name and hull.placement == mesh.placement
        if isinstance(mesh.geometry, coal.BVHModelBase):
            assert isinstance(hull.geometry, coal.ConvexBase)
            H = hull.geometry
            vertices = np.asarray(mesh.geometry.vertices())
            normals, offsets = np.asarray(H.normals()), np.asarray(H.offsets())
            assert (vertices @ normals.T + offsets).max() < 1e-9  # n . x + offset <= 0: inside
        else:
            assert hull.geometry is mesh.geometry or type(hull.geometry) is type(mesh.geometry)


def test_hulls_are_built_once_per_mesh_file():
    CollisionModel(rrc_pin.load("panda"), "hulls")
    built = hull_statistics()
    CollisionModel(rrc_pin.load("panda"), "hulls")
    facing = np.eye(4)
    facing[0, 3] = 1.0
    panda = rrc_pin.load("panda")
    CollisionModel(rrc_pin.combine({"a": (panda, np.eye(4)), "b": (panda, facing)}), "hulls")
    assert hull_statistics() == built
    fresh = panda_meshes()  # new BVH objects of the same files: the cached hulls come back
    obj = next(o for o in fresh.geometryObjects if isinstance(o.geometry, coal.BVHModelBase))
    assert convex_hull(obj) is convex_hull(obj) and hull_statistics().built == built.built
