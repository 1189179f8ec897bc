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
from rrc_pin.solvers.collision.records import BODY, JOINT

Array = npt.NDArray[np.float64]
Index = npt.NDArray[np.int64]
Records = npt.NDArray[np.void]


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
        bodies: Every body (ng,) as the compiled pass reads it
            (:data:`~rrc_pin.solvers.collision.records.BODY`: its joint, shape code, bounding
            sphere, half-space plane, sphere or capsule segment and radius, box placement and
            half sides; ``OTHER``: coal measures its pairs).
        first: First body (npairs,) of each active pair.
        second: Second body (npairs,).
        pair_names: ``(name_a, name_b)`` of each active pair.
        labels: ``"name_a|name_b"`` of each active pair (a constraint row's name).
        every: True for every pair (npairs,): the query's default selection.
        excluded: The pairs left out, by names, with their reasons.
        invariant: The pairs left out because no joint changes their distance
            (:func:`~rrc_pin.geometry.pairs.invariant`), by names, with that distance [m].
        njoints: Number of joints of the model (including the world, 0).
        nv: Number of joint rates of the model.
        support: (njoints, nv) whether rate c moves joint j (row 0, the world: none).
        tree: The model's joints for the compiled forward kinematics, or None (a query reads
            Pinocchio's placements).
        joints: ``tree`` as :data:`~rrc_pin.solvers.collision.records.JOINT` records (empty
            for None).
    """

    geometry: pin.GeometryModel
    names: tuple[str, ...]
    bodies: Records
    first: Index
    second: Index
    pair_names: tuple[tuple[str, str], ...]
    labels: tuple[str, ...]
    every: npt.NDArray[np.bool_]
    excluded: dict[tuple[str, str], Reason]
    invariant: dict[tuple[str, str], float]
    njoints: int
    nv: int
    support: npt.NDArray[np.bool_]
    tree: KinematicTree | None
    joints: Records

    @property
    def joint(self) -> Index:
        """The joint (ng,) each body moves with (0: the world)."""
        joint: Index = self.bodies["joint"]
        return joint


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
    bodies = _bodies(objects, planes={e.name: e.plane for e in extras if e.plane is not None})
    first = np.array([a for a, _ in pairs], dtype=np.int64)
    second = np.array([b for _, b in pairs], dtype=np.int64)
    return Scene(
        geometry=geometry, names=names, bodies=bodies, first=first, second=second,
        pair_names=tuple((names[a], names[b]) for a, b in pairs),
        labels=tuple(f"{names[a]}|{names[b]}" for a, b in pairs),
        every=np.ones(len(pairs), dtype=np.bool_), excluded=excluded, invariant=fixed,
        njoints=model.njoints, nv=model.nv, support=_support(model), tree=tree,
        joints=_joints(tree, model.njoints),
    )  # fmt: skip


def _bodies(objects: list[pin.GeometryObject], planes: dict[str, tuple[Array, float]]) -> Records:
    """The :data:`~rrc_pin.solvers.collision.records.BODY` records of ``objects``.

    ``planes``: the half-spaces' unit normals and offsets [m], by name.
    """
    bodies = np.zeros(len(objects), dtype=BODY)
    for g, obj in enumerate(objects):
        body = bodies[g]
        body["joint"] = obj.parentJoint
        body["shape"] = OTHER
        c, r = bounding_sphere(obj.geometry)
        body["centre"], body["bounding"] = obj.placement.act(c), r
        if str(obj.name) in planes:
            body["normal"], body["offset"] = planes[str(obj.name)]
            body["shape"] = HALFSPACE
        elif isinstance(obj.geometry, coal.Sphere | coal.Capsule):
            capsule = isinstance(obj.geometry, coal.Capsule)
            half = obj.geometry.halfLength if capsule else 0.0
            body["shape"] = CAPSULE if capsule else SPHERE
            body["segment"] = [obj.placement.act(np.array([0.0, 0.0, z])) for z in (-half, half)]
            body["radius"] = obj.geometry.radius
        elif isinstance(obj.geometry, coal.Box):
            body["shape"] = BOX
            body["box"] = obj.placement.homogeneous[:3]
            body["half"] = obj.geometry.halfSide
    return bodies


def _support(model: pin.Model) -> npt.NDArray[np.bool_]:
    """(njoints, nv): whether rate c moves joint j (its supporting joints' rates)."""
    support = np.zeros((model.njoints, model.nv), dtype=np.bool_)
    for j in range(1, model.njoints):
        for i in model.supports[j].tolist()[1:]:
            start = model.joints[i].idx_v
            support[j, start : start + model.joints[i].nv] = True
    return support


def _joints(tree: KinematicTree | None, njoints: int) -> Records:
    """``tree`` as :data:`~rrc_pin.solvers.collision.records.JOINT` records (None: none)."""
    if tree is None:
        return np.zeros(0, dtype=JOINT)
    joints = np.zeros(njoints, dtype=JOINT)
    joints["parent"], joints["kind"], joints["coordinate"] = tree.parent, tree.kind, tree.coordinate
    joints["rotation"], joints["translation"], joints["axis"] = (tree.rotation, tree.translation,
                                                                tree.axis)  # fmt: skip
    return joints
