"""rrc_pin.solvers.collision.narrow_kernels: the compiled narrow phase against coal (1e-9) on
thousands of random
sphere, capsule and half-space pairs, including parallel and intersecting segments, and its
end-point rows against the point-to-segment distance written in numpy."""

from __future__ import annotations

import coal
import numpy as np
import pinocchio as pin
import pytest

from rrc_pin.geometry import shapes
from rrc_pin.solvers.collision.narrow_kernels import (
    BOX,
    CAPSULE,
    HALFSPACE,
    OTHER,
    SPHERE,
    narrow_phase,
)
from rrc_pin.solvers.collision.records import BODY, FOUND

TOL = 1e-9
TRIALS = 500
FAR = 10.0
"""[m] A detection distance every trial is below: each pair gives its row."""


def rotation(rng):
    return pin.exp3(rng.normal(size=3) * 2.0)


def body(kind, rng):
    """(shape code, segment (2, 3) in the body's frame, radius, coal shape)."""
    r = rng.uniform(0.02, 0.12)
    if kind == "sphere":
        return SPHERE, np.zeros((2, 3)), r, coal.Sphere(r)
    half = rng.uniform(0.0, 0.3) if rng.random() < 0.9 else 0.0
    return CAPSULE, np.array([[0, 0, -half], [0, 0, half]]), r, coal.Capsule(r, 2 * half)


def records(shapes, segments, radii, joints):
    """Two bodies as the kernel reads them (bounding spheres never read by these pairs)."""
    bodies = np.zeros(2, dtype=BODY)
    bodies["shape"], bodies["segment"], bodies["radius"] = shapes, segments, radii
    bodies["joint"] = joints
    return bodies


def run(bodies, poses, ends, detection, rows=5):
    """The kernel on the pair (0, 1): (rows, others, found, other)."""
    found = np.zeros(rows, dtype=FOUND)
    other = np.zeros(1, dtype=np.int64)
    rows, others = narrow_phase(poses, bodies, np.zeros((2, 3)), np.array([0]), np.array([1]),
                                np.array([0]), 1, np.ones(1, dtype=np.bool_), detection, ends,
                                found, other)  # fmt: skip
    return rows, others, found, other


def solve(shapes, segments, radii, poses, plane=None, ends=False, detection=FAR):
    """The kernel on one pair (body 0 on joint 1, body 1 on joint 2 or a world half-space)."""
    bodies = records(shapes, np.array(segments), radii, [1, 2 if plane is None else 0])
    if plane is not None:
        bodies["normal"][1], bodies["offset"][1] = plane
    rows, others, found, _ = run(bodies, poses, ends, detection)
    assert others == 0
    return rows, found


def coal_distance(shape_a, Ma, shape_b, Mb):
    result = coal.DistanceResult()
    Ta = coal.Transform3s(Ma[:3, :3], Ma[:3, 3])
    Tb = coal.Transform3s(Mb[:3, :3], Mb[:3, 3])
    coal.distance(shape_a, Ta, shape_b, Tb, coal.DistanceRequest(), result)
    return result


def pose(R, p):
    M = np.eye(4)
    M[:3, :3], M[:3, 3] = R, p
    return M


def draw(case, rng):
    """Poses (3, 4, 4) and two bodies of a trial."""
    kinds = {"sphere capsule": ("sphere", "capsule"), "capsule sphere": ("capsule", "sphere"),
             "spheres": ("sphere", "sphere")}.get(case, ("capsule", "capsule"))  # fmt: skip
    a, b = body(kinds[0], rng), body(kinds[1], rng)
    Ra = rotation(rng)
    pa = rng.normal(size=3) * 0.2
    if case == "parallel":  # the same axis direction, either way round, offset sideways
        Rb = Ra @ (np.eye(3) if rng.random() < 0.5 else np.diag([1.0, -1.0, -1.0]))
        pb = pa + Ra @ np.array([*rng.normal(size=2) * 0.15, rng.uniform(-0.4, 0.4)])
    elif case == "crossing":  # segment B through a point of segment A
        Rb = rotation(rng)
        on_a = pa + Ra @ a[1][1] * rng.uniform(-1, 1)
        pb = on_a - Rb @ b[1][1] * rng.uniform(-1, 1)
    else:
        Rb = rotation(rng)
        pb = pa + rng.normal(size=3) * 0.25
    poses = np.array([np.eye(4), pose(Ra, pa), pose(Rb, pb)])
    return poses, a, b


CASES = ["capsules", "sphere capsule", "capsule sphere", "spheres", "parallel", "crossing"]


@pytest.mark.parametrize("case", CASES)
def test_rows_match_coal(case):
    """Distance to 1e-9 always; witness points and normal where they are unique (not parallel
    segments, not meeting segments, where coal's normal is zero, and this one is the unit
    normal of both segments); in every case the row's own
    conventions: unit normal, ``p_b - p_a = d n``, witnesses on the bodies' surfaces (segments
    apart)."""
    rng = np.random.default_rng(300 + CASES.index(case))
    inside = unique = 0
    for _ in range(TRIALS):
        poses, a, b = draw(case, rng)
        rows, out = solve([a[0], b[0]], [a[1], b[1]], [a[2], b[2]], poses)
        assert rows == 1
        ref = coal_distance(a[3], poses[1], b[3], poses[2])
        d, pa, pb, n = out["distance"][0], out["point_a"][0], out["point_b"][0], out["normal"][0]
        assert d == pytest.approx(ref.min_distance, abs=TOL)
        assert np.linalg.norm(n) == pytest.approx(1.0, abs=1e-12)
        np.testing.assert_allclose(pb - pa, d * n, atol=TOL)
        segments_apart = d + a[2] + b[2] > 1e-6
        for p, (_, seg, r, _), M in ((pa, a, poses[1]), (pb, b, poses[2])):
            ends = seg @ M[:3, :3].T + M[:3, 3]
            if segments_apart:  # on the surface
                assert point_segment(p, ends)[0] == pytest.approx(r, abs=TOL)
        u = (poses[1][:3, :3] @ a[1][1]) * 2
        v = (poses[2][:3, :3] @ b[1][1]) * 2
        conditioned = np.linalg.norm(np.cross(u, v)) > 1e-3 * np.linalg.norm(u) * np.linalg.norm(v)
        if segments_apart and (conditioned or not (u.any() and v.any())):
            np.testing.assert_allclose(pa, ref.getNearestPoint1(), atol=TOL)
            np.testing.assert_allclose(pb, ref.getNearestPoint2(), atol=TOL)
            np.testing.assert_allclose(n, ref.normal, atol=TOL)
            unique += 1
        if not segments_apart and conditioned:  # meeting segments: along u x v
            assert abs(n @ u) + abs(n @ v) < 1e-9
        inside += d < 0
    assert inside >= 10 and (unique >= TRIALS // 2 or case in ("parallel", "crossing"))


def point_segment(p, ends):
    """Distance from p to the segment ``ends`` (2, 3) and the closest point, in numpy."""
    u = ends[1] - ends[0]
    s = 0.0 if not u.any() else float(np.clip((p - ends[0]) @ u / (u @ u), 0.0, 1.0))
    c = ends[0] + s * u
    return float(np.linalg.norm(p - c)), c


@pytest.mark.parametrize("kind", ["capsule", "sphere"])
def test_against_a_halfspace_rows_match_coal(kind):
    rng = np.random.default_rng(7)
    for _ in range(TRIALS):
        a = body(kind, rng)
        poses = np.array([np.eye(4), pose(rotation(rng), rng.normal(size=3) * 0.2), np.eye(4)])
        m = rng.normal(size=3)
        m /= np.linalg.norm(m)
        o = float(m @ poses[1][:3, 3] + rng.uniform(-0.3, 0.3))
        rows, out = solve([a[0], HALFSPACE], [a[1], np.zeros((2, 3))], [a[2], 0.0], poses, (m, o))
        ref = coal_distance(a[3], poses[1], coal.Halfspace(m, o), np.eye(4))
        assert rows == 1
        assert out["distance"][0] == pytest.approx(ref.min_distance, abs=TOL)
        np.testing.assert_allclose(out["normal"][0], -m, atol=1e-12)
        np.testing.assert_allclose(out["point_b"][0] - out["point_a"][0],
                                   out["distance"][0] * out["normal"][0], atol=TOL)  # fmt: skip
        assert m @ out["point_b"][0] == pytest.approx(o, abs=TOL)


def test_against_a_halfspace_the_pairs_own_row_comes_before_its_other_ends():
    """With ``ends``, a capsule against a half-space: its first row is the pair's (coal's
    distance, the lower end), then the other end's, never nearer. (The end written first was
    the segment's first, whichever was lower: the pair's own row came second half the time.)"""
    rng = np.random.default_rng(12)
    second_lower = 0
    for _ in range(TRIALS):
        a = body("capsule", rng)
        poses = np.array([np.eye(4), pose(rotation(rng), rng.normal(size=3) * 0.2), np.eye(4)])
        m = rng.normal(size=3)
        m /= np.linalg.norm(m)
        o = float(m @ poses[1][:3, 3] + rng.uniform(-0.3, 0.3))
        rows, out = solve([a[0], HALFSPACE], [a[1], np.zeros((2, 3))], [a[2], 0.0], poses, (m, o),
                          ends=True)  # fmt: skip
        ref = coal_distance(a[3], poses[1], coal.Halfspace(m, o), np.eye(4))
        assert out["distance"][0] == pytest.approx(ref.min_distance, abs=TOL)
        if rows == 2:
            assert out["distance"][1] >= out["distance"][0] - TOL
            ends = poses[1][:3, :3] @ a[1].T
            second_lower += float(m @ ends[:, 1]) < float(m @ ends[:, 0])
    assert second_lower > TRIALS // 4


def test_end_point_rows_are_each_end_against_the_other_segment():
    """With ``ends``: the first row is the pair's; then every end point of a capsule within the
    detection distance of the other body that is not the closest point already, each at the
    point-to-segment distance (numpy), none below the pair's own distance."""
    rng = np.random.default_rng(11)
    detection = 0.15
    counts = np.zeros(6, dtype=int)
    for _ in range(TRIALS):
        poses, a, b = draw("parallel" if rng.random() < 0.5 else "capsules", rng)
        rows, out = solve([a[0], b[0]], [a[1], b[1]], [a[2], b[2]], poses, ends=True,
                          detection=detection)  # fmt: skip
        plain, first = solve([a[0], b[0]], [a[1], b[1]], [a[2], b[2]], poses, detection=detection)
        counts[rows] += 1
        assert (rows > 0) == (plain == 1)
        if not rows:
            continue
        for key in ("distance", "point_a", "point_b", "normal"):
            np.testing.assert_array_equal(out[key][0], first[key][0])
        world = [seg @ M[:3, :3].T + M[:3, 3] for seg, M in ((a[1], poses[1]), (b[1], poses[2]))]
        expected = []
        for side in (0, 1):
            if not (world[side][1] - world[side][0]).any():
                continue
            for end in world[side]:
                gap, c = point_segment(end, world[1 - side])
                closest = (end, c) if side == 0 else (c, end)
                seen = np.stack(closest)
                main = np.stack([out["point_a"][0] - a[2] * out["normal"][0],
                                 out["point_b"][0] + b[2] * out["normal"][0]])  # fmt: skip
                d = gap - a[2] - b[2]
                if d < detection and np.abs(seen - main).max() > 1e-9:
                    expected.append(d)
        got = out["distance"][1:rows]
        np.testing.assert_allclose(np.sort(got), np.sort(expected), atol=TOL)
        assert (got >= out["distance"][0] - TOL).all()
    assert counts[5] > 5 and counts[1] > 30, counts  # four end rows, and none, both seen


def test_capsule_end_points_against_a_box_match_coal():
    """A capsule against a box goes to coal for its closest points; with ``ends`` each end
    point's row is that point as a sphere of the capsule's radius against the box (coal, to
    1e-9; inside the box too), with the row's conventions."""
    rng = np.random.default_rng(13)
    inside = 0
    for _ in range(TRIALS):
        a = body("capsule", rng)
        half = rng.uniform(0.03, 0.3, 3)
        poses = np.array([np.eye(4), pose(rotation(rng), rng.normal(size=3) * 0.1),
                          pose(rotation(rng), rng.normal(size=3) * 0.1)])  # fmt: skip
        placement = pose(rotation(rng), rng.normal(size=3) * 0.05)  # the box in its joint
        bodies = records([a[0], BOX], [a[1], np.zeros((2, 3))], [a[2], 0.0], [1, 2])
        bodies["box"][1], bodies["half"][1] = placement[:3], half
        rows, others, out, other = run(bodies, poses, True, FAR)
        assert others == 1 and other[0] == 0  # the closest points: coal's
        ends = a[1] @ poses[1][:3, :3].T + poses[1][:3, 3]
        count = 1 if not (a[1][1] - a[1][0]).any() else 2  # then the features' rows
        assert rows >= count
        assert (out["end"][:count] == 1).all() and (out["end"][count:rows] == 2).all()
        for r in range(count):
            ref = coal_distance(coal.Sphere(a[2]), pose(np.eye(3), ends[r]),
                                coal.Box(*(2 * half)), poses[2] @ placement)  # fmt: skip
            d, n = out["distance"][r], out["normal"][r]
            assert d == pytest.approx(ref.min_distance, abs=TOL)
            np.testing.assert_allclose(out["point_b"][r] - out["point_a"][r], d * n, atol=TOL)
            assert np.linalg.norm(n) == pytest.approx(1.0, abs=1e-12)
            inside += d < -a[2]
    assert inside >= 20



SEEDS = (17, 1049562248620298025, int(np.random.SeedSequence().entropy % 2**63))
"""A fixed seed and one drawn fresh each run (named in every failure's message)."""


@pytest.mark.parametrize("seed", SEEDS, ids=("fixed", "found", "fresh"))
@pytest.mark.parametrize("kind", ["box", "cylinder", "convex"])
def test_coal_gets_a_pair_unless_its_bound_is_beyond_the_detection_distance(kind, seed):
    """A sphere or capsule against a shape coal measures: left for coal unless the segment's
    distance to the other's bounding sphere, less both radii, is at least the detection
    distance; so coal never misses a pair within it (coal's distance against the bound), and
    pairs farther are often not measured at all."""
    rng = np.random.default_rng(seed)
    detection = 0.1
    skipped = measured = 0
    for _ in range(TRIALS):
        a = body("capsule" if rng.random() < 0.8 else "sphere", rng)
        size = rng.uniform(0.03, 0.3, 3)
        if kind == "box":
            shape = coal.Box(*size)
        elif kind == "cylinder":
            shape = coal.Cylinder(size[0], size[1])
        else:
            shape = shapes.convex(rng.normal(size=(10, 3)) * size)
        centre, bounding = shapes.bounding_sphere(shape)
        poses = np.array([np.eye(4), pose(rotation(rng), rng.normal(size=3) * 0.1),
                          pose(rotation(rng), rng.normal(size=3) * 0.3)])  # fmt: skip
        bodies = records([a[0], BOX if kind == "box" else OTHER], [a[1], np.zeros((2, 3))],
                         [a[2], 0.0], [1, 2])  # fmt: skip
        bodies["bounding"][1] = bounding
        bodies["box"][1], bodies["half"][1] = np.eye(4)[:3], size / 2
        world = np.zeros((2, 3))
        world[1] = poses[2][:3, :3] @ centre + poses[2][:3, 3]
        found = np.zeros(5, dtype=FOUND)
        other = np.zeros(1, dtype=np.int64)
        _, others = narrow_phase(poses, bodies, world, np.array([0]), np.array([1]),
                                 np.array([0]), 1, np.ones(1, dtype=np.bool_), detection, False,
                                 found, other)  # fmt: skip
        d = coal_distance(a[3], poses[1], shape, poses[2]).min_distance
        assert others == 1 or d >= detection - 1e-9, f"seed {seed}: d {d} not measured"
        skipped += others == 0
        measured += d < detection
    assert skipped > TRIALS // 10 and measured > TRIALS // 10, f"seed {seed}: {skipped}, {measured}"


def segment_to_segment(p0, p1, q0, q1, samples=4001):
    """The least distance of two segments, by sampling the first, then again between the
    nearest sample's neighbours (the distance to a point of it is convex along it, so its
    least lies there): within 1e-9 m here."""
    v, lo, hi = q1 - q0, 0.0, 1.0
    for _ in range(2):
        s = np.linspace(lo, hi, samples)
        points = p0 + s[:, None] * (p1 - p0)
        t = np.clip((points - q0) @ v / (v @ v), 0.0, 1.0)
        d = np.linalg.norm(points - (q0 + t[:, None] * v), axis=1)
        k, step = int(np.argmin(d)), (hi - lo) / (samples - 1)
        lo, hi = max(s[k] - step, 0.0), min(s[k] + step, 1.0)
    return float(d.min())


@pytest.mark.parametrize("seed", SEEDS, ids=("fixed", "found", "fresh"))
def test_capsule_outside_a_box_gets_the_rows_of_its_nearest_edges(seed):
    """A capsule whose segment is outside a box: after its end points' rows, the rows of the
    box's edges nearest the segment (those of the nearest corner once, none an end's row
    repeats), against the distances of the twelve edges to the segment by sampling (1e-6 m);
    its end points' rows exact; the least of all its rows is coal's distance of the segment to
    the box less the radius (to coal's precision)."""
    rng = np.random.default_rng(seed)
    checked = 0
    for _ in range(200):
        a = body("capsule", rng)
        if not (a[1][1] - a[1][0]).any():
            continue
        half = rng.uniform(0.03, 0.3, 3)
        poses = np.array([np.eye(4), pose(rotation(rng), rng.normal(size=3) * 0.25),
                          pose(rotation(rng), np.zeros(3))])  # fmt: skip
        bodies = records([a[0], BOX], [a[1], np.zeros((2, 3))], [a[2], 0.0], [1, 2])
        bodies["box"][1], bodies["half"][1] = np.eye(4)[:3], half
        segment = a[1] @ poses[1][:3, :3].T + poses[1][:3, 3]
        apart = coal_distance(coal.Capsule(0.0, float(np.linalg.norm(a[1][1] - a[1][0]))),
                              poses[1], coal.Box(*(2 * half)), poses[2]).min_distance
        if apart <= 1e-3:  # the segment inside the box, or touching it
            continue
        rows, _, out, _ = run(bodies, poses, True, FAR)
        R = poses[2][:3, :3]
        edges = []
        for c in range(3):
            for s1 in (-1, 1):
                for s2 in (-1, 1):
                    k1, k2 = (c + 1) % 3, (c + 2) % 3
                    mid = s1 * half[k1] * R[:, k1] + s2 * half[k2] * R[:, k2]
                    ends = (mid - half[c] * R[:, c], mid + half[c] * R[:, c])
                    edges.append(segment_to_segment(*segment, *ends) - a[2])
        features = out[2:rows]  # less those an end point's row repeats
        assert 3 <= rows <= 5, f"seed {seed}"
        nearest = sorted(edges)
        local = np.abs((segment - poses[2][:3, 3]) @ R) - half  # the ends in the box's frame
        ends = np.linalg.norm(np.maximum(local, 0.0), axis=1) - a[2]
        np.testing.assert_allclose(out["distance"][:2], ends, rtol=0, atol=1e-12)
        least = min(nearest[0], *ends)
        assert out["distance"][:rows].min() == pytest.approx(least, abs=1e-6), f"seed {seed}"
        # coal's GJK is precise to about 1e-6 m at this size (its tolerance): seed
        # 6420167456669247044 put an end's exact distance 1.03e-6 m below coal's
        assert least == pytest.approx(apart - a[2], abs=1e-5), f"seed {seed}"
        for d in features["distance"]:  # each an edge's distance, and none below the nearest
            assert min(abs(d - e) for e in edges) <= 1e-6, f"seed {seed}"
        assert features["distance"].min() >= nearest[0] - 1e-6, f"seed {seed}"
        np.testing.assert_allclose(features["point_b"] - features["point_a"],
                                   features["distance"][:, None] * features["normal"], atol=TOL)
        checked += 1
    assert checked >= 50, f"seed {seed}: {checked}"
