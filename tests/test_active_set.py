"""The tracking QP on a guessed active set: exact where the guess is right, refused otherwise."""

from __future__ import annotations

import numpy as np
import pytest
import qpsolvers

import rrc_pin
from solvers.active_set import (
    SLACK,
    _solve_small,
    active_joints,
    solve_on_active_set,
    tracking_inverse,
)
from solvers.dls import Damping, task_svd
from solvers.joint_bounds import VelocityBounds
from solvers.qp_problem import tracking_free, tracking_problem_from
from solvers.task_factor import TaskInverse, factor_task

pytest.importorskip("quadprog")


def cases(rng: np.random.Generator, count: int, svd: bool) -> list[tuple]:
    """Tracking problems whose box-free minimiser leaves the box, with quadprog's solution."""
    arms = [rrc_pin.load(name) for name in ("panda", "rrc_k1607")]
    out = []
    while len(out) < count:
        arm = arms[len(out) % 2]
        J = arm.jacobian(arm.random_q(rng))
        task = task_svd(J, None, Damping()) if svd else factor_task(J, None, Damping())
        if not svd and not isinstance(task, TaskInverse):
            continue
        x = rng.standard_normal(6) * rng.choice([0.3, 1.0, 3.0])
        z = rng.standard_normal(7) * 0.1 if rng.random() < 0.3 else None
        lb = -rng.uniform(0.05, 1.0, 7)
        ub = rng.uniform(0.05, 1.0, 7)
        if rng.random() < 0.2:  # a recovering joint: its interval excludes zero
            lb[0], ub[0] = 0.1, 0.3
        bounds = VelocityBounds(lb, ub)
        free = tracking_free(task, x, z, 1e-2)
        if np.all(free.x >= lb) and np.all(free.x <= ub):
            continue
        p = tracking_problem_from(task, free, bounds)
        ref = qpsolvers.solve_qp(p.P, p.q, lb=lb, ub=ub, solver="quadprog")
        out.append((task, free, bounds, p, ref))
    return out


@pytest.mark.parametrize("svd", [False, True])
def test_right_guess_gives_the_exact_solution(svd: bool, rng: np.random.Generator) -> None:
    sizes = set()
    for task, free, bounds, _, ref in cases(rng, 150, svd):
        lower, upper = active_joints(ref, bounds)
        sizes.add(len(lower) + len(upper))
        solution = solve_on_active_set(task, free, bounds, lower, upper)
        assert solution is not None
        x, clip = solution
        assert clip <= SLACK
        assert np.all(x >= bounds.lb) and np.all(x <= bounds.ub)
        assert np.allclose(x, ref, atol=1e-9)
    assert {1, 2, 3} <= sizes


@pytest.mark.parametrize("svd", [False, True])
def test_any_accepted_guess_is_optimal(svd: bool, rng: np.random.Generator) -> None:
    """The KKT check is sufficient: whatever the guess, an answer is the optimum; wrong
    guesses (a joint dropped, added or moved to the other side) are refused."""
    refused = 0
    for task, free, bounds, _, ref in cases(rng, 100, svd):
        lower, upper = active_joints(ref, bounds)
        guesses = [(lower[1:], upper), (lower, upper[1:]), (upper, lower)]
        extra = [i for i in range(7) if i not in lower + upper]
        if extra:
            guesses.append(((*lower, extra[0]), upper))
        for guess in guesses:
            if set(guess[0]) & set(guess[1]):
                continue
            solution = solve_on_active_set(task, free, bounds, *guess)
            if solution is None:
                refused += 1
            else:
                assert np.allclose(solution[0], ref, atol=1e-9)
    assert refused > 200
    assert solve_on_active_set(task, free, bounds, (), ()) is None


@pytest.mark.parametrize("svd", [False, True])
def test_tracking_inverse_is_the_inverse_of_p(svd: bool, rng: np.random.Generator) -> None:
    for task, free, _, p, _ in cases(rng, 30, svd):
        assert np.allclose(tracking_inverse(task, free) @ p.P, np.eye(7), atol=1e-9)


def test_active_joints() -> None:
    b = VelocityBounds(np.array([-1.0, -1.0, -1.0, 0.0]), np.array([1.0, 1.0, 1.0, 0.0]))
    qdot = np.array([-1.0, 0.5, 1.0 - 1e-10, 0.0])
    assert active_joints(qdot, b) == ((0, 3), (2,))  # a pinned joint counts at its lower side


def test_solve_small(rng: np.random.Generator) -> None:
    for k in range(1, 7):
        for _ in range(50):
            A = rng.standard_normal((k, k))
            S = A @ A.T + 0.1 * np.eye(k)
            b = rng.standard_normal(k)
            x = _solve_small(S.tolist(), b.tolist())
            assert x is not None
            assert np.allclose(S @ x, b, atol=1e-10)
    assert _solve_small([[1.0, 2.0], [2.0, 1.0]], [1.0, 1.0]) is None  # indefinite
    assert _solve_small([[0.0]], [1.0]) is None
    assert _solve_small(np.diag([1.0, -1.0, 1.0]).tolist(), [1.0, 1.0, 1.0]) is None
