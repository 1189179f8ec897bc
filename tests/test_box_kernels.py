"""rrc_pin.solvers.collision.box_kernels: a capsule inside a box, its deepest axis against coal's
signed distance and a numpy reference over the twelve axes, and its feature rows holding the
distance to first order where coal's witness alone loses it (a capsule lying along a face)."""

from __future__ import annotations

import coal
import numpy as np
import pinocchio as pin
import pytest

from rrc_pin.solvers.collision.box_kernels import PARALLEL, deepest_axis, inside_rows

TOL = 1e-9
SEEDS = (29, int(np.random.SeedSequence().entropy % 2**63))
"""A fixed seed and one drawn fresh each run (named in every failure's message)."""


def draw(rng):
    """A random capsule (ends (2, 3), radius, length, pose) and box (axes, centre, half)."""
    half = rng.uniform(0.03, 0.3, 3)
    Rb, tb = pin.exp3(rng.normal(size=3) * 2.0), rng.normal(size=3) * 0.05
    Ra, ta = pin.exp3(rng.normal(size=3) * 2.0), rng.normal(size=3) * 0.1
    r, length = rng.uniform(0.01, 0.08), rng.uniform(0.0, 0.3)
    ends = np.array([ta + Ra[:, 2] * length / 2, ta - Ra[:, 2] * length / 2])
    return ends, r, length, (Ra, ta), (Rb, tb, half)


def kernel_args(ends, r, box):
    Rb, tb, half = box
    axes = tuple(tuple(float(x) for x in Rb[:, c]) for c in range(3))
    return tuple(ends[0]), tuple(ends[1]), r, axes, tuple(tb), tuple(half)


def coal_signed(r, length, capsule, box):
    (Ra, ta), (Rb, tb, half) = capsule, box
    result = coal.DistanceResult()
    request = coal.DistanceRequest()  # EPA to its precision: its default 1e-6 is coarser than TOL
    request.gjk_tolerance = request.epa_tolerance = 1e-12
    request.epa_max_iterations = 1000
    coal.distance(coal.Capsule(r, length), coal.Transform3s(Ra, ta), coal.Box(*(2 * half)),
                  coal.Transform3s(Rb, tb), request, result)  # fmt: skip
    return result.min_distance


def reference(ends, r, box):
    """The largest separation over the box's faces and the segment x edge axes, in numpy."""
    Rb, tb, half = box
    u = ends[1] - ends[0]
    axes = [Rb[:, c] for c in range(3)]
    for c in range(3):
        w = np.cross(u, Rb[:, c])
        if np.linalg.norm(w) > PARALLEL * np.linalg.norm(u) and np.linalg.norm(w) > 0:
            axes.append(w / np.linalg.norm(w))
    best = -np.inf
    for m in axes:
        for signed in (m, -m):
            best = max(best, (ends @ signed).min() - r - signed @ tb - np.abs(Rb.T @ signed) @ half)
    return best


@pytest.mark.parametrize("seed", SEEDS, ids=("fixed", "fresh"))
def test_the_deepest_axis_is_coals_signed_distance_with_the_segment_inside(seed):
    """Where the segment is inside the box, the deepest axis's separation is coal's signed
    distance (to 1e-9) and the numpy reference's (1e-12); its rows' least distance is it, with
    coal's conventions; outside, no row."""
    rng = np.random.default_rng(seed)
    inside = 0
    for _ in range(600):
        ends, r, length, capsule, box = draw(rng)
        args = kernel_args(ends, r, box)
        F, m, _ = deepest_axis(*args)
        assert F == pytest.approx(reference(ends, r, box), abs=1e-12), f"seed {seed}"
        count, *rows = inside_rows(*args)
        if F >= -r:
            assert count == 0, f"seed {seed}"
            continue
        inside += 1
        assert F == pytest.approx(coal_signed(r, length, capsule, box), abs=TOL), f"seed {seed}"
        rows = rows[:count]
        along_m = [row[0] for row in rows if np.allclose(row[3], -np.array(m), atol=1e-15)]
        assert min(along_m) == pytest.approx(F, abs=1e-12), f"seed {seed}"
        for d, pa, pb, n in rows:
            np.testing.assert_allclose(np.subtract(pb, pa), d * np.array(n), atol=1e-12)
            assert np.linalg.norm(n) == pytest.approx(1.0, abs=1e-12)
        np.testing.assert_allclose(rows[0][3], -np.array(m), atol=1e-15)
    assert inside >= 300, f"seed {seed}: {inside} inside"


def moved(M, twist, tau):
    """Placement ``M`` (R, t) after the world twist [v_O; w] for ``tau`` [s]."""
    R, t = M
    step = pin.exp6(pin.Motion(twist * tau)).homogeneous
    return step[:3, :3] @ R, step[:3, :3] @ t + step[:3, 3]


def rate(row, twist_a, twist_b):
    """The row's distance rate: n . (v_b(p_b) - v_a(p_a)), v(p) = v_O + w x p."""
    _, pa, pb, n = row
    va = twist_a[:3] + np.cross(twist_a[3:], pa)
    vb = twist_b[:3] + np.cross(twist_b[3:], pb)
    return float(np.dot(n, vb - va))


@pytest.mark.parametrize("seed", SEEDS, ids=("fixed", "fresh"))
def test_the_rows_hold_the_distance_to_first_order_where_the_face_changes(seed):
    """A capsule lying along a box's face inside it, the box turned about an axis in that face
    (one end sinks at first order, the middle stays): the lowest of the rows' linear predictions
    is below coal's distance after the motion but for second order (|d - prediction| below
    0.5 (w tau)^2 m), while the middle's row alone misses it by the first-order sinking."""
    rng = np.random.default_rng(seed)
    for _ in range(50):
        half = rng.uniform(0.1, 0.3, 3)
        depth = rng.uniform(0.03, 0.9) * half.min()
        r, length = rng.uniform(0.01, 0.02), rng.uniform(0.05, 1.5 * half[0])
        Ra = pin.exp3(np.array([0.0, np.pi / 2, 0.0]))  # along the box's x
        capsule = (Ra, np.array([0.0, 0.0, half[2] - depth]))
        box = (np.eye(3), np.zeros(3), half)
        twist_a = np.zeros(6)
        twist_b = np.concatenate([rng.normal(size=3) * 0.01, [0.0, rng.choice([-1, 1]) * 2.0, 0]])
        ends = np.array([capsule[1] + Ra[:, 2] * length / 2, capsule[1] - Ra[:, 2] * length / 2])
        count, *rows = inside_rows(*kernel_args(ends, r, box))
        faces = [row for row in rows[:count] if abs(row[3][2] + 1.0) < 1e-12]  # n = -z
        assert len(faces) >= 2, f"seed {seed}"  # both ends (and a tied edge axis)
        d = coal_signed(r, length, capsule, box)
        for tau in (1e-3, 1e-2):
            Rb, tb = moved((box[0], box[1]), twist_b, tau)
            after = coal_signed(r, length, capsule, (Rb, tb, half))
            predicted = min(row[0] + tau * rate(row, twist_a, twist_b) for row in rows[:count])
            assert after >= predicted - 0.5 * (2.0 * tau) ** 2, f"seed {seed}, tau {tau}"
            middle = d + tau * float(np.dot([0, 0, -1.0], twist_b[:3]))  # the middle's row
            assert after < middle - 0.4 * length / 2 * 2.0 * tau, f"seed {seed}, tau {tau}"
