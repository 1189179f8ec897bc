"""One proximity query and its damper rows in one compiled call, the stages in the order data flows.

1. the joints' placements and WORLD Jacobians from q
   (:func:`~rrc_pin.solvers.collision.proximity_kernels.joint_poses`,
   :func:`~rrc_pin.solvers.collision.proximity_kernels.joint_jacobians`), or given by the caller
   for a model the compiled forward kinematics does not cover;
2. the broad phase: bounding-sphere centres in the world and the asked pairs whose bound is
   below the detection distance (:func:`~rrc_pin.solvers.collision.proximity_kernels.near_pairs`);
3. the narrow phase of those pairs: spheres, capsules and half-spaces measured, other shapes
   returned for coal (:func:`~rrc_pin.solvers.collision.narrow_kernels.narrow_phase`);
4. the damper row of each row found (:func:`pair_rows`), when nothing is left for coal (coal's
   rows are merged by the caller, then :func:`pair_rows` runs over all of them).

The scene's bodies, the joints and the rows are records
(:mod:`rrc_pin.solvers.collision.records`): the call takes 16 arguments, where one array per
field took 49.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.collision.damper_kernels import SLACK, damper_rows
from rrc_pin.solvers.collision.narrow_kernels import FEATURE, narrow_phase
from rrc_pin.solvers.collision.proximity_kernels import (
    joint_jacobians,
    joint_poses,
    near_pairs,
    world_centres,
)
from rrc_pin.solvers.compiled import kernel

Array = npt.NDArray[np.float64]
Index = npt.NDArray[np.int64]
Records = npt.NDArray[np.void]


@kernel
def collision_pass(
    q: Array,
    joints: Records,
    bodies: Records,
    first: Index,
    second: Index,
    keep: npt.NDArray[np.bool_],
    settings: Records,
    support: npt.NDArray[np.bool_],
    poses: Array,
    J: Array,
    world: Array,
    candidates: Index,
    other: Index,
    found: Records,
    G: Array,
    h: Array,
) -> tuple[int, int, int]:
    """The rows of the pairs within the detection distance at ``q`` (module docstring).

    Args:
        q: Joint positions (nv,) [rad or m], one coordinate per joint.
        joints: The kinematic tree (nj,), :data:`~rrc_pin.solvers.collision.records.JOINT`
            records; empty where ``poses`` and ``J`` hold the placements and Jacobians.
        bodies: The scene's bodies (ng,), :data:`~rrc_pin.solvers.collision.records.BODY`.
        first: First body (npairs,) of each pair.
        second: Second body (npairs,).
        keep: Whether each pair (npairs,) is asked for.
        settings: One :data:`~rrc_pin.solvers.collision.records.SETTINGS` record (1,).
        support: (nj, nv) whether rate c moves joint j (row 0, the world: none).
        poses: Joint placements (nj, 4, 4) in the world frame (written from q with a tree).
        J: Every joint's WORLD Jacobian (6, nv) (written from q with a tree and ``rows``).
        world: Out (ng, 3): bounding-sphere centres in the world [m].
        candidates: Out (npairs,): the broad phase's pairs.
        other: Out (npairs,): the pairs left for coal.
        found: Out (6 npairs,) :data:`~rrc_pin.solvers.collision.records.FOUND` rows.
        G: Out (6 npairs, nv): each found row's damper row (with ``rows``, nothing for coal).
        h: Out (6 npairs,) [m/s]: its bound.

    Returns:
        rows: The number of rows found; ``others``: the number of pairs left for coal;
        ``unmoved``: the number of found rows no joint moves (0 where no damper row was
        written).
    """
    s = settings[0]
    if joints.shape[0] > 0:
        joint_poses(q, joints["parent"], joints["rotation"], joints["translation"],
                    joints["kind"], joints["axis"], joints["coordinate"], poses)  # fmt: skip
        if s["rows"]:
            joint_jacobians(poses, joints["kind"], joints["axis"], joints["coordinate"], J)
    world_centres(poses, bodies["joint"], bodies["centre"], world)
    count = near_pairs(first, second, world, bodies["bounding"], bodies["normal"],
                       bodies["offset"], s["detection"], keep, candidates)  # fmt: skip
    rows, others = narrow_phase(poses, bodies, world, first, second, candidates, count, keep,
                                s["detection"], s["ends"], found, other)  # fmt: skip
    unmoved = 0
    if s["rows"] and others == 0:
        unmoved = pair_rows(J, support, bodies, first, second, settings, found, rows, G, h)
    return rows, others, unmoved


@kernel
def pair_rows(
    J: Array,
    support: npt.NDArray[np.bool_],
    bodies: Records,
    first: Index,
    second: Index,
    settings: Records,
    found: Records,
    rows: int,
    G: Array,
    h: Array,
) -> int:
    """The damper rows ``G qdot <= h`` of the first ``rows`` found rows.

    Writes each row's joints (``joint_a``, ``joint_b``) and ``moved``; the damper's parameters
    from ``settings`` (:func:`~rrc_pin.solvers.collision.damper_kernels.damper_rows`). A box
    feature's row farther than its pair's own is never pushed out (at least ``SLACK``): the
    push restores the pair's distance, which is its own row's.

    Returns:
        The number of rows no joint moves.
    """
    joint, pair = bodies["joint"], found["pair"]
    joint_a, joint_b = found["joint_a"], found["joint_b"]
    for r in range(rows):
        joint_a[r] = joint[first[pair[r]]]
        joint_b[r] = joint[second[pair[r]]]
    s = settings[0]
    distance = found["distance"]
    unmoved = damper_rows(J, support, joint_a[:rows], joint_b[:rows], found["point_a"][:rows],
                          found["point_b"][:rows], found["normal"][:rows], distance[:rows],
                          pair[:rows], s["safety"], s["detection"], s["xi"], s["xi_end"],
                          s["blend"], s["band"], s["recovery"], s["still"], G[:rows], h[:rows],
                          found["moved"][:rows])  # fmt: skip
    own = 0.0
    for r in range(rows):
        if found["end"][r] == 0:
            own = distance[r]
        elif found["end"][r] == FEATURE and distance[r] > own:
            h[r] = max(h[r], SLACK)  # a feature's row holds or damps, never pushes out
    return unmoved

