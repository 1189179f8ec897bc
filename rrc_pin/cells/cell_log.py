"""CellLog: a cell's ticks as rows of one packed array, a few hundred bytes a tick.

Every tick of a :class:`~rrc_pin.cells.CellController` is one row of a numpy structured array
(:attr:`CellLog.dtype`): the time, q and the rates applied (float64, exact: ``reverse``
retraces them), the top level's scale, each command's pose error, each grip's error, the
closed chains' largest errors, and the status, mode and level statuses as one-byte codes. No
Python object is kept per tick: gsfc_dual's row is 294 bytes, yeh_tripod's 462, so that the
default capacity (:data:`~rrc_pin.control.trajectory_log.CAPACITY`, 60,000 ticks: 10 minutes
at 100 Hz) holds at most 17.6 MB and 27.7 MB. The array is made at the capacity, on memory the
OS maps a small page at a time as rows are first written
(:func:`~rrc_pin.control.record_ring.rows_array`), and is a ring (the oldest tick forgotten,
:attr:`~CellLog.dropped` counts them): no tick copies the rows kept. A :class:`CellRecord` is
made when a tick is read.
"""

from __future__ import annotations

import csv
import math
import os
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any, NamedTuple, get_args

import numpy as np
import numpy.typing as npt

from rrc_pin.control.record_ring import rows_array
from rrc_pin.control.trajectory_log import CAPACITY, RecordRing, checked_path, reason
from rrc_pin.errors import InvalidInput
from rrc_pin.solvers.tick.pipeline import LevelStatus, Status

Array = npt.NDArray[np.float64]

STATUSES: tuple[str, ...] = get_args(Status)
"""The statuses a row codes, by index."""
LEVEL_STATUSES: tuple[str, ...] = get_args(LevelStatus)
MODES = ("teleop", "reverse")
STATUS_CODES = {name: i for i, name in enumerate(STATUSES)}
LEVEL_CODES = {name: i for i, name in enumerate(LEVEL_STATUSES)}
MODE_CODES = {name: i for i, name in enumerate(MODES)}
"""A status's, level status's or mode's code in a row: its index in the tuple above."""
LEVELS = 4
"""Level statuses a row keeps (a cell's tick has two levels, the top and the posture)."""
NONE = 255
"""The code of a level a tick did not have."""
KINDS = 256
"""Rows' codes kept made (:meth:`CellLog.add`), at most."""


class CellRecord(NamedTuple):
    """One tick as the log keeps it.

    Attributes:
        t: Time at the start of the tick [s].
        q: Configuration at the start (nq,).
        qdot: Joint rates applied over the tick (nv,), the closed chains' correction included.
        status: The tick's status (the resolution's, or ``grip_lost`` / ``contact_lost``).
        scale: The top level's common scale.
        levels: Each level's status, joined by ``/``.
        errors: Pose error [m] of each commanded frame to its target, by command name.
        grip: Grip error [m] of each held object (its hands' relative position to the grip).
        chain_position: The closed chains' largest position error at the start [m].
        chain_rotation: Their largest rotation error at the start [rad].
        mode: ``"teleop"`` or ``"reverse"``.
    """

    t: float
    q: Array
    qdot: Array
    status: str
    scale: float
    levels: str
    errors: dict[str, float]
    grip: dict[str, float]
    chain_position: float
    chain_rotation: float
    mode: str


class CellLog(RecordRing[CellRecord]):
    """A cell's log: its ticks as rows of one packed array (module docstring), and its CSV.

    Built on :class:`~rrc_pin.control.trajectory_log.RecordRing` (the ring every loop's
    ``reverse`` reads: ``len``, ``positions``, ``records``, ``capacity``, ``dropped``), with
    the storage one structured array instead of one object per tick.

    Args:
        nq: Length of the cell's q.
        nv: Length of its qdot.
        commands: The names a tick may command (the pose error's columns).
        objects: The held objects (the grip error's columns).
        capacity: Ticks kept, >= 1.

    Raises:
        InvalidInput: A bad ``capacity``.
    """

    record_type = CellRecord

    def __init__(
        self, nq: int, nv: int, commands: Sequence[str] = (), objects: Sequence[str] = (),
        capacity: int = CAPACITY,
    ) -> None:  # fmt: skip
        super().__init__(None, capacity)
        self.nq, self.nv = nq, nv
        self.commands, self.objects = tuple(commands), tuple(objects)
        self.dtype = np.dtype([
            ("t", "f8"), ("q", "f8", (nq,)), ("qdot", "f8", (nv,)), ("scale", "f8"),
            ("errors", "f8", (len(self.commands),)), ("grip", "f8", (len(self.objects),)),
            ("chain", "f8", (2,)), ("status", "u1"), ("mode", "u1"), ("levels", "u1", (LEVELS,)),
        ])  # fmt: skip
        self._float_at = _float_fields(self.dtype)
        self._error_at = _columns(self.commands, self._float_at[3].start)
        self._grip_at = _columns(self.objects, self._float_at[3].start + len(self.commands))
        self._unknown = np.full(self._float_at[3].stop - self._float_at[3].start, math.nan)
        self._codes_of: dict[tuple[str, str, tuple[str, ...]], npt.NDArray[np.uint8]] = {}
        self._set_table(rows_array((self._capacity,), self.dtype))  # each row written whole (add)
        self._start = 0  # the oldest row's index in the ring
        self._count = 0

    def __len__(self) -> int:
        return self._count

    def __iter__(self) -> Iterator[CellRecord]:
        return iter(self.records)

    @property
    def nbytes(self) -> int:
        """Bytes of the log's array: its capacity times :attr:`dtype`'s size (mapped as rows are
        first written)."""  # noqa: D205, D209
        return int(self._table.nbytes)

    @property
    def capacity(self) -> int:
        """Ticks kept (the oldest forgotten beyond), >= 1."""
        return self._capacity

    @capacity.setter
    def capacity(self, value: int) -> None:
        value = RecordRing[Any](None, value).capacity  # checked as every ring's
        kept = self.table()
        self._dropped += max(0, kept.size - value)
        self._capacity = value
        table = rows_array((value,), self.dtype)
        count = min(kept.size, value)
        table[:count] = kept[kept.size - count :]
        self._set_table(table)
        self._start, self._count = 0, count

    def add(
        self, t: float, q: Array, qdot: Array, status: str, scale: float,
        levels: Sequence[str], errors: dict[str, float], grip: dict[str, float],
        chain: tuple[float, float], mode: str,
    ) -> None:  # fmt: skip
        """Append one tick (the oldest forgotten when the log is full); no object kept.

        The row's floats are written through a float view of the table (:func:`_float_fields`),
        its codes as one array (made once for each status, mode and levels).
        """
        levels = tuple(levels)
        codes = self._codes_of.get((status, mode, levels))
        if codes is None:
            codes = self._codes(status, mode, levels)
        q_at, qdot_at, scale_at, errors_at, chain_at = self._float_at
        index = self._next()
        row = self._floats[index]
        row[0] = t
        row[q_at] = q
        row[qdot_at] = qdot
        row[scale_at] = scale
        row[errors_at] = self._unknown  # the errors' and grips', then those given
        for name, error in errors.items():
            for at in self._error_at.get(name, ()):
                row[at] = error
        for name, error in grip.items():
            for at in self._grip_at.get(name, ()):
                row[at] = error
        row[chain_at], row[chain_at + 1] = chain
        self._codes_table[index] = codes

    def append(self, record: CellRecord) -> None:
        """Append one tick's record (packed into a row).

        Raises:
            InvalidInput: ``record`` is not a :class:`CellRecord`.
        """
        if not isinstance(record, CellRecord):
            raise InvalidInput("record", f"expected a CellRecord, got {type(record).__name__}")
        self.add(record.t, record.q, record.qdot, record.status, record.scale,
                 record.levels.split("/") if record.levels else [], record.errors, record.grip,
                 (record.chain_position, record.chain_rotation), record.mode)  # fmt: skip

    def append_tick(self, tick: tuple[Any, ...]) -> None:
        """Not for a cell's log: it packs each tick as it comes (:meth:`add`).

        Raises:
            InvalidInput: Always.
        """
        raise InvalidInput("tick", "a CellLog packs its ticks: use add() or append()")

    def table(self) -> npt.NDArray[Any]:
        """The ticks kept, oldest first, as a structured array (a copy; :attr:`dtype`)."""
        index = (self._start + np.arange(self._count)) % self._table.size
        kept: npt.NDArray[Any] = self._table[index]
        return kept

    def column(self, name: str) -> npt.NDArray[Any]:
        """One field over the ticks kept, oldest first: (N,) or (N, k) (a copy).

        Raises:
            InvalidInput: ``name`` is not a field of :attr:`dtype` (the error lists them).
        """
        if not isinstance(name, str) or name not in self.dtype.names:  # type: ignore[operator]
            raise InvalidInput("name", f"no column {name!r}; columns: "
                               f"{', '.join(self.dtype.names or ())}")  # fmt: skip
        out: npt.NDArray[Any] = self.table()[name]
        return out

    @property
    def records(self) -> list[CellRecord]:
        """The records kept, in time order, made now from the rows."""
        return [self._record(row) for row in self.table()]

    def __getitem__(self, index: int) -> CellRecord:
        """Record ``index`` (negative from the newest).

        Raises:
            IndexError: No such record.
        """
        if not -self._count <= index < self._count:
            raise IndexError(f"record {index} of {self._count}")
        return self._record(self._table[(self._start + index % self._count) % self._table.size])

    def positions(self, n: int) -> list[Array]:
        """Joint positions ``q`` of the last ``n`` ticks kept, oldest first (copies).

        Raises:
            InvalidInput: ``n`` is not an integer >= 0.
        """
        if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 0:
            raise InvalidInput("n", f"expected an integer >= 0, got {n!r}")
        q = self.column("q")
        return list(q[q.shape[0] - min(int(n), q.shape[0]):])

    def clear(self) -> None:
        """Forget every tick."""
        self._start = self._count = 0

    def save(self, path: str | os.PathLike[str]) -> Path:
        """Write the log as CSV (one row per tick, a header) to ``path``; return the path.

        Raises:
            InvalidInput: Naming ``path``: not a ``.csv`` path, or a file that cannot be
                written (the system's reason).
        """
        out = checked_path(path)
        if out.suffix != ".csv":
            raise InvalidInput("path", f"expected a .csv file, got {str(out)!r}")
        try:
            with out.open("w", newline="") as f:
                w = csv.writer(f)
                w.writerow(["t", "mode", "status", "scale", "levels",
                            *[f"error:{n}" for n in self.commands],
                            *[f"grip:{n}" for n in self.objects],
                            "chain_position", "chain_rotation",
                            *[f"q{i}" for i in range(self.nq)],
                            *[f"qdot{i}" for i in range(self.nv)]])  # fmt: skip
                for rec in self.records:
                    w.writerow([f"{rec.t:.6f}", rec.mode, rec.status, f"{rec.scale:.9g}",
                                rec.levels, *[f"{rec.errors.get(n, math.nan):.9g}"
                                              for n in self.commands],
                                *[f"{rec.grip[n]:.9g}" for n in self.objects],
                                f"{rec.chain_position:.9g}", f"{rec.chain_rotation:.9g}",
                                *[f"{x:.12g}" for x in rec.q],
                                *[f"{x:.12g}" for x in rec.qdot]])  # fmt: skip
        except OSError as exc:
            raise InvalidInput("path", f"cannot write {str(out)!r}: {reason(exc)}") from exc
        return out

    def _codes(self, status: str, mode: str, levels: tuple[str, ...]) -> npt.NDArray[np.uint8]:
        """A row's status, mode and level codes (:attr:`dtype`'s last fields), kept for the next
        rows (a few kinds: statuses, modes, levels' statuses).
        """  # noqa: D205
        kept = [LEVEL_CODES[s] for s in levels[:LEVELS]]
        codes = np.array([STATUS_CODES[status], MODE_CODES[mode], *kept,
                          *[NONE] * (LEVELS - len(kept))], np.uint8)  # fmt: skip
        if len(self._codes_of) >= KINDS:
            self._codes_of.clear()
        self._codes_of[(status, mode, levels)] = codes
        return codes

    def _set_table(self, table: npt.NDArray[Any]) -> None:
        """``table`` the log's rows, with its float and code views (:func:`_float_fields`)."""
        self._table = table
        floats = self._float_at[-1] + 2
        raw = table.view(np.uint8).reshape(table.size, self.dtype.itemsize)
        self._floats: npt.NDArray[np.float64] = raw[:, : 8 * floats].view(np.float64)
        self._codes_table: npt.NDArray[np.uint8] = raw[:, 8 * floats :]

    def _next(self) -> int:
        """The index of the next tick's row (a free one, or the oldest row reused)."""
        size = self._table.size
        if self._count < size:
            index = (self._start + self._count) % size
            self._count += 1
        else:  # full: the oldest row is reused
            index = self._start
            self._start = (self._start + 1) % size
            self._dropped += 1
        return int(index)

    def _record(self, row: Any) -> CellRecord:
        errors = {n: float(e) for n, e in zip(self.commands, row["errors"], strict=True)
                  if not math.isnan(e)}  # fmt: skip
        return CellRecord(
            float(row["t"]), row["q"].copy(), row["qdot"].copy(), STATUSES[row["status"]],
            float(row["scale"]),
            "/".join(LEVEL_STATUSES[c] for c in row["levels"].tolist() if c != NONE), errors,
            {n: float(g) for n, g in zip(self.objects, row["grip"], strict=True)},
            float(row["chain"][0]), float(row["chain"][1]), MODES[row["mode"]],
        )  # fmt: skip


def _columns(names: tuple[str, ...], start: int) -> dict[str, tuple[int, ...]]:
    """Each name's columns in a row read as float64, its field starting at ``start``."""
    return {n: tuple(start + k for k, m in enumerate(names) if m == n) for n in names}


def _float_fields(dtype: np.dtype[Any]) -> tuple[slice, slice, int, slice, int]:
    """Where :class:`CellLog`'s float fields are in a row read as float64 (from ``t`` at 0,
    the row's first bytes): ``q``, ``qdot``, ``scale``, ``errors`` and ``grip`` (one after
    the other) and ``chain``.
    """  # noqa: D205
    at: list[slice] = []
    for name in ("q", "qdot", "scale", "errors", "grip", "chain"):
        field, offset = dtype.fields[name][:2]  # type: ignore[index]
        at.append(slice(offset // 8, (offset + field.itemsize) // 8))
    return at[0], at[1], at[2].start, slice(at[3].start, at[4].stop), at[5].start
