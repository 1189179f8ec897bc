"""RecordRing: ticks and records kept as columns of arrays, in time order, within a capacity."""

from __future__ import annotations

import gc
import mmap
import os
import tracemalloc
from pathlib import Path
from typing import NamedTuple

import numpy as np
import pytest

import rrc_pin
from rrc_pin.control import Controller
from rrc_pin.control.record_ring import CAPACITY, RecordRing, rows_array


class Rec(NamedTuple):
    t: float
    q: np.ndarray
    label: str
    extra: object


class Tick(NamedTuple):
    t: float
    q: np.ndarray


class Ring(RecordRing[Rec]):
    record_type = Rec


def rec(k: int) -> Rec:
    return Rec(float(k), np.array([k, -k], float), f"label {k % 3}", {"k": k})


def derive(tick: Tick) -> Rec:
    return Rec(tick.t, tick.q, "derived", None)


def test_records_come_back_in_order_through_the_wrap() -> None:
    rows = 256
    ring = Ring(capacity=rows * 3)
    for k in range(rows * 4 + 7):
        ring.append(rec(k))
    assert len(ring) == rows * 3 and ring.dropped == rows + 7
    first = rows + 7
    assert [r.t for r in ring.records] == [float(k) for k in range(first, rows * 4 + 7)]
    r = ring[-1]
    assert r.q.tolist() == [rows * 4 + 6, -(rows * 4 + 6)] and r.extra == {"k": rows * 4 + 6}
    assert ring[0].t == first and ring[-len(ring)].t == first
    with pytest.raises(IndexError):
        ring[len(ring)]
    np.testing.assert_array_equal(ring.column_values("t"), np.arange(first, rows * 4 + 7))


def test_no_tick_copies_the_rows_kept() -> None:
    """Each column is made at the capacity's rows with its first value: the ticks after it,
    through the wrap, write into the same arrays (a column grown by doubling copied every row
    kept, 8.6 ms at an arm log's 32,768th tick)."""
    ring = Ring(capacity=1000)
    ring.append(rec(0))
    columns = dict(ring._columns)
    assert all(column.shape[0] == 1000 for column in columns.values())
    for k in range(1, 2500):
        ring.append(rec(k))
    assert all(ring._columns[name] is column for name, column in columns.items())
    assert [r.t for r in ring.records] == [float(k) for k in range(1500, 2500)]


@pytest.mark.parametrize(("shape", "dtype"), [((60_000, 7), "f8"), ((5,), "f8"), ((3, 0), "f8"),
                                             ((4,), "u1,f8,(3,)f8"), ((6,), object)])
def test_rows_array_is_writable_memory_of_the_shape_asked(shape, dtype) -> None:
    """Memory mapped as it is written (an anonymous mmap, small pages), or numpy's own for
    nothing to map and for objects; every element written is read back."""
    dtype = np.dtype(dtype)
    a = rows_array(shape, dtype)
    assert a.shape == shape and a.dtype == dtype and a.flags.writeable and a.flags.c_contiguous
    if a.size and not dtype.hasobject:
        raw = a.view(np.uint8).reshape(-1)
        raw[:] = np.arange(raw.size) % 251
        np.testing.assert_array_equal(a.view(np.uint8).reshape(-1), np.arange(raw.size) % 251)


def _vm_flags(address: int) -> list[str]:
    """The flags of this process's mapping that holds ``address`` (Linux's /proc/self/smaps)."""
    inside = False
    for line in Path("/proc/self/smaps").read_text().splitlines():
        head = line.split()
        if head and "-" in head[0] and not head[0].endswith(":"):
            low, high = (int(x, 16) for x in head[0].split("-"))
            inside = low <= address < high
        elif inside and head[0] == "VmFlags:":
            return head[1:]
    raise AssertionError(f"no mapping holds {address:#x}")


def test_the_columns_decline_transparent_huge_pages() -> None:
    """A log's column of numbers is a mapping that declines huge pages where the OS has them:
    a tick that first wrote a fresh 2 MB page of one numpy had asked huge pages for waited
    while Linux compacted memory for it (4.5-5.1 ms, docs/api.md)."""
    a = rows_array((60_000, 15), np.dtype(np.float64))
    a[:] = 1.0
    if not Path("/sys/kernel/mm/transparent_hugepage").exists():  # none to decline
        assert not hasattr(mmap, "MADV_NOHUGEPAGE") or a.flags.writeable
        return
    flags = _vm_flags(a.ctypes.data)
    assert "nh" in flags and "hg" not in flags, flags


def test_a_forked_process_writes_its_own_copy_of_the_columns() -> None:
    """The mapping is private: a child forked from the process (a worker pool's) that writes
    into a log's columns changes its copy only (a shared mapping gave the parent its writes)."""
    a = rows_array((1000, 3), np.dtype(np.float64))
    a[:] = 1.0
    if not hasattr(os, "fork"):  # no fork: nothing to share the pages with
        assert not hasattr(mmap, "MAP_PRIVATE")
        return
    child = os.fork()
    if child == 0:  # pragma: no cover - the child
        a[:] = 7.0
        os._exit(0 if a[0, 0] == 7.0 else 1)
    _, status = os.waitpid(child, 0)
    assert os.waitstatus_to_exitcode(status) == 0
    assert (a == 1.0).all()


def test_what_is_read_is_a_copy_the_ring_reuses_its_rows() -> None:
    ring = Ring(capacity=3)
    for k in range(3):
        ring.append(rec(k))
    old, q = ring[0], ring.positions(1)[0]
    q[:] = 99.0
    for k in range(3, 9):  # every row overwritten twice
        ring.append(rec(k))
    assert old.t == 0.0 and old.q.tolist() == [0.0, 0.0] and ring[-1].q.tolist() == [8.0, -8.0]


def test_equal_strings_share_one_object() -> None:
    ring = Ring()
    for k in range(30):
        ring.append(rec(k)._replace(label="".join(["lab", "el"])))  # a new object each time
    labels = ring.column_values("label")
    assert len({id(x) for x in labels}) == 1


def test_a_value_that_does_not_fit_its_column_is_kept_as_it_is() -> None:
    ring = Ring()
    ring.append(rec(0))
    ring.append(Rec(None, np.zeros(3), "x", 1))  # type: ignore[arg-type]
    ring.append(rec(2))
    got = ring.records
    assert got[0].t == 0.0 and got[1].t is None and got[2].t == 2.0
    assert got[1].q.shape == (3,) and got[0].q.tolist() == [0.0, 0.0]


def test_capacity_shrinks_and_grows_keeping_the_newest() -> None:
    ring = Ring(capacity=10)
    for k in range(10):
        ring.append(rec(k))
    ring.capacity = 4
    assert [r.t for r in ring] == [6.0, 7.0, 8.0, 9.0] and ring.dropped == 6
    ring.capacity = 1000
    for k in range(10, 300):
        ring.append(rec(k))
    assert len(ring) == 294 and ring[0].t == 6.0 and ring[-1].t == 299.0
    ring.clear()
    assert len(ring) == 0 and ring.records == [] and ring.positions(5) == []
    ring.append(rec(5))
    assert [r.t for r in ring] == [5.0]


def test_ticks_are_derived_once_when_read_and_positions_need_none() -> None:
    calls: list[float] = []

    def counted(tick: Tick) -> Rec:
        calls.append(tick.t)
        return derive(tick)

    ring = Ring(counted, capacity=5)
    for k in range(8):
        ring.append_tick(Tick(float(k), np.array([k, 0.0])))
    assert [q[0] for q in ring.positions(3)] == [5.0, 6.0, 7.0] and calls == []
    assert [r.label for r in ring.records] == ["derived"] * 5
    assert len(ring.records) == 5 and calls == [3.0, 4.0, 5.0, 6.0, 7.0]  # derived once
    ring.append(rec(8))
    assert calls == [3.0, 4.0, 5.0, 6.0, 7.0] and ring[-1].label == "label 2"


def test_each_tick_is_written_into_its_row_as_it_comes() -> None:
    """No batch: a tick's fields are in the columns once it is appended (the same work at
    every tick), its record derived when read; a ring of one keeps the newest."""
    ring = Ring(derive, capacity=100)
    for k in range(250):
        ring.append_tick(Tick(float(k), np.array([k, 0.0])))
        assert ring._size == min(k + 1, 100) and ring._columns["t"][ring._row(ring._size - 1)] == k
    assert len(ring) == 100 and ring.dropped == 150 and ring._pending == 100
    assert [r.t for r in ring] == [float(k) for k in range(150, 250)]
    assert ring[-1].label == "derived" and ring[-1].q.tolist() == [249.0, 0.0]
    small = Ring(derive, capacity=1)
    for k in range(5):
        small.append_tick(Tick(float(k), np.zeros(2)))
    assert [r.t for r in small] == [4.0] and small.dropped == 4
    small.clear()
    assert len(small) == 0 and small.records == []


def test_plain_tuples_and_bad_arguments() -> None:
    ring: RecordRing[tuple] = RecordRing(lambda tick: (*tick, "x"))
    ring.append_tick((0.0, np.zeros(2)))
    assert ring.records[0][2] == "x" and ring.positions(1)[0].tolist() == [0.0, 0.0]
    with pytest.raises(rrc_pin.InvalidInput, match="capacity"):
        RecordRing(capacity=0)
    with pytest.raises(rrc_pin.InvalidInput, match="derive"):
        RecordRing(derive=3)  # type: ignore[arg-type]
    with pytest.raises(rrc_pin.InvalidInput, match="record"):
        Ring().append((0.0, np.zeros(2), "", None))  # type: ignore[arg-type]
    with pytest.raises(rrc_pin.InvalidInput, match="tick"):
        Ring().append_tick(Tick(0.0, np.zeros(2)))


TICKS = 1024
"""Ticks the memory test logs."""


def test_a_tick_of_the_controllers_log_costs_a_few_hundred_bytes(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Issue 38: the log kept each tick's resolution (3.4-3.5 kB a tick pending, 1.1-1.3 kB
    derived; 212-225 MB at 60,000 ticks). Its columns now, made at the capacity: a row of
    8 (19 + 2 nq) + 56 B and its strings for panda (``nbytes``), and no object kept a tick but
    shared strings, measured by tracemalloc over 1,024 ticks, pending and derived (the
    controller's own 128 ticks in turn: stepping it under tracemalloc cost minutes without the
    compiler); at the default capacity under 32 MB."""
    ctl = Controller(rrc_pin.load("panda"))
    log = ctl.log
    rng = np.random.default_rng(0)
    seen: list[object] = []
    append = log.append_tick
    monkeypatch.setattr(log, "append_tick", lambda tick: (seen.append(tick), append(tick)))
    for k in range(128):  # the kernels, the caches and the columns warmed up too
        ctl.step(rng.normal(size=6) * 0.1 if k % 16 == 0 else None, ref="local")
    monkeypatch.undo()
    assert len(log.records) == 128  # the records' columns made too
    log.capacity = TICKS  # every column made again at TICKS rows
    log.clear()
    row = log.nbytes / TICKS
    gc.collect()
    tracemalloc.start()
    try:
        before = tracemalloc.get_traced_memory()[0]
        for k in range(TICKS):
            log.append_tick(seen[k % len(seen)])
        assert log.dropped == 0
        gc.collect()
        pending = (tracemalloc.get_traced_memory()[0] - before) / TICKS
        assert len(log.records) == TICKS
        gc.collect()
        derived = (tracemalloc.get_traced_memory()[0] - before) / TICKS
    finally:
        tracemalloc.stop()
    assert log.nbytes == row * TICKS  # no column made or grown since
    assert 150 < row < 400 and pending < 16 and derived < 80, (row, pending, derived)
    assert (row + derived) * CAPACITY < 32e6
