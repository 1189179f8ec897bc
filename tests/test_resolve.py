"""solvers.resolve: the pipeline on random rows, strict levels against an independent
reference, weighted levels, inequality rows, and the fallback chain."""

from __future__ import annotations

import numpy as np
import pytest
import qpsolvers

import solvers.resolve as resolve_module
from solvers.direction import uniform_scale
from solvers.errors import InputError, ProblemError
from solvers.joint_bounds import JointBounds, StepBounds
from solvers.qp_backends import QPBackend, QPSolution, make_backend
from solvers.resolution import TaskRows
from solvers.resolve import LEAST_NORM, Inequalities, ResolveOptions, resolve

N = 10


def bounds_at(rng: np.random.Generator, n: int = N, tight: float = 1.0) -> StepBounds:
    v = rng.uniform(0.5, 2.0, n) * tight
    jb = JointBounds(np.full(n, -3.0), np.full(n, 3.0), v)
    return jb.step(rng.uniform(-2.5, 2.5, n), 0.01)


def levels_at(
    rng: np.random.Generator, sizes: tuple[int, ...], scale: float
) -> list[list[TaskRows]]:
    return [
        [TaskRows(rng.normal(size=(m, N)), rng.normal(size=m) * scale, None, f"t{k}")]
        for k, m in enumerate(sizes)
    ]


def level_optimum(levels: list[list[TaskRows]], k: int, x: np.ndarray, b: StepBounds) -> float:
    """The least value of level k's squared residual subject to the achieved rates of the
    levels above (those of ``x``) as equality constraints and the bounds (Kanoun et al.
    2011's lexicographic definition), by an interior-point solver (Clarabel), not by the
    null-space parametrisation of the pipeline."""
    A = np.vstack([t.A for t in levels[k]])
    y = np.concatenate([t.b for t in levels[k]])
    above = [t.A for level in levels[:k] for t in level]
    A_eq = np.vstack(above) if above else None
    ref = qpsolvers.solve_qp(
        A.T @ A + 1e-10 * np.eye(N), -A.T @ y, A=A_eq, b=None if A_eq is None else A_eq @ x,
        lb=b.lb, ub=b.ub, solver="clarabel",
    )  # fmt: skip
    assert ref is not None
    return float(np.sum((A @ ref - y) ** 2))


@pytest.mark.filterwarnings("ignore:Converted matrix")  # qpsolvers hands Clarabel CSC matrices
def test_strict_levels_are_lexicographically_optimal(rng: np.random.Generator) -> None:
    """Each level of the answer is optimal within the optimal set of the levels above."""
    backend = make_backend("daqp")
    options = ResolveOptions(direction_preserving=False, damping=None)
    for _ in range(150):
        sizes = tuple(int(m) for m in rng.integers(1, 4, size=3))
        levels = levels_at(rng, sizes, float(rng.choice([0.1, 1.0, 5.0])))
        b = bounds_at(rng)
        r = resolve(levels, b, backend, options)
        assert r.method == "qp" and not r.attempts, r.attempts
        for k in range(3):
            A = np.vstack([t.A for t in levels[k]])
            y = np.concatenate([t.b for t in levels[k]])
            mine = float(np.sum((A @ r.qdot - y) ** 2))
            assert mine <= level_optimum(levels, k, r.qdot, b) * (1 + 1e-6) + 1e-7


def test_lower_levels_are_rarely_dropped() -> None:
    """A lower level whose QP the backend cannot solve is dropped (the levels above kept, the
    attempt recorded). DAQP declared 36 of these 4,000 random lower levels infeasible at its
    default tolerance, feasible as they all are (z = 0 is): joints on their bounds make a
    degenerate vertex there. Its one retry at a looser tolerance leaves 4-6 of them (by CPU
    kernels, daqp_backend.RETRY_TOL)."""
    rng = np.random.default_rng(5)
    backend = make_backend("daqp")
    options = ResolveOptions(direction_preserving=False, damping=None)
    dropped = 0
    for _ in range(4000):
        sizes = tuple(int(m) for m in rng.integers(1, 4, size=3))
        levels = levels_at(rng, sizes, float(rng.choice([0.1, 1.0, 5.0])))
        r = resolve(levels, bounds_at(rng), backend, options)
        dropped += any(name.startswith("level") for name, _ in r.attempts)
    assert dropped <= 12


def test_a_lower_level_never_changes_a_higher_one(rng: np.random.Generator) -> None:
    backend = make_backend("daqp")
    for direction in (True, False):
        options = ResolveOptions(direction_preserving=direction)
        for _ in range(200):
            levels = levels_at(rng, (3, 3, 2), float(rng.choice([0.1, 1.0, 5.0])))
            b = bounds_at(rng)
            for k in range(1, 3):
                upper = resolve(levels[:k], b, backend, options).qdot
                full = resolve(levels[: k + 1], b, backend, options).qdot
                for level in levels[:k]:
                    A = level[0].A
                    np.testing.assert_allclose(A @ full, A @ upper, atol=1e-9)


def test_the_top_level_keeps_one_common_scale(rng: np.random.Generator) -> None:
    """Two tasks on one level, commanded beyond the limits, slow down together."""
    backend = make_backend("daqp")
    for _ in range(100):
        levels = levels_at(rng, (3, 3), 20.0)
        top = [levels[0][0], levels[1][0]]
        b = bounds_at(rng)
        r = resolve([top], b, backend, ResolveOptions(damping=None))
        s = r.scale
        if r.status != "scaled":
            continue
        for t, report in zip(top, r.tasks, strict=True):
            np.testing.assert_allclose(report.achieved, s * t.b, atol=1e-8 * np.abs(t.b).max())
            assert report.scale == pytest.approx(s, abs=1e-8)


@pytest.mark.filterwarnings("ignore:Converted matrix")
def test_weighted_is_one_least_squares(rng: np.random.Generator) -> None:
    backend = make_backend("daqp")
    for _ in range(100):
        tasks = [
            TaskRows(rng.normal(size=(4, N)), rng.normal(size=4), None, "a"),
            TaskRows(rng.normal(size=(3, N)), rng.normal(size=3), np.full(3, 0.1), "b"),
        ]
        b = bounds_at(rng)
        r = resolve([tasks], b, backend, ResolveOptions(), weighted=True)
        A = np.vstack([tasks[0].A, np.sqrt(0.1) * tasks[1].A])
        y = np.concatenate([tasks[0].b, np.sqrt(0.1) * tasks[1].b])
        ref = qpsolvers.solve_qp(A.T @ A + 1e-10 * np.eye(N), -A.T @ y, lb=b.lb, ub=b.ub,
                                 solver="clarabel")  # fmt: skip
        mine, best = np.sum((A @ r.qdot - y) ** 2), np.sum((A @ ref - y) ** 2)
        # optimal up to the least-norm term (LEAST_NORM relative to trace(A^T A))
        assert mine <= best * (1 + 1e-5) + LEAST_NORM * np.sum(A * A)


def test_inequality_rows_are_kept(rng: np.random.Generator) -> None:
    """G qdot <= h (a wall): every answer satisfies it, direction-preserving or not."""
    backend = make_backend("daqp")
    for direction in (True, False):
        for _ in range(100):
            levels = levels_at(rng, (4,), 3.0)
            b = bounds_at(rng)
            rows = Inequalities(rng.normal(size=(2, N)), rng.uniform(0.0, 0.5, 2))
            r = resolve(levels, b, backend, ResolveOptions(direction), rows=rows)
            assert np.all(rows.G @ r.qdot <= rows.h + 1e-9)
            assert np.all(r.qdot >= b.lb) and np.all(r.qdot <= b.ub)


class Broken(QPBackend):
    """A backend that raises, or finds nothing."""

    name = "broken"

    def __init__(self, mode: str) -> None:
        super().__init__()
        self.mode = mode

    def solve(self, qp: object) -> QPSolution:
        if self.mode == "raise":
            raise ProblemError("broken: crashed")
        return QPSolution(None, "maximum iterations reached", 4000, 0.0, self.name)


def test_fallback_chain_order_attempts_and_never_raise(rng: np.random.Generator) -> None:
    levels = levels_at(rng, (6,), 50.0)
    b = bounds_at(rng)
    for mode in ("raise", "not found"):
        r = resolve(levels, b, Broken(mode), ResolveOptions())
        assert r.method == "scipy" and r.status == "fallback"
        assert r.attempts[0][0] == "qp"
        assert np.all(r.qdot >= b.lb) and np.all(r.qdot <= b.ub)
        exact = resolve(levels, b, make_backend("daqp"), ResolveOptions())
        assert r.scale == pytest.approx(exact.scale, rel=1e-4)  # the exact LP
    for fallbacks, method in ((("scaling",), "scaling"), (("dls",), "dls"), ((), "hold")):
        r = resolve(levels, b, Broken("raise"), ResolveOptions(fallbacks=fallbacks))
        assert r.method == method and 0.0 <= r.scale <= 1.0
    recovering = JointBounds(np.full(N, -1.0), np.full(N, 1.0), np.ones(N)).step(
        np.full(N, 1.5), 0.01
    )
    assert not recovering.contains_zero
    r = resolve(levels, recovering, Broken("raise"),
                ResolveOptions(fallbacks=("scaling",)))  # fmt: skip
    assert r.method == "hold" and [a[0] for a in r.attempts] == ["qp", "scaling"]
    np.testing.assert_array_equal(r.qdot, np.clip(0.0, recovering.lb, recovering.ub))
    r = resolve(levels, recovering, Broken("raise"), ResolveOptions())
    assert r.method == "scipy"  # bounded least squares (BVLS)


def test_one_null_direction_is_solved_without_the_backend_or_falls_back(
    rng: np.random.Generator, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Nine rows on ten joints: the exact solve answers (no backend ran), and an answer of it
    outside the bounds (NaN here) is a failure that the fallback chain takes over."""
    levels = levels_at(rng, (N - 1,), 50.0)
    b = bounds_at(rng)
    r = resolve(levels, b, Broken("raise"), ResolveOptions(damping=None))
    assert r.method == "qp" and r.backend == "" and not r.attempts and r.status == "scaled"
    monkeypatch.setattr(resolve_module, "line_scale", lambda *args: (1.0, float("nan")))
    r = resolve(levels, b, Broken("raise"), ResolveOptions(damping=None))
    assert r.method == "scipy" and r.attempts[0][0] == "qp" and "exact" in r.attempts[0][1]
    assert np.all(r.qdot >= b.lb) and np.all(r.qdot <= b.ub)


@pytest.mark.filterwarnings("ignore::RuntimeWarning")
def test_numerical_trouble_never_raises(rng: np.random.Generator) -> None:
    b = bounds_at(rng)
    for A in (rng.normal(size=(6, N)) * 1e300, np.zeros((6, N)), rng.normal(size=(6, N)) * 1e-300):
        r = resolve([[TaskRows(A, np.ones(6) * 1e6, None, "t")]], b,
                    make_backend("daqp"), ResolveOptions())  # fmt: skip
        assert np.all(np.isfinite(r.qdot))
        assert np.all(r.qdot >= b.lb) and np.all(r.qdot <= b.ub)


def test_options_are_checked() -> None:
    with pytest.raises(InputError) as info:
        ResolveOptions(fallbacks=("qp",))
    assert info.value.argument == "fallbacks"
    with pytest.raises(InputError):
        ResolveOptions(fallbacks=("scaling", "scaling"))
    with pytest.raises(InputError) as info:
        ResolveOptions(damping=0.1)  # type: ignore[arg-type]
    assert info.value.argument == "damping"
    assert ResolveOptions(fallbacks="dls").fallbacks == ("dls", "hold")  # type: ignore[arg-type]


def test_fallbacks_keep_the_inequality_rows_or_give_way(rng: np.random.Generator) -> None:
    """dls and scaling answers that break a row count as failed: the next method answers."""
    levels = levels_at(rng, (3,), 50.0)
    b = bounds_at(rng)
    exact = np.linalg.pinv(levels[0][0].A) @ levels[0][0].b
    dls = np.clip(exact, b.lb, b.ub)
    scaled = uniform_scale(exact, b.lb, b.ub) * exact
    g = rng.normal(size=(2, N))
    rows = Inequalities(g, np.array([g[0] @ dls, g[1] @ scaled]) - 0.1)  # both just broken
    for fallbacks in (("dls",), ("scaling",)):
        r = resolve(levels, b, Broken("raise"), ResolveOptions(fallbacks=fallbacks), rows=rows)
        assert [a[0] for a in r.attempts] == ["qp", fallbacks[0]], r.attempts
        assert "breaks an inequality row" in r.attempts[1][1] and r.method == "hold"


def test_hold_can_only_end_the_chain() -> None:
    with pytest.raises(InputError, match="fallbacks: 'hold' always answers"):
        ResolveOptions(fallbacks=("hold", "scipy"))
    assert ResolveOptions(fallbacks=("dls", "hold")).fallbacks == ("dls", "hold")
