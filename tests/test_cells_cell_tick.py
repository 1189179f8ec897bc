"""CellTick: a cell's usual tick with its rows in one compiled call answers as the tasks' and
limits' own path does, bit for bit, over sessions that scale, damp, swing and land a leg, with
a collision limit (its rows loaded, or the tick handed back where one is slid along), and
where the compiled tick finds no answer."""

from __future__ import annotations

import numpy as np
import pytest

import rrc_pin
from rrc_pin import CollisionLimit, CollisionModel, JointLimits
from rrc_pin.cells.cell_tick import CellTick
from rrc_pin.cells.controller import CellController
from rrc_pin.compiled_tick import CompiledTick
from rrc_pin.limits import SingularityLimit
from rrc_pin.solvers.tick.tick import CONSTRAINTS
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


def _session(cell, seed, compiled, monkeypatch, ticks=240, refuse=0, collision=None,
             closure=True):  # fmt: skip
    """Each tick's state and report, ``compiled`` or the tasks' and limits' path alone; every
    ``refuse``-th compiled tick finds no answer (0: none). The tripod swings leg 1 a third of
    the way in and lands it at two thirds."""
    robot = rrc_pin.load(cell)
    ctl = CellController(robot, 0.01, limits=_limits(robot, collision),
                         **({} if closure else {"closure": None}))  # fmt: skip
    ctl._compiles = compiled
    calls = []
    run_loaded = CompiledTick.run_loaded

    def counted(self, q, previous, dt):
        calls.append(self.workspace.ints[CONSTRAINTS])
        if refuse and len(calls) % refuse == 0:
            return FAILED
        return run_loaded(self, q, previous, dt)

    monkeypatch.setattr(CompiledTick, "run_loaded", counted)
    rng = np.random.default_rng(seed)
    names, out = list(ctl.commandable()), []
    for k in range(ticks):
        if cell == "yeh_tripod" and k == ticks // 3:
            ctl.swing("leg1")
            names = ["body", "leg1"]
        if cell == "yeh_tripod" and k == 2 * ticks // 3:
            ctl.land("leg1")
            names = ["body"]
        if k % 20 == 0:
            commands = {n: rng.normal(size=6) * SPEED[n] * rng.choice(SIZES) for n in names
                        if n in SPEED}  # fmt: skip
        r = ctl.step(commands if k % 7 else None).resolution
        out.append((ctl.q, r.qdot, r.applied, r.status, r.scale, r.veer, r.lambda_sq, r.levels,
                    [t.achieved for t in r.tasks], r.active, ctl.chain_error,
                    None if ctl.grip.last is None else ctl.grip.last.error,
                    None if ctl.contact.last is None else ctl.contact.last.error))  # fmt: skip
    return out, len(calls), ctl


def _same(a, b, seed):
    for k, (x, y) in enumerate(zip(a, b, strict=True)):
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
    compiled rows taken on every tick the controller commands (the tripod's swinging leg a
    second frame task), and some of them scaled and damped."""
    compiled, calls, ctl = _session(cell, seed, True, monkeypatch)
    plain, none, _ = _session(cell, seed, False, monkeypatch)
    _same(compiled, plain, seed)
    assert none == 0 and calls == len(compiled), f"seed {seed}: {calls} compiled ticks"
    statuses = {x[3] for x in compiled}
    assert "exact" in statuses and statuses & {"scaled", "damped"}, f"seed {seed}: {statuses}"
    assert isinstance(ctl._cell_tick[1], CellTick)


@pytest.mark.parametrize("cell", ["gsfc_dual", "yeh_tripod"])
@pytest.mark.parametrize("collision", ["capsules", "ball"])
def test_with_a_collision_limit_the_ticks_whose_rows_slide_go_to_the_resolver(
    cell, collision, monkeypatch
):
    """A collision limit beside the chains: its rows are loaded beside the chains' where none
    is slid along, and the tick goes back to the resolver with its rows where one is (the
    ball in the way); the same session, bit for bit, with ticks of both kinds."""
    compiled, calls, _ = _session(cell, SEEDS[0], True, monkeypatch, collision=collision)
    plain, _, _ = _session(cell, SEEDS[0], False, monkeypatch, collision=collision)
    _same(compiled, plain, SEEDS[0])
    statuses = [x[3] for x in compiled]
    assert calls > len(compiled) // 4, f"{calls} compiled ticks"
    if collision == "ball":
        assert calls + statuses.count("sliding") <= len(compiled) and "sliding" in statuses


@pytest.mark.parametrize("cell", ["gsfc_dual", "yeh_tripod"])
def test_a_limits_rows_no_command_slides_along_are_loaded_beside_the_chains(cell, monkeypatch):
    """A singularity limit's rows on every tick: loaded into the compiled tick with the chains'
    rows, the same session bit for bit."""
    compiled, _, ctl = _session(cell, SEEDS[0], True, monkeypatch, collision="singular")
    rows = []
    monkeypatch.setattr(CompiledTick, "run_loaded", lambda self, *a: rows.append(
        int(self.workspace.ints[CONSTRAINTS])) or FAILED)  # fmt: skip
    ctl.step({n: np.zeros(6) for n in ctl.commandable() if n in SPEED})
    plain, _, _ = _session(cell, SEEDS[0], False, monkeypatch, collision="singular")
    _same(compiled, plain, SEEDS[0])
    assert rows and rows[0] > 0, rows


@pytest.mark.parametrize("cell", ["gsfc_dual", "yeh_tripod"])
def test_without_the_closure_the_compiled_rows_answer_as_the_tasks_and_limits_do(
    cell, monkeypatch
):
    """``closure=None``: no correction made with the rows, the same session bit for bit."""
    compiled, calls, _ = _session(cell, SEEDS[0], True, monkeypatch, closure=False)
    plain, _, _ = _session(cell, SEEDS[0], False, monkeypatch, closure=False)
    _same(compiled, plain, SEEDS[0])
    assert calls == len(compiled)


@pytest.mark.parametrize("cell", ["gsfc_dual", "yeh_tripod"])
def test_a_tick_the_compiled_rows_find_no_answer_to_goes_the_tasks_and_limits_path(
    cell, monkeypatch
):
    """Every fifth compiled tick refused: the session is still the same, bit for bit."""
    refused, _, _ = _session(cell, SEEDS[0], True, monkeypatch, ticks=60, refuse=5)
    plain, _, _ = _session(cell, SEEDS[0], False, monkeypatch, ticks=60)
    _same(refused, plain, SEEDS[0])


def test_hands_resolved_each_on_its_own_take_the_resolver(dual):
    """``coupled=False``: the hands' tasks are weighted, not the compiled rows' levels."""
    ctl = CellController(dual, 0.01, coupled=False)
    ctl.step({"object": SPEED["object"]})
    assert ctl._cell_tick[1] is None
