"""The compiled tick within equality rows answers as the Python pipeline does."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
import pytest

import rrc_pin
from rrc_pin.cells import Cell, CellController
from rrc_pin.compiled_tick import TickSource
from rrc_pin.kinematics import Kinematics
from rrc_pin.limits import JointLimits, Limit
from rrc_pin.solvers.tick.equalities import CONTRADICTED, space
from rrc_pin.solvers.tick.pipeline import _equality_space, solve
from rrc_pin.solvers.tick.problem import Constraints
from rrc_pin.solvers.tick.resolution import Resolution

Array = npt.NDArray[np.float64]

KERNELS = 1e-10
"""[rad/s] Rates of a tick the kernels answered: the same kernels, the products with the null
basis in other loops (within 3e-13 in the direction mode; the least squares' projection onto a
saturated box carried them to 7e-12 on panda at 2.6 rad/s)."""
BACKEND = 1e-8
"""Rates of a tick the QP backend answered: DAQP's answer moves with the last bits of its
data (tests/test_tick_answers.py)."""
SLID = 1e-8
"""[rad/s] Rates of a sliding tick: its answer lies on the row it slides along, over it by up
to 1e-12 of rounding on either path, and the tick's last step shrinks the rates into the rows
by that over the row's bound (the panda's wall at 0.01-0.05 here: up to 3e-10)."""


class Equalities(Limit):
    """Equality rows ``C qdot = d`` set by the test."""

    name = "equal"

    def __init__(self, C: Array, d: Array) -> None:
        self.C, self.d = C, d

    def constraints(self, kin: Kinematics, dt: float, previous: Array) -> Constraints:
        names = tuple(f"equal:{i}" for i in range(self.d.size))
        return Constraints(C=self.C, d=self.d, names=names)


def agrees(r: Resolution, resolver: rrc_pin.Resolver) -> None:
    """``r`` (the compiled tick's) is the pipeline's answer to its problem."""
    assert isinstance(r.source, TickSource) or r.status == "fallback"
    answer = solve(r.problem, resolver.backend, resolver.options)
    tol = BACKEND if (r.backend or answer.backend) else SLID if r.status == "sliding" else KERNELS
    np.testing.assert_allclose(r.qdot, answer.qdot, rtol=0.0, atol=tol)
    assert r.status == answer.status and r.levels == answer.levels
    assert r.scale == pytest.approx(answer.scale, abs=max(tol, 1e-9))
    assert r.attempts == answer.attempts


LOWER = 1e-3
"""[rad/s] Rates of a tick whose lower level's QP went to the backend, beside a collision limit
whose rows the tick's answer lies on: DAQP's answer to that QP moves with the null basis's last
bits (up to 2.3e-5 on gsfc_dual here, either path against itself 1e-12; 2.4e-4 before the rows
the subspace cannot move at all were dropped, ``feasibility.release_unmoved``). The top level's
rates agree as ever."""


def agrees_above(r: Resolution, resolver: rrc_pin.Resolver) -> None:
    """:func:`agrees`, but where the backend answered a QP: the top level's rows' rates, the
    statuses, levels and scales as :func:`agrees` has them, the rates within :data:`LOWER`."""
    if not r.backend:
        agrees(r, resolver)
        return
    answer = solve(r.problem, resolver.backend, resolver.options)
    A = r.problem.stacked[0][0]
    np.testing.assert_allclose(A @ r.qdot, A @ answer.qdot, rtol=0.0, atol=BACKEND)
    np.testing.assert_allclose(r.qdot, answer.qdot, rtol=0.0, atol=LOWER)
    assert r.status == answer.status and r.levels == answer.levels
    assert r.scale == pytest.approx(answer.scale, abs=1e-8)
    assert r.attempts == answer.attempts


def test_space_is_the_pipelines(rng: np.random.Generator) -> None:
    """x0 and the null basis, full rank and rank deficient."""
    from rrc_pin.solvers.tick.problem import Box, build

    for rank in (3, 2):
        C = rng.normal(size=(3, 7))
        if rank == 2:
            C[2] = C[0] + C[1]
        d = C @ rng.normal(size=7)
        x0, N, met = space(C, d)
        free = np.full(7, np.inf)
        box = Box(-free, free, np.zeros((2, 7), np.int8), True, False, free)
        expected = _equality_space(build([], [Constraints(box), Constraints(C=C, d=d)], 7, 0.01))
        assert met
        np.testing.assert_allclose(x0, expected.x, atol=1e-13)
        np.testing.assert_allclose(N, expected.N, atol=1e-13)


@pytest.mark.parametrize(("r", "n"), [(6, 14), (18, 24), (3, 3), (1, 7)])
def test_space_against_numpy(r: int, n: int, rng: np.random.Generator) -> None:
    """x0 the pseudo-inverse's rates (zero for d = 0), N orthonormal rows spanning C's null
    space (its projector numpy's), met; full rank and rank deficient."""
    for rank in {r, r - 1}:
        for zero in (True, False):
            C = rng.normal(size=(r, n))
            if rank < r:
                C[-1] = C[0] - 2.0 * C[-2 % r]
            d = np.zeros(r) if zero else C @ rng.normal(size=n)
            x0, N, met = space(C, d)
            assert met
            np.testing.assert_allclose(x0, np.linalg.pinv(C) @ d, rtol=0, atol=1e-12)
            if zero:
                np.testing.assert_array_equal(x0, 0.0)
            free = n - np.linalg.matrix_rank(C)
            assert N.shape == (free, n)
            np.testing.assert_allclose(N @ N.T, np.eye(free), atol=1e-13)
            projector = np.eye(n) - np.linalg.pinv(C) @ C
            np.testing.assert_allclose(N.T @ N, projector, atol=1e-12)


@pytest.mark.parametrize("rates", ["zero", "kept"])
def test_ticks_within_equality_rows_are_the_pipelines(rng: np.random.Generator,
                                                      rates: str) -> None:  # fmt: skip
    """A hand's twist and a posture below, within two equality rows (d zero: the direction
    mode; d kept: the least squares), from fast to slow commands and from a start outside
    the joint limits."""
    panda = rrc_pin.load("panda")
    C = rng.normal(size=(2, panda.nv))
    d = np.zeros(2) if rates == "zero" else 0.05 * rng.normal(size=2)
    resolver = rrc_pin.Resolver(panda, dt=0.01, limits=[JointLimits(), Equalities(C, d)])
    posture = rrc_pin.PostureTask(panda.neutral(), gain=1.0)
    seen = set()
    for k in range(60):
        q = panda.random_q(rng) if k % 10 else panda.upper + 0.05
        twist = rng.normal(size=6) * 10.0 ** rng.uniform(-3, 1)
        hand = rrc_pin.FrameTask(panda.tool_frame, twist)
        r = resolver.solve(q, [[hand], [posture]], priority="strict")
        agrees(r, resolver)
        if r.status != "fallback":
            np.testing.assert_allclose(C @ r.qdot, d, atol=1e-9)
        seen.add(r.status)
    assert len(seen) >= 2


def test_weighted_ticks_within_equality_rows_are_the_pipelines(rng: np.random.Generator) -> None:
    panda = rrc_pin.load("panda")
    C = rng.normal(size=(2, panda.nv))
    resolver = rrc_pin.Resolver(panda, dt=0.01,
                                limits=[JointLimits(), Equalities(C, 0.05 * rng.normal(size=2))])
    posture = rrc_pin.PostureTask(panda.neutral(), gain=1.0, weight=1e-2)
    for _ in range(40):
        twist = rng.normal(size=6) * 10.0 ** rng.uniform(-3, 1)
        r = resolver.solve(panda.random_q(rng), [rrc_pin.FrameTask(panda.tool_frame, twist),
                                                 posture])  # fmt: skip
        agrees(r, resolver)


class Apart(Equalities):
    """Equality rows and one row ``g qdot <= h`` (not one to slide along) that the test sets,
    h < 0: standing still breaks it."""

    def __init__(self, C: Array, d: Array, g: Array, h: float) -> None:
        super().__init__(C, d)
        self.g, self.h = g, np.array([h])

    def constraints(self, kin: Kinematics, dt: float, previous: Array) -> Constraints:
        names = ("apart", *(f"equal:{i}" for i in range(self.d.size)))
        return Constraints(G=self.g[None, :], h=self.h, C=self.C, d=self.d, names=names)


def test_a_row_broken_at_the_start_within_equality_rows_is_restored(
    rng: np.random.Generator,
) -> None:
    """h < 0 with equality rows, compiled: restored as the pipeline restores it, never held
    still (the level's rows once kept the start, zero rates, feasible, and its answer was
    refused)."""
    panda = rrc_pin.load("panda")
    posture = rrc_pin.PostureTask(panda.neutral(), gain=1.0)
    for _ in range(20):
        C, g = rng.normal(size=(2, panda.nv)), rng.normal(size=panda.nv)
        resolver = rrc_pin.Resolver(panda, dt=0.01,
                                    limits=[JointLimits(), Apart(C, np.zeros(2), g, -1e-3)])
        hand = rrc_pin.FrameTask(panda.tool_frame, rng.normal(size=6) * 0.1)
        r = resolver.solve(panda.random_q(rng), [[hand], [posture]], priority="strict")
        assert isinstance(r.source, TickSource)
        assert r.status == "recovering", r.attempts
        assert float(g @ r.qdot) <= -1e-3 + 1e-9
        np.testing.assert_allclose(C @ r.qdot, 0.0, atol=1e-9)
        agrees(r, resolver)


class Wall(Equalities):
    """Equality rows and one row ``g qdot <= h`` the command slides along (a collision pair's),
    set by the test."""

    def __init__(self, C: Array, d: Array, g: Array, h: float) -> None:
        super().__init__(C, d)
        self.g, self.h = g, np.array([h])

    def constraints(self, kin: Kinematics, dt: float, previous: Array) -> Constraints:
        names = ("wall", *(f"equal:{i}" for i in range(self.d.size)))
        return Constraints(G=self.g[None, :], h=self.h, C=self.C, d=self.d, names=names,
                           slide=np.array([True]))  # fmt: skip


@pytest.mark.parametrize("kind", ["slide", "slide and row"])
def test_ticks_that_slide_within_equality_rows_are_the_pipelines(rng: np.random.Generator,
                                                                 kind: str) -> None:  # fmt: skip
    """A row the hand's command runs into and slides along, within two equality rows: the
    compiled sliding stage answers as the pipeline's, from slow commands to far too fast ones
    (the slide's own least squares, the command met along the row, scaled); beside a second
    row not slid along, whose crossing sends the slid command on to the stages after it."""
    panda = rrc_pin.load("panda")
    posture = rrc_pin.PostureTask(panda.neutral(), gain=1.0)
    seen: set[str] = set()
    for k in range(80):
        C = rng.normal(size=(2, panda.nv))
        q = panda.random_q(rng)
        twist = rng.normal(size=6) * 10.0 ** rng.uniform(-2, 1)
        hand = rrc_pin.FrameTask(panda.tool_frame, twist)
        J = hand.rows(Kinematics(panda.model, panda.model.createData(), rrc_pin.Resolver(
            panda).layout, q, q)).A  # fmt: skip
        g = J.T @ twist  # the command runs into the wall: g qdot > 0 along it
        # the wall's bound [rad/s] well above the projection's margin: a sliding answer on the
        # wall by its rounding (1e-12) is shrunk into it by that over the bound, on each path
        limits: list[Limit] = [JointLimits(), Wall(C, np.zeros(2), g / np.linalg.norm(g),
                                                   0.01 + 0.04 * rng.random())]  # fmt: skip
        if kind == "slide and row":
            limits.append(Apart(np.zeros((0, panda.nv)), np.zeros(0), rng.normal(size=panda.nv),
                                1e-3))  # fmt: skip
        resolver = rrc_pin.Resolver(panda, dt=0.01, limits=limits)
        r = resolver.solve(q, [[hand], [posture]], priority="strict")
        assert isinstance(r.source, TickSource), k
        agrees(r, resolver)
        if r.status != "fallback":
            np.testing.assert_allclose(C @ r.qdot, 0.0, atol=1e-9)
        seen.add(r.status)
    assert "sliding" in seen, seen


def test_a_pair_asked_apart_within_equality_rows_is_the_pipelines(
    rng: np.random.Generator,
) -> None:
    """A slide row below zero beside equality rows: the pipeline answers (it relaxes the row
    where the least squares fails; the compiled tick does not)."""
    panda = rrc_pin.load("panda")
    C, g = rng.normal(size=(2, panda.nv)), rng.normal(size=panda.nv)
    resolver = rrc_pin.Resolver(panda, dt=0.01,
                                limits=[JointLimits(), Wall(C, np.zeros(2), g, -1e-3)])
    hand = rrc_pin.FrameTask(panda.tool_frame, rng.normal(size=6) * 0.1)
    r = resolver.solve(panda.neutral(), [[hand]], priority="strict")
    assert not isinstance(r.source, TickSource)
    assert r.status == "recovering" and float(g @ r.qdot) <= -1e-3 + 1e-9


def test_contradicting_rows_fall_back_as_the_pipeline() -> None:
    panda = rrc_pin.load("panda")
    C = np.vstack([np.eye(1, panda.nv), np.eye(1, panda.nv)])
    resolver = rrc_pin.Resolver(panda, dt=0.01,
                                limits=[JointLimits(), Equalities(C, np.array([0.1, -0.1]))])
    r = resolver.solve(panda.neutral(), rrc_pin.FrameTask(panda.tool_frame, np.full(6, 0.01)))
    assert r.status == "fallback" and ("qp", CONTRADICTED) in r.attempts
    agrees(r, resolver)


def test_rows_the_compiled_tick_leaves_to_the_pipeline() -> None:
    """As many equality rows as rates: the pipeline answers."""
    panda = rrc_pin.load("panda")
    limit = Equalities(np.eye(panda.nv), np.zeros(panda.nv))
    resolver = rrc_pin.Resolver(panda, dt=0.01, limits=[JointLimits(), limit])
    r = resolver.solve(panda.neutral(), rrc_pin.FrameTask(panda.tool_frame, np.full(6, 0.01)))
    assert not isinstance(r.source, TickSource)
    np.testing.assert_allclose(r.qdot, 0.0, atol=1e-12)


BALLS = {"gsfc_dual": ("object", [0.0, 0.0, -0.25], 0.08),
         "yeh_tripod": ("body", [0.0, 0.0, -0.6], 0.1)}  # fmt: skip
"""Cell: a ball in the commands' way (benchmarks/bench_cells.py's): the frame its centre is
placed from at the ready pose, the offset [m] and its radius [m]."""


@pytest.mark.parametrize("which", ["dual", "tripod"])
def test_cell_ticks_along_a_collision_limit_are_the_pipelines(
    which: str, request: pytest.FixtureRequest
) -> None:
    """A ball in the way beside a grip or feet in support: the ticks with the collision
    limit's rows are compiled, those that slide along them among them (the held object driven
    into the ball), and each is the pipeline's answer to its problem (the tripod's body on the
    benchmark's random commands, its legs near the ball)."""
    cell: Cell = request.getfixturevalue(which)
    frame, offset, radius = BALLS[cell.name]
    model = rrc_pin.CollisionModel(cell, "capsules")
    model.add_sphere(cell.fk(cell.ready(), frame)[:3, 3] + offset, radius, "ball")
    ctl = CellController(cell, 0.01, limits=[JointLimits(), rrc_pin.CollisionLimit(model)],
                         qp=rrc_pin.QPOptions(time_limit=60.0))  # fmt: skip
    name = ctl.commandable()[0]
    rng = np.random.default_rng(11 if which == "dual" else 2030)
    toward = np.concatenate([np.array(offset) / np.linalg.norm(offset), np.zeros(3)])
    speed = np.array([0.03, 0.03, 0.03, 0.1, 0.1, 0.1])  # the benchmark's body commands
    statuses, rows = [], 0
    hold = 20 if which == "dual" else 50  # ticks a command is held (the benchmark's: 50)
    for k in range(200):
        if k % hold == 0:
            twist = (toward * 0.2 + rng.normal(size=6) * 0.02 if which == "dual"
                     else rng.normal(size=6) * speed)  # fmt: skip
        r = ctl.step({name: twist}).resolution
        if r.status in ("grip_lost", "contact_lost") or r.problem.rows is None:
            continue
        rows += 1
        statuses.append(r.status)
        assert isinstance(r.source, TickSource) or r.status in ("recovering", "fallback")
        agrees_above(r, ctl.resolver)
    assert rows > 20, rows
    assert which == "tripod" or "sliding" in statuses, set(statuses)


@pytest.mark.parametrize("which", ["dual", "tripod"])
def test_cell_ticks_are_the_pipelines(which: str, request: pytest.FixtureRequest) -> None:
    """A held object's grip and feet in support: the compiled tick's answers, command after
    command (slow to beyond reach), are the pipeline's; the report reads the top level alike."""
    cell: Cell = request.getfixturevalue(which)
    ctl = CellController(cell, 0.01)
    name = ctl.commandable()[0]
    rng = np.random.default_rng(7)
    statuses = set()
    for k in range(120):
        twist = rng.normal(size=6) * (0.02 if k < 60 else 0.5)
        r = ctl.step({name: twist}).resolution
        if r.status in ("grip_lost", "contact_lost"):
            continue
        statuses.add(r.status)
        assert isinstance(r.source, TickSource)
        level, stacked, rows = r.source.top()
        assert level == r.problem.levels[0] and rows is r.problem.rows is None
        np.testing.assert_array_equal(stacked, r.problem.stacked[0][0])
        agrees(r, ctl.resolver)
    assert "exact" in statuses and len(statuses) >= 2
