"""A collision scene as the proximity query reads it: geometry, pairs and bounds, frozen.

:class:`~rrc_pin.geometry.CollisionModel` builds a new :class:`Scene` whenever an obstacle is
added, moved, attached or removed, and swaps it in at once: a query running in another thread
keeps reading the scene it started with, and each :class:`~rrc_pin.geometry.proximity.
CollisionData` rebuilds its ``pinocchio.GeometryData`` when it meets a newer scene.

Bodies are ordered robot first, then held objects, then world obstacles; a pair ``(a, b)``
has ``a < b``, so a robot body or a held object is always the pair's first body (A) and an
obstacle its second (B).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import coal
import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.geometry.pairs import Pair, Reason, invariant
from rrc_pin.geometry.shapes import bounding_sphere
from rrc_pin.geometry.tree import KinematicTree
from rrc_pin.solvers.collision.narrow_kernels import BOX, CAPSULE, HALFSPACE, OTHER, SPHERE

Array = npt.NDArray[np.float64]
Index = npt.NDArray[np.int64]


class Extra(NamedTuple):
    """A body the user added: a world obstacle or an object held by a link.

    Attributes:
        name: Its name.
        kind: ``box``, ``sphere``, ``capsule``, ``cylinder``, ``convex`` or ``halfspace``.
        shape: The coal geometry, in its own frame.
        joint: The joint it moves with (0: the world).
        frame: The frame it hangs from (0: the world).
        placement: Its pose in the joint's frame (the world's, for an obstacle).
        plane: For a half-space, its unit normal (3,) and offset [m]; else None.
    """

    name: str
    kind: str
    shape: object
    joint: int
    frame: int
    placement: pin.SE3
    plane: tuple[Array, float] | None = None


@dataclass(frozen=True)
class Scene:
    """Everything a proximity query reads, built once per change (see the module docstring).

    Attributes:
        geometry: The ``pinocchio.GeometryModel``: every body, its collision pairs the active
            pairs in order.
        names: Body names (ng,).
        joint: The joint (ng,) each body moves with (0: the world).
        centre: Bounding-sphere centres (ng, 3) in the frames of their joints [m].
        radius: Bounding radii (ng,) [m]; ``inf`` for a half-space.
        normal: Unit normals (ng, 3) of the half-spaces (zero rows for other bodies).
        offset: Offsets (ng,) [m] of the half-spaces.
        shape: Each body's shape for the compiled narrow phase (ng,): a code of
            :mod:`rrc_pin.solvers.collision.narrow_kernels` (``OTHER``: coal measures its pairs).
        segment: Each sphere's or capsule's segment end points (ng, 2, 3) in its joint's
            frame [m] (a sphere: its centre twice; zeros for other bodies).
        size: Sphere and capsule radii (ng,) [m] (zero for other bodies).
        box_frame: Each box's placement (ng, 3, 4) ``[R | t]`` in its joint's frame (zeros for
            other bodies).
        half: Each box's half sides (ng, 3) [m] (zeros for other bodies).
        first: First body (npairs,) of each active pair.
        second: Second body (npairs,).
        pair_names: ``(name_a, name_b)`` of each active pair.
        labels: ``"name_a|name_b"`` of each active pair (a constraint row's name).
        every: True for every pair (npairs,): the query's default selection.
        excluded: The pairs left out, by names, with their reasons.
        invariant: The pairs left out because no joint changes their distance
            (:func:`~rrc_pin.geometry.pairs.invariant`), by names, with that distance [m].
        njoints: Number of joints of the model (including the world, 0).
        tree: The model's joints for the compiled forward kinematics, or None (a query reads
            Pinocchio's placements).
    """

    geometry: pin.GeometryModel
    names: tuple[str, ...]
    joint: Index
    centre: Array
    radius: Array
    normal: Array
    offset: Array
    shape: Index
    segment: Array
    size: Array
    box_frame: Array
    half: Array
    first: Index
    second: Index
    pair_names: tuple[tuple[str, str], ...]
    labels: tuple[str, ...]
    every: npt.NDArray[np.bool_]
    excluded: dict[tuple[str, str], Reason]
    invariant: dict[tuple[str, str], float]
    njoints: int
    tree: KinematicTree | None


def build_scene(
    model: pin.Model,
    robot: pin.GeometryModel,
    robot_pairs: list[Pair],
    excluded: dict[tuple[str, str], Reason],
    extras: list[Extra],
    tree: KinematicTree | None,
    robot_invariant: dict[tuple[str, str], float],
    decided: dict[tuple[str, str], float | None],
) -> Scene:
    """The scene of ``robot``'s bodies (active pairs ``robot_pairs``) and the ``extras``.

    An extra is paired with every robot body and every other extra, except bodies on its
    own joint (``rigid``: a held object and its hand, an obstacle and the robot's base), two
    world obstacles (neither moves) and pairs whose distance no joint changes (``invariant``:
    :func:`~rrc_pin.geometry.pairs.invariant`, decided here for the extras' pairs; the
    robot's own are decided once, ``robot_invariant`` by names with their distance [m]).
    ``decided`` holds the extras' pairs decided before, by names (their distance, None for a
    pair a joint moves): only new pairs are measured, and added to it.
    """
    held = [e for e in extras if e.joint != 0]
    world = [e for e in extras if e.joint == 0]
    geometry = pin.GeometryModel()
    for obj in robot.geometryObjects:
        geometry.addGeometryObject(obj)
    for extra in held + world:
        geometry.addGeometryObject(
            pin.GeometryObject(extra.name, extra.joint, extra.frame, extra.placement, extra.shape)
        )
    objects = list(geometry.geometryObjects)
    names = tuple(str(o.name) for o in objects)
    joint = np.array([o.parentJoint for o in objects], dtype=np.int64)
    n_robot = robot.ngeoms
    excluded = dict(excluded)
    added = []
    for b in range(n_robot, len(objects)):
        for a in range(b):
            if joint[a] == joint[b]:
                excluded[(names[a], names[b])] = "rigid"
            else:
                added.append((a, b))
    new = [(a, b) for a, b in added if (names[a], names[b]) not in decided]
    found = invariant(model, geometry, new)
    for a, b in new:
        decided[(names[a], names[b])] = found.get((a, b))
    fixed = dict(robot_invariant)
    pairs = list(robot_pairs)
    for a, b in added:
        distance = decided[(names[a], names[b])]
        if distance is None:
            pairs.append((a, b))
        else:
            excluded[(names[a], names[b])] = "invariant"
            fixed[(names[a], names[b])] = distance
    pairs.sort()
    for a, b in pairs:
        geometry.addCollisionPair(pin.CollisionPair(a, b))
    centre = np.zeros((len(objects), 3))
    radius = np.zeros(len(objects))
    normal = np.zeros((len(objects), 3))
    offset = np.zeros(len(objects))
    shape = np.full(len(objects), OTHER, dtype=np.int64)
    segment = np.zeros((len(objects), 2, 3))
    size = np.zeros(len(objects))
    box_frame = np.zeros((len(objects), 3, 4))
    halves = np.zeros((len(objects), 3))
    planes = {e.name: e.plane for e in extras if e.plane is not None}
    for g, obj in enumerate(objects):
        c, r = bounding_sphere(obj.geometry)
        centre[g] = obj.placement.act(c)
        radius[g] = r
        if names[g] in planes:
            normal[g], offset[g] = planes[names[g]]
            shape[g] = HALFSPACE
        elif isinstance(obj.geometry, coal.Sphere | coal.Capsule):
            half = obj.geometry.halfLength if isinstance(obj.geometry, coal.Capsule) else 0.0
            shape[g] = CAPSULE if isinstance(obj.geometry, coal.Capsule) else SPHERE
            segment[g] = [obj.placement.act(np.array([0.0, 0.0, z])) for z in (-half, half)]
            size[g] = obj.geometry.radius
        elif isinstance(obj.geometry, coal.Box):
            shape[g] = BOX
            box_frame[g] = obj.placement.homogeneous[:3]
            halves[g] = obj.geometry.halfSide
    first = np.array([a for a, _ in pairs], dtype=np.int64)
    second = np.array([b for _, b in pairs], dtype=np.int64)
    return Scene(
        geometry=geometry, names=names, joint=joint, centre=centre, radius=radius,
        normal=normal, offset=offset, shape=shape, segment=segment, size=size,
        box_frame=box_frame, half=halves, first=first,
        second=second,
        pair_names=tuple((names[a], names[b]) for a, b in pairs),
        labels=tuple(f"{names[a]}|{names[b]}" for a, b in pairs),
        every=np.ones(len(pairs), dtype=np.bool_), excluded=excluded, invariant=fixed,
        njoints=model.njoints, tree=tree,
    )  # fmt: skip
