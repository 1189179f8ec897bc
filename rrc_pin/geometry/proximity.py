"""One tick's proximity query: the pairs closer than a detection distance, with witnesses.

The steps, in the order data flows:

1. the joint placements of the tick, from q by the compiled forward kinematics of
   :mod:`~rrc_pin.geometry.tree` (or read from Pinocchio's ``data.oMi`` for a model it does
   not cover);
2. the broad phase (:mod:`rrc_pin.solvers.collision.proximity_kernels`, compiled): bounding-sphere
centres in
   the world, and the pairs whose distance bound is below the detection distance;
3. the narrow phase for those candidates only, keeping those below the detection distance:
   pairs of spheres, capsules and half-spaces in one compiled pass
   (:mod:`rrc_pin.solvers.collision.narrow_kernels`, also the capsules' end-point rows when asked),
   the others
   (boxes, cylinders, hulls, meshes) by coal: ``pinocchio.updateGeometryPlacements``, then
   ``pinocchio.computeDistance`` per pair (signed distance, EPA in penetration).

Conventions of a :class:`Proximity` row (coal's): the witness points ``p_a`` on body A and
``p_b`` on body B, world frame; the signed distance ``d`` (negative in penetration); the unit
``normal`` from A to B, also in penetration, with ``p_b - p_a = d * normal``: moving B along
``+normal`` (or A along ``-normal``) increases ``d``.
"""

from __future__ import annotations

from collections.abc import Callable
from operator import itemgetter
from typing import NamedTuple, TypeVar

import coal
import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.geometry.scene import Scene
from rrc_pin.solvers.collision.narrow_kernels import BOX, CAPSULE, SPHERE, narrow_phase
from rrc_pin.solvers.collision.proximity_kernels import joint_poses, near_pairs, world_centres

Array = npt.NDArray[np.float64]
Index = npt.NDArray[np.int64]
T = TypeVar("T")
Select = Callable[[Scene], npt.NDArray[np.bool_]]
"""Gives the pairs of a scene to answer for, as a mask (npairs,) over its pairs."""

ROWS = 5
"""Most rows of one pair: its closest points and four end points."""

REPEAT = 1e-6
"""[m] An end point's row whose witness points are both within this of its pair's own row
(coal's, found to GJK's tolerance) repeats it and is left out."""


class Proximity(NamedTuple):
    """The pairs whose signed distance is below the detection distance, one row each (k rows).

    Attributes:
        names: ``(name_a, name_b)`` of each pair (k,).
        distance: Signed distances (k,) [m], negative in penetration.
        point_a: Witness points (k, 3) on body A, world frame [m].
        point_b: Witness points (k, 3) on body B, world frame [m].
        normal: Unit normals (k, 3) from A to B, world frame (``p_b - p_a = d * normal``).
        joint_a: The joint (k,) body A moves with (a joint index of ``kin.model``; 0: the
            world).
        joint_b: The joint (k,) body B moves with.
        pair: The index (k,) of each row's pair in the scene's pairs
            (:attr:`~rrc_pin.geometry.CollisionModel.pairs` when queried).
    """

    names: tuple[tuple[str, str], ...]
    distance: Array
    point_a: Array
    point_b: Array
    normal: Array
    joint_a: Index
    joint_b: Index
    pair: Index


class CollisionData:
    """The per-caller state of proximity queries: one per resolver (one per thread).

    Holds a ``pinocchio.GeometryData`` (coal's results and cached solver guesses) and the
    broad phase's arrays; rebuilt when it meets a scene newer than its own (an obstacle added).
    Create it with :meth:`CollisionModel.create_data`; never share one between threads.
    """

    __slots__ = ("candidates", "distance", "end", "geometry_data", "normal", "other", "pair",
                 "point_a", "point_b", "poses", "scene", "world")  # fmt: skip

    def __init__(self, scene: Scene) -> None:
        self.refresh(scene)

    def refresh(self, scene: Scene) -> None:
        """Take ``scene`` as the one to answer for (new geometry data and arrays)."""
        self.scene = scene
        self.geometry_data = pin.GeometryData(scene.geometry)
        self.poses = np.zeros((scene.njoints, 4, 4))
        self.poses[0] = np.eye(4)
        self.world = np.zeros((len(scene.names), 3))
        npairs = len(scene.first)
        self.candidates = np.zeros(npairs, dtype=np.int64)
        self.other = np.zeros(npairs, dtype=np.int64)
        # a pair's row and its end points' (rrc_pin.solvers.collision.narrow_kernels)
        rows = ROWS * npairs
        self.pair = np.zeros(rows, dtype=np.int64)
        self.distance = np.zeros(rows)
        self.point_a = np.zeros((rows, 3))
        self.point_b = np.zeros((rows, 3))
        self.normal = np.zeros((rows, 3))
        self.end = np.zeros(rows, dtype=np.int8)


def query(scene: Scene, model: pin.Model, q: Array, placed: Callable[[], pin.Data],
          cdata: CollisionData, detection: float, ends: bool = False,
          select: Select | None = None) -> Proximity:  # fmt: skip
    """The :class:`Proximity` of ``scene`` at joint positions ``q`` (module docstring).

    Args:
        scene: The scene to answer for.
        model: The robot's ``pinocchio.Model``.
        q: Joint positions (nv,) [rad or m], one coordinate per joint.
        placed: Gives the ``pinocchio.Data`` holding the joint placements ``oMi`` at ``q``
            (called only when a pair is near: the narrow phase reads it).
        cdata: The caller's :class:`CollisionData` (refreshed if older than ``scene``).
        detection: Detection distance [m]: pairs with a signed distance below it are rows.
        ends: Also the rows of the capsules' end points
        (:mod:`rrc_pin.solvers.collision.narrow_kernels`): a
            pair may then have several rows, its first its closest points.
        select: Gives the pairs of ``scene`` to answer for ((npairs,) mask), or None: all.
    """
    if cdata.scene is not scene:
        cdata.refresh(scene)
    poses = cdata.poses
    tree = scene.tree
    if tree is not None:
        joint_poses(q, tree.parent, tree.rotation, tree.translation, tree.kind, tree.axis,
                    tree.coordinate, poses)  # fmt: skip
    else:
        poses[:] = [M.homogeneous for M in placed().oMi.tolist()]
    world_centres(poses, scene.joint, scene.centre, cdata.world)
    count = near_pairs(scene.first, scene.second, cdata.world, scene.radius, scene.normal,
                       scene.offset, detection, cdata.candidates)  # fmt: skip
    if count == 0:
        return EMPTY
    keep = scene.every if select is None else select(scene)
    rows, others = narrow_phase(poses, scene.joint, scene.shape, scene.segment, scene.size,
                                scene.box_frame, scene.half, scene.normal, scene.offset,
                                scene.first, scene.second, cdata.candidates, count, keep,
                                detection, ends, cdata.pair, cdata.distance, cdata.point_a,
                                cdata.point_b, cdata.normal, cdata.end, cdata.other)  # fmt: skip
    if others:
        rows = _coal(scene, model, placed(), cdata, detection, rows, others, ends)
    if rows == 0:
        return EMPTY
    index = cdata.pair[:rows].copy()
    taken: slice | Index = slice(0, rows)
    if others:  # coal's rows came last: each pair's own row first, then its end points'
        order = np.argsort(2 * index + cdata.end[:rows], kind="stable")
        order = order[_distinct(order, cdata)]
        index, taken = index[order], order
    names = scene.pair_names
    return Proximity(
        names=gather(names, index),
        distance=cdata.distance[taken].copy(),
        point_a=cdata.point_a[taken].copy(),
        point_b=cdata.point_b[taken].copy(),
        normal=cdata.normal[taken].copy(),
        joint_a=scene.joint[scene.first[index]],
        joint_b=scene.joint[scene.second[index]],
        pair=index,
    )


def gather(items: tuple[T, ...], index: Index) -> tuple[T, ...]:
    """``items[index[r]]`` for every r, in one C-level gather (not a Python loop)."""
    if index.size > 1:
        out: tuple[T, ...] = itemgetter(*index.tolist())(items)
        return out
    return (items[int(index[0])],) if index.size else ()


def _coal(scene: Scene, model: pin.Model, data: pin.Data, cdata: CollisionData,
          detection: float, rows: int, others: int, ends: bool) -> int:  # fmt: skip
    """Append coal's rows for the ``others`` candidates of other shapes after ``rows``.

    With ``ends``, a capsule against a shape the compiled phase leaves to coal (a hull, a
    cylinder, a mesh; a box that is the pair's first body) also gets its end points' rows here:
    each end as a sphere of the capsule's radius against the other body, as the compiled phase
    does for a capsule against a box.

    Returns:
        The number of rows now written.
    """
    gdata = cdata.geometry_data
    geometry = scene.geometry
    pin.updateGeometryPlacements(model, data, geometry, gdata)
    for k in cdata.other[:others].tolist():
        result = pin.computeDistance(geometry, gdata, k)
        if result.min_distance >= detection:
            continue
        a, b = int(scene.first[k]), int(scene.second[k])
        rows = _coal_row(scene, cdata, k, result, 0, rows)
        if not ends:
            continue
        for side, g, o in ((0, a, b), (1, b, a)):
            if scene.shape[g] != CAPSULE or scene.shape[o] in (CAPSULE, SPHERE) or (
                side == 0 and scene.shape[o] == BOX  # the compiled phase wrote these ends
            ):
                continue
            sphere = coal.Sphere(float(scene.size[g]))
            other = geometry.geometryObjects[o].geometry
            M = cdata.poses[scene.joint[g]]
            there = coal.Transform3s(gdata.oMg[o].rotation, gdata.oMg[o].translation)
            for e in range(2):
                centre = M[:3, :3] @ scene.segment[g, e] + M[:3, 3]
                at = coal.Transform3s(np.eye(3), centre)
                end_result = coal.DistanceResult()
                if side == 0:
                    coal.distance(sphere, at, other, there, coal.DistanceRequest(), end_result)
                else:
                    coal.distance(other, there, sphere, at, coal.DistanceRequest(), end_result)
                if end_result.min_distance < detection:
                    rows = _coal_row(scene, cdata, k, end_result, 1, rows)
    return rows


def _coal_row(scene: Scene, cdata: CollisionData, k: int, result: coal.DistanceResult,
              end: int, rows: int) -> int:  # fmt: skip
    """Write coal's ``result`` for pair ``k`` as row ``rows`` (``end``: an end point's)."""
    d = result.min_distance
    cdata.pair[rows] = k
    cdata.end[rows] = end
    cdata.distance[rows] = d
    point_a, point_b = result.getNearestPoint1(), result.getNearestPoint2()
    cdata.point_a[rows] = point_a
    cdata.point_b[rows] = point_b
    centres = cdata.world[scene.second[k]] - cdata.world[scene.first[k]]
    cdata.normal[rows] = _unit(result.normal, d, point_a, point_b, centres)
    return rows + 1


def _distinct(order: Index, cdata: CollisionData) -> npt.NDArray[np.bool_]:
    """Which rows of ``order`` (sorted: a pair's own row, then its end points') to keep.

    An end point's row that repeats its pair's own (coal's closest points at a capsule's end
    against a box, within :data:`REPEAT`) is left out.
    """
    end = cdata.end[order] == 1
    keep = np.ones(order.size, dtype=np.bool_)
    if not end.any():
        return keep
    first = np.maximum.accumulate(np.where(end, 0, np.arange(order.size)))
    own = order[first]
    same = (np.abs(cdata.point_a[order] - cdata.point_a[own]).max(axis=1) <= REPEAT) & (
        np.abs(cdata.point_b[order] - cdata.point_b[own]).max(axis=1) <= REPEAT)  # fmt: skip
    keep[end & same & (cdata.pair[order] == cdata.pair[own])] = False
    return keep


def _unit(normal: Array, distance: float, point_a: Array, point_b: Array,
          centres: Array) -> Array:  # fmt: skip
    """The ``normal`` (3,) of coal made unit.

    coal gives a normal for every pair it measures (EPA's in penetration); should one come
    back zero, the row takes ``(p_b - p_a) / d``, else (witnesses that coincide) the direction
    between the two bodies' bounding-sphere centres (``centres``: B's minus A's), so that no
    row is lost.
    """
    for direction in (normal, (point_b - point_a) * np.sign(distance), centres):
        size = float(np.linalg.norm(direction))
        if size > 1e-12:
            out: Array = direction / size
            return out
    return np.array([0.0, 0.0, 1.0])


def _empty() -> Proximity:
    empty = Proximity((), np.zeros(0), np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, 3)),
                      np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64),
                      np.zeros(0, dtype=np.int64))  # fmt: skip
    for array in empty[1:]:
        array.flags.writeable = False
    return empty


EMPTY = _empty()
"""The answer with no row (read-only arrays, shared: building it costs 4 us a tick)."""
