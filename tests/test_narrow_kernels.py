"""rrc_pin.solvers.collision.narrow_kernels: the compiled narrow phase against coal (1e-9) on
thousands of random
sphere, capsule and half-space pairs, including parallel and intersecting segments, and its
end-point rows against the point-to-segment distance written in numpy."""

from __future__ import annotations

import coal
import numpy as np
import pinocchio as pin
import pytest

from rrc_pin.solvers.collision.narrow_kernels import BOX, CAPSULE, HALFSPACE, SPHERE, narrow_phase

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


def solve(shapes, segments, radii, poses, plane=None, ends=False, detection=FAR):
    """The kernel on one pair (body 0 on joint 1, body 1 on joint 2 or a world half-space)."""
    ng = 2
    shape = np.array(shapes, dtype=np.int64)
    joint = np.array([1, 2 if plane is None else 0], dtype=np.int64)
    normal = np.zeros((ng, 3))
    offset = np.zeros(ng)
    if plane is not None:
        normal[1], offset[1] = plane
    out = {
        "pair": np.zeros(5, dtype=np.int64), "distance": np.zeros(5),
        "point_a": np.zeros((5, 3)), "point_b": np.zeros((5, 3)), "normal": np.zeros((5, 3)),
    }  # fmt: skip
    other = np.zeros(1, dtype=np.int64)
    rows, others = narrow_phase(poses, joint, shape, np.array(segments), np.array(radii),
                                np.zeros((ng, 3, 4)), np.zeros((ng, 3)), normal, offset,
                                np.array([0]), np.array([1]), np.array([0]), 1,
                                np.ones(1, dtype=np.bool_), detection, ends, out["pair"],
                                out["distance"], out["point_a"], out["point_b"], out["normal"],
                                np.zeros(5, dtype=np.int8), other)  # fmt: skip
    assert others == 0
    return rows, out


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
        out = {"pair": np.zeros(5, dtype=np.int64), "distance": np.zeros(5),
               "point_a": np.zeros((5, 3)), "point_b": np.zeros((5, 3)),
               "normal": np.zeros((5, 3)), "end": np.zeros(5, dtype=np.int8)}  # fmt: skip
        frames = np.zeros((2, 3, 4))
        frames[1] = placement[:3]
        halves = np.zeros((2, 3))
        halves[1] = half
        other = np.zeros(1, dtype=np.int64)
        rows, others = narrow_phase(
            poses, np.array([1, 2]), np.array([a[0], BOX]), np.array([a[1], np.zeros((2, 3))]),
            np.array([a[2], 0.0]), frames, halves, np.zeros((2, 3)), np.zeros(2), np.array([0]),
            np.array([1]), np.array([0]), 1, np.ones(1, dtype=np.bool_), FAR, True,
            out["pair"], out["distance"], out["point_a"], out["point_b"], out["normal"],
            out["end"], other)  # fmt: skip
        assert others == 1 and other[0] == 0  # the closest points: coal's
        ends = a[1] @ poses[1][:3, :3].T + poses[1][:3, 3]
        assert rows == (1 if not (a[1][1] - a[1][0]).any() else 2)
        assert (out["end"][:rows] == 1).all()
        for r in range(rows):
            ref = coal_distance(coal.Sphere(a[2]), pose(np.eye(3), ends[r]),
                                coal.Box(*(2 * half)), poses[2] @ placement)  # fmt: skip
            d, n = out["distance"][r], out["normal"][r]
            assert d == pytest.approx(ref.min_distance, abs=TOL)
            np.testing.assert_allclose(out["point_b"][r] - out["point_a"][r], d * n, atol=TOL)
            assert np.linalg.norm(n) == pytest.approx(1.0, abs=1e-12)
            inside += d < -a[2]
    assert inside >= 20
