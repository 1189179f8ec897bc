"""rrc_pin.geometry.capsules: a cylinder between two spheres is merged into one capsule."""

from __future__ import annotations

import coal
import numpy as np
import pinocchio as pin

from rrc_pin.geometry.capsules import MATCH_TOL, to_capsules
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
    merged = to_capsules(triples)
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


def test_a_cylinder_without_its_two_end_spheres_becomes_its_bounding_capsule(rng):
    geometry = pin.GeometryModel()
    M = pin.SE3(pin.exp3(np.array([0.2, 0.4, -0.1])), np.array([0.1, 0.0, 0.3]))
    cyl = coal.Cylinder(0.1, 0.4)
    geometry.addGeometryObject(pin.GeometryObject("c", 0, 0, M, cyl))
    end = pin.SE3(np.eye(3), M.act(np.array([0.0, 0.0, 0.2])))
    geometry.addGeometryObject(pin.GeometryObject("s", 0, 0, end, coal.Sphere(0.1)))
    far = pin.SE3(np.eye(3), M.act(np.array([0.0, 0.0, -0.3])))
    geometry.addGeometryObject(pin.GeometryObject("t", 0, 0, far, coal.Sphere(0.1)))
    merged = to_capsules(geometry)
    assert [type(o.geometry).__name__ for o in merged.geometryObjects] == [
        "Capsule", "Sphere", "Sphere"]  # fmt: skip
    capsule = merged.geometryObjects[0]
    assert capsule.geometry.radius == 0.1 and capsule.geometry.halfLength == 0.2
    for _ in range(200):  # the capsule holds the cylinder: never farther, at most r nearer
        p = M.act(rng.normal(size=3) * 0.4)
        d_cyl = distance(cyl, M, p)
        d_cap = distance(capsule.geometry, capsule.placement, p)
        assert d_cyl - 0.1 - 1e-9 <= d_cap <= d_cyl + 1e-9
        if abs(M.actInv(p)[2]) <= 0.2 and d_cyl > 0:  # off the side: the same distance
            assert abs(d_cap - d_cyl) <= 1e-6


def test_a_triple_is_exactly_its_capsule():
    geometry = pin.GeometryModel()
    R = pin.exp3(np.array([0.3, -0.2, 0.5]))
    M = pin.SE3(R, np.array([0.1, 0.2, 0.3]))
    geometry.addGeometryObject(pin.GeometryObject("c", 0, 0, M, coal.Cylinder(0.05, 0.3)))
    for s in (-1, 1):
        end = pin.SE3(np.eye(3), M.act(np.array([0.0, 0.0, s * 0.15])))
        geometry.addGeometryObject(pin.GeometryObject(f"s{s}", 0, 0, end, coal.Sphere(0.05)))
    (capsule,) = to_capsules(geometry).geometryObjects
    assert capsule.name == "c" and abs(capsule.geometry.halfLength - 0.15) < 1e-15
    rng = np.random.default_rng(3)
    for _ in range(50):
        p = M.act(rng.normal(size=3) * 0.3)
        union = min(distance(o.geometry, o.placement, p) for o in geometry.geometryObjects)
        assert abs(distance(capsule.geometry, capsule.placement, p) - union) < 1e-12


def test_a_box_becomes_the_capsule_along_its_longest_side(rng):
    geometry = pin.GeometryModel()
    M = pin.SE3(pin.exp3(np.array([-0.3, 0.1, 0.6])), np.array([0.0, 0.2, 0.1]))
    box = coal.Box(0.02, 0.12, 0.04)  # sides [m]: the longest along y
    geometry.addGeometryObject(pin.GeometryObject("b", 0, 0, M, box))
    (capsule,) = to_capsules(geometry).geometryObjects
    assert capsule.geometry.halfLength == 0.06
    assert abs(capsule.geometry.radius - np.hypot(0.01, 0.02)) < 1e-15
    corners = [M.act(np.array([x, y, z])) for x in (-0.01, 0.01) for y in (-0.06, 0.06)
               for z in (-0.02, 0.02)]  # fmt: skip
    for p in corners:  # the capsule holds the box: its corners on the capsule's surface
        assert abs(distance(capsule.geometry, capsule.placement, p)) < 1e-9
    for _ in range(200):  # never farther than the box
        p = M.act(rng.normal(size=3) * 0.2)
        assert distance(capsule.geometry, capsule.placement, p) <= distance(box, M, p) + 1e-9
