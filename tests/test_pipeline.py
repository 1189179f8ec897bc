"""rrc_pin.solvers.tick.pipeline on random problems against independent references: strict levels
(Clarabel on the lexicographic definition), the weighted optimum (BVLS), the direction scale
(HiGHS on the whole LP), constraint rows and equality rows, and the fallback chain."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
import qpsolvers
from scipy.optimize import linprog, lsq_linear

import rrc_pin.solvers.tick.pipeline as pipeline_module
from rrc_pin.solvers.collision.damper_kernels import SLACK
from rrc_pin.solvers.errors import InvalidInput, ProblemError
from rrc_pin.solvers.qp_backends import QPBackend, QPSolution, make_backend
from rrc_pin.solvers.tick import feasibility
from rrc_pin.solvers.tick.damping import Damping
from rrc_pin.solvers.tick.direction import uniform_scale
from rrc_pin.solvers.tick.joint_box import joint_box
from rrc_pin.solvers.tick.pipeline import Answer, Options, solve
from rrc_pin.solvers.tick.problem import Box, Constraints, Problem, TaskRows, build
from rrc_pin.solvers.tick.statuses import scale_and_veer

N = 10
DT = 0.01


def box_at(
    rng: np.random.Generator, n: int = N, tight: float = 1.0, q: np.ndarray | None = None
) -> Box:
    """The joint box of a random start in [-3, 3] (velocity limits 0.5-2 rad/s)."""
    v = rng.uniform(0.5, 2.0, n) * tight
    q = rng.uniform(-2.5, 2.5, n) if q is None else q
    lb, ub, kind = np.empty(n), np.empty(n), np.empty((2, n), np.int8)
    zero, recovering = joint_box(
        q,
        np.full(n, -3.0),
        np.full(n, 3.0),
        v,
        0.0,
        1.0,
        DT,
        np.zeros(n),
        np.array([np.inf]),
        lb,
        ub,
        kind,
    )
    return Box(lb, ub, kind, zero, recovering, v)


def levels_at(
    rng: np.random.Generator, sizes: tuple[int, ...], scale: float
) -> list[list[TaskRows]]:
    return [
        [TaskRows(rng.normal(size=(m, N)), rng.normal(size=m) * scale, None, f"t{k}")]
        for k, m in enumerate(sizes)
    ]


def run(
    levels: list[list[TaskRows]],
    box: Box,
    backend: QPBackend | None = None,
    options: Options | None = None,
    *,
    weighted: bool = False,
    direction: bool = True,
    G: np.ndarray | None = None,
    h: np.ndarray | None = None,
    C: np.ndarray | None = None,
    d: np.ndarray | None = None,
) -> tuple[Problem, Answer]:
    names = tuple(f"row{i}" for i in range(0 if h is None else h.size))
    names += tuple(f"eq{i}" for i in range(0 if d is None else d.size))
    problem = build(
        levels, [Constraints(box, G, h, C, d, names)], N, DT, weighted=weighted, direction=direction
    )
    answer = solve(problem, backend or make_backend("daqp"), options or Options())
    return problem, answer


def stacked(level: list[TaskRows]) -> tuple[np.ndarray, np.ndarray]:
    return np.vstack([t.A for t in level]), np.concatenate([t.b for t in level])


def veer_accepted(A: np.ndarray, answer: Answer) -> bool:
    """Whether the answer's reported veer is one the pipeline accepts a backend's direction
    answer at: its task rates off the command by at most DIRECTION_TOL |A| |qdot|."""
    off = np.linalg.norm(A @ answer.qdot) * np.sin(answer.veer)
    bound = pipeline_module.DIRECTION_TOL * np.linalg.norm(A) * np.linalg.norm(answer.qdot)
    return bool(off <= bound * (1.0 + 1e-6))


def level_optimum(levels: list[list[TaskRows]], k: int, x: np.ndarray, box: Box) -> float:
    """The least value of level k's squared residual subject to the achieved rates of the
    levels above (those of ``x``) as equality constraints and the box (Kanoun et al. 2011's
    lexicographic definition), by an interior-point solver (Clarabel), not by the null-space
    parametrisation of the pipeline."""
    A, y = stacked(levels[k])
    above = [t.A for level in levels[:k] for t in level]
    A_eq = np.vstack(above) if above else None
    ref = qpsolvers.solve_qp(
        A.T @ A + 1e-10 * np.eye(N),
        -A.T @ y,
        A=A_eq,
        b=None if A_eq is None else A_eq @ x,
        lb=box.lb,
        ub=box.ub,
        solver="clarabel",
    )
    assert ref is not None
    return float(np.sum((A @ ref - y) ** 2))


def lp_maximum(
    A: np.ndarray, b: np.ndarray, box: Box, G: np.ndarray | None = None, h: np.ndarray | None = None
) -> float:
    """max s in [0, 1] with A qdot = s b within the box and rows: HiGHS on (qdot, s)."""
    m, n = A.shape
    rows = np.zeros((0, n + 1)) if G is None else np.c_[G, np.zeros(len(G))]
    result = linprog(
        np.r_[np.zeros(n), -1.0],
        A_ub=rows if G is not None else None,
        b_ub=h,
        A_eq=np.c_[A, -b],
        b_eq=np.zeros(m),
        bounds=[*zip(box.lb, box.ub, strict=True), (0.0, 1.0)],
        method="highs",
    )
    assert result.status == 0, result.message
    return float(result.x[-1])


@pytest.mark.filterwarnings("ignore:Converted matrix")  # qpsolvers hands Clarabel CSC matrices
def test_strict_levels_are_lexicographically_optimal(rng: np.random.Generator) -> None:
    """Each level of the answer is optimal within the optimal set of the levels above."""
    for _ in range(150):
        sizes = tuple(int(m) for m in rng.integers(1, 4, size=3))
        levels = levels_at(rng, sizes, float(rng.choice([0.1, 1.0, 5.0])))
        box = box_at(rng)
        _, answer = run(levels, box, direction=False, options=Options(damping=None))
        assert answer.method == "qp" and not answer.attempts, answer.attempts
        for k in range(3):
            A, y = stacked(levels[k])
            mine = float(np.sum((A @ answer.qdot - y) ** 2))
            assert mine <= level_optimum(levels, k, answer.qdot, box) * (1 + 1e-6) + 1e-7


def test_lower_levels_are_rarely_dropped() -> None:
    """A lower level whose answer leaves the box beyond rounding is dropped (the levels above
    kept, the attempt recorded): over 2,000 random three-level problems, a handful."""
    rng = np.random.default_rng(5)
    backend = make_backend("daqp")
    dropped = 0
    for _ in range(2000):
        sizes = tuple(int(m) for m in rng.integers(1, 4, size=3))
        levels = levels_at(rng, sizes, float(rng.choice([0.1, 1.0, 5.0])))
        _, answer = run(levels, box_at(rng), backend, Options(damping=None), direction=False)
        dropped += "dropped" in answer.levels
    assert dropped <= 6


def test_a_lower_level_never_changes_a_higher_one(rng: np.random.Generator) -> None:
    backend = make_backend("daqp")
    for direction in (True, False):
        for _ in range(200):
            levels = levels_at(rng, (3, 3, 2), float(rng.choice([0.1, 1.0, 5.0])))
            box = box_at(rng)
            for k in range(1, 3):
                upper = run(levels[:k], box, backend, direction=direction)[1].qdot
                full = run(levels[: k + 1], box, backend, direction=direction)[1].qdot
                for level in levels[:k]:
                    A = level[0].A
                    np.testing.assert_allclose(A @ full, A @ upper, atol=1e-9)


def test_the_top_level_keeps_one_common_scale_the_lp_maximum(rng: np.random.Generator) -> None:
    """Two tasks on one level commanded beyond the limits slow down together, to the largest
    scale any rates within the box allow (HiGHS on the whole LP)."""
    scaled = 0
    for _ in range(150):
        levels = levels_at(rng, (3, 3), 20.0)
        top = [levels[0][0], levels[1][0]]
        box = box_at(rng)
        _, answer = run([top], box, options=Options(damping=None))
        A, b = stacked(top)
        best = lp_maximum(A, b, box)
        assert answer.scale == pytest.approx(best, abs=1e-9)
        assert answer.status in ("scaled", "exact") and veer_accepted(A, answer)
        np.testing.assert_allclose(A @ answer.qdot, answer.scale * b, atol=1e-9 * np.abs(b).max())
        scaled += answer.status == "scaled"
    assert scaled > 100


def test_where_the_lp_maximum_is_one_the_command_is_met_exactly(rng: np.random.Generator) -> None:
    """The exact least-norm rates leave the box, yet another solution fits: met, zero veer."""
    met = 0
    for _ in range(300):
        levels = levels_at(rng, (6,), float(rng.uniform(0.5, 3.0)))
        box = box_at(rng)
        A, b = stacked(levels[0])
        if lp_maximum(A, b, box) < 1.0 - 1e-12:
            continue
        _, answer = run(levels, box)
        assert answer.status == "exact" and answer.scale == 1.0 and answer.veer == 0.0
        np.testing.assert_allclose(A @ answer.qdot, b, atol=1e-9 * (1.0 + np.abs(b).max()))
        exact = np.linalg.pinv(A) @ b
        met += not feasibility.inside(exact, box.lb, box.ub)
    assert met > 20  # the exact rates did not fit: the null space answered


@pytest.mark.parametrize("seed", [20261209, int(np.random.SeedSequence().entropy % 2**63)])
def test_a_command_beyond_large_is_scaled_never_exact(seed: int) -> None:
    """Commands of 1e100-1e300 are divided down before the numerics (problem.LARGE). Before,
    their exact rates fitted the box after the division and the answer said ``exact``, scale 1,
    while the hand moved at the command over its largest entry. Now: ``scaled``, the scale the
    fraction of the command achieved, which is the LP maximum along it (HiGHS, on the
    command's direction at a size the LP can hold)."""
    rng = np.random.default_rng(seed)
    for _ in range(60):
        levels = levels_at(rng, (6,), 1.0)
        box = box_at(rng)
        A, d = stacked(levels[0])
        size = 10.0 ** rng.uniform(100, 300)
        problem, answer = run([[levels[0][0]._replace(b=d * size)]], box)
        assert problem.factors[0] < 1.0 and answer.status == "scaled", seed
        best = lp_maximum(A, d * 1e3, box) * 1e3 / size  # the LP along d, below one at 1e3
        assert answer.scale == pytest.approx(best, rel=1e-6), seed
        np.testing.assert_allclose(A @ answer.qdot, answer.scale * size * d,
                                   atol=1e-9 * best * size * np.abs(d).max())  # fmt: skip


def test_a_divided_command_met_in_an_unbounded_box_is_a_scale_of_it(
    rng: np.random.Generator,
) -> None:
    """Without bounds the divided command is met: at the top level ``scaled`` by the factor it
    was divided by, a lower level ``scaled`` too, never ``exact`` or ``met``."""
    free = Box(np.full(N, -np.inf), np.full(N, np.inf), np.zeros((2, N), np.int8), True, False,
               np.full(N, np.inf))  # fmt: skip
    for direction in (True, False):
        levels = levels_at(rng, (3, 3), 1e200)
        problem, answer = run(levels, free, direction=direction)
        assert answer.status in ("scaled", "least_squares") and answer.levels[1] != "met"
        assert 0.0 < answer.scale <= problem.factors[0] < 1e-190
        A, b = stacked(levels[0])
        np.testing.assert_allclose(A @ answer.qdot, answer.scale * b, atol=1e-9 * answer.scale
                                   * np.abs(b).max())  # fmt: skip


@pytest.mark.filterwarnings("ignore:Converted matrix")
def test_weighted_is_the_exact_optimum_of_its_costs(rng: np.random.Generator) -> None:
    """Within 1e-6 rad/s of scipy's BVLS on the same costs and box, limits active."""
    active = 0
    for _ in range(200):
        tasks = [
            TaskRows(rng.normal(size=(6, N)), rng.normal(size=6) * 3.0, None, "a"),
            TaskRows(rng.normal(size=(6, N)), rng.normal(size=6), np.full(6, 0.1), "b"),
            TaskRows(np.eye(N), rng.normal(size=N), np.full(N, 1e-2), "posture"),
        ]
        box = box_at(rng)
        _, answer = run([tasks], box, weighted=True)
        root = [np.ones(6), np.sqrt(np.full(6, 0.1)), np.sqrt(np.full(N, 1e-2))]
        A = np.vstack([r[:, None] * t.A for r, t in zip(root, tasks, strict=True)])
        y = np.concatenate([r * t.b for r, t in zip(root, tasks, strict=True)])
        ref = lsq_linear(A, y, bounds=(box.lb, box.ub), method="bvls", tol=1e-14).x
        np.testing.assert_allclose(answer.qdot, ref, atol=1e-6)
        active += not feasibility.inside(np.linalg.lstsq(A, y, rcond=None)[0], box.lb, box.ub)
    assert active > 150


def test_constraint_rows_are_kept_and_the_scale_is_the_lp_maximum(rng: np.random.Generator) -> None:
    """A random G qdot <= h (a few rows) beside the box: never broken beyond 1e-12, the
    direction scale the LP maximum of the whole problem, in either mode."""
    for direction in (True, False):
        for _ in range(150):
            levels = levels_at(rng, (4,), 3.0)
            box = box_at(rng)
            G = rng.normal(size=(3, N))
            h = rng.uniform(0.0, 0.5, 3)
            _, answer = run(levels, box, direction=direction, G=G, h=h)
            assert np.all(G @ answer.qdot <= h + 1e-12), G @ answer.qdot - h
            assert np.all(answer.qdot >= box.lb) and np.all(answer.qdot <= box.ub)
            if direction:
                A, b = stacked(levels[0])
                # 1e-8: both sides come from active-set solvers with tolerances near 1e-9 (DAQP's
                # primal tolerance on unit rows, HiGHS's simplex); measured worst 1.5e-9 under
                # OpenBLAS's Sandybridge kernels. Never above the maximum, beyond that rounding.
                maximum = lp_maximum(A, b, box, G, h)
                assert answer.scale == pytest.approx(maximum, abs=1e-8)
                assert answer.scale <= maximum + 1e-9


def test_a_row_broken_at_the_start_is_restored(rng: np.random.Generator) -> None:
    """h < 0 (a wall already crossed): the answer moves back across it where the box allows,
    reported as recovering."""
    for _ in range(100):
        levels = levels_at(rng, (4,), 1.0)
        box = box_at(rng)
        g = rng.normal(size=(1, N))
        lowest = float(np.minimum(g[0] * box.lb, g[0] * box.ub).sum())  # g qdot's least value
        h = np.array([0.5 * lowest])  # broken at zero rates, restorable within the box
        _, answer = run(levels, box, G=g, h=h)
        assert answer.status == "recovering"
        assert float((g @ answer.qdot)[0]) <= h[0] + 1e-9


def test_equality_rows_hold_and_the_command_scales_within_them(rng: np.random.Generator) -> None:
    """C qdot = 0 (a foot in support): met to rounding, the top level the LP maximum within
    them."""
    for _ in range(100):
        levels = levels_at(rng, (3,), 5.0)
        box = box_at(rng)
        C = rng.normal(size=(3, N))
        _, answer = run(levels, box, C=C, d=np.zeros(3))
        np.testing.assert_allclose(C @ answer.qdot, 0.0, atol=1e-9)
        A, b = stacked(levels[0])
        with_contacts = np.vstack([A, C])
        assert answer.scale == pytest.approx(
            lp_maximum(with_contacts, np.r_[b, np.zeros(3)], box), abs=1e-7
        )


def lowest_within(g: np.ndarray, C: np.ndarray, box: Box) -> float:
    """The least value of ``g qdot`` with ``C qdot = 0`` within the box (HiGHS)."""
    result = linprog(g[0], A_eq=C, b_eq=np.zeros(len(C)), bounds=list(zip(box.lb, box.ub,
                     strict=True)), method="highs")  # fmt: skip
    assert result.status == 0, result.message
    return float(result.fun)


@pytest.mark.parametrize("slide", [True, False])
def test_a_row_broken_at_the_start_is_restored_within_equality_rows(
    rng: np.random.Generator, slide: bool
) -> None:
    """h < 0 with equality rows (a collision pair below its safety distance, two hands
    holding an object): the least squares within the rows moves back across it where the box
    and the equality rows allow, reported as recovering, never held still (the rows' QP once
    kept only their start, zero rates, feasible, and its answer was refused)."""
    for _ in range(50):
        levels = levels_at(rng, (4,), 1.0)
        box = box_at(rng)
        C, g = rng.normal(size=(2, N)), rng.normal(size=(1, N))
        h = np.array([0.5 * lowest_within(g, C, box)])
        problem = build(levels, [Constraints(box, g, h, C, np.zeros(2), ("pair", "e0", "e1"),
                                             np.array([slide]))], N, DT)  # fmt: skip
        answer = solve(problem, make_backend("daqp"), Options())
        assert answer.status == "recovering" and answer.method == "qp", answer.attempts
        assert float((g @ answer.qdot)[0]) <= h[0] + 1e-9
        np.testing.assert_allclose(C @ answer.qdot, 0.0, atol=1e-9)


def test_a_pair_that_cannot_be_pushed_apart_within_equality_rows_is_kept_apart(
    rng: np.random.Generator,
) -> None:
    """A slide row asking a pair apart beyond what the box and equality rows allow: as without
    equality rows (pipeline._damped_within), the pair only kept from approaching."""
    for _ in range(50):
        levels = levels_at(rng, (4,), 1.0)
        box = box_at(rng)
        C, g = rng.normal(size=(2, N)), rng.normal(size=(1, N))
        h = np.array([1.5 * lowest_within(g, C, box)])  # out of reach
        problem = build(levels, [Constraints(box, g, h, C, np.zeros(2), ("pair", "e0", "e1"),
                                             np.array([True]))], N, DT)  # fmt: skip
        answer = solve(problem, make_backend("daqp"), Options())
        assert answer.status == "recovering" and answer.method == "qp", answer.attempts
        assert [a[0] for a in answer.attempts] == ["slide"], answer.attempts
        assert float((g @ answer.qdot)[0]) <= 1e-9
        np.testing.assert_allclose(C @ answer.qdot, 0.0, atol=1e-9)


def test_the_dual_cells_tick_below_a_safety_distance_is_restored() -> None:
    """A tick of benchmarks/bench_cells.py's gsfc_dual session with collision (tick 2997 of
    3000): the grip's six equality rows, a pair 1.6e-6 m below its safety distance asking
    8.1e-5 m/s apart, a joint on its position limit; it was held still (``fallback``, the
    QP's answer refused) and is restored within every constraint."""
    data = np.load(Path(__file__).parent / "data" / "gsfc_dual_recovering.npz")
    levels = [[TaskRows(data["A0_0"], data["b0_0"], None, "object", data["u0_0"])],
              [TaskRows(data["A1_0"], data["b1_0"], data["w1_0"], "posture")]]  # fmt: skip
    box = Box(data["lb"], data["ub"], data["kind"], True, False, data["velocity"])
    G, h, C, d = data["G"], data["h"], data["C"], data["d"]
    names = tuple(f"row{i}" for i in range(h.size + d.size))
    problem = build(levels, [Constraints(box, G, h, C, d, names, data["slide"])], 14,
                    float(data["dt"]))  # fmt: skip
    answer = solve(problem, make_backend("daqp"), Options())
    assert answer.status == "recovering" and answer.method == "qp", answer.attempts
    assert answer.attempts == ()
    assert (G @ answer.qdot <= h + 1e-9).all()
    assert ((answer.qdot >= box.lb) & (answer.qdot <= box.ub)).all()
    np.testing.assert_allclose(C @ answer.qdot, d, atol=1e-9)


class Broken(QPBackend):
    """A backend that raises (its own error or a foreign one), finds nothing, or answers
    with the wrong shape or NaN."""

    name = "broken"

    def __init__(self, mode: str) -> None:
        super().__init__()
        self.mode = mode

    def solve(self, qp: object) -> QPSolution:
        if self.mode == "raise":
            raise ProblemError("broken: crashed")
        if self.mode == "foreign":
            raise KeyError("something inside the backend")
        if self.mode == "shape":
            return QPSolution(np.zeros(2), "solved", 1, 0.0, self.name)
        if self.mode == "nan":
            return QPSolution(np.full(qp.q.size, np.nan), "solved", 1, 0.0, self.name)  # type: ignore[attr-defined]
        nz = qp.q.size  # type: ignore[attr-defined]
        malformed: dict[str, Any] = {
            "None": None,
            "tuple": (np.zeros(nz), "solved", 1, 0.0, self.name),
            "strings": QPSolution(np.array(["0"] * nz), "solved", 1, 0.0, self.name),
            "ragged": QPSolution([0.0, [0.0]], "solved", 1, 0.0, self.name),
            "complex": QPSolution(np.zeros(nz, complex), "solved", 1, 0.0, self.name),
            "iterations": QPSolution(np.zeros(nz), "solved", "3", 0.0, self.name),
            "time": QPSolution(np.zeros(nz), "solved", 3, np.nan, self.name),
        }
        if self.mode in malformed:
            return malformed[self.mode]  # type: ignore[no-any-return]
        return QPSolution(None, "maximum iterations reached", 4000, 0.0, self.name)


MALFORMED = ["None", "tuple", "strings", "ragged", "complex", "iterations", "time"]


@pytest.fixture
def backend_only(monkeypatch: pytest.MonkeyPatch) -> None:
    """The direction QP handed to the backend: the compiled active-set solver answers none."""
    monkeypatch.setattr(pipeline_module, "solved_along",
                        lambda A, w, *rest: (w, -1.0, 0.0, 0))  # fmt: skip


@pytest.mark.parametrize("mode", ["raise", "foreign", "shape", "nan", "not found", *MALFORMED])
@pytest.mark.usefixtures("backend_only")
def test_every_backend_fault_falls_back(mode: str, rng: np.random.Generator) -> None:
    """Issue 28 item 4: a backend's exception (its own or foreign), an answer of the wrong
    shape or a non-finite one always goes to the fallback chain; and so does an answer that
    is not a QPSolution (None escaped as an AttributeError before), or one whose solution,
    iterations or time are not what they say."""
    levels = levels_at(rng, (3,), 50.0)  # seven null directions: the backend's QP
    box = box_at(rng)
    _, answer = run(levels, box, Broken(mode))
    assert answer.method == "scipy" and answer.status == "fallback"
    assert answer.attempts[0][0] == "qp" and "broken" in answer.attempts[0][1]
    assert np.all(answer.qdot >= box.lb) and np.all(answer.qdot <= box.ub)
    exact = run(levels, box)[1]
    assert answer.scale == pytest.approx(exact.scale, rel=1e-6)  # the exact LP


@pytest.mark.usefixtures("backend_only")
def test_fallback_chain_order_and_hold(rng: np.random.Generator) -> None:
    levels = levels_at(rng, (3,), 50.0)
    box = box_at(rng)
    for fallbacks, method in ((("scaling",), "scaling"), ((), "hold")):
        _, answer = run(levels, box, Broken("raise"), Options(fallbacks=fallbacks))
        assert answer.method == method and 0.0 <= answer.scale <= 1.0
    recovering = box_at(rng, q=np.full(N, 3.5))
    assert not recovering.contains_zero
    _, answer = run(levels, recovering, Broken("raise"), Options(fallbacks=("scaling",)))
    assert answer.method == "hold" and [a[0] for a in answer.attempts] == ["qp", "scaling"]
    np.testing.assert_array_equal(answer.qdot, np.clip(0.0, recovering.lb, recovering.ub))
    _, answer = run(levels, recovering, Broken("raise"))
    assert answer.method == "scipy"  # bounded least squares (BVLS)


def test_one_null_direction_is_solved_without_the_backend(rng: np.random.Generator) -> None:
    """Nine rows on ten joints: the exact kernel answers, no backend runs."""
    levels = levels_at(rng, (N - 1,), 50.0)
    _, answer = run(levels, box_at(rng), Broken("raise"), Options(damping=None))
    assert answer.method == "qp" and answer.backend == "" and not answer.attempts
    assert answer.status == "scaled"


@pytest.mark.filterwarnings("ignore::RuntimeWarning")
def test_numerical_trouble_never_raises(rng: np.random.Generator) -> None:
    box = box_at(rng)
    for A in (rng.normal(size=(6, N)) * 1e300, np.zeros((6, N)), rng.normal(size=(6, N)) * 1e-300):
        for b in (np.ones(6) * 1e6, np.full(6, 1.7e308), np.zeros(6)):
            for direction in (True, False):
                _, answer = run([[TaskRows(A, b, None, "t")]], box, direction=direction)
                assert np.all(np.isfinite(answer.qdot))
                assert np.all(answer.qdot >= box.lb) and np.all(answer.qdot <= box.ub)
                assert 0.0 <= answer.scale <= 1.0 and np.isfinite(answer.veer)


def test_options_are_checked() -> None:
    with pytest.raises(InvalidInput) as info:
        Options(fallbacks=("qp",))
    assert info.value.argument == "fallbacks"
    with pytest.raises(InvalidInput):
        Options(fallbacks=("scaling", "scaling"))
    with pytest.raises(InvalidInput) as info:
        Options(damping=0.1)  # type: ignore[arg-type]
    assert info.value.argument == "damping"
    with pytest.raises(InvalidInput, match="fallbacks: 'hold' always answers"):
        Options(fallbacks=("hold", "scipy"))
    with pytest.raises(InvalidInput) as info:
        Options(fallbacks=np.array([["scipy"]]))  # type: ignore[arg-type]
    assert info.value.argument == "fallbacks"
    assert Options(fallbacks="scaling").fallbacks == ("scaling", "hold")  # type: ignore[arg-type]


def test_fallbacks_keep_the_constraint_rows_or_give_way(rng: np.random.Generator) -> None:
    """A scaling answer that breaks a row counts as failed: the next method answers."""
    levels = levels_at(rng, (3,), 50.0)
    box = box_at(rng)
    exact = np.linalg.pinv(levels[0][0].A) @ levels[0][0].b
    scaled = uniform_scale(exact, box.lb, box.ub) * exact
    g = rng.normal(size=(1, N))
    h = np.array([g[0] @ scaled - 0.1])  # just broken by the uniform scale
    _, answer = run(levels, box, Broken("raise"), Options(fallbacks=("scaling",)), G=g, h=h)
    assert [a[0] for a in answer.attempts] == ["qp", "scaling"], answer.attempts
    assert "breaks a constraint row" in answer.attempts[1][1] and answer.method == "hold"


def test_damping_only_past_the_threshold(rng: np.random.Generator, monkeypatch) -> None:
    """Below the condition-number threshold a command that cannot be met is scaled, never
    damped; the damping module is not consulted at all."""
    calls = []
    monkeypatch.setattr(Damping, "lambda_sq", lambda *a: calls.append(a) or None)
    for _ in range(100):
        levels = levels_at(rng, (6,), 20.0)
        _, answer = run(levels, box_at(rng), options=Options(Damping(threshold=1e12)))
        assert answer.status == "scaled" and veer_accepted(stacked(levels[0])[0], answer)
    assert calls == []
    assert pipeline_module.EXACT_TOL == 1e-9


# -- slide rows (collision pairs): the command loses its component into them, not its speed --


def plane_problem(slide: bool | None, b: tuple[float, float, float]) -> Problem:
    """Three joints moving a point (A = I); a floor row -qdot_z <= 0 (no approach)."""
    n = 3
    free = np.full(n, 2.0)
    box = Box(-free, free.copy(), np.zeros((2, n), np.int8), True, False, free.copy())
    rows = Constraints(
        G=np.array([[0.0, 0.0, -1.0]]), h=np.array([0.0]), names=("hand|floor",),
        slide=None if slide is None else np.array([slide]), distance=np.array([0.02]),
    )  # fmt: skip
    task = TaskRows(np.eye(n), np.array(b), None, "hand")
    return build([[task]], [Constraints(box), rows], n, DT)


def test_a_slide_row_keeps_the_tangential_component_of_a_command_into_it() -> None:
    answer = solve(plane_problem(True, (0.1, 0.05, -0.1)), make_backend("daqp"), Options())
    assert answer.status == "sliding"
    # A = I is well conditioned: the sliding stage does not damp it (pipeline._slide), so the
    # command keeps all of its tangential component; z: the row met with slide_kernels.MARGIN
    # (1e-12 m/s) to spare
    assert np.allclose(answer.qdot, (0.1, 0.05, 0.0), rtol=1e-12, atol=2e-12)
    tangential = np.hypot(0.1, 0.05)
    assert answer.veer == pytest.approx(np.arctan2(0.1, tangential), abs=1e-9)
    assert answer.scale == pytest.approx(tangential**2 / (tangential**2 + 0.01), rel=1e-9)


def test_a_row_without_the_slide_flag_still_scales_the_command_to_a_stop() -> None:
    for flag in (None, False):
        answer = solve(plane_problem(flag, (0.1, 0.05, -0.1)), make_backend("daqp"), Options())
        assert answer.status == "scaled"
        assert np.allclose(answer.qdot, 0.0, atol=1e-12)


def test_a_slide_row_not_crossed_changes_nothing() -> None:
    for b in ((0.1, 0.05, 0.1), (0.1, 0.0, 0.0), (3.0, 0.0, 1.0)):
        plain = solve(plane_problem(None, b), make_backend("daqp"), Options())
        slid = solve(plane_problem(True, b), make_backend("daqp"), Options())
        assert slid.status == plain.status and slid.veer == plain.veer == 0.0
        assert np.array_equal(slid.qdot, plain.qdot)


def test_sliding_keeps_the_box_by_scaling_the_kept_command() -> None:
    answer = solve(plane_problem(True, (4.0, 0.0, -1.0)), make_backend("daqp"), Options())
    assert answer.status == "sliding"
    assert np.allclose(answer.qdot, (2.0, 0.0, 0.0), rtol=1e-5, atol=1e-12)  # the box's 2 along x
    assert answer.qdot[2] >= -1e-12


def test_sliding_reports_the_pair_and_its_distance() -> None:
    from rrc_pin.solvers.tick.resolution import Resolution

    problem = plane_problem(True, (0.1, 0.0, -0.1))
    answer = solve(problem, make_backend("daqp"), Options())
    (row,) = Resolution.of(problem, answer, 0.0, None).active_rows
    assert row.name == "hand|floor" and row.distance == 0.02 and row.bound == 0.0


def test_a_slid_command_met_by_other_joints_is_met_not_scaled() -> None:
    """Four joints moving a point, joint 4 along z like joint 3; a slide row on joint 3 alone
    (-qdot_3 <= 1e-9, a held pair's bound: rrc_pin.solvers.collision.damper_kernels.SLACK). The
    least-norm
    rates of a command down share z between joints 3 and 4 and cross the row; the slide
    meets the command with joint 4 and keeps the row: those rates are the answer (the
    least-norm rates scaled back to the row would stand still). To the cost of the null space
    in the sliding stage (pipeline.SLIDE_DAMPING: 1e-2 of the rows' mean squared singular
    value; 0.66 % of the command along z here): to 1 %."""
    n = 4
    free = np.full(n, 2.0)
    box = Box(-free, free.copy(), np.zeros((2, n), np.int8), True, False, free.copy())
    rows = Constraints(G=np.array([[0.0, 0.0, -1.0, 0.0]]), h=np.array([SLACK]),
                       names=("link3|floor",), slide=np.array([True]),
                       distance=np.array([0.02]))  # fmt: skip
    A = np.array([[1.0, 0, 0, 0], [0, 1.0, 0, 0], [0, 0, 1.0, 1.0]])
    b = np.array([0.1, 0.05, -0.1])
    problem = build([[TaskRows(A, b, None, "hand")]], [Constraints(box), rows], n, DT)
    answer = solve(problem, make_backend("daqp"), Options())
    assert answer.status == "sliding"
    np.testing.assert_allclose(A @ answer.qdot, b, rtol=1e-2, atol=1e-12)
    assert -answer.qdot[2] <= SLACK and answer.scale == pytest.approx(1.0, abs=1e-2)


def test_a_backends_scaled_answer_reports_the_veer_it_measured(rng: np.random.Generator) -> None:
    """Six rows on ten joints: the direction problem goes to the backend (four null
    directions), whose answer may leave the command's direction by its rounding (accepted up to
    DIRECTION_TOL |A| |qdot|). A scaled answer reports that angle as measured, not 0."""
    scaled = measured = 0
    for _ in range(60):
        levels = levels_at(rng, (6,), 20.0)
        _, answer = run(levels, box_at(rng), options=Options(damping=None))
        if answer.status != "scaled":
            continue
        scaled += 1
        A, b = stacked(levels[0])
        y = A @ answer.qdot
        veer = scale_and_veer(y, b)[1]
        assert answer.veer == pytest.approx(veer, abs=1e-7) and veer_accepted(A, answer)
        measured += answer.veer > 0.0
    assert scaled > 20 and measured > 0
