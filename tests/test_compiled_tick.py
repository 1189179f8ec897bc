"""A resolver's compiled ticks (rrc_pin/compiled_tick.py): the default twist's way and the
tasks' way give the same answer bitwise; the resolution builds the problem the Python pipeline
builds, where it is read; bad values are named before any state changes."""

from __future__ import annotations

import numpy as np
import pytest

import rrc_pin
from rrc_pin import FrameTask, PostureTask, Resolver
from rrc_pin.errors import InvalidInput
from rrc_pin.kinematics import Kinematics
from rrc_pin.solvers.tick.problem import Constraints, build

SEEDS = [20261206, int(np.random.SeedSequence().entropy % 2**63)]


@pytest.fixture(scope="module")
def panda() -> rrc_pin.Robot:
    return rrc_pin.load("panda")


@pytest.mark.parametrize("seed", SEEDS)
def test_a_twist_answers_as_its_task_does(panda: rrc_pin.Robot, seed: int) -> None:
    """solve(q, twist) goes straight into the compiled call; the same tick as one FrameTask
    goes the tasks' way: the same floats, the same report."""
    rng = np.random.default_rng(seed)
    fast, general = Resolver(panda), Resolver(panda)
    for _ in range(200):
        q = panda.random_q(rng)
        twist = rng.normal(size=6) * rng.choice([0.05, 0.5, 5.0])
        a = fast.solve(q, twist)
        b = general.solve(q, [[FrameTask(panda.tool_frame, twist)]], priority="strict")
        assert np.array_equal(a.qdot, b.qdot)
        assert (a.status, a.levels, a.scale, a.veer) == (b.status, b.levels, b.scale, b.veer)
        assert a.active == b.active and a.residual == b.residual


def test_the_problem_is_built_where_it_is_read(panda: rrc_pin.Robot) -> None:
    rng = np.random.default_rng(2)
    resolver = Resolver(panda)
    tasks = [FrameTask(panda.tool_frame, rng.normal(size=6)), PostureTask(panda.ready(),
                                                                           weight=0.1)]  # fmt: skip
    q = panda.random_q(rng)
    r = resolver.solve(q, tasks)
    assert "problem" not in r.__dict__  # not built yet
    kin = Kinematics(panda.model, panda.model.createData(), resolver.layout, q, q)
    rows = [[t.rows(kin) for t in tasks]]
    box = resolver.limits[0].constraints(kin, resolver.dt, np.zeros(panda.nv))
    want = build(rows, [box], panda.nv, resolver.dt, weighted=True)
    problem = r.problem
    assert problem.mode == want.mode == "weighted"
    np.testing.assert_array_equal(problem.box.lb, want.box.lb)
    np.testing.assert_array_equal(problem.box.kind, want.box.kind)
    for (A, b), (A_, b_) in zip(problem.stacked, want.stacked, strict=True):
        np.testing.assert_array_equal(A, A_)
        np.testing.assert_array_equal(b, b_)
    assert r.box is problem.box or np.array_equal(r.box.ub, problem.box.ub)
    assert isinstance(Constraints(problem.box).box, type(want.box))



@pytest.mark.parametrize("speed", [0.05, 5.0, 1e200])
@pytest.mark.parametrize("weighted", [False, True])
def test_the_top_level_is_read_as_the_problem_stacks_it(panda: rrc_pin.Robot, speed: float,
                                                        weighted: bool) -> None:  # fmt: skip
    """TickSource.top's rows are the problem's top level stacked in its metric, bitwise: the
    direction mode's units, a level's weights, a command past the cap (its rates rescaled,
    its rows not)."""
    rng = np.random.default_rng(7)
    resolver = Resolver(panda)
    weight = np.array([1.0, 4.0, 1.0, 0.5, 1.0, 2.0]) if weighted else 1.0
    modes = set()
    for k in range(20):
        top_tasks = [FrameTask(panda.tool_frame, rng.normal(size=6) * speed, weight=weight),
                     FrameTask("panda_link5", rng.normal(size=6) * speed)][: 1 + k % 2]
        tasks = [top_tasks, [PostureTask(panda.ready(), weight=0.1)]]
        r = resolver.solve(panda.random_q(rng), tasks, priority="strict")
        level, top, rows = r.source.top()
        problem = r.problem
        assert level == problem.levels[0] and rows == problem.rows
        assert np.array_equal(top, problem.stacked[0][0])
        modes.add(problem.mode)
    assert "direction" in modes


@pytest.mark.parametrize(("name", "command"), [("gsfc_dual", "object"), ("yeh_tripod", "body")])
def test_a_tick_within_equality_rows_keeps_its_top_level_as_the_problem_stacks_it(
    name: str, command: str
) -> None:
    """A cell's tick (a grip's or the feet's equality rows) keeps its top level's rows in their
    metric from its kernel: bitwise the problem's, on exact, scaled and damped ticks."""
    from rrc_pin.cells import CellController
    from rrc_pin.solvers.tick.damping import Damping

    controller = CellController(rrc_pin.load(name), 0.01, damping=Damping(10.0))  # damped often
    rng = np.random.default_rng(2030)
    speed = np.array([0.15, 0.15, 0.15, 0.4, 0.4, 0.4]) / (1.0 if name == "gsfc_dual" else 5.0)
    statuses = set()
    for k in range(400):
        if k % 20 == 0:
            twist = rng.normal(size=6) * speed * (1.0, 10.0)[k // 20 % 2]
        r = controller.step({command: twist}).resolution
        level, top, rows = r.source.top()
        assert r.source.stacked is not None
        problem = r.problem
        assert level == problem.levels[0] and rows == problem.rows
        assert np.array_equal(top, problem.stacked[0][0])
        statuses.add(r.status)
    assert {"exact", "scaled", "damped"} <= statuses, statuses


@pytest.mark.parametrize("which", ["q", "twist"])
def test_a_bad_value_is_named_and_changes_nothing(panda: rrc_pin.Robot, which: str) -> None:
    resolver = Resolver(panda)
    q, twist = panda.ready(), np.array([0.1, 0.0, 0.0, 0.0, 0.0, 0.0])
    resolver.solve(q, twist)
    before = resolver.warm_start_state()["last_qdot"]
    bad_q, bad_twist = q.copy(), twist.copy()
    if which == "q":
        bad_q[3] = np.nan
    else:
        bad_twist[4] = np.inf
    with pytest.raises(InvalidInput) as error:
        resolver.solve(bad_q, bad_twist)
    assert error.value.argument == which
    assert np.array_equal(resolver.warm_start_state()["last_qdot"], before)


def test_solve_at_reads_the_callers_kinematics(panda: rrc_pin.Robot) -> None:
    resolver = Resolver(panda)
    q = panda.random_q(np.random.default_rng(3))
    kin = Kinematics(panda.model, panda.model.createData(), resolver.layout, q, q)
    J = kin.jacobian(panda.tool_frame, "world_aligned")
    twist = np.array([0.05, 0.0, -0.02, 0.0, 0.1, 0.0])
    a = resolver.solve_at(kin, twist)
    b = Resolver(panda).solve(q, twist)
    assert np.array_equal(a.qdot, b.qdot)
    assert kin.jacobian(panda.tool_frame, "world_aligned") is J  # read, not computed again
    with pytest.raises(InvalidInput, match="kinematics"):
        resolver.solve_at(q, twist)  # type: ignore[arg-type]


def test_a_twist_of_any_layout_answers_alike(panda: rrc_pin.Robot) -> None:
    """Read-only, strided or int arrays answer as fresh ones (copied, or the general way); the
    rates are read-only; the previous rates are the resolver's, after a reset or a tasks' tick
    too (acceleration limits read them)."""
    rng = np.random.default_rng(4)
    limits = rrc_pin.JointLimits(acceleration=np.full(panda.nv, 20.0))
    a, b = Resolver(panda, limits=limits), Resolver(panda, limits=limits)
    q = panda.random_q(rng)
    for k in range(12):
        twist = rng.normal(size=6) * 0.3
        if k == 4:
            a.reset()
            b.reset()
        if k == 7:
            tasks = [FrameTask(panda.tool_frame, twist)]
            assert np.array_equal(a.solve(q, tasks).qdot, b.solve(q, tasks).qdot)
        q_ro, twist_ro = q.copy(), twist.copy()
        q_ro.flags.writeable = twist_ro.flags.writeable = False
        strided = np.repeat(twist, 2)[::2]
        r = a.solve(q_ro, twist_ro if k % 2 else strided)
        want = b.solve(q.copy(), twist.copy())
        assert np.array_equal(r.qdot, want.qdot) and r.status == want.status
        assert not r.qdot.flags.writeable
        q = q + r.qdot * a.dt
    whole = np.round(q).astype(int)
    assert np.array_equal(a.solve(whole, np.zeros(6)).qdot, b.solve(whole.astype(float),
                                                                      np.zeros(6)).qdot)
