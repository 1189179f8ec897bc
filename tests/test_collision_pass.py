"""rrc_pin.solvers.collision.collision_pass: one compiled call against its references.

On two facing pandas (capsules) with a floor, a sphere and a capsule obstacle, at random
configurations: the placements and Jacobians against Pinocchio (1e-12), the pairs found against
coal over every pair (the same set, distances to 1e-9), each row against the narrow phase run
alone on every pair at Pinocchio's placements (1e-12), each damper row and bound against the
damper's formula written in numpy with Pinocchio's joint Jacobians (1e-12). With a hull in the
scene the pass leaves its pairs to coal and writes no damper row; :func:`pair_rows` then writes
them all.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import rrc_pin
from rrc_pin import CollisionModel
from rrc_pin.geometry.proximity import search
from rrc_pin.solvers.collision.collision_pass import collision_pass, pair_rows
from rrc_pin.solvers.collision.damper_kernels import damper_bound
from rrc_pin.solvers.collision.narrow_kernels import narrow_phase
from rrc_pin.solvers.collision.records import FOUND

SEEDS = (23, int(np.random.SeedSequence().entropy % 2**63))
"""A fixed seed and one drawn fresh each run (named in every failure's message)."""

SAFETY, DETECTION, XI, XI_END, BLEND, BAND, RECOVERY, STILL = (0.02, 0.15, 0.5, 4.0, 0.005,
                                                               1e-3, 50.0, 1e-9)  # fmt: skip


def settings():
    s = search(DETECTION, True)
    s["rows"], s["safety"], s["xi"], s["xi_end"] = True, SAFETY, XI, XI_END
    s["blend"], s["band"], s["recovery"], s["still"] = BLEND, BAND, RECOVERY, STILL
    return s


def scene(facing_pandas, hull=False):
    robot = facing_pandas(0.8)
    cm = CollisionModel(robot, "capsules")
    cm.add_halfspace((0, 0, 1), -0.05, name="floor")
    cm.add_sphere((0.4, 0.25, 0.5), 0.06, name="ball")
    T = np.eye(4)
    T[:3, 3] = (0.4, -0.25, 0.4)
    cm.add_capsule(T, 0.04, 0.3, name="bar")
    if hull:
        cm.add_convex(T, np.random.default_rng(0).normal(size=(12, 3)) * 0.06, name="rock")
    return robot, cm


def workspace(sc):
    npairs = len(sc.first)
    return dict(poses=np.zeros((sc.njoints, 4, 4)), J=np.zeros((6, sc.nv)),
                world=np.zeros((len(sc.names), 3)), candidates=np.zeros(npairs, np.int64),
                other=np.zeros(npairs, np.int64), found=np.zeros(5 * npairs, FOUND),
                G=np.zeros((5 * npairs, sc.nv)), h=np.zeros(5 * npairs))  # fmt: skip


def run(sc, q, w, s):
    return collision_pass(q, sc.joints, sc.bodies, sc.first, sc.second, sc.every, s, sc.support,
                          w["poses"], w["J"], w["world"], w["candidates"], w["other"],
                          w["found"], w["G"], w["h"])  # fmt: skip


def damper_reference(found, rows, J, support):
    """G (rows, nv) and h (rows,) of the module docstring of damper_kernels, in numpy."""
    G, h = np.zeros((rows, J.shape[1])), np.zeros(rows)
    span = DETECTION - SAFETY
    own = 0.0
    for r in range(rows):
        row = found[r]
        n = row["normal"]
        rates = []
        for j, p in ((row["joint_a"], row["point_a"]), (row["joint_b"], row["point_b"])):
            rates.append((n @ (J[:3] - pin.skew(p) @ J[3:])) * support[j])
        G[r] = -(rates[1] - rates[0])
        if r > 0 and found[r - 1]["pair"] == row["pair"]:
            gain = XI + (XI_END - XI) * np.clip((row["distance"] - own) / BLEND, 0.0, 1.0)
        else:
            gain, own = XI, row["distance"]
        h[r] = damper_bound(row["distance"] - SAFETY, span, gain, BAND, RECOVERY)
    return G, h


@pytest.mark.parametrize("seed", SEEDS, ids=("fixed", "fresh"))
def test_the_pass_matches_pinocchio_coal_and_its_stages(facing_pandas, seed):
    robot, cm = scene(facing_pandas)
    sc = cm.scene
    model = robot.model
    w = workspace(sc)
    rng = np.random.default_rng(seed)
    seen = 0
    for _ in range(30):
        q = np.clip(robot.ready() + rng.uniform(-0.8, 0.8, robot.nq), robot.lower, robot.upper)
        rows, others, unmoved = run(sc, q, w, settings())
        assert others == 0
        data = model.createData()
        pin.computeJointJacobians(model, data, robot.to_pinocchio(q))
        oMi = np.array([M.homogeneous for M in data.oMi.tolist()])
        np.testing.assert_allclose(w["poses"], oMi, atol=1e-12, err_msg=f"seed {seed}")
        np.testing.assert_allclose(w["J"], data.J, atol=1e-12, err_msg=f"seed {seed}")
        gdata = sc.geometry.createData()
        pin.computeDistances(model, data, sc.geometry, gdata, robot.to_pinocchio(q))
        every = np.array([r.min_distance for r in gdata.distanceResults])
        found = w["found"][:rows]
        own = found[found["end"] == 0]
        assert set(own["pair"].tolist()) == set(np.flatnonzero(every < DETECTION).tolist())
        np.testing.assert_allclose(own["distance"], every[own["pair"]], atol=1e-9)
        alone = np.zeros(w["found"].size, FOUND)  # every pair, no broad phase
        count = narrow_phase(oMi, sc.bodies, w["world"], sc.first, sc.second,
                             np.arange(len(sc.first)), len(sc.first), sc.every, DETECTION, True,
                             alone, np.zeros(len(sc.first), np.int64))[0]  # fmt: skip
        assert count == rows
        for field in ("pair", "end", "distance", "point_a", "point_b", "normal"):
            np.testing.assert_allclose(found[field], alone[field][:rows], atol=1e-12)
        G, h = damper_reference(found, rows, data.J, sc.support)
        np.testing.assert_allclose(w["G"][:rows], G, atol=1e-12, err_msg=f"seed {seed}")
        np.testing.assert_allclose(w["h"][:rows], h, atol=1e-12, err_msg=f"seed {seed}")
        moved = np.abs(G).max(axis=1, initial=0.0) > STILL
        np.testing.assert_array_equal(found["moved"], moved)
        assert unmoved == rows - np.count_nonzero(moved)
        seen += rows
    assert seen > 100, f"seed {seed}: {seen} rows"


def test_pairs_left_for_coal_get_no_damper_row_in_the_pass(facing_pandas):
    """With a hull near, the pass stops before the damper rows; :func:`pair_rows` writes them
    over every row the caller hands it (the limit merges coal's rows first)."""
    robot, cm = scene(facing_pandas, hull=True)
    sc = cm.scene
    w = workspace(sc)
    rng = np.random.default_rng(29)
    left = 0
    for _ in range(30):
        q = np.clip(robot.ready() + rng.uniform(-0.8, 0.8, robot.nq), robot.lower, robot.upper)
        w["G"][:] = np.nan
        rows, others, unmoved = run(sc, q, w, settings())
        if not others:
            continue
        left += 1
        assert unmoved == 0 and np.isnan(w["G"]).all()
        unmoved = pair_rows(w["J"], sc.support, sc.bodies, sc.first, sc.second, settings(),
                            w["found"], rows, w["G"], w["h"])  # fmt: skip
        G, h = damper_reference(w["found"], rows, w["J"], sc.support)
        np.testing.assert_allclose(w["G"][:rows], G, atol=1e-12)
        np.testing.assert_allclose(w["h"][:rows], h, atol=1e-12)
    assert left >= 3


def test_given_placements_are_read_without_a_tree():
    """An empty tree: the pass reads ``poses`` and ``J`` as given (a model the compiled
    forward kinematics does not cover)."""
    robot = rrc_pin.load("panda")
    cm = CollisionModel(robot, "capsules")
    cm.add_sphere((0.45, 0.0, 0.45), 0.1, name="ball")
    sc = cm.scene
    w = workspace(sc)
    q = robot.ready()
    data = robot.model.createData()
    pin.computeJointJacobians(robot.model, data, robot.to_pinocchio(q))
    rows, _, _ = run(sc, q, w, settings())
    G, found = w["G"][:rows].copy(), w["found"][:rows].copy()
    assert rows > 0
    given = workspace(sc)
    given["poses"][:] = w["poses"]
    given["J"][:] = w["J"]
    far = q + 0.5  # the tree would place the arm elsewhere: only the given poses are read
    rows_given, _, _ = collision_pass(far, sc.joints[:0], sc.bodies, sc.first, sc.second,
                                      sc.every, settings(), sc.support, given["poses"],
                                      given["J"], given["world"], given["candidates"],
                                      given["other"], given["found"], given["G"],
                                      given["h"])  # fmt: skip
    assert rows_given == rows
    np.testing.assert_array_equal(given["G"][:rows], G)
    np.testing.assert_array_equal(given["found"][:rows], found)
