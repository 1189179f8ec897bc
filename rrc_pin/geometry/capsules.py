"""Capsules written in a URDF as a cylinder between two spheres, merged back into capsules.

URDF has no capsule element (urdfdom, which Pinocchio parses with, refuses one), so capsule
models write each capsule as a ``<cylinder>`` and two ``<sphere>`` elements of the same radius
centred on the ends of its axis: example-robot-data's ``panda_collision.urdf`` does, and so do
the generated URDFs of the paper arms (:mod:`rrc_pin.urdf_export`). The union of the three is
exactly the capsule, so replacing them by one ``coal.Capsule`` gives coal its exact
capsule-capsule and capsule-half-space formulas: one object instead of three, and a ninth of
the pairs. The capsule's axis joins the two sphere centres (it holds the spheres exactly); a
URDF that rounds its angles (``panda_collision.urdf`` writes pi/2 as 1.57) puts the spheres
off the cylinder's ends by up to :data:`MATCH_TOL`, and the capsule's side then differs from
the cylinder's by as much.

A cylinder without its end spheres (baxter's links) becomes the capsule that bounds it: the
same axis, radius and length, with a half-sphere of its radius added at each end; a box
(baxter's fingers) the capsule along its longest side, of radius the half-diagonal of its
cross-section. The capsule holds the shape, so distances to it are conservative (shorter by
at most its radius), and every link gets the compiled capsule formulas and their end-point
rows (:mod:`rrc_pin.solvers.collision.narrow_kernels`) instead of coal's GJK without them: a box's
or
cylinder's closest point jumps across a face in one step where a capsule's end is already
constrained (baxter's 10-minute session went 3.5 mm below the safety distance on cylinders,
docs/api.md).
"""

from __future__ import annotations

import coal
import numpy as np
import numpy.typing as npt
import pinocchio as pin

MATCH_TOL = 1e-4
"""[m] How far a sphere's centre and radius may be from the cylinder's end and radius (0.1 mm:
panda_collision.urdf's 1.57 for pi/2 moves its hand's sphere centres 0.06 mm)."""


def to_capsules(geometry: pin.GeometryModel) -> pin.GeometryModel:
    """A copy of ``geometry`` with every cylinder and box made a capsule (module docstring).

    A cylinder merges with two spheres of its radius on the same frame centred on the two
    ends of its axis (each sphere used once); the capsule takes the cylinder's name and
    placement. A cylinder without both spheres, and a box, become their bounding capsules.
    Everything else is kept as it is, in order.
    """
    objects = list(geometry.geometryObjects)
    used: set[int] = set()
    capsules: dict[int, tuple[coal.Capsule, pin.SE3]] = {}
    for i, obj in enumerate(objects):
        shape = obj.geometry
        if isinstance(shape, coal.Box):
            capsules[i] = _bounding(shape, obj.placement)
        if not isinstance(shape, coal.Cylinder):
            continue
        ends = [obj.placement.act(np.array([0.0, 0.0, s * shape.halfLength])) for s in (-1, 1)]
        low = _sphere_at(objects, used, obj.parentFrame, ends[0], shape.radius)
        high = _sphere_at(objects, used | {low} if low is not None else used, obj.parentFrame,
                          ends[1], shape.radius)  # fmt: skip
        if low is None or high is None:
            capsules[i] = (coal.Capsule(shape.radius, 2.0 * shape.halfLength), obj.placement)
            continue
        used.update((low, high))
        a, b = objects[low].placement.translation, objects[high].placement.translation
        capsules[i] = (coal.Capsule(shape.radius, float(np.linalg.norm(b - a))), _axis(a, b))
    out = pin.GeometryModel()
    for i, obj in enumerate(objects):
        if i in used:
            continue
        shape, placement = capsules.get(i, (obj.geometry, obj.placement))
        out.addGeometryObject(
            pin.GeometryObject(obj.name, obj.parentJoint, obj.parentFrame, placement, shape)
        )
    return out


def _bounding(box: coal.Box, placement: pin.SE3) -> tuple[coal.Capsule, pin.SE3]:
    """The capsule holding ``box``: along its longest side, through its centre."""
    half = np.asarray(box.halfSide, dtype=float)
    i = int(np.argmax(half))
    radius = float(np.hypot(*np.delete(half, i)))
    turn = np.roll(np.eye(3), 2 - i, axis=1)  # a rotation whose z axis is the box's axis i
    return coal.Capsule(radius, 2.0 * float(half[i])), placement * pin.SE3(turn, np.zeros(3))


def _axis(a: npt.NDArray[np.float64], b: npt.NDArray[np.float64]) -> pin.SE3:
    """A placement at the middle of ``a`` and ``b`` whose z axis points from ``a`` to ``b``."""
    z = (b - a) / np.linalg.norm(b - a)
    helper = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(helper, z)
    x /= np.linalg.norm(x)
    return pin.SE3(np.column_stack([x, np.cross(z, x), z]), (a + b) / 2.0)


def _sphere_at(
    objects: list[pin.GeometryObject],
    used: set[int],
    frame: int,
    centre: npt.NDArray[np.float64],
    radius: float,
) -> int | None:
    """Index of an unused sphere of ``radius`` on ``frame`` centred at ``centre``, or None."""
    for j, obj in enumerate(objects):
        if (
            j not in used
            and obj.parentFrame == frame
            and isinstance(obj.geometry, coal.Sphere)
            and abs(obj.geometry.radius - radius) <= MATCH_TOL
            and np.linalg.norm(obj.placement.translation - centre) <= MATCH_TOL
        ):
            return j
    return None
