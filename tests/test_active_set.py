"""The compiled dual active-set solver against DAQP and scipy, on seeded random QPs."""

from __future__ import annotations

import daqp
import numpy as np
import pytest
from scipy.optimize import linprog

from rrc_pin.solvers.qp_backends import active_set
from rrc_pin.solvers.qp_backends.active_set import (
    INFEASIBLE,
    NOT_CONVERGED,
    NOT_DEFINITE,
    SOLVED,
    one_sided,
    solve,
)


def random_qp(rng: np.random.Generator) -> tuple[np.ndarray, ...]:
    """P, q, C, lo, hi, lb, ub: 1-8 variables, 0-39 rows; a third with repeated (parallel)
    rows, some with a side below zero (often infeasible), sides infinite at random."""
    nz, p = int(rng.integers(1, 9)), int(rng.integers(0, 40))
    B = rng.standard_normal((nz, nz))
    P = B @ B.T + 10.0 ** rng.uniform(-4.0, 0.0) * np.eye(nz)
    q = rng.standard_normal(nz) * rng.uniform(0.1, 10.0)
    C = rng.standard_normal((p, nz))
    if p > 1 and rng.random() < 0.3:  # degenerate: rows parallel to others
        C[p // 2 :] = C[: p - p // 2] * rng.uniform(0.5, 2.0)
    lo = np.where(rng.random(p) < 0.5, -np.inf, -rng.uniform(0.0, 2.0, p))
    low_side = -0.5 if rng.random() < 0.2 else 0.0
    hi = np.where(rng.random(p) < 0.3, np.inf, rng.uniform(low_side, 2.0, p))
    lb = np.where(rng.random(nz) < 0.5, -np.inf, -rng.uniform(0.0, 1.0, nz))
    ub = np.where(rng.random(nz) < 0.5, np.inf, rng.uniform(0.0, 1.0, nz))
    return P, q, C, lo, hi, lb, ub


def feasible(C: np.ndarray, lo: np.ndarray, hi: np.ndarray, lb: np.ndarray, ub: np.ndarray
             ) -> bool:  # fmt: skip
    """Whether any z meets the constraints (HiGHS on the zero objective)."""
    if (lo > hi).any() or (lb > ub).any():
        return False
    nz = lb.size
    upper, lower = np.isfinite(hi), np.isfinite(lo)
    result = linprog(np.zeros(nz), A_ub=np.vstack([C[upper], -C[lower], np.zeros((0, nz))]),
                     b_ub=np.concatenate([hi[upper], -lo[lower]]),
                     bounds=list(zip(np.where(np.isfinite(lb), lb, None),
                                     np.where(np.isfinite(ub), ub, None), strict=True)),
                     method="highs")  # fmt: skip
    return bool(result.status == 0)


def by_daqp(P: np.ndarray, q: np.ndarray, C: np.ndarray, lo: np.ndarray, hi: np.ndarray,
            lb: np.ndarray, ub: np.ndarray) -> np.ndarray | None:  # fmt: skip
    """DAQP's answer (the backend's settings: primal tolerance 1e-9), or None."""
    nz = q.size
    x, _, flag, _ = daqp.solve(P, q, C, np.concatenate([ub, hi]), np.concatenate([lb, lo]),
                               np.zeros(nz + hi.size, np.intc), primal_tol=1e-9)  # fmt: skip
    return np.asarray(x) if flag > 0 else None


def violation(C: np.ndarray, lo: np.ndarray, hi: np.ndarray, lb: np.ndarray, ub: np.ndarray,
              x: np.ndarray) -> float:  # fmt: skip
    Cx = C @ x
    return float(max(0.0, *(Cx - hi), *(lo - Cx), *(x - ub), *(lb - x)))


def test_three_thousand_random_qps_agree_with_daqp() -> None:
    """Where both answer: within 1e-9 of DAQP (relative to the answer's size; measured 4e-12);
    where it says infeasible, HiGHS finds no point either; 3 of 3,000 not answered (degenerate
    vertices: DAQP, the tick's fallback, answers them), none wrongly."""
    rng = np.random.default_rng(20261206)
    codes = {SOLVED: 0, INFEASIBLE: 0, NOT_CONVERGED: 0, NOT_DEFINITE: 0}
    worst = 0.0
    for _ in range(3000):
        P, q, C, lo, hi, lb, ub = random_qp(rng)
        x = np.empty(q.size)
        code, steps = solve(P, q, C, lo, hi, lb, ub, x)
        codes[code] += 1
        assert steps >= 0
        if code == SOLVED:
            assert violation(C, lo, hi, lb, ub, x) <= 1e-9 * (1.0 + np.abs(x).max())
            other = by_daqp(P, q, C, lo, hi, lb, ub)
            if other is not None:
                worst = max(worst, np.abs(x - other).max() / (1.0 + np.abs(other).max()))
        elif code == INFEASIBLE:
            assert not feasible(C, lo, hi, lb, ub)
    assert worst <= 1e-9, worst
    assert codes[NOT_CONVERGED] <= 6 and codes[NOT_DEFINITE] == 0, codes
    assert codes[SOLVED] > 2500 and codes[INFEASIBLE] > 100, codes


def test_degenerate_vertices_and_duplicated_rows() -> None:
    """Many rows through one point (an LP-like vertex, as the direction QP's at a joint on its
    limit): the optimum (to the solver's tolerance, which grows with the unconstrained
    minimum's distance: P down to 1e-6), or a refusal (5 of 500), never a wrong answer."""
    rng = np.random.default_rng(3)
    refused = 0
    for _ in range(500):
        nz = int(rng.integers(2, 6))
        P = np.diag(10.0 ** rng.uniform(-6.0, 0.0, nz))
        q = rng.standard_normal(nz)
        vertex = rng.standard_normal(nz) * 0.1
        C = rng.standard_normal((3 * nz, nz))
        C[nz : 2 * nz] = C[:nz] * 3.0  # the same rows again, scaled
        hi = C @ vertex  # every row through the vertex
        lo = np.full(hi.size, -np.inf)
        lb, ub = np.full(nz, -np.inf), np.full(nz, np.inf)
        x = np.empty(nz)
        code, _ = solve(P, q, C, lo, hi, lb, ub, x)
        if code != SOLVED:
            refused += 1
            continue
        start = -np.linalg.solve(P, q)  # the unconstrained minimum
        allowed = 2.0 * (active_set.PRIMAL_TOL * (1.0 + np.abs(hi).max())
                         + active_set.ROUNDING * np.abs(start).max())  # fmt: skip
        allowed *= np.linalg.norm(C, axis=1).max()  # the solver's rows are of unit norm
        assert violation(C, lo, hi, lb, ub, x) <= allowed
        other = by_daqp(P, q, C, lo, hi, lb, ub)
        if other is not None:
            assert np.abs(x - other).max() <= 1e-6 * (1.0 + np.abs(other).max())
    assert refused <= 10, refused


def test_edge_cases() -> None:
    P, q = np.eye(2), np.array([-1.0, -1.0])
    x = np.empty(2)
    none = np.zeros((0, 2)), np.zeros(0), np.zeros(0)
    free = np.full(2, -np.inf), np.full(2, np.inf)
    assert solve(P, q, *none, *free, x) == (SOLVED, 0)  # no constraint: the minimum
    np.testing.assert_array_equal(x, [1.0, 1.0])
    # the probe of make_backend: z1 + z2 <= 1 within [0, 1]^2 gives (0.5, 0.5)
    code, _ = solve(P, q, np.array([[1.0, 1.0]]), np.array([-np.inf]), np.ones(1),
                    np.zeros(2), np.ones(2), x)  # fmt: skip
    assert code == SOLVED
    np.testing.assert_allclose(x, [0.5, 0.5], atol=1e-15)
    zeros = np.zeros((1, 2))
    assert solve(P, q, zeros, np.array([0.5]), np.array([1.0]), *free, x)[0] == INFEASIBLE
    assert solve(P, q, zeros, np.array([-0.5]), np.array([1.0]), *free, x)[0] == SOLVED
    assert solve(np.zeros((2, 2)), q, *none, *free, x)[0] == NOT_DEFINITE
    assert solve(P, q, *none, np.ones(2), np.zeros(2), x)[0] == INFEASIBLE  # lb > ub


def test_one_sided_rows_are_of_unit_norm() -> None:
    C = np.array([[3.0, 4.0], [0.0, 0.0]])
    N, b, possible = one_sided(C, np.array([-5.0, -1.0]), np.array([np.inf, 1.0]),
                               np.array([-np.inf, 0.0]), np.array([2.0, np.inf]))  # fmt: skip
    assert possible
    np.testing.assert_allclose(N, [[0.6, 0.8], [-1.0, 0.0], [0.0, 1.0]])
    np.testing.assert_allclose(b, [-1.0, -2.0, 0.0])


@pytest.mark.compiled
def test_the_solver_names_itself() -> None:
    assert active_set.NAME == "active_set"
