"""rrc_pin.geometry.proximity: signed distances, witness points and normals of a tick.

Against analytic formulas on primitive shapes (1e-9, in and out of penetration, seeded random
poses), through the whole query: a shape held by a link of an arm at a random configuration
(body A) against a world obstacle (body B). And against coal on every pair (the broad phase
drops nothing) on robots, cells and obstacles.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import rrc_pin
from rrc_pin.geometry import CollisionModel, Proximity
from rrc_pin.geometry.proximity import EMPTY, measure, search
from rrc_pin.kinematics import Kinematics, Layout

TOL = 1e-9
TRIALS = 40
WELL_POSED = 1e-3
"""[m] Trials whose witness points are not unique to this margin are drawn again."""


# -- analytic references (A: the held shape, B: the obstacle; normal from A to B) -----------


def closest_on_segment(a, b, p):
    t = np.clip((p - a) @ (b - a) / ((b - a) @ (b - a)), 0.0, 1.0)
    return a + t * (b - a)


def segment_segment(p1, q1, p2, q2):
    """Closest points of two segments (Ericson, Real-Time Collision Detection, 5.1.9)."""
    d1, d2, r = q1 - p1, q2 - p2, p1 - p2
    a, e, f = d1 @ d1, d2 @ d2, d2 @ r
    c, b = d1 @ r, d1 @ d2
    denom = a * e - b * b
    s = np.clip((b * f - c * e) / denom, 0.0, 1.0) if denom > 1e-15 else 0.0
    t = (b * s + f) / e
    if t < 0.0:
        t, s = 0.0, np.clip(-c / a, 0.0, 1.0)
    elif t > 1.0:
        t, s = 1.0, np.clip((b - c) / a, 0.0, 1.0)
    return p1 + s * d1, p2 + t * d2


def between_points(ca, ra, cb, rb):
    """Two points inflated by radii (spheres, and capsules through their closest axis points)."""
    gap = cb - ca
    n = gap / np.linalg.norm(gap)
    return np.linalg.norm(gap) - ra - rb, ca + ra * n, cb - rb * n, n


def axis(T, length):
    return T[:3, :3] @ [0, 0, -length / 2] + T[:3, 3], T[:3, :3] @ [0, 0, length / 2] + T[:3, 3]


def sphere_box(c, r, T, size):
    R, t = T[:3, :3], T[:3, 3]
    local, half = R.T @ (c - t), np.asarray(size) / 2
    inside = np.all(np.abs(local) < half)
    if not inside:
        b = R @ np.clip(local, -half, half) + t
        d, pa, pb, n = between_points(c, r, b, 0.0)
        return d, pa, pb, n
    depth = half - np.abs(local)
    k = int(np.argmin(depth))
    face = np.zeros(3)
    face[k] = np.sign(local[k])
    f = R @ face
    return -(depth[k] + r), c - r * f, c + depth[k] * f, -f


def against_plane(points, r, normal, offset):
    """A body given by its deepest points (capsule ends, box vertices) inflated by r, against
    the solid ``normal . x <= offset``; (d, p_a, p_b, n), and the gap to the next point."""
    h = points @ normal - offset
    order = np.argsort(h)
    v = points[order[0]]
    d = h[order[0]] - r
    pa = v - r * normal
    return (d, pa, pa - d * normal, -normal), h[order[1]] - h[order[0]]


# -- the harness ------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def arm():
    return rrc_pin.load("kr5_3r")


def random_pose(rng, scale=1.0):
    return pin.SE3(pin.exp3(rng.normal(size=3)), scale * rng.normal(size=3)).homogeneous


def held_world_pose(arm, q, T_link):
    return arm.fk(q, "link3") @ T_link


def one_row(cm, arm, q, detection=10.0) -> Proximity:
    prox = cm.proximity_at(q, detection)
    assert len(prox.names) == 1
    return prox


CASES = ["sphere-sphere", "sphere-capsule", "capsule-capsule", "sphere-box",
         "capsule-halfspace", "box-halfspace"]  # fmt: skip


def draw(case, rng, arm):
    """One trial: the CollisionModel, q, and the analytic (d, p_a, p_b, n); None if ill-posed."""
    cm = CollisionModel(arm, geometry=pin.GeometryModel())
    q = arm.random_q(rng)
    T_link = random_pose(rng, 0.1)
    TA = held_world_pose(arm, q, T_link)
    TB = TA @ random_pose(rng, 0.08)
    ra, rb = rng.uniform(0.02, 0.1, size=2)
    la, lb = rng.uniform(0.05, 0.3, size=2)
    ca, cb = TA[:3, 3], TB[:3, 3]
    if case == "sphere-sphere":
        cm.attach("link3", "sphere", T_link, radius=ra)
        cm.add_sphere(cb, rb)
        if np.linalg.norm(cb - ca) < WELL_POSED:
            return None
        return cm, q, between_points(ca, ra, cb, rb)
    if case == "sphere-capsule":
        cm.attach("link3", "sphere", T_link, radius=ra)
        cm.add_capsule(TB, rb, lb)
        c = closest_on_segment(*axis(TB, lb), ca)
        if np.linalg.norm(c - ca) < WELL_POSED:
            return None
        return cm, q, between_points(ca, ra, c, rb)
    if case == "capsule-capsule":
        cm.attach("link3", "capsule", T_link, radius=ra, length=la)
        cm.add_capsule(TB, rb, lb)
        a, b = segment_segment(*axis(TA, la), *axis(TB, lb))
        if np.linalg.norm(b - a) < WELL_POSED:
            return None
        return cm, q, between_points(a, ra, b, rb)
    if case == "sphere-box":
        size = rng.uniform(0.05, 0.3, size=3)
        cm.attach("link3", "sphere", T_link, radius=ra)
        cm.add_box(TB, size)
        local = np.abs(TB[:3, :3].T @ (ca - cb))
        depth = np.sort(size / 2 - local)
        if np.all(local < size / 2) and depth[1] - depth[0] < WELL_POSED:
            return None
        return cm, q, sphere_box(ca, ra, TB, size)
    normal = rng.normal(size=3)
    normal /= np.linalg.norm(normal)
    if case == "capsule-halfspace":
        cm.attach("link3", "capsule", T_link, radius=ra, length=la)
        points = np.array(axis(TA, la))
        offset = float(normal @ ca + rng.uniform(-0.2, 0.2))
        cm.add_halfspace(normal, offset)
        expected, gap = against_plane(points, ra, normal, offset)
    else:
        size = rng.uniform(0.05, 0.3, size=3)
        cm.attach("link3", "box", T_link, size=size)
        corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
        points = (TA[:3, :3] @ (corners * size / 2).T).T + ca
        offset = float(normal @ ca + rng.uniform(-0.2, 0.2))
        cm.add_halfspace(normal, offset)
        expected, gap = against_plane(points, 0.0, normal, offset)
    return (cm, q, expected) if gap > WELL_POSED else None


@pytest.mark.parametrize("case", CASES)
def test_distances_witnesses_and_normals_match_the_analytic_formulas(case, arm):
    rng = np.random.default_rng(100 + CASES.index(case))
    seen = {"in": 0, "out": 0}
    done = 0
    while done < TRIALS:
        trial = draw(case, rng, arm)
        if trial is None:
            continue
        cm, q, (d, pa, pb, n) = trial
        prox = one_row(cm, arm, q)
        assert prox.distance[0] == pytest.approx(d, abs=TOL)
        np.testing.assert_allclose(prox.point_a[0], pa, atol=TOL)
        np.testing.assert_allclose(prox.point_b[0], pb, atol=TOL)
        np.testing.assert_allclose(prox.normal[0], n, atol=TOL)
        assert prox.joint_a[0] == arm.model.getJointId("joint3") and prox.joint_b[0] == 0
        seen["in" if d < 0 else "out"] += 1
        done += 1
    assert seen["in"] >= 5 and seen["out"] >= 5, seen  # both sides of contact were tested


# -- the broad phase drops nothing ------------------------------------------------------------


def scenes():
    panda = rrc_pin.load("panda")
    facing = np.eye(4)
    facing[:3, :3] = np.diag([-1.0, -1.0, 1.0])
    facing[0, 3] = 0.9
    cell = rrc_pin.combine({"left": (panda, np.eye(4)), "right": (panda, facing)})
    return [("panda", panda, "capsules"), ("panda", panda, "hulls"),
            ("two pandas", cell, "capsules"), ("two pandas", cell, "hulls"),
            ("barker6", rrc_pin.load("barker6"), "capsules")]  # fmt: skip


@pytest.mark.parametrize(("label", "robot", "variant"), scenes(),
                         ids=[f"{s[0]}-{s[2]}" for s in scenes()])  # fmt: skip
def test_the_broad_phase_never_drops_a_pair_within_the_detection_distance(label, robot, variant):
    cm = CollisionModel(robot, variant)
    cm.add_halfspace((0, 0, 1), -0.05, name="floor")
    T = np.eye(4)
    T[:3, 3] = (0.45, 0.1, 0.3)
    cm.add_box(T, (0.2, 0.3, 0.1), name="box")
    cm.add_sphere((0.3, -0.3, 0.6), 0.08, name="ball")
    scene = cm.scene
    rng = np.random.default_rng(7)
    rows = 0
    for detection in (0.0, 0.05, 0.2):
        for _ in range(25):
            q = robot.random_q(rng)
            prox = cm.proximity_at(q, detection)
            data = scene.geometry.createData()
            pin.computeDistances(robot.model, robot.model.createData(), scene.geometry, data,
                                 robot.to_pinocchio(q))  # fmt: skip
            every = np.array([r.min_distance for r in data.distanceResults])
            near = {scene.pair_names[k] for k in np.flatnonzero(every < detection)}
            assert set(prox.names) == near
            for k, names in enumerate(prox.names):
                assert prox.distance[k] == pytest.approx(
                    every[scene.pair_names.index(names)], abs=1e-6  # GJK's tolerance on hulls
                )
            rows += len(prox.names)
    assert rows > 50  # the scenes do come near


def test_rows_hold_their_conventions_on_a_cell(rng, facing_pandas):
    """p_b - p_a = d n with a unit n, joints of the model, A before B, in the pairs' order."""
    cell = facing_pandas(0.7)
    cm = CollisionModel(cell, "hulls")
    cm.add_halfspace((0, 0, 1), 0.0, name="floor")
    order = {names: k for k, names in enumerate(cm.pairs)}
    for _ in range(20):
        prox = cm.proximity_at(cell.random_q(rng), 0.1)
        np.testing.assert_allclose(np.linalg.norm(prox.normal, axis=1), 1.0, atol=1e-12)
        gap = prox.point_b - prox.point_a - prox.distance[:, None] * prox.normal
        assert np.abs(gap).max(initial=0.0) < 1e-6
        assert [order[n] for n in prox.names] == sorted(order[n] for n in prox.names)
        for k, (a, b) in enumerate(prox.names):
            ga, gb = (cm.scene.geometry.getGeometryId(x) for x in (a, b))
            assert prox.joint_a[k] == cm.scene.joint[ga] and prox.joint_b[k] == cm.scene.joint[gb]
            assert ga < gb


def test_proximity_reads_the_resolvers_kinematics_and_matches_proximity_at(rng):
    arm = rrc_pin.load("panda")
    cm = CollisionModel(arm)
    cm.add_halfspace((0, 0, 1), 0.3, name="shelf")
    data = cm.create_data()
    model = arm.model
    pdata = model.createData()
    layout = Layout.of(arm)
    for _ in range(10):
        q = arm.random_q(rng)
        kin = Kinematics(model, pdata, layout, q, arm.to_pinocchio(q))
        got, want = cm.proximity(kin, data, 0.1), cm.proximity_at(q, 0.1)
        assert got.names == want.names
        np.testing.assert_allclose(got.distance, want.distance, atol=1e-12)
        np.testing.assert_allclose(got.point_a, want.point_a, atol=1e-12)


def test_an_empty_answer_is_shared_and_read_only():
    arm = rrc_pin.load("kr5_3r")
    cm = CollisionModel(arm)
    prox = cm.proximity_at(arm.ready(), 0.0)
    assert prox is EMPTY and prox.distance.shape == (0,) and prox.normal.shape == (0, 3)
    assert not prox.distance.flags.writeable


def test_data_follows_a_changed_scene():
    """A data created before an obstacle was added answers for the scene with it."""
    arm = rrc_pin.load("kr5_3r")
    cm = CollisionModel(arm)
    data = cm.create_data()
    cm.add_halfspace((0, 0, 1), 10.0, name="flood")  # everything below z = 10 is inside it
    prox = cm.proximity_at(arm.ready(), 0.0, data)
    assert {b for _, b in prox.names} == {"flood"} and (prox.distance < 0).all()


def test_a_capsule_against_a_hull_gets_its_end_points_rows():
    """coal measures a capsule against a convex hull; with ``ends`` each end point of the capsule
    also gets a row, its distance the analytic one from that end to the (cubic) hull."""
    robot = rrc_pin.load("panda")
    cm = CollisionModel(robot)
    q = robot.ready()
    data = robot.model.createData()
    pin.forwardKinematics(robot.model, data, robot.to_pinocchio(q))
    geometry = cm.scene.geometry
    gdata = pin.GeometryData(geometry)
    pin.updateGeometryPlacements(robot.model, data, geometry, gdata)
    (link,) = [i for i, o in enumerate(geometry.geometryObjects) if o.name == "panda_link5_0"]
    capsule = geometry.geometryObjects[link].geometry
    M = gdata.oMg[link]
    ends = [M.act(np.array([0.0, 0.0, s * capsule.halfLength])) for s in (-1.0, 1.0)]
    half = 0.05  # a cube beside the link, nearer one end, its axis skew to the cube's faces
    centre = ends[0] + M.rotation @ np.array([capsule.radius + half + 0.03, 0.0, 0.02])
    corners = np.array([[x, y, z] for x in (-half, half) for y in (-half, half)
                        for z in (-half, half)])  # fmt: skip
    T = np.eye(4)
    T[:3, 3] = centre
    cm.add_convex(T, corners, name="cube")

    def to_cube(p):
        return float(np.linalg.norm(np.maximum(np.abs(p - centre) - half, 0.0))) - capsule.radius

    prox = cm.proximity_at(q, 0.3, ends=True)
    rows = [k for k, names in enumerate(prox.names) if names == ("panda_link5_0", "cube")]
    assert len(rows) == 3  # the closest points, then each end
    for k, p in zip(rows[1:], ends, strict=True):
        assert abs(prox.distance[k] - to_cube(p)) < 1e-6  # GJK's tolerance
    assert prox.distance[rows[0]] <= min(prox.distance[rows[1:]]) + 1e-6
    assert cm.proximity_at(q, 0.3).names.count(("panda_link5_0", "cube")) == 1  # no ends


def test_copies_are_the_first_rows_and_own_their_values(facing_pandas):
    robot = facing_pandas(0.8)
    cm = CollisionModel(robot, "capsules")
    sc, cdata = cm.scene, cm.create_data()
    settings = search(0.15, True)
    for field, value in (("rows", True), ("safety", 0.02), ("xi", 0.5), ("xi_end", 4.0),
                         ("blend", 0.005), ("band", 1e-3), ("recovery", 50.0), ("still", 1e-9)):
        settings[field] = value

    def run(q):
        return measure(sc, robot.model, q, lambda: None, cdata, settings, sc.every)[0]

    rows = run(robot.ready())
    assert rows > 0
    got = cdata.copies(rows)
    found = cdata.found[:rows]
    expected = [a.copy() for a in (cdata.G[:rows], cdata.h[:rows], found["distance"],
                                   found["pair"])]  # fmt: skip
    run(robot.ready() + 0.1)  # the pass writes its arrays again
    for copy, want in zip(got, expected, strict=True):
        np.testing.assert_array_equal(copy, want)
        assert copy.dtype == want.dtype
        assert copy.flags.c_contiguous and copy.flags.writeable
        assert not any(np.shares_memory(copy, a) for a in (cdata.G, cdata.h, cdata.found))


def test_the_pass_arguments_are_kept_while_the_settings_and_pairs_are_the_same(facing_pandas):
    cm = CollisionModel(facing_pandas(0.8), "capsules")
    sc, cdata = cm.scene, cm.create_data()
    settings, keep = search(0.1, True), sc.every.copy()
    first = cdata.arguments(settings, keep)
    assert cdata.arguments(settings, keep) is first
    assert first[4] is keep and first[5] is settings and first[-1] is cdata.h
    assert cdata.arguments(search(0.1, True), keep) is not first
    assert cdata.arguments(settings, sc.every.copy())[4] is not keep
    cm.add_sphere((0.4, 0.0, 0.5), 0.05, name="ball")
    cdata.refresh(cm.scene)  # new arrays: nothing of the former scene's kept
    assert cdata.arguments(settings, keep)[-1] is cdata.h
