"""The exact direction-preserving step with one null-space direction (plane LP)."""

from __future__ import annotations

import numpy as np
import pytest

from solvers.plane_lp import max_scale_one_null


def reference_u(a: np.ndarray, w: np.ndarray, lb: np.ndarray, ub: np.ndarray) -> float:
    """max u by brute force: the LP optimum is a vertex of the feasible polygon, i.e. an
    intersection of two boundary lines (an independent algorithm: vertex enumeration)."""
    n = a.size
    alpha = np.concatenate([a, a, [0.0, 0.0]])
    beta = np.concatenate([w, w, [1.0, 1.0]])
    gamma = np.concatenate([lb, ub, [0.0, 1.0]])
    best = 0.0
    for i in range(2 * n + 2):
        for j in range(i + 1, 2 * n + 2):
            det = alpha[i] * beta[j] - alpha[j] * beta[i]
            if abs(det) < 1e-12:
                continue
            z = (gamma[i] * beta[j] - gamma[j] * beta[i]) / det
            u = (alpha[i] * gamma[j] - alpha[j] * gamma[i]) / det
            q = z * a + u * w
            if -1e-12 <= u <= 1 + 1e-12 and np.all(q >= lb - 1e-11) and np.all(q <= ub + 1e-11):
                best = max(best, min(u, 1.0))
    return best


@pytest.mark.parametrize("seed", range(3))
def test_largest_scale_matches_vertex_enumeration(seed: int) -> None:
    rng = np.random.default_rng(seed)
    for _ in range(150):
        n = 7
        a = rng.standard_normal(n)
        a /= np.linalg.norm(a)
        a[rng.random(n) < 0.1] = 0.0  # joints the null direction does not move
        w = rng.standard_normal(n) * rng.choice([0.1, 1.0, 10.0])
        lb = -rng.uniform(0.0, 1.0, n) * (rng.random(n) > 0.15)  # some bounds exactly 0
        ub = rng.uniform(0.0, 1.0, n) * (rng.random(n) > 0.15)
        target = rng.standard_normal()
        z, u = max_scale_one_null(a, w, lb, ub, target)
        qdot = z * a + u * w
        assert 0.0 <= u <= 1.0
        assert np.all(qdot >= lb - 1e-12) and np.all(qdot <= ub + 1e-12)
        assert u == pytest.approx(reference_u(a, w, lb, ub), abs=1e-9)
        # z is the target clipped into the feasible interval at u: moving toward the target
        # breaks a bound
        if abs(z - target) > 1e-9:
            step = z + np.sign(target - z) * 1e-6
            moved = step * a + u * w
            assert np.any(moved < lb - 1e-13) or np.any(moved > ub + 1e-13)


def test_unconstrained_scale_is_one() -> None:
    a = np.array([1.0, 0.0, 0.0])
    w = np.array([0.1, 0.2, -0.1])
    z, u = max_scale_one_null(a, w, -np.ones(3), np.ones(3), 0.3)
    assert u == 1.0 and z == 0.3


def test_stuck_joint_forces_zero_scale() -> None:
    """A joint pinned at 0 that the null direction cannot move and w needs: s = 0."""
    a = np.array([1.0, 0.0])
    w = np.array([0.5, 1.0])
    z, u = max_scale_one_null(a, w, np.array([-1.0, 0.0]), np.array([1.0, 0.0]))
    assert u == 0.0 and z == 0.0
