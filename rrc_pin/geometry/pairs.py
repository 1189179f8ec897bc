"""Which pairs of a robot's bodies a collision check leaves out, and why.

A pair is left out (with its reason) when:

- ``rigid``: both bodies move with the same joint (one link, or links joined by fixed joints,
  or two bodies fixed to the world): their distance never changes, no joint rate can act on it;
- ``adjacent``: one body's joint is the other's parent joint: links joined by a joint touch at
  that joint by design;
- ``srdf``: the robot's SRDF disables the two links (``pinocchio.removeCollisionPairs``);
- ``always``: a paper arm's links whose capsules overlap at every configuration
  (:func:`rrc_pin.link_capsules.always_touching`: a spherical wrist);
- ``ready``: of the pairs left, those already in contact at the robot's ready configuration
  (MoveIt's "default" rule: bodies that touch in the robot's own start pose overlap by
  construction: a cover over a joint, the K-1607's wrist, whose offsets a5 = -a6 bring link 7
  back onto the forearm's axis).

Every other pair of the robot's bodies is active.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
import numpy.typing as npt
import pinocchio as pin

Reason = Literal["rigid", "adjacent", "srdf", "always", "ready"]
REASONS: tuple[str, ...] = ("adjacent", "always", "ready", "rigid", "srdf")
Pair = tuple[int, int]


def all_pairs(count: int) -> list[Pair]:
    """Every pair ``(i, j)`` of ``count`` objects, ``i < j``, in order."""
    return [(i, j) for i in range(count) for j in range(i + 1, count)]


def kinematic_reason(model: pin.Model, joint_a: int, joint_b: int) -> Reason | None:
    """``rigid`` or ``adjacent`` for bodies on these joints of ``model``, else None."""
    if joint_a == joint_b:
        return "rigid"
    if model.parents[joint_a] == joint_b or model.parents[joint_b] == joint_a:
        return "adjacent"
    return None


def in_contact(
    model: pin.Model,
    geometry: pin.GeometryModel,
    pairs: list[Pair],
    q_pin: npt.NDArray[np.float64],
) -> list[bool]:
    """For each pair, whether its bodies touch or overlap (distance <= 0) at ``q_pin``."""
    if not pairs:
        return []
    probe = pin.GeometryModel()
    for obj in geometry.geometryObjects:
        probe.addGeometryObject(obj)
    for i, j in pairs:
        probe.addCollisionPair(pin.CollisionPair(i, j))
    data, gdata = model.createData(), probe.createData()
    pin.computeDistances(model, data, probe, gdata, q_pin)
    return [result.min_distance <= 0.0 for result in gdata.distanceResults]
