"""One tick's proximity query: the pairs closer than a detection distance, with witnesses.

The steps, in the order data flows:

1. the joint placements of the tick, from q by the compiled forward kinematics of
   :mod:`~rrc_pin.geometry.tree` (or read from Pinocchio's ``data.oMi`` for a model it does
   not cover);
2. the broad phase (:mod:`solvers.proximity_kernels`, compiled): bounding-sphere centres in
   the world, and the pairs whose distance bound is below the detection distance;
3. the narrow phase for those candidates only: ``pinocchio.updateGeometryPlacements``, then
   ``pinocchio.computeDistance`` per candidate (coal: signed distance, EPA in penetration),
   keeping those below the detection distance.

Conventions of a :class:`Proximity` row (coal's): the witness points ``p_a`` on body A and
``p_b`` on body B, world frame; the signed distance ``d`` (negative in penetration); the unit
``normal`` from A to B, also in penetration, with ``p_b - p_a = d * normal``: moving B along
``+normal`` (or A along ``-normal``) increases ``d``.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.geometry.scene import Scene
from solvers.proximity_kernels import joint_poses, near_pairs, world_centres

Array = npt.NDArray[np.float64]
Index = npt.NDArray[np.int64]


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
    """

    names: tuple[tuple[str, str], ...]
    distance: Array
    point_a: Array
    point_b: Array
    normal: Array
    joint_a: Index
    joint_b: Index


class CollisionData:
    """The per-caller state of proximity queries: one per resolver (one per thread).

    Holds a ``pinocchio.GeometryData`` (coal's results and cached solver guesses) and the
    broad phase's arrays; rebuilt when it meets a scene newer than its own (an obstacle added).
    Create it with :meth:`CollisionModel.create_data`; never share one between threads.
    """

    __slots__ = ("candidates", "geometry_data", "poses", "scene", "world")

    def __init__(self, scene: Scene) -> None:
        self.refresh(scene)

    def refresh(self, scene: Scene) -> None:
        """Take ``scene`` as the one to answer for (new geometry data and arrays)."""
        self.scene = scene
        self.geometry_data = pin.GeometryData(scene.geometry)
        self.poses = np.zeros((scene.njoints, 4, 4))
        self.poses[0] = np.eye(4)
        self.world = np.zeros((len(scene.names), 3))
        self.candidates = np.zeros(len(scene.first), dtype=np.int64)


def query(scene: Scene, model: pin.Model, q: Array, placed: Callable[[], pin.Data],
          cdata: CollisionData, detection: float) -> Proximity:  # fmt: skip
    """The :class:`Proximity` of ``scene`` at joint positions ``q`` (module docstring).

    Args:
        scene: The scene to answer for.
        model: The robot's ``pinocchio.Model``.
        q: Joint positions (nv,) [rad or m], one coordinate per joint.
        placed: Gives the ``pinocchio.Data`` holding the joint placements ``oMi`` at ``q``
            (called only when a pair is near: the narrow phase reads it).
        cdata: The caller's :class:`CollisionData` (refreshed if older than ``scene``).
        detection: Detection distance [m]: pairs with a signed distance below it are rows.
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
    gdata = cdata.geometry_data
    geometry = scene.geometry
    pin.updateGeometryPlacements(model, placed(), geometry, gdata)
    rows: list[int] = []
    distance: list[float] = []
    point_a: list[Array] = []
    point_b: list[Array] = []
    normal: list[Array] = []
    for k in cdata.candidates[:count].tolist():  # the few candidates, not every pair
        result = pin.computeDistance(geometry, gdata, k)
        d = result.min_distance
        if d < detection:
            rows.append(k)
            distance.append(d)
            point_a.append(result.getNearestPoint1())
            point_b.append(result.getNearestPoint2())
            normal.append(result.normal)
    if not rows:
        return EMPTY
    index = np.array(rows, dtype=np.int64)
    return Proximity(
        names=tuple(scene.pair_names[k] for k in rows),
        distance=np.array(distance),
        point_a=np.array(point_a),
        point_b=np.array(point_b),
        normal=_unit(np.array(normal), np.array(distance), np.array(point_a),
                     np.array(point_b),
                     cdata.world[scene.second[index]] - cdata.world[scene.first[index]]),
        joint_a=scene.joint[scene.first[index]],
        joint_b=scene.joint[scene.second[index]],
    )


def _unit(normal: Array, distance: Array, point_a: Array, point_b: Array,
          centres: Array) -> Array:  # fmt: skip
    """``normal`` rows (k, 3) made unit.

    coal gives a normal for every pair it measures (EPA's in penetration); should one come
    back zero, the row takes ``(p_b - p_a) / d``, else (witnesses that coincide) the direction
    between the two bodies' bounding-sphere centres (``centres``: B's minus A's), so that no
    row is lost.
    """
    norm = np.linalg.norm(normal, axis=1)
    bad = norm < 1e-12
    if bad.any():
        for k in np.flatnonzero(bad):
            gap = (point_b[k] - point_a[k]) * np.sign(distance[k])
            for direction in (gap, centres[k], np.array([0.0, 0.0, 1.0])):
                size = float(np.linalg.norm(direction))
                if size > 1e-12:
                    normal[k], norm[k] = direction, size
                    break
    out: Array = normal / norm[:, None]
    return out


def _empty() -> Proximity:
    empty = Proximity((), np.zeros(0), np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, 3)),
                      np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64))  # fmt: skip
    for array in empty[1:]:
        array.flags.writeable = False
    return empty


EMPTY = _empty()
"""The answer with no row (read-only arrays, shared: building it costs 4 us a tick)."""
