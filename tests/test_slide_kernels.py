"""rrc_pin.solvers.tick.slide_kernels: the sliding stage's projection against DAQP (1e-8) on random
problems
(redundant and square metrics, infinite bounds, rows broken at zero), infeasible data refused,
never NaN; its damped optimum against the normal equations and bounded through a singularity."""

from __future__ import annotations

import numpy as np
import qpsolvers

from rrc_pin.solvers.tick.slide_kernels import INFEASIBLE, SOLVED, damped_optimum, project

TRIALS = 1500


def random_problem(rng, trial):
    n = int(rng.integers(2, 15))
    p = int(rng.integers(0, 30))
    A = rng.normal(size=(int(rng.integers(1, n + 1)), n))
    damping = 10.0 ** rng.uniform(-4, -1)
    w = rng.normal(size=n) * 2.0
    lb, ub = -rng.uniform(0.1, 2.0, n), rng.uniform(0.1, 2.0, n)
    if trial % 5 == 0:
        lb[0], ub[-1] = -np.inf, np.inf
    G = rng.normal(size=(p, n))
    h = rng.uniform(-0.05, 1.0, p) if trial % 3 == 0 else rng.uniform(0.0, 1.0, p)
    return A, damping, w, lb, ub, G, h


def test_project_is_the_qp_optimum_or_refuses_an_empty_set() -> None:
    rng = np.random.default_rng(29)
    solved = refused = 0
    for trial in range(TRIALS):
        A, damping, w, lb, ub, G, h = random_problem(rng, trial)
        n = w.size
        M = A.T @ A + damping * np.trace(A.T @ A) / A.shape[0] * np.eye(n)
        x = np.full(n, np.nan)
        code = project(A, damping, w, lb, ub, G, h, 0.0, x)
        ref = qpsolvers.solve_qp(M, -M @ w, G if h.size else None, h if h.size else None,
                                 lb=lb, ub=ub, solver="daqp")  # fmt: skip
        if ref is None:
            assert code == INFEASIBLE
            refused += 1
            continue
        assert code == SOLVED
        assert np.isfinite(x).all()
        np.testing.assert_allclose(x, ref, atol=1e-8 * (1.0 + np.abs(ref).max()))
        assert (x <= ub + 1e-9).all() and (x >= lb - 1e-9).all()
        assert (G @ x <= h + 1e-9).all()
        solved += 1
    assert solved > TRIALS // 2 and refused > 0


def test_project_keeps_the_margin_and_returns_w_when_it_is_inside() -> None:
    A = np.eye(3)
    lb, ub = np.full(3, -2.0), np.full(3, 2.0)
    G, h = np.array([[0.0, 0.0, -1.0]]), np.array([0.0])
    x = np.empty(3)
    assert project(A, 1e-2, np.array([0.1, 0.05, -0.1]), lb, ub, G, h, 1e-12, x) == SOLVED
    np.testing.assert_allclose(x, (0.1, 0.05, 0.0), atol=1e-11)
    assert float(G[0] @ x) <= 0.0  # on the row's safe side, not across it by rounding
    w = np.array([0.1, 0.05, 0.1])
    assert project(A, 1e-2, w, lb, ub, G, h, 1e-12, x) == SOLVED
    assert np.array_equal(x, w)


def test_project_refuses_a_row_of_zeros_broken_at_w() -> None:
    x = np.empty(2)
    code = project(np.eye(2), 1e-2, np.zeros(2), np.full(2, -1.0), np.full(2, 1.0),
                   np.zeros((1, 2)), np.array([-1.0]), 0.0, x)  # fmt: skip
    assert code == INFEASIBLE


def test_damped_optimum_minimises_its_cost_and_stays_bounded_at_a_singularity() -> None:
    rng = np.random.default_rng(3)
    for _ in range(200):
        n = int(rng.integers(2, 15))
        A = rng.normal(size=(int(rng.integers(1, n + 1)), n))
        b = rng.normal(size=A.shape[0])
        mu = 1e-2 * np.trace(A.T @ A) / A.shape[0]
        M = A.T @ A + mu * np.eye(n)
        t = np.linalg.solve(M, A.T @ b)
        out = np.empty(n)
        assert damped_optimum(A, 1e-2, b, out)
        np.testing.assert_allclose(out, np.linalg.solve(M, A.T @ b + mu * t), rtol=1e-9,
                                   atol=1e-12)  # fmt: skip
    A = np.array([[1.0, 0.0], [0.0, 1e-9]])  # one direction nearly lost: the exact rates 1e9
    out = np.empty(2)
    assert damped_optimum(A, 1e-2, np.array([1.0, 1.0]), out)
    assert np.isfinite(out).all() and np.abs(out).max() < 2.0
