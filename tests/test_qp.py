"""The QP record: its qpsolvers.Problem has the same solution, feasibility, decoding."""

from __future__ import annotations

import numpy as np
import pytest
import qpsolvers

from rrc_pin.solvers.qp_backends import make_backend
from rrc_pin.solvers.qp_backends.qp import QP, Decoding


def feasible(qp: QP, z: np.ndarray, tol: float = 0.0) -> bool:
    """True when ``z`` satisfies every bound and row of ``qp`` within ``tol`` (False for NaN)."""
    if not ((z >= qp.lb - tol).all() and (z <= qp.ub + tol).all()):
        return False
    if qp.C is None or qp.l is None or qp.u is None:
        return True
    c = qp.C @ z
    return bool((c >= qp.l - tol).all() and (c <= qp.u + tol).all())


def random_qp(rng: np.random.Generator, nz: int, nc: int, infinite: float) -> QP:
    """A feasible strictly convex QP; each side is infinite with probability ``infinite``."""
    A = rng.standard_normal((nz, nz))
    P = A @ A.T + 0.1 * np.eye(nz)
    q = rng.standard_normal(nz) * 3.0
    z0 = rng.standard_normal(nz)  # a feasible point
    C = rng.standard_normal((nc, nz)) if nc else None
    sides = []
    for center, size in ((z0, nz), (C @ z0 if C is not None else None, nc)):
        if center is None:
            sides.append((None, None))
            continue
        lo = center - rng.uniform(0.0, 1.0, size)
        hi = center + rng.uniform(0.0, 1.0, size)
        lo[rng.random(size) < infinite] = -np.inf
        hi[rng.random(size) < infinite] = np.inf
        sides.append((lo, hi))
    (lb, ub), (lo, hi) = sides
    return QP(P, q, C, lo, hi, lb, ub, f"random:{nz}:{nc}")


def reference(qp: QP) -> np.ndarray:
    """The QP solved by quadprog (Goldfarb-Idnani, exact active set) on the Problem."""
    sol = qpsolvers.solve_problem(qp.problem(), solver="quadprog")
    assert sol.found
    return np.asarray(sol.x)


@pytest.mark.parametrize("infinite", [0.0, 0.3, 1.0])
def test_problem_has_the_same_solution(infinite: float, rng: np.random.Generator) -> None:
    """quadprog on the one-sided Problem, DAQP on the two-sided rows: the same z."""
    pytest.importorskip("quadprog")
    daqp = make_backend("daqp")
    for k in range(60):
        qp = random_qp(rng, int(rng.integers(1, 7)), int(rng.integers(0, 5)), infinite)
        via_problem = reference(qp)
        direct = daqp.solve(qp)
        assert direct.x is not None
        np.testing.assert_allclose(via_problem, direct.x, rtol=0, atol=1e-9, err_msg=str(k))
        assert feasible(qp, via_problem, tol=1e-9) and feasible(qp, direct.x, tol=1e-9)
        # and DAQP through qpsolvers, on the Problem
        sol = qpsolvers.solve_problem(qp.problem(), solver="daqp")
        np.testing.assert_allclose(sol.x, direct.x, rtol=0, atol=1e-9)


def test_problem_keeps_only_the_finite_sides() -> None:
    P, q = np.eye(3), np.zeros(3)
    C = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 1.0]])
    l = np.array([-1.0, -np.inf, -np.inf])  # noqa: E741
    u = np.array([2.0, 3.0, np.inf])
    finite_box = QP(P, q, C, l, u, -np.ones(3), np.ones(3), "k").problem()
    assert isinstance(finite_box, qpsolvers.Problem)
    # rows: u of rows 0 and 1, then -l of row 0; the third row has no finite side
    np.testing.assert_array_equal(finite_box.G, np.vstack([C[:2], -C[:1]]))
    np.testing.assert_array_equal(finite_box.h, [2.0, 3.0, 1.0])
    np.testing.assert_array_equal(finite_box.lb, -np.ones(3))
    np.testing.assert_array_equal(finite_box.ub, np.ones(3))
    assert finite_box.A is None and finite_box.b is None
    # an infinite box side: the finite box sides become rows, no lb/ub (no inf anywhere)
    lb = np.array([-1.0, -np.inf, 0.0])
    ub = np.array([np.inf, 1.0, 2.0])
    problem = QP(P, q, C, l, u, lb, ub, "k").problem()
    assert problem.lb is None and problem.ub is None
    assert problem.G is not None and problem.h is not None
    assert problem.G.shape == (3 + 4, 3) and np.isfinite(problem.h).all()
    np.testing.assert_array_equal(problem.G[3:], [[0, 1, 0], [0, 0, 1], [-1, 0, 0], [0, 0, -1]])
    np.testing.assert_array_equal(problem.h[3:], [1.0, 2.0, 1.0, 0.0])
    # no rows and a free box: an unconstrained problem
    free = QP(P, q, None, None, None, np.full(3, -np.inf), np.full(3, np.inf), "k").problem()
    assert free.G is None and free.h is None and free.lb is None and free.ub is None
    np.testing.assert_array_equal(free.P, P)
    np.testing.assert_array_equal(free.q, q)


def test_problem_with_only_infinite_rows_solves() -> None:
    pytest.importorskip("quadprog")
    qp = QP(np.eye(2), np.array([-3.0, 0.5]), np.ones((2, 2)), np.full(2, -np.inf),
            np.full(2, np.inf), np.full(2, -1.0), np.full(2, 1.0), "k")  # fmt: skip
    problem = qp.problem()
    assert problem.G is None or problem.G.shape[0] == 0
    sol = qpsolvers.solve_problem(problem, solver="quadprog")
    np.testing.assert_allclose(sol.x, [1.0, -0.5], atol=1e-12)


def test_feasible() -> None:
    qp = QP(np.eye(2), np.zeros(2), np.array([[1.0, 1.0]]), np.array([-np.inf]),
            np.array([1.0]), np.zeros(2), np.ones(2), "k")  # fmt: skip
    assert feasible(qp, np.array([0.5, 0.5]))
    assert feasible(qp, np.array([0.0, 1.0]))  # on the bounds
    assert not feasible(qp, np.array([0.6, 0.5]))  # the row
    assert feasible(qp, np.array([0.6, 0.5]), tol=0.1)
    assert not feasible(qp, np.array([-1e-9, 0.5]))  # the box
    assert feasible(qp, np.array([-1e-9, 0.5]), tol=1e-8)
    assert not feasible(qp, np.array([np.nan, 0.5]))
    assert not feasible(qp, np.array([0.2, np.nan]), tol=1.0)
    box = qp._replace(C=None, l=None, u=None)
    assert feasible(box, np.array([1.0, 1.0])) and not feasible(box, np.array([1.0, 1.1]))
    assert not feasible(box, np.array([np.nan, 0.0]))


def test_decoding_rates(rng: np.random.Generator) -> None:
    z = rng.standard_normal(3)
    x0 = rng.standard_normal(5)
    M = rng.standard_normal((5, 3))
    assert Decoding(None, None).rates(z) is z  # z is the joint rates
    np.testing.assert_array_equal(Decoding(None, M).rates(z), M @ z)
    np.testing.assert_array_equal(Decoding(x0, M).rates(z), x0 + M @ z)
    np.testing.assert_array_equal(Decoding(x0[:3], None).rates(z), x0[:3] + z)
