"""RecordRing: a controller's last ticks as columns of arrays, their records derived when read.

A tick or a record is a tuple of named fields (a ``NamedTuple``: a tick's field names are
those of the record fields it fills). Each field is one column, made at the first value it
gets: a float is a float64 column, an array of numbers a (rows, *shape) column of its dtype,
anything else (text, a mapping) an object column whose equal strings share one object. A
row is then its numbers and a pointer per text field: a few hundred bytes a tick for an arm
(docs/api.md, "The trajectory log's memory"), not the objects a tick was made of. A value
that does not fit its column (another shape, a None) turns that column into an object
column: nothing is refused or lost. A tick's fields are written into their row as it comes,
its record derived when the ring is read: every tick costs the same.

Each column is made at the capacity's rows, then the ring overwrites its oldest rows: no tick
copies the rows kept (docs/api.md, "The trajectory log's memory"). A column of numbers is
memory the OS maps a small page at a time as rows are first written (:func:`rows_array`), so
the memory in use grows with the ticks written.
"""

from __future__ import annotations

import contextlib
import math
import mmap
from collections.abc import Callable, Iterator
from typing import Any, Generic, NamedTuple, TypeVar

import numpy as np
import numpy.typing as npt

from rrc_pin.errors import InvalidInput

Array = npt.NDArray[np.float64]
R = TypeVar("R", bound=tuple[Any, ...])

CAPACITY = 60_000
"""Ticks a log keeps by default: 10 minutes at 100 Hz (:attr:`RecordRing.capacity`)."""

SHARED_TEXTS = 4096
"""Distinct strings a ring shares between its rows (more are kept as they come)."""


class Plan(NamedTuple):
    """The columns of a kind of entry, by kind of column, each with its field's position."""

    numbers: list[tuple[int, npt.NDArray[np.float64]]]
    """float64 columns."""
    arrays: list[tuple[int, npt.NDArray[Any], tuple[int, ...], np.dtype[Any]]]
    """Array columns, with their row shape and dtype."""
    objects: list[tuple[int, npt.NDArray[Any]]]
    """Object columns."""


class RecordRing(Generic[R]):
    """The last ticks of a controller, in time order: a ring of records derived when read.

    What every controller's log shares (:class:`~rrc_pin.control.TrajectoryLog` for one
    arm, :class:`~rrc_pin.cells.controller.CellLog` for a cell): a controller appends its
    ticks as they are (:meth:`append_tick`) and the log derives their records when it is
    read (``records``, in place: once); the ring keeps the last ``capacity`` ticks
    (appending to a full log forgets the oldest, :attr:`dropped` counts them), and
    :meth:`positions` gives the joint positions ``Controller.reverse`` retraces without
    deriving a record. Storage: the module docstring.

    Args:
        derive: Makes the record of a tick (the controller's), or None for a log of records
            only.
        capacity: Ticks kept, >= 1 (default :data:`CAPACITY`: 10 minutes at 100 Hz);
            settable (a smaller one forgets the oldest ticks at once).

    Raises:
        InvalidInput: ``derive`` not callable, or a bad ``capacity``, named.
    """

    record_type: type[tuple[Any, ...]] = tuple
    """The records' class (:meth:`append` refuses others); a record's second field is q."""

    def __init__(self, derive: Callable[[Any], R] | None = None, capacity: int = CAPACITY
                 ) -> None:  # fmt: skip
        if derive is not None and not callable(derive):
            raise InvalidInput("derive", f"expected a callable or None, got {derive!r}")
        self._capacity = _checked_capacity(capacity)
        self._derive = derive
        self._columns: dict[str, npt.NDArray[Any]] = {}
        self._rows = self._capacity  # rows every column has
        self._start = 0  # the row of the oldest entry
        self._size = 0
        self._pending = 0  # the newest entries, ticks not yet derived
        self._tick: tuple[type, tuple[str, ...]] | None = None  # the ticks' class and fields
        self._fields: tuple[str, ...] = getattr(self.record_type, "_fields", ())  # records'
        self._texts: dict[str, str] = {}  # one object per string (SHARED_TEXTS of them)
        self._plans: dict[tuple[type, int], Plan] = {}  # per kind of entry, its columns
        self._dropped = 0

    @property
    def dropped(self) -> int:
        """Ticks forgotten because the log was full (the oldest first)."""
        return self._dropped

    def __len__(self) -> int:
        return self._size

    def __iter__(self) -> Iterator[R]:
        return iter(self.records)

    @property
    def capacity(self) -> int:
        """Ticks kept (the oldest forgotten beyond), >= 1."""
        return self._capacity

    @capacity.setter
    def capacity(self, value: int) -> None:
        value = _checked_capacity(value)
        keep = min(self._size, value)
        self._dropped += self._size - keep
        order = self._order()[self._size - keep:]
        for name, column in self._columns.items():
            fresh = rows_array((value, *column.shape[1:]), column.dtype)
            fresh[:keep] = column[order]
            self._columns[name] = fresh
        self._plans.clear()
        self._rows = value
        self._start, self._size = 0, keep
        self._pending = min(self._pending, keep)
        self._capacity = value

    @property
    def nbytes(self) -> int:
        """Bytes of the columns, each of the capacity's rows: the numbers, and a pointer a row
        for a column of objects (the objects not counted)."""  # noqa: D205, D209
        return sum(int(column.nbytes) for column in self._columns.values())

    @property
    def records(self) -> list[R]:
        """The records kept, in time order, as a new list (the ticks pending derived now)."""
        self._derive_pending()
        return [self._record(row) for row in self._order().tolist()]

    def __getitem__(self, index: int) -> R:
        """Record ``index`` (negative from the newest), without making the others.

        Raises:
            IndexError: No such record.
        """
        if isinstance(index, bool) or not isinstance(index, (int, np.integer)):
            raise TypeError(f"record indices are integers, not {type(index).__name__}")
        self._derive_pending()
        if not -self._size <= index < self._size:
            raise IndexError(f"record {index} of {self._size}")
        return self._record(self._row(int(index) % self._size))

    def append(self, record: R) -> None:
        """Add one tick's record (forgetting the oldest tick when the log is full).

        Raises:
            InvalidInput: ``record`` is not a :attr:`record_type`.
        """
        if not isinstance(record, self.record_type):
            raise InvalidInput("record", f"expected a {self.record_type.__name__}, got "
                               f"{type(record).__name__}")  # fmt: skip
        self._derive_pending()  # they are older
        self._fields = self._fields or _fields(record)
        self._store(self._push(), record)

    def append_tick(self, tick: Any) -> None:
        """Add one tick, its record derived when the log is read (``derive``).

        Args:
            tick: What ``derive`` takes: a tuple that starts as its record, ``(t, q, ...)`` (a
                ``NamedTuple`` whose field names are those of the record it fills).
        """
        if self._derive is None:
            raise InvalidInput("tick", "this log has no derive: append records")
        if self._tick is None or type(tick) is not self._tick[0]:
            self._tick = (type(tick), _fields(tick))
        self._store(self._push(), tick)
        self._pending = min(self._pending + 1, self._size)

    def positions(self, n: int) -> list[Array]:
        """Joint positions ``q`` of the last ``n`` ticks kept, oldest first, no record derived.

        (What ``Controller.reverse`` retraces: reading ``records`` after a long session
        would derive every record first.)

        Raises:
            InvalidInput: ``n`` is not an integer >= 0.
        """
        if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 0:
            raise InvalidInput("n", f"expected an integer >= 0, got {n!r}")
        n = min(int(n), self._size)
        if not n:
            return []
        column = self._columns[self._q_name()]
        return [_value(column, row) for row in self._order()[self._size - n:].tolist()]

    def clear(self) -> None:
        """Forget every record (the columns are kept for the next ones)."""
        self._start = self._size = self._pending = 0

    def column_values(self, name: str) -> npt.NDArray[Any]:
        """Field ``name`` of every record kept, in time order: a new (N, ...) array.

        Raises:
            KeyError: No record has that field.
        """
        self._derive_pending()
        if not self._size:
            return np.empty(0)
        return self._columns[name][self._order()]

    # -- storage -----------------------------------------------------------------------------

    def _order(self) -> npt.NDArray[np.intp]:
        """The rows of the entries kept, oldest first."""
        return (self._start + np.arange(self._size)) % self._rows

    def _row(self, i: int) -> int:
        """The row of entry ``i`` (0 the oldest)."""
        return (self._start + i) % self._rows

    def _push(self) -> int:
        """The row of a new newest entry: a free one, else the oldest's, forgotten."""
        if self._size < self._capacity:
            self._size += 1
            return (self._start + self._size - 1) % self._rows
        row = self._start  # a full ring has as many rows as its capacity
        self._start = (row + 1) % self._rows
        self._dropped += 1
        return row

    def _store(self, row: int, entry: tuple[Any, ...]) -> None:
        """Write ``entry``'s fields into ``row`` of their columns."""
        key = (type(entry), len(entry))  # plain tuples: their length tells them apart
        plan = self._plans.get(key)
        if plan is None:
            plan = self._plans[key] = self._plan(entry)
        if not self._write(plan, row, entry):
            self._plans.clear()  # a value its column cannot hold: the column holds objects now
            self._store_slowly(row, entry)

    def _write(self, plan: Plan, row: int, entry: tuple[Any, ...]) -> bool:
        """Write ``entry``'s fields into ``row`` of ``plan``'s columns, until a value does not
        fit its column; whether they all did.
        """  # noqa: D205
        for i, column in plan.numbers:
            value = entry[i]
            if type(value) is not float and not isinstance(value, np.floating):
                return False
            column[row] = value
        for i, array, shape, dtype in plan.arrays:
            value = entry[i]
            if (type(value) is not np.ndarray or value.shape != shape
                    or (value.dtype is not dtype and value.dtype != dtype)):  # fmt: skip
                return False
            array[row] = value
        texts = self._texts
        for i, objects in plan.objects:
            value = entry[i]
            if type(value) is str:  # one object per string
                shared = texts.get(value)
                if shared is not None:
                    value = shared
                elif len(texts) < SHARED_TEXTS:
                    texts[value] = value
            objects[row] = value
        return True

    def _plan(self, entry: tuple[Any, ...]) -> Plan:
        """The columns of ``entry``'s fields (made where missing), by kind."""
        plan = Plan([], [], [])
        for i, (name, value) in enumerate(zip(_fields(entry), entry, strict=True)):
            column = self._columns.get(name)
            if column is None:
                column = self._columns[name] = _column_for(value, self._rows)
            if column.dtype == object:
                plan.objects.append((i, column))
            elif column.ndim == 1:
                plan.numbers.append((i, column))
            else:
                plan.arrays.append((i, column, column.shape[1:], column.dtype))
        return plan

    def _store_slowly(self, row: int, entry: tuple[Any, ...]) -> None:
        """:meth:`_store` where a column must first become an object column."""
        for name, value in zip(_fields(entry), entry, strict=True):
            column = self._columns.get(name)
            if column is None:
                column = self._columns[name] = _column_for(value, self._rows)
            elif not _fits(column, value):
                column = self._columns[name] = self._as_objects(column)
            column[row] = value

    def _as_objects(self, column: npt.NDArray[Any]) -> npt.NDArray[Any]:
        """``column`` as an object column holding the same values."""
        out = np.empty(self._rows, dtype=object)
        for row in self._order().tolist():
            out[row] = _value(column, row)
        return out

    def _record(self, row: int) -> R:
        """The record stored in ``row`` (new arrays: the ring reuses its rows)."""
        values = (_value(self._columns[name], row) for name in self._fields)
        if self.record_type is tuple:
            return tuple(values)  # type: ignore[return-value]
        return self.record_type(*values)  # type: ignore[return-value]

    def _derive_pending(self) -> None:
        """Turn the ticks not yet derived into their records, in their rows."""
        if not self._pending:
            return
        assert self._derive is not None and self._tick is not None  # append_tick's checks
        kind, names = self._tick
        for row in self._order()[self._size - self._pending:].tolist():
            values = [_value(self._columns[n], row) for n in names]
            record = self._derive(kind(*values) if hasattr(kind, "_fields") else kind(values))
            self._fields = self._fields or _fields(record)
            self._store(row, record)
        self._pending = 0

    def _q_name(self) -> str:
        """The name of the entries' second field, q (a record's, else a tick's)."""
        names = self._fields or (self._tick[1] if self._tick is not None else ())
        return names[1]


def _fields(entry: tuple[Any, ...]) -> tuple[str, ...]:
    """An entry's field names: a NamedTuple's, else its positions."""
    names: tuple[str, ...] | None = getattr(entry, "_fields", None)
    return names if names is not None else tuple(str(i) for i in range(len(entry)))


def _column_for(value: Any, rows: int) -> npt.NDArray[Any]:
    """An empty column of ``rows`` rows for values like ``value`` (module docstring)."""
    if isinstance(value, (float, np.floating)):
        return rows_array((rows,), np.dtype(np.float64))
    if isinstance(value, np.ndarray) and value.dtype.kind in "biuf":
        return rows_array((rows, *value.shape), value.dtype)
    return np.empty(rows, dtype=object)


def _fits(column: npt.NDArray[Any], value: Any) -> bool:
    """Whether ``value`` is stored in ``column`` as it is."""
    if column.dtype == object:
        return True
    if column.ndim == 1:
        return isinstance(value, (float, np.floating))
    return (isinstance(value, np.ndarray) and value.shape == column.shape[1:]
            and value.dtype == column.dtype)  # fmt: skip


def _value(column: npt.NDArray[Any], row: int) -> Any:
    """The value in ``row``: a float, a new array, or the object stored."""
    if column.dtype == object:
        return column[row]
    if column.ndim == 1:
        return float(column[row])
    return column[row].copy()


def _checked_capacity(value: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
        raise InvalidInput("capacity", f"expected an integer >= 1 (ticks), got {value!r}")
    return int(value)


def rows_array(shape: tuple[int, ...], dtype: np.dtype[Any]) -> npt.NDArray[Any]:
    """An array of ``shape``, not initialised, on memory the OS maps as it is first written.

    A small page at a time (a log writes each row before it reads it): an anonymous ``mmap``
    declining transparent huge pages (``MADV_NOHUGEPAGE``, where the OS has them). numpy asks
    Linux for huge pages for an array of 4 MB or more, and a tick that wrote the first row of a
    fresh 2 MB page waited while the kernel compacted memory for one (docs/api.md, "The
    trajectory log's memory").
    """
    size = math.prod(shape) * dtype.itemsize
    if size == 0 or dtype.hasobject:
        return np.empty(shape, dtype)
    # private: a process forked from this one writes into copies of the pages, not these
    pages = (mmap.mmap(-1, size, flags=mmap.MAP_PRIVATE) if hasattr(mmap, "MAP_PRIVATE")
             else mmap.mmap(-1, size))  # fmt: skip
    if hasattr(mmap, "MADV_NOHUGEPAGE"):
        with contextlib.suppress(OSError):  # a kernel without transparent huge pages
            pages.madvise(mmap.MADV_NOHUGEPAGE)
    return np.frombuffer(pages, dtype).reshape(shape)
