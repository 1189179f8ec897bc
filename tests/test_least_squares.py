"""A least-squares level: its unconstrained optimum where it fits, else a QP of its stated costs."""

from __future__ import annotations

import numpy as np
import pytest
import qpsolvers
from scipy.optimize import lsq_linear

from rrc_pin.solvers.qp_backends import make_backend
from rrc_pin.solvers.qp_backends.base import QPBackend, QPSolution
from rrc_pin.solvers.qp_backends.qp import QP, Work
from rrc_pin.solvers.tick.least_squares import (
    TIE_BREAK,
    WELL_CONDITIONED,
    Subspace,
    least_squares,
    tie_broken,
)
from rrc_pin.solvers.tick.problem import Box, Rows


class Recording(QPBackend):
    """DAQP, keeping every QP it is handed."""

    name = "recording"

    def __init__(self) -> None:
        super().__init__()
        self.daqp = make_backend("daqp")
        self.seen: list[QP] = []

    def solve(self, qp: QP) -> QPSolution:
        self.seen.append(qp)
        return self.daqp.solve(qp)


def box(n: int, v: float) -> Box:
    return Box(np.full(n, -v), np.full(n, v), np.zeros((2, n), np.int8), True, False,
               np.full(n, v))  # fmt: skip


def test_the_unconstrained_optimum_needs_no_backend(rng: np.random.Generator) -> None:
    A, b = rng.normal(size=(4, 6)), rng.normal(size=4) * 0.1
    backend = Recording()
    x, _ = least_squares(A, b, Subspace(None, None), box(6, 10.0), None, backend, Work(), "t",
                         False)  # fmt: skip
    np.testing.assert_allclose(x, np.linalg.pinv(A) @ b, atol=1e-12)
    assert backend.seen == []


def test_a_saturating_command_reaches_the_backend_with_costs_of_unit_size(
    rng: np.random.Generator,
) -> None:
    """A command 1e7 times what the box reaches: the costs are divided by their largest entry
    (the minimiser is the same; proxqp, handed gradients 1e7 times P, iterated for 10 s)."""
    for _ in range(20):
        A, b = rng.normal(size=(8, 6)), rng.normal(size=8) * 1e7
        backend = Recording()
        x, _ = least_squares(A, b, Subspace(None, None), box(6, 2.0), None, backend, Work(),
                             "t", False)  # fmt: skip
        (qp,) = backend.seen
        assert max(np.abs(qp.P).max(), np.abs(qp.q).max()) == 1.0
        reference = lsq_linear(A, b, bounds=(-2.0, 2.0), method="bvls", tol=1e-14).x
        np.testing.assert_allclose(x, reference, atol=1e-6)


def test_a_definite_level_outside_its_constraints_is_projected_without_the_backend(
    rng: np.random.Generator,
) -> None:
    """Where the optimum is one point (more independent rows than unknowns), the kernel's
    projection in the metric B^T B answers: the top level against BVLS, a lower level in a
    null space with a row against qpsolvers' least squares (DAQP) on the same costs."""
    for _ in range(100):
        A, b = rng.normal(size=(9, 6)), rng.normal(size=9) * 3.0
        backend = Recording()
        x, _ = least_squares(A, b, Subspace(None, None), box(6, 1.0), None, backend, Work(),
                             "t", False)  # fmt: skip
        reference = lsq_linear(A, b, bounds=(-1.0, 1.0), method="bvls", tol=1e-14).x
        np.testing.assert_allclose(x, reference, atol=1e-9)
        assert backend.seen == []
    n, d = 7, 3
    for _ in range(100):
        N = np.linalg.qr(rng.normal(size=(n, d)))[0].T  # orthonormal rows (d, n)
        x0 = rng.uniform(-0.5, 0.5, n)
        A, b = rng.normal(size=(5, n)), rng.normal(size=5) * 3.0
        rows = Rows(rng.normal(size=(1, n)), np.array([0.3]), ("row",))
        rows = Rows(rows.G, rows.G @ x0 + 0.3, ("row",))  # x0 meets it
        backend = Recording()
        x, _ = least_squares(A, b, Subspace(x0, N), box(n, 1.0), rows, backend, Work(), "t",
                             False)  # fmt: skip
        assert backend.seen == []
        B, c = A @ N.T, b - A @ x0
        G = np.vstack([N.T, -N.T, rows.G @ N.T])
        h = np.concatenate([1.0 - x0, 1.0 + x0, rows.h - rows.G @ x0])
        z = qpsolvers.solve_ls(B, c, G, h, solver="daqp")
        np.testing.assert_allclose(x, x0 + z @ N, atol=1e-7)


def test_a_joint_the_level_above_holds_at_its_bound_leaves_the_projection_free(
    rng: np.random.Generator,
) -> None:
    """The levels above keep joint 0 at its upper bound (it lies in their rows' span), so the
    level's null space moves it only by rounding (exactly 0 or 1e-17). That row, at the start,
    tightened by the projection's margin, was a bound no z meets (0 <= -1e-24: refused, DAQP
    answered) or a plane through the start in a direction of rounding: the answer then hung on
    the basis's last bits. It is dropped: the projection answers, as the QP without it."""
    n = 6
    for _ in range(100):
        above = np.vstack([np.eye(1, n), rng.normal(size=(2, n))])
        N = np.linalg.svd(above)[2][3:]  # the null space of the levels above (3, n)
        x0 = np.linalg.pinv(above) @ rng.normal(size=3)
        x0[0] = 1.0  # joint 0 on its upper bound
        x0[1:] = np.clip(x0[1:], -0.9, 0.9)
        A, b = rng.normal(size=(n, n)), rng.normal(size=n) * 5.0
        backend = Recording()
        x, _ = least_squares(A, b, Subspace(x0, N), box(n, 1.0), None, backend, Work(), "t",
                             False)  # fmt: skip
        assert backend.seen == []
        keep = np.arange(1, n)  # the QP on the joints the level moves
        B, c = A @ N.T, b - A @ x0
        G = np.vstack([N.T[keep], -N.T[keep]])
        h = np.concatenate([1.0 - x0[keep], 1.0 + x0[keep]])
        z = qpsolvers.solve_ls(B, c, G, h, solver="quadprog")
        np.testing.assert_allclose(x, x0 + z @ N, atol=1e-9)


def test_a_square_level_is_projected_in_its_tie_broken_metric(rng: np.random.Generator) -> None:
    """As many rows as unknowns (a cell's body task in its chains' null space): the backend's
    QP carries the tie-break (TIE_BREAK); where that metric's condition number is at most
    WELL_CONDITIONED the kernel projects in it, DAQP's answer to the same QP within its
    tolerance, else the backend answers. Fewer rows than unknowns (a condition number of 1e6)
    stay the backend's."""
    n, d = 7, 4
    projected = 0
    for _ in range(100):
        N = np.linalg.qr(rng.normal(size=(n, d)))[0].T
        x0 = rng.uniform(-0.3, 0.3, n)
        A, b = rng.normal(size=(d, n)), rng.normal(size=d) * 3.0
        backend = Recording()
        x, _ = least_squares(A, b, Subspace(x0, N), box(n, 1.0), None, backend, Work(), "t",
                             False)  # fmt: skip
        B, c = A @ N.T, b - A @ x0
        optimum = x0 + np.linalg.lstsq(B, c, rcond=None)[0] @ N
        if np.all(np.abs(optimum) <= 1.0):  # inside the box: the least squares, no tie-break
            np.testing.assert_allclose(x, optimum, atol=1e-9)
            assert backend.seen == []
            continue
        P = B.T @ B + TIE_BREAK * max(np.trace(B.T @ B), 1.0) * np.eye(d)
        if np.linalg.cond(P) > WELL_CONDITIONED:
            assert len(backend.seen) == 1
            continue
        assert backend.seen == []
        projected += 1
        G, h = np.vstack([N.T, -N.T]), np.concatenate([1.0 - x0, 1.0 + x0])
        z = qpsolvers.solve_qp(P, -B.T @ c, G, h, solver="daqp")
        np.testing.assert_allclose(x, x0 + z @ N, atol=1e-9)
    assert projected > 30, projected
    A, b = rng.normal(size=(d - 1, n)), np.full(d - 1, 50.0)
    backend = Recording()
    least_squares(A, b, Subspace(x0, N), box(n, 1.0), None, backend, Work(), "t", False)
    assert len(backend.seen) == 1


@pytest.mark.filterwarnings("ignore:overflow:RuntimeWarning")  # the plain-Python run's sum
def test_tie_broken_leaves_an_overflowing_metric_to_the_backend() -> None:
    """Rows beyond 1e154 make the metric's trace overflow: no eigenvalues asked (numba's raise
    on infinities), the projection not taken."""
    for H in (np.diag([1e308, 1e308, 1.0]), np.full((3, 3), np.inf)):
        assert not tie_broken(H, np.ones(3))[3]
    assert tie_broken(np.diag([1.0, 2.0, 3.0]), np.ones(3))[3]
