"""CellTick: a cell's usual tick with its rows in one compiled call answers as the tasks' and
limits' own path does, bit for bit, over sessions that scale, damp, swing and land a leg, and
where the compiled tick finds no answer."""

from __future__ import annotations

import numpy as np
import pytest

from rrc_pin.cells.cell_tick import CellTick
from rrc_pin.cells.controller import CellController
from rrc_pin.compiled_tick import CompiledTick
from rrc_pin.solvers.tick.top import FAILED

SEEDS = (0, int(np.random.SeedSequence().entropy % 2**63))
"""A fixed seed and one drawn fresh each run (named in every failure's message)."""
SIZES = (1.0, 1.0, 1e-3, 10.0, 300.0)
"""Factors on a segment's command: slow, too fast for the joints, far too fast."""
SPEED = {"object": np.array([0.15, 0.15, 0.15, 0.4, 0.4, 0.4]),
         "body": np.array([0.03, 0.03, 0.03, 0.1, 0.1, 0.1]),
         "leg1": np.array([0.05, 0.05, 0.05, 0.0, 0.0, 0.0])}  # fmt: skip


def _session(cell, seed, compiled, monkeypatch, ticks=240, refuse=0):
    """Each tick's state and report, ``compiled`` or the tasks' and limits' path alone; every
    ``refuse``-th compiled tick finds no answer (0: none). The tripod swings leg 1 a third of
    the way in and lands it at two thirds."""
    ctl = CellController(cell, 0.01)
    ctl._compiles = compiled
    calls = []
    run_loaded = CompiledTick.run_loaded

    def counted(self, q, previous, dt):
        calls.append(1)
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
def test_a_tick_the_compiled_rows_find_no_answer_to_goes_the_tasks_and_limits_path(
    cell, monkeypatch
):
    """Every fifth compiled tick refused: the session is still the same, bit for bit."""
    refused, _, _ = _session(cell, SEEDS[0], True, monkeypatch, ticks=60, refuse=5)
    plain, _, _ = _session(cell, SEEDS[0], False, monkeypatch, ticks=60)
    _same(refused, plain, SEEDS[0])


def test_other_limits_or_free_hands_take_the_tasks_and_limits_path(dual):
    """A collision limit beside the chains, or hands resolved each on its own: no CellTick."""
    from rrc_pin import CollisionLimit, CollisionModel, JointLimits

    limited = CellController(dual, 0.01, limits=[JointLimits(),
                                                 CollisionLimit(CollisionModel(dual, "capsules"))])
    apart = CellController(dual, 0.01, coupled=False)
    for ctl in (limited, apart):
        ctl.step({"object": SPEED["object"]})
        assert ctl._cell_tick[1] is None
