"""rrc_pin.geometry.robot_geometry: every robot's collision geometry and its filtered pairs."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import coal
import numpy as np
import pinocchio as pin
import pytest

import rrc_pin
from rrc_pin import models
from rrc_pin.errors import InvalidInput
from rrc_pin.geometry import CollisionModel
from rrc_pin.geometry.robot_geometry import (
    COLLISION_SRDFS,
    robot_geometry,
    variants_of,
)
from rrc_pin.link_capsules import link_capsules
from rrc_pin.loading import robots_directory
from rrc_pin.urdf_export import COMMITTED_DIR, check

CATALOGUE = list(models.CATALOGUE)


def distance_to_segment(p, a, b):
    if np.allclose(a, b):
        return float(np.linalg.norm(p - a))
    t = np.clip((p - a) @ (b - a) / ((b - a) @ (b - a)), 0.0, 1.0)
    return float(np.linalg.norm(p - a - t * (b - a)))


def world_axes(cm, robot, q):
    """Each body's axis (capsule: its two ends; sphere: its centre twice) in the world, and
    its radius."""
    model, data = robot.model, robot.model.createData()
    pin.forwardKinematics(model, data, robot.to_pinocchio(q))
    out = []
    for obj in cm.scene.geometry.geometryObjects:
        M = data.oMi[obj.parentJoint] * obj.placement
        shape = obj.geometry
        half = getattr(shape, "halfLength", 0.0)
        out.append((M.act(np.array([0, 0, -half])), M.act(np.array([0, 0, half])), shape.radius))
    return out


def skeleton(spec, q):
    """The DH chain's joint origins, the corners between a link's two offsets, the tool and
    the extra frames, by the DH chain product (independent of Pinocchio and the URDF)."""
    chain = spec.chain
    F = chain.frames(q)
    points = [F[i, :3, 3] for i in range(1, chain.nq + 1)]
    for i, row in enumerate(chain.rows, start=1):
        if chain.convention == "modified":
            points.append(F[i, :3, 3] - F[i, :3, 2] * row.d)
        else:
            points.append(F[i, :3, 3] - F[i, :3, 0] * row.a)
    tool = chain.fk(q)
    points.append(tool[:3, 3])
    points += [(tool @ chain.extra_frame(n))[:3, 3] for n, _ in chain.extra_frames]
    return points


@pytest.mark.parametrize("name", CATALOGUE)
def test_paper_arm_capsules_hold_the_dh_chain_at_any_configuration(name, rng):
    robot = rrc_pin.load(name)
    cm = CollisionModel(robot)
    assert cm.variant == "capsules"
    capsules = link_capsules(robot.spec)
    assert len(cm.bodies) == len(capsules)
    radii = dict(zip([f"link{i + 1}" for i in range(robot.nq)], robot.spec.collision_radii,
                     strict=True))  # fmt: skip
    for obj, capsule in zip(cm.scene.geometry.geometryObjects, capsules, strict=True):
        assert robot.model.frames[obj.parentFrame].name == capsule.link
        assert obj.geometry.radius == pytest.approx(radii[capsule.link], abs=1e-15)
        assert 2 * getattr(obj.geometry, "halfLength", 0.0) == pytest.approx(capsule.length,
                                                                              abs=1e-12)
    for _ in range(20):
        q = robot.random_q(rng)
        axes = world_axes(cm, robot, q)
        for p in skeleton(robot.spec, q):
            assert min(distance_to_segment(p, a, b) for a, b, _ in axes) < 1e-9


def test_the_committed_urdfs_hold_the_capsules_and_match_their_tables():
    specs = list(models.CATALOGUE.values())
    assert check(COMMITTED_DIR, specs) == []
    for spec in specs:
        from_file = rrc_pin.load(str(COMMITTED_DIR / f"{spec.name}.urdf"))
        assert from_file.spec is not None  # recognised as the catalogue arm
        cm = CollisionModel(from_file)
        merged = [(str(cm.robot.model.frames[o.parentFrame].name), o.geometry.radius,
                   2 * getattr(o.geometry, "halfLength", 0.0))
                  for o in cm.scene.geometry.geometryObjects]  # fmt: skip
        expected = [(c.link, c.radius, c.length) for c in link_capsules(spec)]
        assert len(merged) == len(expected)
        for got, want in zip(merged, expected, strict=True):
            assert got[0] == want[0] and np.allclose(got[1:], want[1:], atol=1e-12)


@pytest.mark.parametrize("name", [*CATALOGUE, "panda", "ur5"])
def test_no_active_pair_is_rigid_or_adjacent_or_touching_at_ready(name):
    robot = rrc_pin.load(name)
    cm = CollisionModel(robot)
    model, scene = robot.model, cm.scene
    for a, b in cm.pairs:
        ja, jb = (int(scene.joint[scene.names.index(x)]) for x in (a, b))
        assert ja != jb and model.parents[ja] != jb and model.parents[jb] != ja, (a, b)
    assert len(cm.proximity_at(robot.ready(), 0.0).names) == 0
    assert len(cm.pairs) + len(cm.excluded) == len(cm.bodies) * (len(cm.bodies) - 1) // 2


def srdf_disabled(robot_name):
    root = ET.parse(robots_directory() / COLLISION_SRDFS[robot_name]).getroot()
    return {frozenset((e.get("link1"), e.get("link2"))) for e in root.iter("disable_collisions")}


@pytest.mark.parametrize("variant", ["capsules", "hulls"])
def test_panda_leaves_out_the_pairs_its_srdf_disables(variant):
    panda = rrc_pin.load("panda")
    cm = CollisionModel(panda, variant)
    disabled = srdf_disabled("panda")
    link = {str(o.name): str(panda.model.frames[o.parentFrame].name)
            for o in cm.scene.geometry.geometryObjects}  # fmt: skip
    active_links = {frozenset((link[a], link[b])) for a, b in cm.pairs}
    assert not active_links & disabled
    srdf = [p for p, r in cm.excluded.items() if r == "srdf"]
    assert srdf and all(frozenset(link[x] for x in p) in disabled for p in srdf)
    if variant == "hulls":
        assert len(cm.pairs) == 44  # the count: panda's meshes after SRDF and adjacency


def test_two_combined_pandas_keep_their_own_pairs_and_pair_every_body_across(facing_pandas):
    panda = rrc_pin.load("panda")
    cell = facing_pandas(1.0)
    one = CollisionModel(panda)
    two = CollisionModel(cell)
    n = len(one.bodies)
    own = {(f"{k}/{a}", f"{k}/{b}") for k in ("left", "right") for a, b in one.pairs}
    across = {(a, b) for a, b in two.pairs if a.split("/")[0] != b.split("/")[0]}
    assert set(two.pairs) == own | across
    # all but the two bases (both fixed to the world) and the pairs no joint moves: link 1's
    # capsule turns about its own axis, against the other base or the other link 1
    assert len(across) == n * n - 4
    assert set(two.invariant) == {("left/panda_link0_0", "right/panda_link1_0"),
                                  ("left/panda_link1_0", "right/panda_link0_0"),
                                  ("left/panda_link1_0", "right/panda_link1_0")}  # fmt: skip
    assert two.invariant[("left/panda_link1_0", "right/panda_link1_0")] == pytest.approx(
        1.0 - 2 * 0.09, abs=1e-9)  # the bases 1 m apart, the capsules' radius 0.09 m
    links = {f"panda_link{i}_0" for i in range(1, 8)}
    arm_pairs = {(a, b) for a, b in across
                 if a.split("/")[1] in links and b.split("/")[1] in links}  # fmt: skip
    assert len(arm_pairs) == 48
    assert two.excluded[("left/panda_link0_0", "right/panda_link0_0")] == "rigid"
    # at its base: the right arm's bodies are the left arm's, moved by the placement
    q = panda.ready()
    left = one.proximity_at(q, 10.0)
    both = two.proximity_at(np.concatenate([q, q]), 10.0)
    for names, d in zip(left.names, left.distance, strict=True):
        k = both.names.index((f"right/{names[0]}", f"right/{names[1]}"))
        assert both.distance[k] == pytest.approx(d, abs=1e-9)


def test_variants_and_their_refusals():
    assert variants_of(rrc_pin.load("panda")) == ("capsules", "hulls", "urdf")
    assert variants_of(rrc_pin.load("ur5")) == ("hulls", "urdf")
    with pytest.raises(InvalidInput, match="hulls, urdf") as info:
        CollisionModel(rrc_pin.load("ur5"), "capsules")
    assert info.value.argument == "geometry"
    with pytest.raises(InvalidInput, match="geometry"):
        CollisionModel(rrc_pin.load("ur5"), "spheres")
    sample = rrc_pin.Robot(pin.buildSampleModelManipulator(), "effector_body", name="sample",
                           source="built in code")  # fmt: skip
    with pytest.raises(InvalidInput, match="GeometryModel") as info:
        CollisionModel(sample)
    assert info.value.argument == "robot"


def test_a_geometry_model_of_ones_own_is_filtered_by_the_kinematic_rules():
    model = pin.buildSampleModelManipulator()
    geometry = pin.buildSampleGeometryModelManipulator(model)
    sample = rrc_pin.Robot(model, "effector_body", name="sample", source="built in code")
    cm = CollisionModel(sample, geometry)
    assert cm.variant == "given" and len(cm.bodies) == geometry.ngeoms
    assert set(cm.excluded.values()) <= {"rigid", "adjacent", "ready", "invariant"}
    # the shoulder's sphere sits where its three joints' axes meet: the elbow's sphere turns
    # about its centre, 0.9 m away whatever the joints
    assert cm.invariant == pytest.approx({("shoulder_object", "elbow_object"): 0.9}, abs=1e-12)
    bad = pin.GeometryModel()
    bad.addGeometryObject(pin.GeometryObject("far", 99, pin.SE3.Identity(), coal.Sphere(0.1)))
    with pytest.raises(InvalidInput, match="joint 99"):
        CollisionModel(sample, bad)


def test_meshes_become_hulls_that_sign_penetration():
    """Why hulls: coal measures a mesh in penetration as 0; its hull gives the depth."""
    panda = rrc_pin.load("panda")
    q = panda.ready()
    meshes = CollisionModel(panda, "urdf")
    hulls = CollisionModel(panda, "hulls")
    for cm in (meshes, hulls):
        cm.add_halfspace((0, 0, 1), 0.3, name="raised floor")  # the elbow sinks into it
    deep = {n: d for n, d in zip(*_pair_distances(hulls, q), strict=True) if "floor" in n[1]}
    flat = {n: d for n, d in zip(*_pair_distances(meshes, q), strict=True) if "floor" in n[1]}
    sunk = [n for n, d in deep.items() if d < -0.01]
    assert sunk and all(flat[n] == 0.0 or flat[n] > deep[n] for n in sunk)


def _pair_distances(cm, q):
    prox = cm.proximity_at(q, 0.0)
    return prox.names, prox.distance


def test_robot_geometry_reads_the_files_once():
    panda = rrc_pin.load("panda")
    first = robot_geometry(panda, "hulls")
    again = robot_geometry(panda, "hulls")
    assert [o.geometry for o in first.objects.geometryObjects] == [
        o.geometry for o in again.objects.geometryObjects
    ]
