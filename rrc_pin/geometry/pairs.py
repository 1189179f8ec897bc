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
  back onto the forearm's axis);
- ``invariant``: a pair whose distance no joint changes (:func:`invariant`): a body that turns
  about its own axis of symmetry (panda_link1's capsule about joint 1) against the world, or
  against a body that turns about its own axis too; a SCARA's links over a floor. Its row
  would be zero, or the rounding of a zero (coal's witness points), and a start inside the
  safety distance could never leave it.

Every other pair of the robot's bodies is active.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Literal

import numpy as np
import numpy.typing as npt
import pinocchio as pin

Reason = Literal["rigid", "adjacent", "srdf", "always", "ready", "invariant"]
REASONS: tuple[str, ...] = ("adjacent", "always", "invariant", "ready", "rigid", "srdf")
Pair = tuple[int, int]

SAMPLES = 64
"""Configurations at which :func:`invariant` measures each pair (its early ones end the
search for almost every pair: a distance that changes changes at once)."""

INVARIANT_TOL = 1e-5
"""[m] A pair whose distance stays within this of its value at the first configuration over
every sample is ``invariant``: dropped, it can come at most this much closer. Ten times coal's
scatter on pairs that are invariant: 1.1e-6 m (GJK, a capsule turning about its axis against
a cylinder, 2,000 configurations), 2e-16 against a box.
"""


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


def invariant(
    model: pin.Model, geometry: pin.GeometryModel, pairs: list[Pair]
) -> dict[Pair, float]:
    """The pairs of ``geometry``'s objects whose distance no joint of ``model`` changes.

    Only the joints that move one body and not the other (the symmetric difference of their
    supports) can change a pair's distance; the others move both bodies as one or neither.
    Where every such joint has one coordinate (revolute, prismatic, continuous), the pair is
    measured at :data:`SAMPLES` configurations drawn within the joints' limits (a fixed
    seed: the answer is the same at every call), and it is invariant where the distance never
    leaves its first value by more than :data:`INVARIANT_TOL`. A pair moved by a joint of
    several coordinates (a free-flyer root against the world) is never invariant.

    Args:
        model: The robot's model.
        geometry: Its objects (on joints of ``model``), the world's on joint 0.
        pairs: Object index pairs to decide.

    Returns:
        The invariant pairs and their distance [m] (signed: negative in penetration).
    """
    objects = geometry.geometryObjects
    supports = [set(model.supports[j].tolist()[1:]) for j in range(model.njoints)]
    single = [model.joints[j].nv == 1 and model.joints[j].nq in (1, 2)
              for j in range(model.njoints)]  # fmt: skip
    candidates = []
    for a, b in pairs:
        moving = supports[objects[a].parentJoint] ^ supports[objects[b].parentJoint]
        if moving and all(single[j] for j in moving):
            candidates.append((a, b))
    if not candidates:
        return {}
    probe = pin.GeometryModel()
    for obj in objects:
        probe.addGeometryObject(obj)
    for a, b in candidates:
        probe.addCollisionPair(pin.CollisionPair(a, b))
    data, gdata = model.createData(), probe.createData()
    sample = _sampler(model, single)

    def measured(alive: list[int]) -> npt.NDArray[np.float64]:
        pin.forwardKinematics(model, data, sample())
        pin.updateGeometryPlacements(model, data, probe, gdata)
        return np.array([pin.computeDistance(probe, gdata, k).min_distance for k in alive])

    alive = list(range(len(candidates)))
    first = measured(alive)
    for _ in range(SAMPLES - 1):
        keep = np.abs(measured(alive) - first) <= INVARIANT_TOL
        alive = [k for k, kept in zip(alive, keep.tolist(), strict=True) if kept]
        first = first[keep]
        if not alive:
            return {}
    return {candidates[k]: float(v) for k, v in zip(alive, first.tolist(), strict=True)}


def _sampler(model: pin.Model, single: list[bool]) -> Callable[[], npt.NDArray[np.float64]]:
    """Draws configurations (nq,) for :func:`invariant` (a fixed seed).

    Each joint of one coordinate within its limits (infinite sides at pi), a continuous one's
    angle in [-pi, pi], the others at their neutral value.
    """
    rng = np.random.default_rng(0)
    joints = [model.joints[j] for j in range(model.njoints)]
    one = np.array([jt.idx_q for jt, s in zip(joints, single, strict=True) if s and jt.nq == 1],
                   dtype=np.int64)  # fmt: skip
    two = np.array([jt.idx_q for jt, s in zip(joints, single, strict=True) if s and jt.nq == 2],
                   dtype=np.int64)  # fmt: skip
    low, high = model.lowerPositionLimit[one], model.upperPositionLimit[one]
    low = np.where(np.isfinite(low), low, -np.pi)
    high = np.where(np.isfinite(high), high, np.pi)
    neutral = pin.neutral(model)

    def sample() -> npt.NDArray[np.float64]:
        q: npt.NDArray[np.float64] = neutral.copy()
        u = rng.random(one.size + two.size)
        q[one] = low + (high - low) * u[: one.size]
        angle = np.pi * (2.0 * u[one.size :] - 1.0)
        q[two], q[two + 1] = np.cos(angle), np.sin(angle)
        return q

    return sample
