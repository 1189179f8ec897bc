"""rrc_pin.geometry.CollisionModel: obstacles, held objects, walls, and input refused whole."""

from __future__ import annotations

import threading

import numpy as np
import pinocchio as pin
import pytest

import rrc_pin
from rrc_pin.errors import InvalidInput, RrcPinError
from rrc_pin.geometry import CollisionModel, Wall


@pytest.fixture(scope="module")
def panda():
    return rrc_pin.load("panda")


@pytest.fixture
def cm(panda):
    return CollisionModel(panda)


def at(x, y, z):
    T = np.eye(4)
    T[:3, 3] = (x, y, z)
    return T


def test_obstacles_get_names_and_pair_with_every_moving_body(cm):
    moving = [b for b in cm.bodies if cm.scene.joint[cm.bodies.index(b)] != 0]
    assert cm.add_box(at(0.5, 0, 0.2), (0.3, 0.3, 0.1), name="table") == "table"
    assert cm.add_sphere((0.4, 0.2, 0.5), 0.05) == "sphere0"
    assert cm.add_sphere(at(0.4, -0.2, 0.5), 0.05) == "sphere1"
    cm.add_capsule(at(0.3, 0.3, 0.3), 0.04, 0.2, name="bar")
    cm.add_cylinder(at(-0.3, 0.3, 0.3), 0.04, 0.2, name="post")
    cm.add_convex(at(0.0, 0.6, 0.3), np.random.default_rng(0).normal(size=(12, 3)) * 0.05,
                  name="rock")  # fmt: skip
    cm.add_halfspace((0, 0, 2), 0.0, name="floor")
    obstacles = ["table", "sphere0", "sphere1", "bar", "post", "rock", "floor"]
    assert cm.bodies[-len(obstacles):] == tuple(obstacles)
    for name in obstacles:
        partners = {a for a, b in cm.pairs if b == name}
        # not the base (fixed), not another obstacle, not a body no joint moves relative to it:
        # panda_link1's capsule turns about its own axis (joint 1); link 2's lies along joint
        # 2's axis, which stays at the shoulder's height (the floor's distance never changes)
        still = {"panda_link1_0", "panda_link2_0"} if name == "floor" else {"panda_link1_0"}
        assert partners == set(moving) - still, name
        assert {a for a, b in cm.invariant if b == name} == still, name
        assert all(cm.excluded[(a, name)] == "invariant" for a in still), name
        assert cm.excluded[("panda_link0_0", name)] == "rigid"
    floor = cm.scene.names.index("floor")
    np.testing.assert_allclose(cm.scene.normal[floor], (0, 0, 1))  # normalised


def test_the_halfspace_side_is_normal_dot_x_below_offset(panda, cm):
    cm.add_halfspace((0, 0, 1), 0.2, name="shelf")  # the solid z <= 0.2
    prox = cm.proximity_at(panda.ready(), 10.0)
    for (_, b), d, pa in zip(prox.names, prox.distance, prox.point_a, strict=True):
        if b == "shelf":
            assert d == pytest.approx(pa[2] - 0.2, abs=1e-9)  # A's lowest point above z = 0.2


def test_a_held_object_moves_with_its_link_and_skips_its_hand(panda, cm):
    name = cm.attach("panda_hand", "box", at(0, 0, 0.15), size=(0.04, 0.04, 0.2), name="part")
    assert name == "part" and cm.bodies.index("part") < len(cm.bodies)
    hand_joint = cm.scene.joint[cm.bodies.index("panda_hand_0")]
    assert cm.scene.joint[cm.bodies.index("part")] == hand_joint
    partners = {a for a, b in cm.pairs if b == "part"}
    same = {n for n in cm.bodies if cm.scene.joint[cm.bodies.index(n)] == hand_joint}
    assert not partners & same and partners
    cm.add_halfspace((0, 0, 1), 0.0, name="floor")
    assert ("part", "floor") in cm.pairs  # held before world: the held object is body A
    q = panda.ready()
    prox = cm.proximity_at(q, 10.0)
    k = prox.names.index(("part", "floor"))
    corners = [panda.fk(q, "panda_hand") @ at(0, 0, 0.15) @ at(sx * 0.02, sy * 0.02, sz * 0.1)
               for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]  # fmt: skip
    assert prox.distance[k] == pytest.approx(min(T[2, 3] for T in corners), abs=1e-9)


def test_kinds_and_dimensions_of_held_objects(cm):
    cm.attach("panda_link5", "sphere", np.eye(4), radius=0.05)
    cm.attach("panda_link5", "capsule", np.eye(4), radius=0.05, length=0.1)
    cm.attach("panda_link5", "cylinder", np.eye(4), radius=0.05, length=0.1)
    cm.attach("panda_link5", "convex", np.eye(4), points=[*np.eye(3).tolist(), [0, 0, 0]])
    for kwargs, argument in [({}, "radius"), ({"radius": 0.1, "size": (1, 1, 1)}, "size")]:
        with pytest.raises(InvalidInput) as info:
            cm.attach("panda_link5", "sphere", np.eye(4), **kwargs)
        assert info.value.argument == argument
    with pytest.raises(InvalidInput, match="box, capsule") as info:
        cm.attach("panda_link5", "halfspace", np.eye(4))
    assert info.value.argument == "kind"


def test_remove_takes_an_obstacle_a_held_object_or_walls(cm):
    before = cm.pairs
    cm.add_box(at(1, 0, 0), (0.1, 0.1, 0.1), name="crate")
    cm.attach("panda_hand", "sphere", np.eye(4), radius=0.02, name="ball")
    cm.add_workspace(at(0.4, 0, 0.4), (0.6, 0.8, 0.6), name="cage")
    for name in ("crate", "ball", "cage"):
        cm.remove(name)
    assert cm.pairs == before and cm.walls() == ()
    with pytest.raises(InvalidInput, match="nothing named") as info:
        cm.remove("crate")
    assert info.value.argument == "name"


def test_walls_of_a_workspace_box_hold_its_inside(panda, cm, rng):
    T = pin.SE3(pin.exp3(rng.normal(size=3)), rng.normal(size=3)).homogeneous
    size = np.array([0.4, 0.6, 0.8])
    assert cm.add_workspace(T, size, name="cage") == "cage"
    walls = cm.walls("panda_hand_tcp")
    assert len(walls) == 6 and all(isinstance(w, Wall) for w in walls)
    assert [w.name for w in walls] == [f"cage/{f}" for f in ("+x", "-x", "+y", "-y", "+z", "-z")]
    for _ in range(200):
        local = rng.uniform(-0.6, 0.6, size=3) * size
        p = T[:3, :3] @ local + T[:3, 3]
        inside = bool(np.all(np.abs(local) <= size / 2))
        assert all(w.normal @ p <= w.offset for w in walls) == inside
    cm.add_wall((0, 0, -2), -0.2, name="above the table")  # -2 z <= -0.2: z >= 0.1
    wall = cm.walls()[-1]
    assert wall.frame == "panda_hand_tcp" and wall.normal @ (0, 0, 0.05) > wall.offset
    np.testing.assert_allclose(wall.normal, (0, 0, -1))
    assert cm.walls("panda_link3") == ()


def test_walls_of_a_robot_with_several_tools_name_their_frame():
    baxter = rrc_pin.load("baxter")
    cm = CollisionModel(baxter)
    with pytest.raises(InvalidInput, match="left_gripper") as info:
        cm.add_wall((0, 0, 1), 1.0)
    assert info.value.argument == "frame"
    cm.add_wall((0, 0, 1), 1.0, frame="left_gripper")
    assert cm.walls("left_gripper")[0].frame == "left_gripper"


BAD = [
    (lambda cm: cm.add_box(at(0, 0, 0), (0.1, 0.0, 0.1)), "size"),
    (lambda cm: cm.add_box(at(0, 0, 0), (0.1, -1, 0.1)), "size"),
    (lambda cm: cm.add_box(at(0, 0, 0), (0.1, np.nan, 0.1)), "size"),
    (lambda cm: cm.add_box(np.diag([2.0, 1, 1, 1]), (0.1, 0.1, 0.1)), "T"),  # not rigid
    (lambda cm: cm.add_box(np.full((4, 4), np.nan), (0.1, 0.1, 0.1)), "T"),
    (lambda cm: cm.add_box(np.eye(3), (0.1, 0.1, 0.1)), "T"),
    (lambda cm: cm.add_sphere((0, 0, np.inf), 0.1), "center_or_T"),
    (lambda cm: cm.add_sphere((0, 0, 0), 0.0), "radius"),
    (lambda cm: cm.add_capsule(at(0, 0, 0), 0.1, -0.2), "length"),
    (lambda cm: cm.add_cylinder(at(0, 0, 0), -0.1, 0.2), "radius"),
    (lambda cm: cm.add_convex(at(0, 0, 0), np.eye(3)), "points"),  # three points: no volume
    (lambda cm: cm.add_halfspace((0, 0, 0), 0.0), "normal"),
    (lambda cm: cm.add_halfspace((0, 0, 1), np.nan), "offset"),
    (lambda cm: cm.attach("no_such_link", "sphere", np.eye(4), radius=0.1), "link"),
    (lambda cm: cm.attach("panda_hand", "sphere", np.eye(4) * 2, radius=0.1), "T_link_shape"),
    (lambda cm: cm.add_box(at(0, 0, 0), (0.1, 0.1, 0.1), name="panda_link3_0"), "name"),
    (lambda cm: cm.add_box(at(0, 0, 0), (0.1, 0.1, 0.1), name=""), "name"),
    (lambda cm: cm.add_workspace(at(0, 0, 0), (1, 0, 1)), "size"),
    (lambda cm: cm.add_workspace(at(0, 0, 0), (1, 1, 1), frame="nowhere"), "frame"),
    (lambda cm: cm.add_wall((np.nan, 0, 1), 0.0), "normal"),
    (lambda cm: cm.proximity_at(np.zeros(7), np.nan), "detection"),
    (lambda cm: cm.proximity_at(np.zeros(7), -0.1), "detection"),
    (lambda cm: cm.proximity_at(np.zeros(7), 0.1, data="mine"), "data"),
    (lambda cm: cm.proximity_at(np.zeros(6), 0.1), "q"),
]


@pytest.mark.parametrize(("call", "argument"), BAD, ids=[f"{a}-{i}" for i, (_, a) in
                                                          enumerate(BAD)])  # fmt: skip
def test_bad_input_is_refused_naming_the_argument_and_changes_nothing(cm, call, argument):
    cm.add_box(at(0.5, 0, 0.2), (0.3, 0.3, 0.1), name="table")
    before = (cm.scene, cm.pairs, cm.walls(), cm.bodies)
    with pytest.raises(InvalidInput) as info:
        call(cm)
    assert info.value.argument == argument
    assert isinstance(info.value, RrcPinError)
    assert (cm.scene, cm.pairs, cm.walls(), cm.bodies) == before


def test_kinematics_of_another_robot_is_refused(cm):
    from rrc_pin.kinematics import Kinematics, Layout

    other = rrc_pin.load("ur5")
    kin = Kinematics(other.model, other.model.createData(), Layout.of(other), other.ready(),
                     other.ready())  # fmt: skip
    with pytest.raises(InvalidInput) as info:
        cm.proximity(kin, cm.create_data(), 0.1)
    assert info.value.argument == "kin"


def test_threads_query_with_their_own_data_while_obstacles_change(panda, cm):
    """Two threads, each with its own data, while a third adds obstacles: no tearing."""
    cm.add_halfspace((0, 0, 1), 0.1, name="floor")
    q = panda.ready()
    expected = cm.proximity_at(q, 0.5)
    errors: list[BaseException] = []

    def query() -> None:
        data = cm.create_data()
        try:
            for _ in range(200):
                prox = cm.proximity_at(q, 0.5, data)
                base = [k for k, n in enumerate(prox.names) if n in expected.names]
                assert len(base) == len(expected.names)
        except BaseException as exc:
            errors.append(exc)

    threads = [threading.Thread(target=query) for _ in range(2)]
    for t in threads:
        t.start()
    for k in range(20):
        cm.add_sphere((2.0 + k, 0, 0), 0.1)  # far away: changes no row
    for t in threads:
        t.join()
    assert errors == []


SEEDS = (5, int(np.random.SeedSequence().entropy % 2**63))
"""A fixed seed and one drawn fresh each run (named in every failure)."""


def distances_at(cm, robot, rng, count):
    """Every pair's distance (active and invariant) at ``count`` random configurations."""
    geometry = pin.GeometryModel()
    for obj in cm.scene.geometry.geometryObjects:
        geometry.addGeometryObject(obj)
    names = list(cm.bodies)
    pairs = [*cm.pairs, *cm.invariant]
    for a, b in pairs:
        geometry.addCollisionPair(pin.CollisionPair(names.index(a), names.index(b)))
    data, gdata = robot.model.createData(), geometry.createData()
    out = []
    for _ in range(count):
        pin.computeDistances(robot.model, data, geometry, gdata,
                             robot.to_pinocchio(robot.random_q(rng)))  # fmt: skip
        out.append([r.min_distance for r in gdata.distanceResults])
    return pairs, np.array(out)


@pytest.mark.parametrize("seed", SEEDS, ids=("fixed", "fresh"))
def test_a_pair_is_invariant_exactly_where_no_joint_changes_its_distance(panda, seed):
    """Obstacles of every shape at random poses, and shapes held by link 1 on its axis (where
    turning it moves nothing) or off it, by the hand: the pairs left out as invariant keep
    their distance (to 1e-5 m) at random configurations, and those a joint moves are rows."""
    rng = np.random.default_rng(seed)
    cm = CollisionModel(panda)

    def pose():
        T = np.eye(4)
        T[:3, :3] = pin.exp3(rng.normal(size=3))
        T[:3, 3] = rng.uniform((-0.8, -0.8, -0.2), (0.8, 0.8, 1.0))
        return T

    cm.add_box(pose(), rng.uniform(0.05, 0.4, 3), name="box")
    cm.add_sphere(pose(), rng.uniform(0.02, 0.2), name="ball")
    cm.add_capsule(pose(), 0.05, rng.uniform(0.05, 0.5), name="bar")
    cm.add_cylinder(pose(), 0.05, rng.uniform(0.05, 0.5), name="post")
    cm.add_convex(pose(), rng.normal(size=(10, 3)) * 0.1, name="rock")
    normal = rng.normal(size=3)
    cm.add_halfspace(normal, float(rng.uniform(-0.5, -0.2)) * np.linalg.norm(normal),
                     name="plane")  # fmt: skip
    axis = np.eye(4)
    axis[2, 3] = rng.uniform(-0.2, 0.0)  # on joint 1's axis, in link 1's frame
    off = np.eye(4)
    off[:3, 3] = (0.12, 0.0, -0.1)
    cm.attach("panda_link1", "sphere", axis, radius=0.03, name="on axis")
    cm.attach("panda_link1", "sphere", off, radius=0.03, name="off axis")
    cm.attach("panda_hand", "box", np.eye(4), size=(0.05, 0.05, 0.05), name="held")
    pairs, d = distances_at(cm, panda, rng, 24)
    spread = dict(zip(pairs, np.ptp(d, axis=0).tolist(), strict=True))
    for pair in cm.invariant:
        assert spread[pair] <= 1e-5, f"seed {seed}: {pair} {spread[pair]}"
    world = ("box", "ball", "bar", "post", "rock", "plane")
    for obstacle in world:
        assert ("on axis", obstacle) in cm.invariant, f"seed {seed}"
        assert ("off axis", obstacle) in cm.pairs and spread[("off axis", obstacle)] > 1e-3
        assert ("held", obstacle) in cm.pairs and spread[("held", obstacle)] > 1e-3
    moved = [p for p in cm.pairs if spread[p] > 1e-5]
    assert len(moved) >= len(cm.pairs) - 2, f"seed {seed}: {set(cm.pairs) - set(moved)}"


def test_a_free_flying_base_moves_every_body_against_the_world():
    """The tripod's root is a free flyer: no body is invariant against a world obstacle."""
    tripod = rrc_pin.load("yeh_tripod")
    cm = CollisionModel(tripod)
    cm.add_halfspace((0.0, 0.0, 1.0), -1.0, name="floor")
    assert not [p for p in cm.invariant if "floor" in p]
    assert all((body, "floor") in cm.pairs for body in cm.bodies[:-1]
               if cm.scene.joint[cm.bodies.index(body)] != 0)  # fmt: skip
