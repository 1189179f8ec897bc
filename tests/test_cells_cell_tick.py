"""CellTick: a cell's usual tick with its rows in one compiled call answers as the tasks' and
limits' own path does, bit for bit, over sessions that scale, damp, swing and land a leg, with
a collision limit (its rows loaded, slid along or not; the tick handed back where a pair is
asked apart), a singularity limit's rows, the closure off, a posture changed in place, and
ticks whose top level finds no answer (the fallbacks); a posture of the wrong size is
refused."""

from __future__ import annotations

import numpy as np
import pytest

import rrc_pin
from rrc_pin import CollisionLimit, CollisionModel, JointLimits, PostureTask, QPOptions
from rrc_pin.cells import cell_tick
from rrc_pin.cells.controller import CellController
from rrc_pin.compiled_tick import CompiledTick
from rrc_pin.errors import InvalidInput
from rrc_pin.limits import SingularityLimit
from rrc_pin.solvers.tick.top import FAILED

SEEDS = (0, int(np.random.SeedSequence().entropy % 2**63))
"""A fixed seed and one drawn fresh each run (named in every failure's message)."""
SIZES = (1.0, 1.0, 1e-3, 10.0, 300.0)
"""Factors on a segment's command: slow, too fast for the joints, far too fast."""
SPEED = {"object": np.array([0.15, 0.15, 0.15, 0.4, 0.4, 0.4]),
         "body": np.array([0.03, 0.03, 0.03, 0.1, 0.1, 0.1]),
         "leg1": np.array([0.05, 0.05, 0.05, 0.0, 0.0, 0.0])}  # fmt: skip
BALLS = {"gsfc_dual": ("object", [0.0, 0.0, -0.25], 0.08),
         "yeh_tripod": ("body", [0.0, 0.0, -0.6], 0.1)}  # fmt: skip
"""Cell: a ball in the commands' way (benchmarks/bench_cells.py's): the frame its centre is
placed from at the ready pose, the offset [m] and its radius [m]."""


def _limits(cell, collision):
    """The controller's limits: the joint limits, with a collision limit on the cell's capsules
    (and a ball in the way) where ``collision``, or a singularity limit on the first tool
    frame whose rows are always there (``"singular"``)."""
    if not collision:
        return None
    if collision == "singular":
        return [JointLimits(), SingularityLimit(cell.tool_frames[0], 0.02, detection=5.0)]
    model = CollisionModel(cell, "capsules")
    if collision == "ball":
        frame, offset, radius = BALLS[cell.name]
        model.add_sphere(cell.fk(cell.ready(), frame)[:3, 3] + offset, radius, "ball")
    return [JointLimits(), CollisionLimit(model)]


class Session:
    """One controller's session, ``compiled`` or the tasks' and limits' path alone: each tick's
    state and report; the ticks whose rows the compiled call wrote (:attr:`compiled`), the
    other limits' reads (:attr:`reads`). Every ``refuse``-th tick's top level finds no answer
    (0: none), on either path. The tripod swings leg 1 a third of the way in and lands it at
    two thirds; ``moved`` moves the posture's reference in place halfway."""

    def __init__(self, cell, seed, compiled, monkeypatch, ticks=120, refuse=0, collision=None,
                 closure=True, moved=False):  # fmt: skip
        robot = rrc_pin.load(cell)
        # the backend's time cap far off: a QP the machine stalls past the default 50 ms would
        # be refused on one path only (the sliding ticks' QPs), which is not what is compared
        self.ctl = ctl = CellController(robot, 0.01, limits=_limits(robot, collision),
                                        qp=QPOptions(time_limit=60.0),
                                        **({} if closure else {"closure": None}))  # fmt: skip
        ctl._compiles = compiled
        self.compiled, self.reads, self.ticks = 0, 0, []
        rows, run_loaded = cell_tick.cell_rows, CompiledTick.run_loaded
        runs = []

        def written(*args):
            self.compiled += 1
            return rows(*args)

        self.written = []  # whether each tick's rows were the compiled call's

        def run(compiled_tick, q, previous, dt):
            runs.append(1)
            code = run_loaded(compiled_tick, q, previous, dt)
            return FAILED if refuse and len(runs) % refuse == 0 else code

        monkeypatch.setattr(cell_tick, "cell_rows", written)
        monkeypatch.setattr(CompiledTick, "run_loaded", run)
        for limit in ctl.resolver.limits[1:-2]:
            constraints = limit.constraints

            def read(kin, dt, previous, constraints=constraints):
                self.reads += 1
                return constraints(kin, dt, previous)

            monkeypatch.setattr(limit, "constraints", read)
        rng = np.random.default_rng(seed)
        names = list(ctl.commandable())
        for k in range(ticks):
            if cell == "yeh_tripod" and k == ticks // 3:
                ctl.swing("leg1")
                names = ["body", "leg1"]
            if cell == "yeh_tripod" and k == 2 * ticks // 3:
                ctl.land("leg1")
                names = ["body"]
            if moved and k == ticks // 2:
                ctl.posture.q_ref += 0.3
            if k % 20 == 0:
                commands = {n: rng.normal(size=6) * SPEED[n] * rng.choice(SIZES) for n in names
                            if n in SPEED}  # fmt: skip
            before = self.compiled
            r = ctl.step(commands if k % 7 else None).resolution
            self.written.append(self.compiled > before)
            self.ticks.append((
                ctl.q, r.qdot, r.applied, r.status, r.scale, r.veer, r.lambda_sq, r.levels,
                r.attempts, [t.achieved for t in r.tasks], r.active, ctl.chain_error,
                None if ctl.grip.last is None else ctl.grip.last.error,
                None if ctl.contact.last is None else ctl.contact.last.error,
            ))  # fmt: skip
        monkeypatch.undo()


def _same(a, b, seed):
    for k, (x, y) in enumerate(zip(a.ticks, b.ticks, strict=True)):
        for i, (u, v) in enumerate(zip(x, y, strict=True)):
            where = f"seed {seed}, tick {k}, field {i}"
            if isinstance(u, list):  # each task's achieved rates
                assert len(u) == len(v), where
                for p, r in zip(u, v, strict=True):
                    np.testing.assert_array_equal(p, r, err_msg=where)
            elif isinstance(u, np.ndarray):
                np.testing.assert_array_equal(u, v, err_msg=where)
            else:
                assert u == v, f"{where}: {u} != {v}"


@pytest.mark.parametrize("cell", ["gsfc_dual", "yeh_tripod"])
@pytest.mark.parametrize("seed", SEEDS, ids=["fixed", "fresh"])
def test_the_compiled_rows_answer_as_the_tasks_and_limits_do(cell, seed, monkeypatch):
    """The same configurations, rates, statuses, reports and chain errors on every tick, the
    compiled rows written on every tick (the tripod's swinging leg a second frame task), some
    ticks scaled and damped."""
    compiled = Session(cell, seed, True, monkeypatch, ticks=240)
    plain = Session(cell, seed, False, monkeypatch, ticks=240)
    _same(compiled, plain, seed)
    assert plain.compiled == 0 and compiled.compiled == len(compiled.ticks), compiled.compiled
    statuses = {x[3] for x in compiled.ticks}
    assert "exact" in statuses and statuses & {"scaled", "damped"}, f"seed {seed}: {statuses}"


@pytest.mark.parametrize("cell", ["gsfc_dual", "yeh_tripod"])
@pytest.mark.parametrize("collision", ["capsules", "ball"])
def test_with_a_collision_limit_its_rows_are_loaded_beside_the_chains(
    cell, collision, monkeypatch
):
    """A collision limit beside the chains, read once a tick either way: its rows are loaded
    beside the chains' rows, the ticks that slide along them compiled too (the ball in the
    way), and a tick with a pair asked apart goes back to the resolver with its rows; the same
    session, bit for bit."""
    ticks = 240 if collision == "ball" else 120  # the ball met: sliding ticks
    compiled = Session(cell, SEEDS[0], True, monkeypatch, ticks=ticks, collision=collision)
    plain = Session(cell, SEEDS[0], False, monkeypatch, ticks=ticks, collision=collision)
    _same(compiled, plain, SEEDS[0])
    assert compiled.reads == plain.reads == ticks
    assert compiled.compiled > ticks // 2, compiled.compiled
    if collision == "ball":
        slid = [w for w, x in zip(compiled.written, compiled.ticks, strict=True)
                if x[3] == "sliding"]  # fmt: skip
        assert slid and all(slid), (len(slid), sum(slid))


@pytest.mark.parametrize("cell", ["gsfc_dual", "yeh_tripod"])
def test_a_limits_rows_no_command_slides_along_are_loaded_beside_the_chains(cell, monkeypatch):
    """A singularity limit's rows on every tick: loaded into the compiled tick with the chains'
    rows, the same session bit for bit."""
    compiled = Session(cell, SEEDS[0], True, monkeypatch, collision="singular")
    plain = Session(cell, SEEDS[0], False, monkeypatch, collision="singular")
    _same(compiled, plain, SEEDS[0])
    assert compiled.compiled == len(compiled.ticks)
    kin = compiled.ctl._kinematics()
    limit = compiled.ctl.resolver.limits[1]
    assert limit.constraints(kin, 0.01, np.zeros(kin.layout.nv)).h.size > 0


@pytest.mark.parametrize("cell", ["gsfc_dual", "yeh_tripod"])
def test_without_the_closure_the_compiled_rows_answer_as_the_tasks_and_limits_do(
    cell, monkeypatch
):
    """``closure=None``: no correction made with the rows, the same session bit for bit."""
    compiled = Session(cell, SEEDS[0], True, monkeypatch, closure=False)
    plain = Session(cell, SEEDS[0], False, monkeypatch, closure=False)
    _same(compiled, plain, SEEDS[0])
    assert compiled.compiled == len(compiled.ticks)


def test_a_posture_moved_in_place_is_read_at_every_tick(monkeypatch):
    """``ctl.posture.q_ref`` changed in place halfway: the compiled rows read the new
    reference at once, as the posture's own rows do (and the session moves otherwise)."""
    compiled = Session("gsfc_dual", SEEDS[0], True, monkeypatch, moved=True)
    plain = Session("gsfc_dual", SEEDS[0], False, monkeypatch, moved=True)
    still = Session("gsfc_dual", SEEDS[0], True, monkeypatch)
    _same(compiled, plain, SEEDS[0])
    assert not np.array_equal(compiled.ticks[-1][0], still.ticks[-1][0])


@pytest.mark.parametrize("cell", ["gsfc_dual", "yeh_tripod"])
@pytest.mark.parametrize("collision", [None, "capsules"])
def test_a_tick_whose_top_level_finds_no_answer_is_the_fallbacks_once(
    cell, collision, monkeypatch
):
    """Every fifth tick's top level refused on both paths: the fallbacks answer it from the
    compiled rows, the other limits read once; the session the same, bit for bit."""
    refused = Session(cell, SEEDS[0], True, monkeypatch, ticks=60, refuse=5, collision=collision)
    plain = Session(cell, SEEDS[0], False, monkeypatch, ticks=60, refuse=5, collision=collision)
    _same(refused, plain, SEEDS[0])
    assert refused.compiled == 60 and "fallback" in {x[3] for x in refused.ticks}
    assert refused.reads == plain.reads == (60 if collision else 0)


def test_a_posture_of_another_size_is_refused_naming_q_ref(dual):
    """A posture whose reference is not one position per joint: refused before any motion,
    as the resolver's path refuses it."""
    ctl = CellController(dual, 0.01)
    ctl.step({"object": SPEED["object"]})
    q = ctl.q.copy()
    ctl.posture = PostureTask(np.zeros(dual.nv - 2), gain=0.1, weight=1e-3)
    with pytest.raises(InvalidInput, match="q_ref"):
        ctl.step({"object": SPEED["object"]})
    np.testing.assert_array_equal(ctl.q, q)


def test_hands_resolved_each_on_their_own_take_the_resolver(dual):
    """``coupled=False``: the hands' tasks are weighted, not the compiled rows' levels."""
    ctl = CellController(dual, 0.01, coupled=False)
    ctl.step({"object": SPEED["object"]})
    assert ctl._cell_tick[1] is None
