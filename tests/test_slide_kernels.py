"""rrc_pin.solvers.tick.slide_kernels: the sliding stage's projection against DAQP (1e-8) on random
problems
(redundant and square metrics, infinite bounds, rows broken at zero), infeasible data refused,
never NaN; its metric and target against numpy's SVD (undamped where the rows are well
conditioned, bounded through a singularity)."""

from __future__ import annotations

import numpy as np
import pytest
import qpsolvers

from rrc_pin.solvers.linalg import cholesky
from rrc_pin.solvers.tick.slide_kernels import (
    INFEASIBLE,
    SOLVED,
    TINY,
    project,
    project_factored,
    slide_metric,
)

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


def test_project_factored_is_project_in_the_metric_of_its_factor() -> None:
    rng = np.random.default_rng(31)
    for trial in range(300):
        A, damping, w, lb, ub, G, h = random_problem(rng, trial)
        n = w.size
        M = A.T @ A + max(damping * np.trace(A.T @ A) / A.shape[0], TINY) * np.eye(n)
        L = np.zeros((n, n))
        assert cholesky(M, 1e-13, L)
        x, y = np.full(n, np.nan), np.full(n, np.nan)
        code = project(A, damping, w, lb, ub, G, h, 1e-12, x)
        assert project_factored(L, w, lb, ub, G, h, 1e-12, y) == code
        if code == SOLVED:
            np.testing.assert_allclose(y, x, atol=1e-9 * (1.0 + np.abs(x).max()))


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


SEEDS = (3, 1052011918281309717, int(np.random.SeedSequence().entropy % 2**63))
"""A fixed seed, the one whose undamped rows (condition 5e8) failed on an older CPU, and one
drawn fresh each run (printed on failure)."""


def metric_of(A, b, mu_rel, threshold):
    """slide_metric's inputs from numpy's SVD, and its M and target written out."""
    m, n = A.shape
    U, s, Vt = np.linalg.svd(A)
    k = min(m, n)
    rank = int(np.sum(s > 1e-9 * s[0])) if s[0] > 0 else 0
    mu = mu_rel * np.sum(s**2) / m
    ratio = s[:rank] * threshold / s[0]  # sigma_i / sigma_on
    f = mu * np.maximum(1.0 - ratio**2, 0.0)
    V = Vt.T
    null = Vt[rank:]
    root = np.vstack([np.sqrt(f)[:, None] * Vt[:rank], np.sqrt(mu) * null])  # D = root^T root
    M = A.T @ A + root.T @ root
    # t, the damped least squares, and argmin |A x - b|^2 + (x - t)^T D (x - t), each as a
    # least squares of the stacked rows (not the normal equations: M squares the condition)
    stacked = np.vstack([A, root])
    t = np.linalg.lstsq(stacked, np.concatenate([b, np.zeros(root.shape[0])]), rcond=None)[0]
    want = np.linalg.lstsq(stacked, np.concatenate([b, root @ t]), rcond=None)[0]
    inputs = (U[:, :k] * s[:k], s[:k].copy(), V[:, :k].copy(), rank, null.copy())
    return inputs, M, want


@pytest.mark.parametrize("seed", SEEDS, ids=("fixed", "condition-5e8", "fresh"))
def test_slide_metric_is_the_damped_metric_and_its_optimum(seed) -> None:
    rng = np.random.default_rng(seed)
    for trial in range(300):
        n = int(rng.integers(2, 15))
        m = int(rng.integers(1, n + 1))
        A = rng.normal(size=(m, n)) * rng.uniform(0.1, 3.0, n)
        if trial % 3 == 0:  # ill conditioned: some directions past the onset
            U, s, Vt = np.linalg.svd(A, full_matrices=False)
            A = U @ np.diag(s * np.logspace(0, -rng.uniform(1, 5), s.size)) @ Vt
        b = rng.normal(size=m)
        threshold = float(rng.choice([10.0, 100.0, np.inf]))
        (US, sigma, right, rank, null), M, want = metric_of(A, b, 1e-2, threshold)
        B, target = np.empty((m + n, n)), np.empty(n)
        rows = slide_metric(A, US, sigma, right, rank, null, b, 1e-2, threshold, B, target)
        scale = np.abs(M).max()
        np.testing.assert_allclose(B[:rows].T @ B[:rows], M, atol=1e-10 * scale,
                                   err_msg=f"seed {seed} trial {trial}")  # fmt: skip
        # a backward-stable solve is accurate to about cond * eps (Higham, Accuracy and
        # Stability of Numerical Algorithms, 2002, 20.1): undamped rows of condition 5e8 give
        # 1e-8 relative, on both sides of the comparison
        conditioned = 1e-9 + 4.0 * np.linalg.cond(B[:rows]) * np.finfo(float).eps
        np.testing.assert_allclose(target, want, rtol=1e-8, atol=conditioned * np.abs(want).max(),
                                   err_msg=f"seed {seed} trial {trial}")  # fmt: skip


def test_slide_metric_leaves_well_conditioned_rows_undamped_and_a_singularity_bounded() -> None:
    A = np.array([[1.0, 0.0, 0.0], [0.0, 0.5, 0.0]])  # condition 2: its exact rates, the
    b = np.array([0.3, -0.2])  # null space (joint 3) at mu
    (US, sigma, right, rank, null), _, _ = metric_of(A, b, 1e-2, 100.0)
    B, target = np.empty((5, 3)), np.empty(3)
    rows = slide_metric(A, US, sigma, right, rank, null, b, 1e-2, 100.0, B, target)
    np.testing.assert_allclose(target, (0.3, -0.4, 0.0), atol=1e-15)
    mu = 1e-2 * (1.0 + 0.25) / 2
    np.testing.assert_allclose(B[:rows].T @ B[:rows], np.diag([1.0, 0.25, mu]), atol=1e-15)
    A = np.array([[1.0, 0.0], [0.0, 1e-9]])  # one direction nearly lost: the exact rates 1e9
    (US, sigma, right, rank, null), _, _ = metric_of(A, np.ones(2), 1e-2, 100.0)
    B, target = np.empty((4, 2)), np.empty(2)
    slide_metric(A, US, sigma, right, rank, null, np.ones(2), 1e-2, 100.0, B, target)
    assert np.isfinite(target).all() and np.abs(target).max() < 20.0
