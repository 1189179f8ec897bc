"""The QPs the compiled tick hands to the backend (solvers/tick/backend_calls.py): answered by the
pipeline's own functions, and a backend's failure recorded where the pipeline records it."""

from __future__ import annotations

import numpy as np
import pytest

from rrc_pin.solvers.qp_backends import QPBackend, QPSolution, make_backend
from rrc_pin.solvers.qp_backends.qp import QP, Work
from rrc_pin.solvers.tick import backend_calls, least_squares
from rrc_pin.solvers.tick.pipeline import backend_along
from rrc_pin.solvers.tick.problem import Box, Rows

N = 6


class Refusing(QPBackend):
    """A backend that finds no solution."""

    name = "refusing"

    def solve(self, qp: QP) -> QPSolution:
        return QPSolution(None, "no solution", 1, 0.0, self.name)


def problem(rng: np.random.Generator) -> tuple:
    """Three rows, the rates w of a command along them, their null space, a box, two rows."""
    lb, ub = -np.ones(N), np.ones(N)
    A = rng.normal(size=(3, N))
    null = np.linalg.svd(A)[2][3:].copy()
    G, h = rng.normal(size=(2, N)), np.array([0.1, 0.2])
    w = np.linalg.pinv(A) @ (rng.normal(size=3) * 3.0)
    return A, w, null, lb, ub, G, h


def test_the_direction_problem_is_the_pipelines(rng: np.random.Generator) -> None:
    for _ in range(20):
        A, w, null, lb, ub, G, h = problem(rng)
        backend_calls.enter(backend_calls.Context(make_backend("daqp"), np.ones(N)))
        try:
            qdot, u, veer = backend_calls.direction(A, w, null, lb, ub, G, h)
        finally:
            backend_calls.leave()
        box = Box(lb, ub, np.zeros((2, 0), np.int8), True, False, np.ones(N))
        want = backend_along(A, w, null, box, Rows(G, h, ()), make_backend("daqp"), Work(),
                             compiled=False)  # fmt: skip
        assert u == want.u and veer == want.veer
        np.testing.assert_array_equal(qdot, want.qdot)
        # the compiled active-set solver (tried first by the tick) agrees with DAQP
        kernel = backend_along(A, w, null, box, Rows(G, h, ()), make_backend("daqp"), Work())
        np.testing.assert_allclose(kernel.qdot, want.qdot, atol=1e-9)
        assert kernel.u == pytest.approx(want.u, abs=1e-9)


@pytest.mark.parametrize(("where", "label", "tail"), [
    (backend_calls.TOP, "qp", ""), (backend_calls.SLIDE, "slide", "the command kept as given"),
    (backend_calls.SLIDE_RELAXING, "slide", "the pairs asked apart only kept apart"),
    (2, "level 2", "the levels above kept"),
])  # fmt: skip
def test_a_failure_is_recorded_where_the_pipeline_records_it(
    where: int, label: str, tail: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(least_squares, "_projected", lambda *a: None)  # a level's QP: DAQP's
    rng = np.random.default_rng(1)
    A, w, null, lb, ub, G, h = problem(rng)
    context = backend_calls.Context(Refusing(), np.ones(N))
    backend_calls.enter(context)
    try:
        if where == backend_calls.TOP:
            qdot, u, _ = backend_calls.direction(A, w, null, lb, ub, G, h)
            assert u < 0.0
        elif where > 0:
            qdot, _ = backend_calls.level(where, A, rng.normal(size=3), np.zeros(N), null, lb,
                                          ub, G, h, False)  # fmt: skip
            qdot = qdot if qdot.size else np.empty(0)
        else:
            qdot = backend_calls.slide(where, np.eye(N), w, lb, ub, G, h)
    finally:
        backend_calls.leave()
    assert context.work is not None
    (attempt,) = context.work.attempts
    assert attempt[0] == label and attempt[1].startswith("refusing: no solution")
    assert attempt[1].endswith(tail)
    if where != backend_calls.TOP:
        assert qdot.size == 0


def test_compile_calls_asks_every_call_and_leaves_nothing_behind() -> None:
    """Each call answered once (none failed), the backend's warm starts forgotten, no
    context left entered."""
    asked: list[int] = []

    class Counting(QPBackend):
        name = "counting"

        def __init__(self) -> None:
            self.inner = make_backend("daqp")
            self.resets = 0

        def solve(self, qp: QP) -> QPSolution:
            asked.append(qp.P.shape[0])
            return self.inner.solve(qp)

        def reset(self) -> None:
            self.resets += 1
            self.inner.reset()

    backend = Counting()
    context = backend_calls.Context(backend, np.ones(N))
    backend_calls.compile_calls(context)
    assert asked and backend.resets == 1
    assert context.work is not None and not context.work.attempts, context.work.attempts
    assert getattr(backend_calls._LOCAL, "context", None) is None
