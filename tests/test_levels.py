"""A least-squares level in the compiled tick (solvers/tick/levels.py) against numpy and the
pipeline's level (solvers/tick/least_squares.py): the same rates and null space to 1e-12 on
random levels, the top one and lower ones in a null space (some with a joint the levels above
hold at its bound), with and without constraint rows, the optimum inside the constraints,
projected onto them, or the backend's QP."""

from __future__ import annotations

import numpy as np
import pytest

from rrc_pin.solvers.qp_backends import make_backend
from rrc_pin.solvers.qp_backends.qp import Work
from rrc_pin.solvers.tick import backend_calls, levels
from rrc_pin.solvers.tick.least_squares import Subspace, least_squares
from rrc_pin.solvers.tick.problem import Box, Rows

SEEDS = [20261206, int(np.random.SeedSequence().entropy % 2**63)]
N = 8


@pytest.mark.parametrize("seed", SEEDS)
def test_products_against_numpy(seed: int) -> None:
    rng = np.random.default_rng(seed)
    for _ in range(100):
        m, n, k = rng.integers(1, 9, 3)
        A, B = rng.normal(size=(m, n)), rng.normal(size=(n, k))
        np.testing.assert_allclose(levels.product(A, B), A @ B, atol=1e-13)


def level_case(rng: np.random.Generator) -> tuple:
    """A level's rows and rates, a box around zero, maybe rows, maybe a subspace."""
    m = int(rng.integers(2, 12))
    A, b = rng.normal(size=(m, N)), rng.normal(size=m) * rng.choice([0.1, 1.0, 5.0])
    lb, ub = -rng.uniform(0.2, 1.5, N), rng.uniform(0.2, 1.5, N)
    p = int(rng.integers(0, 3))
    G, h = rng.normal(size=(p, N)), rng.uniform(0.0, 1.0, p)
    if rng.random() < 0.5:  # a lower level: x feasible, N spanning some free directions
        d = int(rng.integers(1, N))
        M = rng.normal(size=(N, N))
        held = rng.random() < 0.3  # joint 0 kept at its bound by the levels above
        if held:
            M[:, 0] = np.eye(N)[0]
        basis = np.linalg.qr(M)[0][:, int(held):int(held) + d].T.copy()
        x = np.clip(rng.normal(size=N) * 0.1, lb * 0.5, ub * 0.5)
        if held:
            x[0] = ub[0]
        h = np.maximum(h, G @ x)
    else:
        basis, x = np.empty((0, N)), np.zeros(N)
    return A, b, x, basis, lb, ub, G, h


@pytest.mark.parametrize("seed", SEEDS)
def test_a_level_answers_as_the_pipeline(seed: int) -> None:
    rng = np.random.default_rng(seed)
    context = backend_calls.Context(make_backend("daqp"), np.full(N, 1.5))
    worst, projected = 0.0, 0
    for _ in range(300):
        A, b, x, basis, lb, ub, G, h = level_case(rng)
        whole = basis.shape[0] == 0
        box = Box(lb, ub, np.zeros((2, N), np.int8), True, False, np.full(N, 1.5))
        rows = Rows(G, h, tuple(f"r{i}" for i in range(h.size))) if h.size else None
        space = Subspace(None, None) if whole else Subspace(x, basis)
        want, want_null = least_squares(A, b, space, box, rows, make_backend("daqp"), Work(),
                                        "level", True)  # fmt: skip
        backend_calls.enter(context)
        try:
            tol = 1e-6 * (1 + np.linalg.norm(np.full(N, 1.5)))
            got, null = levels.least_squares(0 if whole else 1, A, b, x, basis, lb, ub, G, h,
                                             tol, True)  # fmt: skip
        finally:
            backend_calls.leave()
        worst = max(worst, float(np.abs(got - want).max()))
        projected += not (np.all(want >= lb) and np.all(want <= ub) and np.all(
            np.abs(A @ want - b) < 1e-9))  # fmt: skip
        np.testing.assert_allclose(null, want_null, atol=1e-12)
    assert worst < 1e-9, worst
    assert projected > 50  # the constraints bound many of them


@pytest.mark.parametrize("start", ["within", "outside"])
def test_subspace_rows_against_numpy(start: str) -> None:
    """The box and rows of rates ``x + N^T z`` as one-sided rows in z, with the slack around
    z = 0 that least_squares._level_qp gives them: where x breaks a bound by at most the
    tolerance, widened to it; beyond (x a row asks away from), the bound kept."""
    rng = np.random.default_rng(3)
    basis = np.linalg.qr(rng.normal(size=(N, N)))[0][:, :3].T.copy()
    x, lb, ub = rng.normal(size=N) * 0.1, -np.ones(N), np.ones(N)
    lb[0] = -np.inf
    G = rng.normal(size=(2, N))
    tol = 1e-6
    broken = 0.5 * tol if start == "within" else 1e-3
    h = np.array([0.5, float(G[1] @ x) - broken])
    Gz, hz = levels.subspace_rows(x, basis, lb, ub, G, h, tol)
    C = np.vstack([basis.T, G @ basis.T])
    lo = np.minimum(np.concatenate([lb - x, np.full(2, -np.inf)]), 0.0) - levels.ROUNDING
    hi = np.maximum(np.concatenate([ub - x, h - G @ x]), 0.0) + levels.ROUNDING
    if start == "outside":
        hi[-1] = h[1] - G[1] @ x + levels.ROUNDING
    low, high = np.isfinite(lo), np.isfinite(hi)
    np.testing.assert_allclose(Gz, np.vstack([C[high], -C[low]]), atol=1e-15)
    np.testing.assert_allclose(hz, np.concatenate([hi[high], -lo[low]]), atol=1e-15)


def test_metric_projection_is_project_to_the_bit() -> None:
    """The projection in the level's factorised metric is project's, bit for bit, and project's
    own where the metric's diagonal is too small to ignore its damping."""
    from rrc_pin.solvers import linalg
    from rrc_pin.solvers.tick.slide_kernels import MARGIN, project

    rng = np.random.default_rng(7)
    for trial in range(200):
        B = rng.normal(size=(12, 5)) * (1e-160 if trial % 50 == 0 else 1.0)
        w = rng.normal(size=5)
        lb, ub = -rng.uniform(0.1, 1.0, 5), rng.uniform(0.1, 1.0, 5)
        G, h = rng.normal(size=(3, 5)), rng.uniform(0.0, 1.0, 3)
        H, g, L = np.empty((5, 5)), np.empty(5), np.zeros((5, 5))
        linalg.normal_equations(B, np.zeros(12), np.ones(12), H, g)
        if not linalg.cholesky(H, 1e-12, L):
            continue
        x, y = np.full(5, np.nan), np.full(5, np.nan)
        code = project(B, 0.0, w, lb, ub, G, h, MARGIN, x)
        assert levels.metric_projection(B, H, L, w, lb, ub, G, h, y) == code
        assert np.array_equal(x, y, equal_nan=True)
