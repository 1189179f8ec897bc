"""One tick in one compiled call (solvers/tick/tick.py) against the Python pipeline it takes the
place of (solvers/tick/pipeline.py, its reference): random problems of every mode (direction,
tracking, weighted; one level, strict levels; the joint box alone or with constraint rows, some
of them slide rows), the same rates to 1e-9 of their size, the same statuses, levels, scales and
veers; its pieces against numpy; bad inputs coded before anything is written."""

from __future__ import annotations

from typing import get_args

import numba
import numpy as np
import pytest

from rrc_pin.solvers.qp_backends import make_backend
from rrc_pin.solvers.qp_backends.qp import velocity_tolerance
from rrc_pin.solvers.tick import backend_calls, tick, top
from rrc_pin.solvers.tick.damping import Damping
from rrc_pin.solvers.tick.joint_box import joint_box
from rrc_pin.solvers.tick.pipeline import Options, Status, served, solve
from rrc_pin.solvers.tick.problem import Box, Constraints, TaskRows, build

STATUS_NAMES = get_args(Status)

SEEDS = [20261206, 6307242558226725790, 8806618223483400590, 481931199943053647,
         int(np.random.SeedSequence().entropy % 2**63)]  # fmt: skip
N, DT = 7, 0.01
LEVELS = ("met", "scaled", "traded", "dropped")
RATE_TOL = 1e-9
"""Rates' difference relative to their size, and scales' difference, where the kernels
answered."""
BACKEND_TOL = 1e-5
"""Where the backend (DAQP) answered a stage: its answer moves with the last bits of its data,
which the compiled tick forms in its own loops. On a scaled two-level problem with three rows the
pipeline's own rates moved by 9.6e-7 (its scale by 4.1e-7) when its task or constraint rows were
moved by one ulp, as far as the compiled tick's differ from it there."""


def limits(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    lower = -rng.uniform(1.0, 3.0, N)
    return lower, -lower * rng.uniform(0.5, 1.5, N), rng.uniform(0.5, 2.0, N)


def tasks(rng: np.random.Generator, weighted: bool) -> list[list[TaskRows]]:
    """One to three levels of one or two tasks, weights and units at random."""
    count = 1 if weighted else int(rng.integers(1, 4))
    out = []
    for k in range(count):
        level = []
        for t in range(int(rng.integers(1, 3))):
            m = int(rng.integers(1, 5))
            weight = None if rng.random() < 0.5 else rng.uniform(0.1, 2.0, m)
            unit = None if rng.random() < 0.5 else rng.uniform(0.3, 1.5, m)
            b = rng.normal(size=m) * rng.choice([0.05, 0.5, 5.0])
            level.append(TaskRows(rng.normal(size=(m, N)), b, weight, f"t{k}{t}", unit))
        out.append(level)
    return out


def case(rng: np.random.Generator) -> tuple:
    lower, upper, velocity = limits(rng)
    q = rng.uniform(lower, upper)
    if rng.random() < 0.1:  # a start outside the range: the box excludes standing still
        q[0] = upper[0] + 0.1
    weighted = rng.random() < 0.3
    levels = tasks(rng, weighted)
    p = int(rng.integers(0, 4)) if rng.random() < 0.5 else 0
    G, h = rng.normal(size=(p, N)), rng.uniform(0.0, 0.5, p)
    slide = rng.random(p) < 0.5
    return q, lower, upper, velocity, levels, weighted, G, h, slide, rng.random() < 0.8


def pipeline_answer(q, lower, upper, velocity, levels, weighted, G, h, slide, direction):
    lb, ub, kind = np.empty(N), np.empty(N), np.empty((2, N), np.int8)
    zero, recovering = joint_box(q, lower, upper, velocity, 0.0, 1.0, DT, np.zeros(N),
                                         np.array([np.inf]), lb, ub, kind)  # fmt: skip
    box = Box(lb, ub, kind, zero, recovering, velocity)
    names = tuple(f"row{i}" for i in range(h.size))
    limits_ = [Constraints(box), Constraints(G=G, h=h, names=names, slide=slide)]
    problem = build(levels, limits_, N, DT, weighted=weighted, direction=direction)
    return solve(problem, make_backend("daqp"), Options(Damping()))


def compiled_answer(q, lower, upper, velocity, levels, weighted, G, h, slide, direction):
    ws = tick.Workspace(lower, upper, velocity, np.array([np.inf]), 0.0, 1.0, 100.0, direction,
                        velocity_tolerance(velocity))  # fmt: skip
    ws.load_levels(levels, weighted)
    if h.size:
        ws.load_rows(G, h, slide)
    else:
        ws.load_rows(None, None, None)
    backend_calls.enter(backend_calls.Context(make_backend("daqp"), velocity))
    try:
        code = ws.run(q, np.zeros(N), DT)
    finally:
        backend_calls.leave()
    return code, ws


@pytest.mark.parametrize("seed", SEEDS)
def test_random_problems_answered_as_the_pipeline(seed: int) -> None:
    rng = np.random.default_rng(seed)
    kinds: dict[str, int] = {}
    relabelled = 0  # a lower level served by one tick, dropped by the other (its rates the same)
    sensitive = 0  # rates apart by more than RATE_TOL, as far as the pipeline's own rounding
    for _ in range(400):
        args = case(rng)
        want = pipeline_answer(*args)
        code, ws = compiled_answer(*args)
        if code == tick.FAILED:  # the fallbacks' answer: not the compiled call's
            assert want.method != "qp"
            continue
        status = STATUS_NAMES[code]
        kinds[status] = kinds.get(status, 0) + 1
        qdot = ws.joints[tick.QDOT]
        assert status == want.status
        got = tuple(LEVELS[c] for c in ws.level_codes())
        tol = RATE_TOL if want.backend == "" else BACKEND_TOL
        if got != want.levels:  # a lower level's QP at rounding: refused on one side only
            # (the backend's, on data apart in their last bits; the rates are checked below)
            pairs = zip(got, want.levels, strict=True)
            assert all(g == w or "dropped" in {g, w} for g, w in pairs), (got, want.levels)
            relabelled += 1
        apart, scale_tol = np.abs(qdot - want.qdot).max(), tol
        if apart > tol * (1.0 + np.abs(want.qdot).max()):
            spread, scale_spread = own_spread(args, want.qdot, want.scale, rng)
            assert apart <= 3.0 * spread, (seed, apart)
            scale_tol = max(tol, 3.0 * scale_spread)
            sensitive += 1
        assert ws.reals[tick.SCALE] == pytest.approx(want.scale, abs=scale_tol), seed
        if max(want.scale, ws.reals[tick.SCALE]) > 1e-9:
            assert ws.reals[tick.VEER] == pytest.approx(want.veer, abs=1e-7)
    assert {"exact", "scaled", "least_squares"} <= set(kinds), kinds
    assert relabelled <= 4, relabelled  # 1 of 400 seen (the top's QP answered 1e-9 apart)
    assert sensitive <= 4, sensitive  # 1 of 400 seen (fresh seed 6307242558226725790)


def own_spread(args: tuple, qdot: np.ndarray, scale: float, rng: np.random.Generator
               ) -> tuple[float, float]:  # fmt: skip
    """How far the pipeline's own rates and scale move when its task and constraint rows move
    by one ulp (8 draws): the answer's sensitivity to rounding. A lower level pinned by
    constraint rows whose slack is :data:`~rrc_pin.solvers.tick.least_squares.ROUNDING`
    (1e-12 rad/s) and whose smallest singular value is 4.9e-4 is a region 1e-8 wide: one ulp
    of its data moved the pipeline's rates by up to 3.2e-8, and the compiled tick's answer,
    formed in its own loops, lay 1.3e-8 from the pipeline's (seed 481931199943053647: rates
    1.1e-8 apart, the pipeline's own spread 1.1e-8, the scales 2.8e-9 apart)."""
    q, lower, upper, velocity, levels, weighted, G, h, slide, direction = args

    def ulp(a: np.ndarray) -> np.ndarray:
        return a * (1.0 + np.finfo(float).eps * rng.choice([-1.0, 1.0], a.shape))

    spread = scale_spread = 0.0
    for _ in range(8):
        moved = [[TaskRows(ulp(t.A), t.b, t.weight, t.name, t.unit) for t in level]
                 for level in levels]  # fmt: skip
        answer = pipeline_answer(q, lower, upper, velocity, moved, weighted, ulp(G), h, slide,
                                 direction)  # fmt: skip
        spread = max(spread, float(np.abs(answer.qdot - qdot).max()))
        scale_spread = max(scale_spread, abs(answer.scale - scale))
    return spread, scale_spread


def test_stacked_rows_are_the_problems(rng: np.random.Generator) -> None:
    velocity = limits(rng)[2]
    lb, ub = -velocity, velocity
    for _ in range(100):
        (level,) = tasks(rng, weighted=True)
        normalised = bool(rng.random() < 0.5)
        A = np.vstack([t.A for t in level])
        b = np.concatenate([t.b for t in level])
        weight = np.concatenate([np.ones(t.b.size) if t.weight is None else t.weight
                                 for t in level])  # fmt: skip
        unit = np.concatenate([np.ones(t.b.size) if t.unit is None else t.unit for t in level])
        rows, rates, factor = tick.stacked(A, b, weight, unit, normalised, lb, ub)
        box = Box(lb, ub, np.zeros((2, N), np.int8), True, False, velocity)
        problem = build([level], [Constraints(box)], N, DT, direction=normalised)
        want_A, want_b = problem.stacked[0]
        np.testing.assert_allclose(rows, want_A, atol=1e-15)
        np.testing.assert_allclose(rates, want_b, atol=1e-15)
        assert factor == problem.rate_factor


def test_served_and_the_shrink_into_rows_against_the_pipelines(rng: np.random.Generator) -> None:
    for _ in range(200):
        A = rng.normal(size=(3, N))
        b = rng.normal(size=3) * (rng.random() < 0.9)
        qdot = rng.normal(size=N)
        for x in (qdot, np.linalg.pinv(A) @ b, 0.5 * np.linalg.pinv(A) @ b):
            assert LEVELS[tick.served(A, b, x, 1.0)] == served(A @ x, b)


@pytest.mark.parametrize("bad", ["position", "rate", "row"])
def test_bad_inputs_are_coded_before_anything_is_written(bad: str) -> None:
    rng = np.random.default_rng(4)
    lower, upper, velocity = limits(rng)
    ws = tick.Workspace(lower, upper, velocity, np.array([np.inf]), 0.0, 1.0, 100.0, True, 1e-6)
    level = [[TaskRows(rng.normal(size=(6, N)), rng.normal(size=6), None, "t")]]
    ws.load_levels(level, False)
    ws.load_rows(None, None, None)
    q = np.zeros(N)
    if bad == "position":
        q[2] = np.nan
    elif bad == "rate":
        ws.rates[tick.RATE, 1] = np.inf
    else:
        ws.task_rows[5, 3] = -np.inf
    before = ws.joints[tick.QDOT].copy()
    assert ws.run(q, np.zeros(N), DT) == tick.INVALID_INPUT
    codes = {"position": tick.BAD_POSITION, "rate": tick.BAD_RATE, "row": tick.BAD_ROWS}
    assert ws.ints[tick.INVALID] == codes[bad]
    assert np.array_equal(ws.joints[tick.QDOT], before)


def test_the_default_tick_passes_a_box_without_standing_still_on() -> None:
    """run_box answers one level in the direction mode; a start outside the range (the box
    excludes zero: the least-squares mode) is run's."""
    rng = np.random.default_rng(5)
    lower, upper, velocity = limits(rng)
    ws = tick.Workspace(lower, upper, velocity, np.array([np.inf]), 0.0, 1.0, 100.0, True, 1e-6)
    ws.load_levels([[TaskRows(rng.normal(size=(6, N)), rng.normal(size=6), None, "t")]], False)
    ws.load_rows(None, None, None)
    q = np.zeros(N)
    ws.joints[tick.POSITION], ws.reals[tick.DT] = q, DT
    args = (ws.joints, ws.task_rows, ws.rates, ws.ints, ws.reals)
    assert tick.run_box(*args) >= 0
    q[0] = upper[0] + 0.5
    ws.joints[tick.POSITION] = q
    assert tick.run_box(*args) == tick.ELSEWHERE
    backend_calls.enter(backend_calls.Context(make_backend("daqp"), velocity))
    try:
        assert ws.run(q, np.zeros(N), DT) == STATUS_NAMES.index("recovering")
    finally:
        backend_calls.leave()


@pytest.mark.parametrize("seed", [6, 7, 8])
def test_the_twist_entry_answers_as_run_box(seed: int) -> None:
    """run_twist on the caller's rows, rates and positions answers as run_box on the loaded
    workspace: the same rates, box and report; the rates left as the next tick's previous;
    bad values and a box without standing still passed on, nothing written to the previous."""
    rng = np.random.default_rng(seed)
    lower, upper, velocity = limits(rng)
    ws = tick.Workspace(lower, upper, velocity, np.full(N, 50.0), 0.0, 1.0, 100.0, True, 1e-6)
    answered = 0
    for _ in range(30):
        J, b = rng.normal(size=(6, N)), rng.normal(size=6) * rng.choice([0.1, 1.0, 10.0])
        q, previous = rng.uniform(lower, upper), rng.normal(size=N) * 0.2
        ws.load_levels([[TaskRows(J, b, None, "t", np.ones(6))]], False)
        ws.load_rows(None, None, None)
        ws.joints[tick.POSITION], ws.joints[tick.PREVIOUS], ws.reals[tick.DT] = q, previous, DT
        code = tick.run_box(ws.joints, ws.task_rows, ws.rates, ws.ints, ws.reals)
        ws.joints[tick.PREVIOUS] = previous
        out = np.empty(tick.twist_size(N, 6))
        got = tick.run_twist(J, b, q, DT, ws.joints, ws.rates, ws.ints, ws.reals, out)
        if code == tick.ELSEWHERE:  # previous rates far from zero: the box excludes it
            assert got[0] == code
            continue
        want = (code, *ws.reals[[tick.SCALE, tick.VEER, tick.CLIP, tick.LAMBDA_SQ]].tolist())
        assert got == want
        assert np.array_equal(out[:N], ws.joints[tick.QDOT])
        assert np.array_equal(out[N : 5 * N].reshape(4, N),
                              ws.joints[[tick.LB, tick.UB, tick.KIND, tick.KIND + 1]])
        assert np.array_equal(out[5 * N : -2], b) and out[-2] == 1.0
        assert np.array_equal(ws.joints[tick.PREVIOUS], out[:N])
        answered += 1
    assert answered >= 20
    previous = ws.joints[tick.PREVIOUS].copy()
    bad = q.copy()
    bad[2] = np.nan
    assert tick.run_twist(J, b, bad, DT, ws.joints, ws.rates, ws.ints, ws.reals,
                          out)[0] == tick.INVALID_INPUT
    outside = q.copy()
    outside[0] = upper[0] + 0.5
    assert tick.run_twist(J, b, outside, DT, ws.joints, ws.rates, ws.ints, ws.reals,
                          out)[0] == tick.ELSEWHERE
    assert np.array_equal(ws.joints[tick.PREVIOUS], previous)


def _constant_rows(rng: np.random.Generator) -> list[TaskRows]:
    """Tasks whose rows, weights or units are read-only arrays owning their values (loaded once
    while they come at the same rows), beside writable ones, None and read-only views."""
    out = []
    for k in range(4):
        m = int(rng.integers(1, 5))
        A, weight, unit = rng.normal(size=(m, N)), rng.uniform(0.1, 2, m), rng.uniform(0.3, 1.5, m)
        for part in (A, weight, unit):
            part.flags.writeable = rng.random() < 0.3
        view = rng.uniform(0.1, 2.0, 2 * m)[::2]
        view.flags.writeable = False  # a view of values that may change: loaded every tick
        weight_or = (None, weight, view)[int(rng.integers(0, 3))]
        out.append(TaskRows(A, rng.normal(size=m), weight_or,
                            f"t{k}", None if rng.random() < 0.3 else unit))  # fmt: skip
    return out


@pytest.mark.parametrize("seed", SEEDS)
def test_loaded_rows_are_a_fresh_workspaces_after_any_sequence(seed: int) -> None:
    """Levels of the same tasks in other orders, places and numbers, a twist over them, a
    view's values changed: after each load the workspace holds what a fresh one loads."""
    rng = np.random.default_rng(seed)
    lower, upper, velocity = limits(rng)

    def workspace() -> tick.Workspace:
        return tick.Workspace(lower, upper, velocity, np.array([np.inf]), 0.0, 1.0, 100.0,
                              True, 1e-6)  # fmt: skip

    pool, ws = _constant_rows(rng), workspace()
    for step in range(200):
        picked = [pool[int(i)] for i in rng.integers(0, len(pool), int(rng.integers(1, 5)))]
        cut = int(rng.integers(0, len(picked)))
        levels = [picked] if cut == 0 else [picked[:cut], picked[cut:]]
        view = pool[int(rng.integers(0, len(pool)))].weight
        if view is not None and view.base is not None:
            view.base[:] = rng.uniform(0.1, 2.0, view.base.size)
        ws.load_levels(levels, len(levels) == 1)
        fresh = workspace()
        fresh.load_levels(levels, len(levels) == 1)
        m = int(fresh.ints[tick.ROWS])
        assert np.array_equal(ws.task_rows[:m], fresh.task_rows[:m]), (seed, step)
        assert np.array_equal(ws.rates[:, :m], fresh.rates[:, :m]), (seed, step)
        used = tick.STARTS + len(levels) + 1
        assert np.array_equal(ws.ints[:used], fresh.ints[:used]), (seed, step)
        if rng.random() < 0.2:  # the default tick's twist over the rows loaded last
            ws.load_twist(rng.normal(size=(6, N)), (0, 1, 2, 3, 4, 5), rng.normal(size=6))


@pytest.mark.compiled
def test_the_stages_compiled_beside_are_those_the_default_tick_calls() -> None:
    """compile_stages compiles the stages for the types run_box passes them: run_box's body,
    compiled anew, calls them without compiling another signature (its compilation then loads
    them from the cache a second process filled)."""
    tick.compile_stages()
    stages = (top.scaled_along, top.damping)
    before = [set(stage.signatures) for stage in stages]
    fresh = numba.njit(tick.run_box.py_func)  # not cached: its callees typed anew
    rng = np.random.default_rng(9)
    lower, upper, velocity = limits(rng)
    ws = tick.Workspace(lower, upper, velocity, np.array([np.inf]), 0.0, 1.0, 100.0, True, 1e-6)
    ws.load_levels([[TaskRows(rng.normal(size=(6, N)), rng.normal(size=6), None, "t")]], False)
    ws.load_rows(None, None, None)
    ws.joints[tick.POSITION], ws.reals[tick.DT] = np.zeros(N), DT
    assert fresh(ws.joints, ws.task_rows, ws.rates, ws.ints, ws.reals) >= 0
    assert [set(stage.signatures) for stage in stages] == before
