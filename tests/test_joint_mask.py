"""A joint mask (rrc_pin.solvers.tick.joint_mask, Resolver.mask): masked joints exactly still,
the others solving as the reduced model (pinocchio.buildReducedModel) would.

Closed-loop runs on panda, rrc_k1607 and baxter whose mask changes every 50 ticks, weighted and
strict, within joint and collision limits: every tick's rates compared with those of a
resolver built on the model reduced at that configuration, the same tasks, limits and options
(and the same units of the task rows: the full robot's reaches, which the mask keeps).

The two problems agree within DATA_TOL (1e-12: the two models' Jacobians and collision
distances differ by roundoff; a collision row's G within 3 times its own spread when q moves
by 1e-15 rad, where coal's witness points between near-parallel features amplify the roundoff
by 1e4), and the rates within TOL (1e-9) at every tick but where the
pipeline's answer jumps under such roundoff (strict levels: 227 of 3,000 ticks of baxter over
twenty seeds, up to 0.37 rad/s, a top level of rank 11 with an arm masked below six joints,
where the reduced model's own rates move by 8.5e-3 rad/s when its rows move by 1e-14; one
tick of rrc_k1607, 2.3e-6).
At such a tick the test shows that each side's rates are the pipeline's answer to its own
numbers (within SAME, a fresh backend; both resolvers start each tick cold, as a warm start
moves such an answer too: 1.6e-6 at one tick): the gap is between the answers to two
problems DATA_TOL apart, the pipeline's, not the mask's.
Fresh seeds at every run (printed on failure), beside fixed ones.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
import pinocchio as pin
import pytest

import rrc_pin
from rrc_pin import CollisionLimit, CollisionModel, FrameTask, JointLimits, PostureTask, Resolver
from rrc_pin.geometry.robot_geometry import robot_geometry
from rrc_pin.resolver import QPOptions
from rrc_pin.robot import Robot
from rrc_pin.solvers.qp_backends import make_backend
from rrc_pin.solvers.tick.joint_box import VELOCITY
from rrc_pin.solvers.tick.joint_mask import free_columns, scattered, widened_rates
from rrc_pin.solvers.tick.pipeline import Options, solve
from rrc_pin.solvers.tick.problem import Box, Constraints, Problem, TaskRows, build
from rrc_pin.solvers.tick.resolution import Resolution

SEEDS = [20261206, 5663478059289580763, int(np.random.SeedSequence().entropy % 2**63)]
TOL = 1e-9  # [rad/s] the masked resolver against the reduced model's
DATA_TOL = 1e-12  # their problems' numbers (two models' roundoff: Jacobians, fcl distances)
SAME = 1e-12  # [rad/s] the masked rates against the pipeline's answer to their own numbers
SLACK = 1e-6  # the room (in the row's units) a row in one problem only leaves at its answer
Pairing = tuple[list[int], list[int], list[int], list[int]]
UNHURRIED = QPOptions(time_limit=60.0)
"""The backends' time per QP: a loaded machine's wall clock must not refuse one side's answer
(the default 50 ms cap answers ``fallback`` there; both sides' answers are compared)."""
PERIOD = 50  # ticks between mask changes
TICKS = 150
DT = 0.01
ARMS = {  # the run's robot, and whether its collision pairs are limits too
    "panda": True,
    "rrc_k1607": False,
    "baxter": True,
}


def test_the_free_columns_and_back() -> None:
    """Every row block keeps its free columns, the box its free entries; written back with
    zero columns and a zero box (the plain numpy of the module docstring)."""
    rng = np.random.default_rng(SEEDS[0])
    n, free = 5, np.array([0, 2, 3])
    A, G, C = rng.normal(size=(4, n)), rng.normal(size=(3, n)), rng.normal(size=(1, n))
    lb, ub = -rng.uniform(0.5, 1.0, n), rng.uniform(0.5, 1.0, n)
    lb[1] = 0.2  # a masked joint whose box excludes zero: out of range, it stays
    box = Box(lb, ub, np.zeros((2, n), np.int8), False, True, ub.copy())
    limits = [Constraints(box, G, np.ones(3), C, np.zeros(1), ("g0", "g1", "g2", "c0"))]
    posture = TaskRows(np.eye(n), np.arange(n, dtype=float), None, "posture")
    levels, kept = free_columns([[TaskRows(A, np.ones(4), None, "t"), posture]],
                                [[False, True]], limits, free)  # fmt: skip
    assert np.array_equal(levels[0][0].A, A[:, free])
    assert np.array_equal(levels[0][1].A, np.eye(3)) and np.array_equal(levels[0][1].b, free)
    small = kept[0]
    assert small.box is not None and small.G is not None and small.C is not None
    assert np.array_equal(small.G, G[:, free]) and np.array_equal(small.C, C[:, free])
    assert np.array_equal(small.box.lb, lb[free]) and np.array_equal(small.box.ub, ub[free])
    assert small.box.contains_zero and not small.box.recovering  # the joint out of range is held
    reduced = build(levels, kept, free.size, DT)
    report = scattered(reduced, [[TaskRows(A, np.ones(4), None, "t"), posture]], free, n)
    assert np.array_equal(report.box.lb[[1, 4]], [0.0, 0.0])
    assert np.array_equal(report.box.ub[[1, 4]], [0.0, 0.0])
    assert np.array_equal(report.box.kind[:, [1, 4]], np.full((2, 2), VELOCITY))
    assert report.rows is not None and np.array_equal(report.rows.G[:, free], G[:, free])
    assert not report.rows.G[:, [1, 4]].any() and report.mode == reduced.mode
    assert np.array_equal(widened_rates(np.array([1.0, 2.0, 3.0]), free, n),
                          [1.0, 0.0, 2.0, 3.0, 0.0])  # fmt: skip


def _reduced(robot: Robot, masked: tuple[str, ...], q: npt.NDArray[np.float64],
             collision: bool) -> tuple[Robot, CollisionModel | None]:  # fmt: skip
    """The robot without ``masked`` (locked at ``q``), and its collision model."""
    locked = [robot.model.getJointId(name) for name in masked]
    q_pin = robot.to_pinocchio(q)
    if not collision:
        model = pin.buildReducedModel(robot.model, locked, q_pin)
        return Robot(model, robot.tool_frames, name="reduced", source="reduced"), None
    geometry = robot_geometry(robot).objects
    model, objects = pin.buildReducedModel(robot.model, geometry, locked, q_pin)
    reduced = Robot(model, robot.tool_frames, name="reduced", source="reduced")
    return reduced, CollisionModel(reduced, objects)


def _limits(cm: CollisionModel | None, pairs: list[tuple[str, str]]) -> list[object]:
    """Joint limits (and an acceleration bound), and collision rows of the pairs ``pairs``."""
    joint = JointLimits(acceleration=40.0)
    if cm is None:
        return [joint]
    return [joint, CollisionLimit(cm, 0.02, 0.25, pairs=pairs)]


def _tasks(robot: Robot, twists: list[npt.NDArray[np.float64]], q_ref: npt.NDArray[np.float64],
           strict: bool) -> list[object]:  # fmt: skip
    """A frame task per tool, a posture below (its own level when ``strict``)."""
    frames = [FrameTask(tool, twist) for tool, twist in zip(robot.tool_frames, twists,
                                                              strict=True)]  # fmt: skip
    posture = PostureTask(q_ref, gain=0.5, weight=1e-3)
    return [frames, [posture]] if strict else [*frames, posture]


@pytest.mark.parametrize("strict", [False, True], ids=["weighted", "strict"])
@pytest.mark.parametrize("name", list(ARMS))
@pytest.mark.parametrize("seed", SEEDS)
def test_a_mask_changed_every_50_ticks_solves_as_the_reduced_model(
    name: str, strict: bool, seed: int
) -> None:
    """Masked joints at exactly 0.0, the free ones as the reduced model's resolver within
    TOL, at every tick of a closed-loop run."""
    rng = np.random.default_rng(seed)
    robot = rrc_pin.load(name)
    collision = ARMS[name]
    cm = CollisionModel(robot) if collision else None
    resolver = None
    q = robot.ready()
    q_ref = robot.ready()
    qdot = np.zeros(robot.nv)
    reduced: Resolver | None = None
    free = np.arange(robot.nv)
    jumps = 0  # ticks where the pipeline's answer jumps at the models' roundoff
    try:
        for k in range(TICKS):
            if k % PERIOD == 0:  # a new mask, and the reduced model where it locks the joints
                count = int(rng.integers(1, robot.nv - 1))
                masked = tuple(rng.choice(robot.joint_names, count, replace=False).tolist())
                small, small_cm = _reduced(robot, masked, q, collision)
                pairs = [] if cm is None else sorted(set(cm.pairs) & set(small_cm.pairs))
                if resolver is None or collision:  # the pairs both models keep: a new limit
                    resolver = Resolver(robot, DT, limits=_limits(cm, pairs), qp=UNHURRIED)
                    resolver.mask(masked)
                else:
                    resolver.unmask()
                    resolver.mask(masked)
                assert set(resolver.masked) == set(masked)
                reduced = Resolver(small, DT, limits=_limits(small_cm, pairs), qp=UNHURRIED)
                # the one difference the mask keeps on purpose: the task rows' units (a frame's
                # reach) stay the full robot's; the reduced model's chains are shorter
                reduced._layout = reduced.layout._replace(reach=resolver.layout.reach)
                free = np.array([i for i, j in enumerate(robot.joint_names) if j not in masked])
            twists = [rng.normal(0.0, [0.1, 0.1, 0.1, 0.3, 0.3, 0.3]) for _ in robot.tool_frames]
            tasks = _tasks(robot, twists, q_ref, strict)
            priority = "strict" if strict else "weighted"
            assert reduced is not None
            resolver.reset()  # cold backends: each answer a function of its problem alone
            reduced.reset()
            r = resolver.solve(q, tasks, priority=priority, qdot_prev=qdot)
            expected = reduced.solve(q[free], _tasks(small, twists, q_ref[free], strict),
                                     priority=priority, qdot_prev=qdot[free])  # fmt: skip
            held = np.setdiff1d(np.arange(robot.nv), free)
            assert (r.qdot[held] == 0.0).all()
            assert r.masked == resolver.masked
            data_gap, witness_gap = _gap(r.problem, expected.problem, free)
            assert data_gap <= DATA_TOL
            if witness_gap > DATA_TOL:
                spread = _witness_spread(resolver, q, tasks, priority, qdot, r.problem)
                assert witness_gap <= 3.0 * spread, (witness_gap, spread)
            _unpaired_rows_are_slack(r, expected, free)
            gap = np.abs(r.qdot[free] - expected.qdot).max()
            assert gap > TOL or r.status == expected.status, (r, expected)
            if gap > TOL:  # the pipeline's answer to the masked numbers, DATA_TOL apart
                mine = _answer(_numbers_of(r.problem, expected.problem, free))
                assert np.abs(mine - r.qdot[free]).max() <= SAME, (gap, r, expected)
                theirs = _answer(expected.problem)
                assert np.abs(theirs - expected.qdot).max() <= SAME, (gap, r, expected)
                jumps += 1
            qdot = r.qdot
            q = robot.integrate(q, qdot, DT)
    except AssertionError as exc:
        raise AssertionError(f"{name} tick {k}: seed {seed}: {exc}") from exc
    print(f"{name}: {jumps} of {TICKS} ticks beyond {TOL} (seed {seed})")


def _gap(masked: Problem, reduced: Problem, free: npt.NDArray[np.intp]) -> tuple[float, float]:
    """The largest difference between the masked resolver's problem on the joints ``free``
    and the reduced model's: in task rows, rates, constraint bounds and box; and in the
    constraint rows G (collision rows: coal's witness points, see :func:`_witness_spread`)."""
    gaps = [0.0]
    witness = 0.0
    for (A, b), (A_r, b_r) in zip(masked.stacked, reduced.stacked, strict=True):
        assert not A[:, np.setdiff1d(np.arange(A.shape[1]), free)].any()
        gaps += [np.abs(A[:, free] - A_r).max(initial=0.0), np.abs(b - b_r).max(initial=0.0)]
    assert (masked.rows is None) == (reduced.rows is None)
    if masked.rows is not None and reduced.rows is not None:
        mine, theirs, _, _ = _paired(masked, reduced, free)
        witness = np.abs(masked.rows.G[mine][:, free] - reduced.rows.G[theirs]).max(initial=0.0)
        gaps.append(np.abs(masked.rows.h[mine] - reduced.rows.h[theirs]).max(initial=0.0))
    gaps += [np.abs(masked.box.lb[free] - reduced.box.lb).max(),
             np.abs(masked.box.ub[free] - reduced.box.ub).max()]  # fmt: skip
    assert (masked.equalities is None) == (reduced.equalities is None)
    if masked.equalities is not None and reduced.equalities is not None:
        gaps += [np.abs(masked.equalities[0][:, free] - reduced.equalities[0]).max(),
                 np.abs(masked.equalities[1] - reduced.equalities[1]).max()]  # fmt: skip
    assert masked.mode == reduced.mode and masked.factors == pytest.approx(reduced.factors)
    return float(max(gaps)), float(witness)


def _witness_spread(resolver: Resolver, q: npt.NDArray[np.float64], tasks: list[object],
                    priority: str, qdot_prev: npt.NDArray[np.float64],
                    problem: Problem) -> float:  # fmt: skip
    """How far the masked resolver's own constraint rows G move when ``q`` moves by 1e-15
    rad (8 draws): between near-parallel features coal's witness points move 1e4 times as
    far (panda_link2|panda_hand: 1e-11 m), so the two models' roundoff moves these rows by
    more than DATA_TOL."""
    assert problem.rows is not None
    rng = np.random.default_rng(0)
    spread = 0.0
    for _ in range(8):
        resolver.reset()
        nearby = resolver.robot.integrate(q, rng.normal(0.0, 1e-15, qdot_prev.size), 1.0)
        moved = resolver.solve(nearby, tasks, priority=priority, qdot_prev=qdot_prev).problem
        if moved.rows is not None and moved.rows.names == problem.rows.names:
            spread = max(spread, float(np.abs(moved.rows.G - problem.rows.G).max()))
    return spread


def _unpaired_rows_are_slack(masked: Resolution, reduced: Resolution,
                             free: npt.NDArray[np.intp]) -> None:  # fmt: skip
    """A row in one problem only holds with room at that problem's answer (SLACK), so that
    it leaves the answer as it is."""
    if masked.problem.rows is None or reduced.problem.rows is None:
        return
    _, _, mine, theirs = _paired(masked.problem, reduced.problem, free)
    for rows, picked, qdot in ((masked.problem.rows, mine, masked.qdot),
                               (reduced.problem.rows, theirs, reduced.qdot)):  # fmt: skip
        room = rows.h[picked] - rows.G[picked] @ qdot
        assert (room > SLACK).all(), ([rows.names[i] for i in picked], room)


def _paired(masked: Problem, reduced: Problem, free: npt.NDArray[np.intp]) -> Pairing:
    """The two problems' constraint rows paired by name, nearest in (G, h) first (each
    collision model numbers its pairs in its own order: the reduced geometry model's objects
    are ordered anew). Returns the paired rows of ``masked`` and of ``reduced``, then the rows
    of each left unpaired: a box's feature row chosen at a near tie of two features'
    distances, present in one problem only."""
    assert masked.rows is not None and reduced.rows is not None
    G, h, G_r, h_r = masked.rows.G[:, free], masked.rows.h, reduced.rows.G, reduced.rows.h
    near = sorted((np.abs(G[i] - G_r[j]).max() + abs(h[i] - h_r[j]), i, j)
                  for i, name in enumerate(masked.rows.names)
                  for j, other in enumerate(reduced.rows.names) if name == other)  # fmt: skip
    mine: list[int] = []
    theirs: list[int] = []
    for _, i, j in near:
        if i not in mine and j not in theirs:
            mine.append(i)
            theirs.append(j)
    alone = [i for i in range(h.size) if i not in mine]
    return mine, theirs, alone, [j for j in range(h_r.size) if j not in theirs]


def _numbers_of(masked: Problem, reduced: Problem, free: npt.NDArray[np.intp]) -> Problem:
    """The reduced model's problem with the masked problem's numbers (rows and bounds)."""
    rows = None
    if reduced.rows is not None and masked.rows is not None:
        mine, theirs, _, _ = _paired(masked, reduced, free)
        names = tuple(reduced.rows.names[j] for j in theirs)
        rows = reduced.rows._replace(G=np.ascontiguousarray(masked.rows.G[mine][:, free]),
                                     h=masked.rows.h[mine], names=names)  # fmt: skip
    return reduced._replace(
        stacked=tuple((np.ascontiguousarray(A[:, free]), b) for A, b in masked.stacked),
        rows=rows)  # fmt: skip


def _answer(problem: Problem) -> npt.NDArray[np.float64]:
    """The pipeline's rates for ``problem`` (a fresh backend, the resolver's options)."""
    backend = make_backend("daqp", UNHURRIED.time_limit)
    answer: npt.NDArray[np.float64] = solve(problem, backend, Options()).qdot
    return answer
