"""A least-squares level: its unconstrained optimum where it fits, else a QP of its stated costs."""

from __future__ import annotations

import numpy as np
from scipy.optimize import lsq_linear

from solvers.least_squares import Subspace, least_squares
from solvers.problem import Box
from solvers.qp import QP, Work
from solvers.qp_backends import make_backend
from solvers.qp_backends.base import QPBackend, QPSolution


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
