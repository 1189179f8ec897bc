"""One tick's proximity query: the pairs closer than a detection distance, with witnesses.

One compiled pass (:mod:`rrc_pin.solvers.collision.collision_pass`) runs the steps in the order
data flows:

1. the joint placements of the tick, from q by the compiled forward kinematics of
   :mod:`~rrc_pin.geometry.tree` (with their Jacobians where damper rows are asked for), or
   read from Pinocchio's ``data.oMi`` (and ``data.J``) for a model it does not cover;
2. the broad phase: bounding-sphere centres in the world, and the pairs whose distance bound is
   below the detection distance;
3. the narrow phase for those candidates only, keeping those below the detection distance:
   pairs of spheres, capsules and half-spaces measured in the pass (also the capsules'
   end-point rows when asked), the others (boxes, cylinders, hulls, meshes) left for coal where
   a sphere's or capsule's exact distance to their bounding sphere is below it too; coal then
   measures those (``pinocchio.updateGeometryPlacements``, then ``pinocchio.computeDistance``
   per pair: signed distance, EPA in penetration), here;
4. for the collision limit, the damper row of each row (in the pass when coal had nothing).

Conventions of a :class:`Proximity` row (coal's): the witness points ``p_a`` on body A and
``p_b`` on body B, world frame; the signed distance ``d`` (negative in penetration); the unit
``normal`` from A to B, also in penetration, with ``p_b - p_a = d * normal``: moving B along
``+normal`` (or A along ``-normal``) increases ``d``.
"""

from __future__ import annotations

from collections.abc import Callable
from operator import itemgetter
from typing import Any, NamedTuple, TypeVar

import coal
import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.geometry.scene import Scene
from rrc_pin.solvers.collision.collision_pass import collision_pass, pair_rows
from rrc_pin.solvers.collision.narrow_kernels import BOX, CAPSULE, SPHERE
from rrc_pin.solvers.collision.records import FOUND, SETTINGS

Array = npt.NDArray[np.float64]
Index = npt.NDArray[np.int64]
Records = npt.NDArray[np.void]
T = TypeVar("T")
Select = Callable[[Scene], npt.NDArray[np.bool_]]
"""Gives the pairs of a scene to answer for, as a mask (npairs,) over its pairs."""

ROWS = 6
"""Most rows of one pair: its closest points and four end points (two capsules); a capsule
against a box, its two end points and up to three features' rows
(:mod:`rrc_pin.solvers.collision.box_kernels`)."""

REPEAT = 1e-6
"""[m] An end point's row whose witness points are both within this of its pair's own row
(coal's, found to GJK's tolerance) repeats it and is left out."""


GJK_TOLERANCE = 1e-10
r"""[m] coal's GJK tolerance :math:`\tau` for the pairs it measures: GJK stops where the
distance is within :math:`\tau(1 + \|v\|)` of its iterate's :math:`\|v\|`. Where the closest
points are not unique (a capsule lying along a box's face) the iterate may stop a tangential
offset :math:`\delta` from them, :math:`\|v\| - d \approx \delta^2 / 2d`, so the normal tilts
by up to :math:`\theta \approx \sqrt{2\tau(1 + d)/d}`, and the damper row with it, which then
takes :math:`\sin\theta` of the speed it removes into the pair from the speed along it. coal's
default, 1e-6, is 0.01 rad at d = 0.02 m (panda's finger sliding on a tilted slab: 0.39 deg,
1.1 % of its tangential speed; where GJK stops depends on the solver's cached state, so the
same configuration gave different rows from one call to the next); 1e-10 is 1e-4 rad there,
less farther (CHANGELOG.md: its cost and the recorded ticks)."""


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
    compiled pass's arrays (placements, Jacobians, the rows found, their damper rows); rebuilt
    when it meets a scene newer than its own (an obstacle added). Create it with
    :meth:`CollisionModel.create_data`; never share one between threads.
    """

    __slots__ = ("G", "J", "_bound", "candidates", "distance", "found", "geometry_data", "h",
                 "other", "pair", "poses", "scene", "world")  # fmt: skip

    def __init__(self, scene: Scene) -> None:
        self.refresh(scene)

    def refresh(self, scene: Scene) -> None:
        """Take ``scene`` as the one to answer for (new geometry data and arrays)."""
        self.scene = scene
        self.geometry_data = pin.GeometryData(scene.geometry)
        for request in self.geometry_data.distanceRequests:
            request.gjk_tolerance = GJK_TOLERANCE
        self.poses = np.zeros((scene.njoints, 4, 4))
        self.poses[0] = np.eye(4)
        self.J = np.zeros((6, scene.nv))
        self.world = np.zeros((len(scene.names), 3))
        npairs = len(scene.first)
        self.candidates = np.zeros(npairs, dtype=np.int64)
        self.other = np.zeros(npairs, dtype=np.int64)
        rows = ROWS * npairs  # a pair's row and its end points' (narrow_kernels)
        self.found = np.zeros(rows, dtype=FOUND)
        self.distance, self.pair = self.found["distance"], self.found["pair"]  # views, kept
        self.G = np.zeros((rows, scene.nv))
        self.h = np.zeros(rows)
        self._bound: tuple[Records | None, npt.NDArray[np.bool_] | None, tuple[Any, ...]] = (
            None, None, ())  # fmt: skip

    def arguments(self, settings: Records, keep: npt.NDArray[np.bool_]) -> tuple[Any, ...]:
        """:func:`collision_pass`'s arguments after q, kept while ``settings`` and ``keep`` are
        the same arrays."""  # noqa: D205, D209
        bound = self._bound
        if bound[0] is not settings or bound[1] is not keep:
            s = self.scene
            arguments = (s.joints, s.bodies, s.first, s.second, keep, settings, s.support,
                         self.poses, self.J, self.world, self.candidates, self.other, self.found,
                         self.G, self.h)  # fmt: skip
            bound = self._bound = (settings, keep, arguments)
        return bound[2]

    def copies(self, rows: int) -> tuple[Array, Array, Array, Index]:
        """Copies of the first ``rows`` damper rows ``G`` (rows, nv) and bounds ``h`` (rows,),
        and of the found rows' distances (rows,) [m] and pairs (rows,): what a tick's
        constraints keep while the pass's arrays are written again."""  # noqa: D205, D209
        return (self.G[:rows].copy(), self.h[:rows].copy(), self.distance[:rows].copy(),
                self.pair[:rows].copy())  # fmt: skip


def search(detection: float, ends: bool) -> Records:
    """The settings (1,) of a query without damper rows (:data:`SETTINGS`)."""
    settings = np.zeros(1, dtype=SETTINGS)
    settings["detection"], settings["ends"] = detection, ends
    return settings


def query(scene: Scene, model: pin.Model, q: Array, placed: Callable[[], pin.Data],
          cdata: CollisionData, detection: float, ends: bool = False,
          select: Select | None = None) -> Proximity:  # fmt: skip
    """The :class:`Proximity` of ``scene`` at joint positions ``q`` (module docstring).

    Args:
        scene: The scene to answer for.
        model: The robot's ``pinocchio.Model``.
        q: Joint positions (nv,) [rad or m], one coordinate per joint.
        placed: Gives the ``pinocchio.Data`` holding the joint placements ``oMi`` at ``q``
            (called only where the compiled forward kinematics does not cover the model, or
            coal has pairs to measure).
        cdata: The caller's :class:`CollisionData` (refreshed if older than ``scene``).
        detection: Detection distance [m]: pairs with a signed distance below it are rows.
        ends: Also the rows of the capsules' end points
            (:mod:`rrc_pin.solvers.collision.narrow_kernels`): a pair may then have several
            rows, its first its closest points.
        select: Gives the pairs of ``scene`` to answer for ((npairs,) mask), or None: all.
    """
    keep = scene.every if select is None else select(scene)
    rows, _ = measure(scene, model, q, placed, cdata, search(detection, ends), keep)
    return proximity_of(cdata, rows)


def measure(scene: Scene, model: pin.Model, q: Array, placed: Callable[[], pin.Data],
            cdata: CollisionData, settings: Records,
            keep: npt.NDArray[np.bool_]) -> tuple[int, int]:  # fmt: skip
    """Run the pass at ``q`` into ``cdata``: the rows found, and their damper rows if asked.

    Args:
        scene: The scene to answer for.
        model: The robot's ``pinocchio.Model``.
        q: Joint positions (nv,) [rad or m], one coordinate per joint.
        placed: Gives the ``pinocchio.Data`` at ``q`` with every joint's placement and
            Jacobian (called only where the compiled forward kinematics does not cover the
            model, or coal has pairs to measure).
        cdata: The caller's :class:`CollisionData` (refreshed if older than ``scene``).
        settings: One :data:`SETTINGS` record (1,): the detection distance, the end points'
            rows, the damper rows and their parameters.
        keep: The pairs of ``scene`` to answer for ((npairs,) mask).

    Returns:
        rows: The number of rows in ``cdata.found`` (each pair's own row, then its end
        points'; pairs in the scene's order); ``unmoved``: how many of them no joint moves
        (with damper rows, in ``cdata.G`` and ``cdata.h``; else 0).
    """
    if cdata.scene is not scene:
        cdata.refresh(scene)
    if scene.tree is None:
        data = placed()
        cdata.poses[:] = [M.homogeneous for M in data.oMi.tolist()]
        if settings["rows"][0]:
            cdata.J[:] = data.J
    rows, others, unmoved = collision_pass(q, *cdata.arguments(settings, keep))
    if others:
        rows = _coal(scene, model, placed(), cdata, float(settings["detection"][0]), rows, others,
                     bool(settings["ends"][0]))  # fmt: skip
        if settings["rows"][0]:
            unmoved = pair_rows(cdata.J, scene.support, scene.bodies, scene.first, scene.second,
                                settings, cdata.found, rows, cdata.G, cdata.h)  # fmt: skip
    return rows, unmoved


def proximity_of(cdata: CollisionData, rows: int) -> Proximity:
    """The :class:`Proximity` of the first ``rows`` rows of ``cdata`` (copies)."""
    if rows == 0:
        return EMPTY
    scene = cdata.scene
    found = cdata.found[:rows]
    index = found["pair"].copy()
    return Proximity(
        names=gather(scene.pair_names, index),
        distance=found["distance"].copy(),
        point_a=found["point_a"].copy(),
        point_b=found["point_b"].copy(),
        normal=found["normal"].copy(),
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
    does for a capsule against a box. The rows are then put in order (each pair's own row
    first, then its end points', pairs in the scene's order).

    Returns:
        The number of rows now written.
    """
    gdata = cdata.geometry_data
    geometry = scene.geometry
    shape, radius, segment = scene.bodies["shape"], scene.bodies["radius"], scene.bodies["segment"]
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
            if shape[g] != CAPSULE or shape[o] in (CAPSULE, SPHERE) or (
                side == 0 and shape[o] == BOX  # the compiled phase wrote these ends
            ):
                continue
            sphere = coal.Sphere(float(radius[g]))
            other = geometry.geometryObjects[o].geometry
            M = cdata.poses[scene.joint[g]]
            there = coal.Transform3s(gdata.oMg[o].rotation, gdata.oMg[o].translation)
            request = coal.DistanceRequest()
            request.gjk_tolerance = GJK_TOLERANCE
            for e in range(2):
                centre = M[:3, :3] @ segment[g, e] + M[:3, 3]
                at = coal.Transform3s(np.eye(3), centre)
                end_result = coal.DistanceResult()
                if side == 0:
                    coal.distance(sphere, at, other, there, request, end_result)
                else:
                    coal.distance(other, there, sphere, at, request, end_result)
                if end_result.min_distance < detection:
                    rows = _coal_row(scene, cdata, k, end_result, 1, rows)
    found = cdata.found
    order = np.argsort(3 * found["pair"][:rows] + found["end"][:rows], kind="stable")
    order = order[_distinct(found[order])]
    found[: order.size] = found[order]
    return int(order.size)


def _coal_row(scene: Scene, cdata: CollisionData, k: int, result: coal.DistanceResult,
              end: int, rows: int) -> int:  # fmt: skip
    """Write coal's ``result`` for pair ``k`` as row ``rows`` (``end``: an end point's)."""
    d = result.min_distance
    point_a, point_b = result.getNearestPoint1(), result.getNearestPoint2()
    centres = cdata.world[scene.second[k]] - cdata.world[scene.first[k]]
    row = cdata.found[rows]
    row["pair"], row["end"], row["distance"] = k, end, d
    row["point_a"], row["point_b"] = point_a, point_b
    row["normal"] = _unit(result.normal, d, point_a, point_b, centres)
    return rows + 1


def _distinct(rows: Records) -> npt.NDArray[np.bool_]:
    """Which of ``rows`` (sorted: a pair's own row, then its end points') to keep.

    An end point's row that repeats its pair's own (coal's closest points at a capsule's end
    against a box, within :data:`REPEAT`) is left out.
    """
    end = rows["end"] != 0
    keep = np.ones(rows.size, dtype=np.bool_)
    if not end.any():
        return keep
    own = rows[np.maximum.accumulate(np.where(end, 0, np.arange(rows.size)))]
    same = (np.abs(rows["point_a"] - own["point_a"]).max(axis=1) <= REPEAT) & (
        np.abs(rows["point_b"] - own["point_b"]).max(axis=1) <= REPEAT)  # fmt: skip
    keep[end & same & (rows["pair"] == own["pair"])] = False
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
"""The answer with no row (read-only arrays, shared)."""
