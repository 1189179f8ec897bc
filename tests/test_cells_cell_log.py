"""CellLog: a cell's ticks as packed rows, their memory, the ring, the records and the CSV."""

from __future__ import annotations

import numpy as np
import pytest

import rrc_pin
from rrc_pin.cells import CellController, CellLog, CellRecord
from rrc_pin.cells.cell_log import (
    LEVEL_CODES,
    LEVEL_STATUSES,
    LEVELS,
    MODE_CODES,
    MODES,
    NONE,
    STATUS_CODES,
    STATUSES,
)
from rrc_pin.control.trajectory_log import CAPACITY
from rrc_pin.errors import InvalidInput

LIMIT = 32e6
"""[bytes] What a cell's log may hold at its default capacity."""


@pytest.mark.parametrize(("name", "row"), [("gsfc_dual", 294), ("yeh_tripod", 462)])
def test_a_full_log_at_the_default_capacity_holds_under_32_mb(name, row):
    """60,000 ticks (10 minutes at 100 Hz) of the ready-made cells, filled: the array's bytes
    are the row's size times the ticks, under 32 MB, nothing else kept per tick."""
    ctl = CellController(name, 0.01)
    log = ctl.log
    assert log.capacity == CAPACITY == 60_000
    assert log.dtype.itemsize == row
    ctl.step()  # one real tick, then the rest packed as it would be
    rec = log[-1]
    for _ in range(CAPACITY - 1):
        log.add(rec.t, rec.q, rec.qdot, rec.status, rec.scale, rec.levels.split("/"),
                rec.errors, rec.grip, (rec.chain_position, rec.chain_rotation), rec.mode)
    assert len(log) == CAPACITY and log.dropped == 0
    assert log.nbytes == row * CAPACITY < LIMIT, log.nbytes
    log.add(rec.t, rec.q, rec.qdot, rec.status, rec.scale, [], {}, {}, (0.0, 0.0), "teleop")
    assert len(log) == CAPACITY and log.dropped == 1 and log.nbytes == row * CAPACITY


def test_no_tick_copies_the_rows_kept():
    """The array is made at the capacity: the ticks, through the wrap and a capacity changed,
    write into it (an array grown by doubling copied every row kept, 59 ms at gsfc_dual's
    32,768th tick)."""
    log = CellLog(3, 2, ["object"], capacity=1000)
    table = log._table
    assert log.nbytes == 1000 * log.dtype.itemsize
    for k in range(2500):
        log.add(0.01 * k, np.full(3, k), np.zeros(2), "exact", 1.0, [], {"object": k}, {},
                (0.0, 0.0), "teleop")  # fmt: skip
        assert log._table is table
    np.testing.assert_array_equal(log.column("t"), 0.01 * np.arange(1500, 2500))
    log.capacity = 400  # the newest kept, in a table of the new capacity
    np.testing.assert_array_equal(log.column("t"), 0.01 * np.arange(2100, 2500))
    assert log.nbytes == 400 * log.dtype.itemsize and log.dropped == 2100
    table = log._table
    log.add(25.0, np.zeros(3), np.zeros(2), "exact", 1.0, [], {}, {}, (0.0, 0.0), "teleop")
    assert log._table is table and log.column("t")[-1] == 25.0 and len(log) == 400


def test_records_come_back_as_they_were_logged():
    log = CellLog(3, 2, ["object", "left"], ["object"], capacity=4)
    rows = []
    for k in range(6):
        rec = CellRecord(0.01 * k, np.arange(3.0) + k, np.array([k, -k], float),
                         ("exact", "scaled", "grip_lost")[k % 3], 0.5 + k / 10,
                         "met/traded" if k % 2 else "scaled", {"object": 1e-3 * k},
                         {"object": 1e-9},
                         1e-9 * k, 2e-9 * k, ("teleop", "reverse")[k % 2])  # fmt: skip
        log.append(rec)
        rows.append(rec)
    assert len(log) == 4 and log.dropped == 2
    for got, want in zip(log.records, rows[2:], strict=True):
        assert got.t == want.t and got.status == want.status and got.mode == want.mode
        assert got.levels == want.levels and got.scale == want.scale
        assert got.errors == want.errors and got.grip == want.grip  # "left" not commanded
        np.testing.assert_array_equal(got.q, want.q)
        np.testing.assert_array_equal(got.qdot, want.qdot)
        assert got.chain_position == want.chain_position
        assert got.chain_rotation == want.chain_rotation
    assert log[-1].t == rows[-1].t and log[0].t == rows[2].t
    np.testing.assert_array_equal(log.positions(2)[0], rows[4].q)
    np.testing.assert_array_equal(log.column("q")[:, 0], [2.0, 3.0, 4.0, 5.0])
    with pytest.raises(IndexError):
        log[4]
    log.capacity = 2  # the oldest forgotten at once
    assert len(log) == 2 and log.dropped == 4 and log[0].t == rows[4].t
    log.clear()
    assert len(log) == 0 and log.positions(3) == []


def test_bad_input_is_named():
    log = CellLog(2, 2)
    with pytest.raises(InvalidInput, match="record"):
        log.append(("not", "a", "record"))  # type: ignore[arg-type]
    with pytest.raises(InvalidInput, match="name: no column 'x'"):
        log.column("x")
    with pytest.raises(InvalidInput, match="capacity"):
        log.capacity = 0
    with pytest.raises(InvalidInput, match="tick"):
        log.append_tick((0.0, np.zeros(2)))
    with pytest.raises(InvalidInput, match="n: "):
        log.positions(-1)


def test_the_csv_has_a_row_per_tick_with_the_chains_errors(tmp_path):
    ctl = CellController(rrc_pin.load("gsfc_dual"), 0.01)
    for _ in range(3):
        ctl.step({"object": [0.01, 0, 0, 0, 0, 0]})
    text = ctl.save(tmp_path / "cell.csv").read_text().splitlines()
    header = text[0].split(",")
    assert len(text) == 4 and header[:5] == ["t", "mode", "status", "scale", "levels"]
    assert "grip:object" in header and "chain_position" in header and "qdot13" in header
    row = dict(zip(header, text[2].split(","), strict=True))
    assert row["status"] == "exact" and row["levels"] == "met/traded"
    assert float(row["error:object"]) < 1e-6
    assert float(row["chain_position"]) < 1e-8
    with pytest.raises(InvalidInput, match="path: expected a .csv"):
        ctl.save(tmp_path / "cell.npz")
    with pytest.raises(InvalidInput, match="path: cannot write"):
        ctl.save(tmp_path / "missing" / "cell.csv")


def _former_row(log, t, q, qdot, status, scale, levels, errors, grip, chain, mode):
    """A row as the log packed it in one assignment (the reference of :meth:`CellLog.add`)."""
    codes = [LEVEL_CODES[s] for s in levels[:LEVELS]]
    row = np.zeros(1, log.dtype)
    row[0] = (t, q, qdot, scale, [errors.get(n, np.nan) for n in log.commands],
              [grip.get(n, np.nan) for n in log.objects], chain, STATUS_CODES[status],
              MODE_CODES[mode], codes + [NONE] * (LEVELS - len(codes)))  # fmt: skip
    return row


@pytest.mark.parametrize(("commands", "objects"), [(["object", "left", "right"], ["object"]),
                                                   (["body", "leg1"], []), ([], [])])
def test_each_row_is_the_one_assignment_of_its_fields_byte_for_byte(commands, objects, rng):
    """Ticks with some commands' and grips' errors (names the log does not know ignored),
    levels of any length (past LEVELS cut), through the table's growth and its ring: the
    rows are those the former tuple assignment wrote, and read back as the same records."""
    nq, nv = 5, 4
    log = CellLog(nq, nv, commands, objects, capacity=1500)
    want = []
    for k in range(2000):
        errors = {n: float(rng.uniform()) for n in [*commands, "other"] if rng.uniform() < 0.5}
        grip = {n: float(rng.uniform()) for n in [*objects, "other"] if rng.uniform() < 0.7}
        levels = tuple(rng.choice(LEVEL_STATUSES, size=int(rng.integers(0, LEVELS + 2))))
        tick = (0.01 * k, rng.normal(size=nq), rng.normal(size=nv),
                STATUSES[int(rng.integers(len(STATUSES)))], float(rng.uniform()), levels, errors,
                grip, (float(rng.uniform()), float(rng.uniform())), MODES[k % 2])  # fmt: skip
        log.add(*tick)
        want.append(_former_row(log, *tick))
    table = log.table()
    assert table.tobytes() == np.concatenate(want[-1500:]).tobytes()
    assert log.dropped == 500 and log[-1].levels == "/".join(levels[:LEVELS])
    assert log[-1].errors == {n: e for n, e in errors.items() if n in commands}
