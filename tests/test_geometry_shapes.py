"""rrc_pin.geometry.shapes: checked dimensions and bounding spheres that hold their shapes."""

from __future__ import annotations

import coal
import numpy as np
import pytest

from rrc_pin.errors import InvalidInput
from rrc_pin.geometry import shapes


def support(shape, direction):
    """The farthest point of ``shape`` along ``direction`` (in its own frame)."""
    d = direction / np.linalg.norm(direction)
    if isinstance(shape, coal.Sphere):
        return shape.radius * d
    if isinstance(shape, coal.Capsule):
        return np.array([0, 0, np.sign(d[2]) * shape.halfLength]) + shape.radius * d
    if isinstance(shape, coal.Cylinder):
        radial = np.array([d[0], d[1], 0.0])
        norm = np.linalg.norm(radial)
        rim = shape.radius * radial / norm if norm > 0 else np.zeros(3)
        return rim + np.array([0, 0, np.sign(d[2]) * shape.halfLength])
    if isinstance(shape, coal.Box):
        return np.sign(d) * shape.halfSide
    points = np.asarray(shape.points())
    return points[np.argmax(points @ d)]


@pytest.mark.parametrize("make", [
    lambda: shapes.box((0.1, 0.4, 0.2)),
    lambda: shapes.sphere(0.3),
    lambda: shapes.capsule(0.05, 0.4),
    lambda: shapes.cylinder(0.05, 0.4),
    lambda: shapes.convex(np.random.default_rng(1).normal(size=(20, 3)) + np.array([1, 0, 0])),
], ids=["box", "sphere", "capsule", "cylinder", "convex"])  # fmt: skip
def test_bounding_spheres_hold_their_shapes_and_touch_them(make, rng):
    shape = make()
    centre, radius = shapes.bounding_sphere(shape)
    farthest = 0.0
    for _ in range(500):
        p = support(shape, rng.normal(size=3))
        farthest = max(farthest, float(np.linalg.norm(p - centre)))
    assert farthest <= radius + 1e-12
    assert farthest >= 0.95 * radius  # not loose: the broad phase stays selective


def test_a_halfspace_is_unit_and_unbounded():
    shape, n, d = shapes.halfspace((0, 0, 2), 1.0)
    np.testing.assert_allclose(n, (0, 0, 1))
    assert d == 0.5 and shape.d == 0.5
    assert shapes.bounding_sphere(shape)[1] == np.inf


@pytest.mark.parametrize(("make", "argument"), [
    (lambda: shapes.box((1, 1)), "size"),
    (lambda: shapes.box((1, 1, 0)), "size"),
    (lambda: shapes.sphere(-1.0), "radius"),
    (lambda: shapes.sphere(True), "radius"),
    (lambda: shapes.capsule(0.1, np.inf), "length"),
    (lambda: shapes.cylinder(0.1, 0.0), "length"),
    (lambda: shapes.convex(np.zeros((5, 3))), "points"),
    (lambda: shapes.convex([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]]), "points"),  # flat
    (lambda: shapes.halfspace((0, 0, 0), 1.0), "normal"),
], ids=["box2", "box0", "sphere-", "sphere-bool", "capsule-inf", "cylinder0", "convex-point",
        "convex-flat", "halfspace0"])  # fmt: skip
def test_bad_dimensions_are_refused(make, argument):
    with pytest.raises(InvalidInput) as info:
        make()
    assert info.value.argument == argument
