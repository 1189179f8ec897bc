"""rrc_pin.geometry.capsules: a cylinder between two spheres is merged into one capsule."""

from __future__ import annotations

import coal
import numpy as np
import pinocchio as pin

from rrc_pin.geometry.capsules import MATCH_TOL, merge_capsules
from rrc_pin.loading import robots_directory


def panda_collision():
    folder = robots_directory()
    path = str(folder / "panda_description/urdf/panda_collision.urdf")
    model = pin.buildModelFromUrdf(path)
    return model, pin.buildGeomFromUrdf(model, path, pin.GeometryType.COLLISION)


def distance(shape, M, p):
    """Signed distance from the point p to a shape at placement M (coal, a tiny sphere)."""
    result = coal.DistanceResult()
    T = coal.Transform3s(M.rotation, M.translation)
    P = coal.Transform3s(np.eye(3), p)
    return coal.distance(shape, T, coal.Sphere(1e-9), P, coal.DistanceRequest(), result) + 1e-9


def test_panda_collision_merges_into_thirteen_capsules_of_the_same_solid(rng):
    _, triples = panda_collision()
    merged = merge_capsules(triples)
    assert triples.ngeoms == 39 and merged.ngeoms == 13
    assert all(isinstance(o.geometry, coal.Capsule) for o in merged.geometryObjects)
    for frame in {o.parentFrame for o in merged.geometryObjects}:  # each link's solid
        before = [o for o in triples.geometryObjects if o.parentFrame == frame]
        after = [o for o in merged.geometryObjects if o.parentFrame == frame]
        for _ in range(30):
            p = after[0].placement.act(rng.normal(size=3) * 0.15)
            union = min(distance(o.geometry, o.placement, p) for o in before)
            capsules = min(distance(o.geometry, o.placement, p) for o in after)
            assert abs(capsules - union) <= MATCH_TOL


def test_a_cylinder_without_its_two_end_spheres_stays_a_cylinder():
    model = pin.Model()
    geometry = pin.GeometryModel()
    cyl = coal.Cylinder(0.1, 0.4)
    geometry.addGeometryObject(pin.GeometryObject("c", 0, 0, pin.SE3.Identity(), cyl))
    end = pin.SE3(np.eye(3), np.array([0.0, 0.0, 0.2]))
    geometry.addGeometryObject(pin.GeometryObject("s", 0, 0, end, coal.Sphere(0.1)))
    far = pin.SE3(np.eye(3), np.array([0.0, 0.0, -0.3]))
    geometry.addGeometryObject(pin.GeometryObject("t", 0, 0, far, coal.Sphere(0.1)))
    merged = merge_capsules(geometry)
    assert [type(o.geometry).__name__ for o in merged.geometryObjects] == [
        "Cylinder", "Sphere", "Sphere"]  # fmt: skip
    assert model.njoints == 1


def test_a_triple_is_exactly_its_capsule():
    geometry = pin.GeometryModel()
    R = pin.exp3(np.array([0.3, -0.2, 0.5]))
    M = pin.SE3(R, np.array([0.1, 0.2, 0.3]))
    geometry.addGeometryObject(pin.GeometryObject("c", 0, 0, M, coal.Cylinder(0.05, 0.3)))
    for s in (-1, 1):
        end = pin.SE3(np.eye(3), M.act(np.array([0.0, 0.0, s * 0.15])))
        geometry.addGeometryObject(pin.GeometryObject(f"s{s}", 0, 0, end, coal.Sphere(0.05)))
    (capsule,) = merge_capsules(geometry).geometryObjects
    assert capsule.name == "c" and abs(capsule.geometry.halfLength - 0.15) < 1e-15
    rng = np.random.default_rng(3)
    for _ in range(50):
        p = M.act(rng.normal(size=3) * 0.3)
        union = min(distance(o.geometry, o.placement, p) for o in geometry.geometryObjects)
        assert abs(distance(capsule.geometry, capsule.placement, p) - union) < 1e-12
