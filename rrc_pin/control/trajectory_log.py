"""TrajectoryLog: what a controller did at every tick, saved to CSV or NPZ and loaded back."""

from __future__ import annotations

import csv
from collections.abc import Callable
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np
import numpy.typing as npt

from rrc_pin.errors import InvalidInput

Array = npt.NDArray[np.float64]
TWIST = ("vx", "vy", "vz", "wx", "wy", "wz")
TEXT = ("mode", "method", "status", "active", "singularity", "note")
"""Text columns (the rest are numbers)."""


class LogRecord(NamedTuple):
    """One tick of a controller.

    Attributes:
        t: Time at the start of the tick [s].
        q: Joint positions at the start of the tick (nq,) [rad or m].
        qdot: Joint rates applied over the tick (nq,) [rad/s or m/s].
        commanded: The operator's command (speed override and deadman applied), base axes
            (``world_aligned``) (6,) [m/s, rad/s].
        achieved: The tool twist the rates produce, ``J qdot``, ``world_aligned`` (6,).
        scale: The resolution's scale, in [0, 1].
        factor: The strategy's speed factor, in [0, 1].
        sigma_min: Smallest singular value of the task Jacobian at ``q``.
        manipulability: Product of its singular values.
        drift_position: Distance [m] from the reference pose at the start of the tick.
        drift_rotation: Angle [rad] from the reference orientation (Nguyen eq. (37) norm).
        mode: ``"teleop"`` or ``"reverse"``.
        method: The resolution's method (``qp``, ``scipy``, ...).
        status: The resolution's status (``exact``, ``scaled``, ...).
        active: The active limits, ``joint:side:kind`` joined by ``;``.
        singularity: The singularity near (``SingularityLabel``), "" if none.
        note: What the strategy did.
    """

    t: float
    q: Array
    qdot: Array
    commanded: Array
    achieved: Array
    scale: float
    factor: float
    sigma_min: float
    manipulability: float
    drift_position: float
    drift_rotation: float
    mode: str
    method: str
    status: str
    active: str
    singularity: str
    note: str


VECTORS = ("q", "qdot", "commanded", "achieved")
SCALARS = ("t", "scale", "factor", "sigma_min", "manipulability", "drift_position",
           "drift_rotation")  # fmt: skip


class TrajectoryLog:
    """The records of one controller, in time order, with array views for analysis.

    A controller appends its ticks as they are (:meth:`append_tick`) and the log derives
    their records when it is read (``records``, :meth:`column`, :meth:`save`): what a record
    adds to a tick (the singular values, the singularity's name, the achieved twist, the
    resolution's status, scale and active limits) costs more than the rest of a controller's
    tick, and is paid once, when someone looks.

    Args:
        joint_names: Names of the joints (the CSV's column names).
        derive: Makes the record of a tick passed to :meth:`append_tick` (the controller's),
            or None for a log of records only.
    """

    def __init__(
        self, joint_names: list[str] | tuple[str, ...],
        derive: Callable[[Any], LogRecord] | None = None,
    ) -> None:  # fmt: skip
        self.joint_names = tuple(joint_names)
        self._records: list[LogRecord] = []
        self._ticks: list[tuple[Any, ...]] = []
        self._derive = derive

    def __len__(self) -> int:
        return len(self._records) + len(self._ticks)

    @property
    def records(self) -> list[LogRecord]:
        """Every record, in time order (the ticks appended so far derived now)."""
        if self._ticks:
            assert self._derive is not None  # append_tick refuses a log without derive
            self._records.extend(map(self._derive, self._ticks))
            self._ticks.clear()
        return self._records

    def append(self, record: LogRecord) -> None:
        """Add one tick's record."""
        self.records.append(record)

    def append_tick(self, tick: tuple[Any, ...]) -> None:
        """Add one tick, its record derived when the log is read (``derive``).

        Args:
            tick: What ``derive`` takes: a tuple that starts as its record, ``(t, q, ...)``.
        """
        if self._derive is None:
            raise InvalidInput("tick", "this log has no derive: append records")
        self._ticks.append(tick)

    def positions(self, n: int) -> list[Array]:
        """Joint positions ``q`` of the last ``n`` ticks, oldest first, no record derived.

        (What :meth:`Controller.reverse` retraces: reading ``records`` after a long session
        would derive every record first.)
        """
        ticks = self._ticks[len(self._ticks) - n:] if n > 0 else []
        rest = n - len(ticks)
        records = self._records[len(self._records) - rest:] if rest > 0 else []
        return [r.q for r in records] + [t[1] for t in ticks]  # a tick's (t, q, ...)

    def clear(self) -> None:
        """Forget every record."""
        self._records.clear()
        self._ticks.clear()

    def column(self, name: str) -> Array | npt.NDArray[np.str_]:
        """One field over every record: (N,) for scalars and text, (N, k) for vectors.

        Raises:
            InvalidInput: ``name`` is not a field of :class:`LogRecord` (the error lists them).
        """
        if name not in LogRecord._fields:
            columns = ", ".join(LogRecord._fields)
            raise InvalidInput("name", f"no column {name!r}; columns: {columns}")
        values = [getattr(r, name) for r in self.records]
        if name in TEXT:
            return np.array(values, dtype=str)
        width = len(self.joint_names) if name in ("q", "qdot") else 6
        if name in VECTORS:
            return np.array(values, dtype=np.float64).reshape(len(values), width)
        return np.array(values, dtype=np.float64)

    # -- files ----------------------------------------------------------------------------

    def header(self) -> list[str]:
        """The CSV's column names."""
        out = ["t"]
        out += [f"q:{n}" for n in self.joint_names] + [f"qdot:{n}" for n in self.joint_names]
        out += [f"commanded:{a}" for a in TWIST] + [f"achieved:{a}" for a in TWIST]
        return out + [s for s in SCALARS if s != "t"] + list(TEXT)

    def save(self, path: str | Path) -> Path:
        """Write the log to ``path``: ``.csv`` (one row per tick, a header) or ``.npz``.

        Raises:
            InvalidInput: ``path`` ends neither in ``.csv`` nor in ``.npz``.
            OSError: The file cannot be written.
        """
        path = Path(path)
        if path.suffix == ".npz":
            arrays: dict[str, Any] = {name: self.column(name) for name in LogRecord._fields}
            arrays["joint_names"] = np.array(self.joint_names, dtype=str)
            np.savez(path, **arrays)
            return path
        if path.suffix != ".csv":
            raise InvalidInput("path", f"expected a .csv or .npz file, got {str(path)!r}")
        with path.open("w", newline="") as f:
            writer = csv.writer(f)
            writer.writerow(self.header())
            for r in self.records:
                row = [repr(float(r.t))]
                row += [repr(float(v)) for v in (*r.q, *r.qdot, *r.commanded, *r.achieved)]
                row += [repr(float(getattr(r, s))) for s in SCALARS if s != "t"]
                writer.writerow(row + [getattr(r, s) for s in TEXT])
        return path

    @classmethod
    def load(cls, path: str | Path) -> TrajectoryLog:
        """A log read back from a file written by :meth:`save` (numbers exact: ``repr``).

        Raises:
            InvalidInput: ``path`` ends neither in ``.csv`` nor in ``.npz``, or its columns are
                not a log's.
            OSError: The file cannot be read.
        """
        path = Path(path)
        if path.suffix == ".npz":
            with np.load(path, allow_pickle=False) as data:
                names = [str(n) for n in data["joint_names"]]
                columns = {name: data[name] for name in LogRecord._fields}
        elif path.suffix == ".csv":
            names, columns = _read_csv(path)
        else:
            raise InvalidInput("path", f"expected a .csv or .npz file, got {str(path)!r}")
        log = cls(names)
        for i in range(len(columns["t"])):
            fields: dict[str, Any] = {name: _item(columns[name][i], name)
                                      for name in LogRecord._fields}  # fmt: skip
            log.append(LogRecord(**fields))
        return log


def _read_csv(path: Path) -> tuple[list[str], dict[str, Any]]:
    """Joint names and columns of a CSV log.

    Raises:
        InvalidInput: The header is not a log's.
    """
    with path.open(newline="") as f:
        reader = csv.reader(f)
        header = next(reader, [])
        rows = list(reader)
    names = [h[2:] for h in header if h.startswith("q:")]
    if header != TrajectoryLog(names).header():
        raise InvalidInput("path", f"{str(path)!r} does not hold a trajectory log")
    n, k = len(names), len(SCALARS) - 1
    numbers = np.array([r[: 1 + 2 * n + 12 + k] for r in rows], dtype=np.float64).reshape(
        len(rows), 1 + 2 * n + 12 + k
    )
    text = [r[1 + 2 * n + 12 + k:] for r in rows]
    widths = {"q": n, "qdot": n, "commanded": 6, "achieved": 6}
    columns: dict[str, Any] = {"t": numbers[:, 0]}
    at = 1
    for name in VECTORS:
        columns[name], at = numbers[:, at:at + widths[name]], at + widths[name]
    for name in SCALARS[1:]:
        columns[name], at = numbers[:, at], at + 1
    for j, name in enumerate(TEXT):
        columns[name] = [row[j] for row in text]
    return names, columns


def _item(value: Any, name: str) -> Any:
    """One record's field from a column of the NPZ file."""
    if name in TEXT:
        return str(value)
    if name in VECTORS:
        return np.array(value, dtype=np.float64)
    return float(value)
