"""TrajectoryLog: what a controller did at every tick, saved to CSV or NPZ and loaded back.

The log is a :class:`~rrc_pin.control.record_ring.RecordRing`: it keeps the last
:data:`CAPACITY` ticks (10 minutes at 100 Hz) as columns of arrays and forgets the oldest
beyond, so that its memory is bounded however long a controller runs: ``8 (19 + 2 nq) + 56``
bytes a tick (the numbers, and a pointer per text field), 320 B for a 7-joint arm, 19.2 MB at
the default capacity (docs/api.md, "The trajectory log's memory").
"""

from __future__ import annotations

import csv
import os
import zipfile
from collections.abc import Callable
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np
import numpy.typing as npt

from rrc_pin.control.record_ring import CAPACITY as CAPACITY  # where the logs import it
from rrc_pin.control.record_ring import RecordRing as RecordRing
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


class TrajectoryLog(RecordRing[LogRecord]):
    """The records of one arm's controller (:class:`LogRecord`), with array views and files.

    A :class:`RecordRing` (its ring, lazy records and ``positions``): what a record adds to
    a tick (the kinematics at q: the singular values, the singularity's name, the achieved
    twist) costs more than the rest of a controller's tick, and is paid once, when someone
    looks. Save it (:meth:`save`) before it fills to
    keep a whole session; ``Controller.reverse`` retraces within what is kept.

    Args:
        joint_names: Names of the joints (the CSV's column names).
        derive: Makes the record of a tick passed to :meth:`append_tick` (the controller's),
            or None for a log of records only.
        capacity: Ticks kept, >= 1 (default :data:`CAPACITY`: 10 minutes at 100 Hz).

    Raises:
        InvalidInput: ``joint_names`` not a sequence of names, ``derive`` not callable, or a
            bad ``capacity``, named.
    """

    record_type = LogRecord

    def __init__(
        self, joint_names: list[str] | tuple[str, ...],
        derive: Callable[[Any], LogRecord] | None = None,
        capacity: int = CAPACITY,
    ) -> None:  # fmt: skip
        if isinstance(joint_names, str) or not isinstance(joint_names, (list, tuple)) or not all(
            isinstance(n, str) for n in joint_names
        ):
            raise InvalidInput("joint_names", f"expected a list of names, got {joint_names!r}")
        super().__init__(derive, capacity)
        self.joint_names = tuple(joint_names)

    def column(self, name: str) -> Array | npt.NDArray[np.str_]:
        """One field over every record: (N,) for scalars and text, (N, k) for vectors.

        Raises:
            InvalidInput: ``name`` is not a field of :class:`LogRecord` (the error lists them).
        """
        if not isinstance(name, str) or name not in LogRecord._fields:
            columns = ", ".join(LogRecord._fields)
            raise InvalidInput("name", f"no column {name!r}; columns: {columns}")
        values = self.column_values(name)
        if name in TEXT:
            return np.array(values.tolist(), dtype=str)
        if name in VECTORS:
            width = len(self.joint_names) if name in ("q", "qdot") else 6
            return np.asarray(values, dtype=np.float64).reshape(len(values), width)
        return np.asarray(values, dtype=np.float64)

    # -- files ----------------------------------------------------------------------------

    def header(self) -> list[str]:
        """The CSV's column names."""
        out = ["t"]
        out += [f"q:{n}" for n in self.joint_names] + [f"qdot:{n}" for n in self.joint_names]
        out += [f"commanded:{a}" for a in TWIST] + [f"achieved:{a}" for a in TWIST]
        return out + [s for s in SCALARS if s != "t"] + list(TEXT)

    def save(self, path: str | os.PathLike[str]) -> Path:
        """Write the log to ``path``: ``.csv`` (one row per tick, a header) or ``.npz``.

        Raises:
            InvalidInput: Naming ``path``: not a path, ending neither in ``.csv`` nor in
                ``.npz``, or a file that cannot be written (a missing folder, no permission:
                the system's reason).
        """
        path = checked_path(path)
        try:
            if path.suffix == ".npz":
                arrays: dict[str, Any] = {name: self.column(name) for name in LogRecord._fields}
                arrays["joint_names"] = np.array(self.joint_names, dtype=str)
                with path.open("wb") as f:  # np.savez(path) would add ".npz" to other names
                    np.savez(f, **arrays)
                return path
            with path.open("w", newline="") as f:
                writer = csv.writer(f)
                writer.writerow(self.header())
                for r in self.records:
                    row = [repr(float(r.t))]
                    row += [repr(float(v)) for v in (*r.q, *r.qdot, *r.commanded, *r.achieved)]
                    row += [repr(float(getattr(r, s))) for s in SCALARS if s != "t"]
                    writer.writerow(row + [getattr(r, s) for s in TEXT])
        except OSError as exc:
            raise InvalidInput("path", f"cannot write {str(path)!r}: {reason(exc)}") from exc
        return path

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> TrajectoryLog:
        """A log read back from a file written by :meth:`save` (numbers exact: ``repr``).

        Its capacity holds every record of the file (at least :data:`CAPACITY`).

        Raises:
            InvalidInput: Naming ``path``: not a path, ending neither in ``.csv`` nor in
                ``.npz``, a file that cannot be read (missing, a folder, no permission), or
                whose contents are not a log's (the first thing that is not, said).
        """
        path = checked_path(path)
        try:
            if path.suffix == ".npz":
                with np.load(path, allow_pickle=False) as data:
                    missing = [k for k in ("joint_names", *LogRecord._fields) if k not in data]
                    if missing:
                        raise _NotALog(f"no field {missing[0]!r}")
                    names = [str(n) for n in data["joint_names"]]
                    columns = {name: data[name] for name in LogRecord._fields}
            else:
                names, columns = _read_csv(path)
            log = cls(names, capacity=max(CAPACITY, len(columns["t"])))
            for i in range(len(columns["t"])):
                fields: dict[str, Any] = {name: _item(columns[name][i], name, len(names))
                                          for name in LogRecord._fields}  # fmt: skip
                log.append(LogRecord(**fields))
        except OSError as exc:
            raise InvalidInput("path", f"cannot read {str(path)!r}: {reason(exc)}") from exc
        except (_NotALog, ValueError, TypeError, KeyError, IndexError, EOFError, csv.Error,
                zipfile.BadZipFile) as exc:  # fmt: skip
            raise InvalidInput(
                "path", f"{str(path)!r} does not hold a trajectory log ({reason(exc)})"
            ) from exc
        return log


class _NotALog(Exception):
    """A file's contents are not a trajectory log's (turned into InvalidInput by ``load``)."""


def checked_path(path: str | os.PathLike[str]) -> Path:
    """``path`` as a Path ending in ``.csv`` or ``.npz``.

    Raises:
        InvalidInput: Not a str or os.PathLike, or another suffix (named ``path``).
    """
    if not isinstance(path, (str, os.PathLike)) or not os.fspath(path):
        raise InvalidInput("path", f"expected a file name (str or os.PathLike), got {path!r}")
    out = Path(path)
    if out.suffix not in (".csv", ".npz"):
        raise InvalidInput("path", f"expected a .csv or .npz file, got {str(out)!r}")
    return out


def reason(exc: BaseException) -> str:
    """An exception's message without the path it repeats."""
    if isinstance(exc, OSError) and exc.strerror:
        return exc.strerror
    return str(exc) or type(exc).__name__


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
        raise _NotALog("its header is not a log's")
    n, k = len(names), len(SCALARS) - 1
    width = 1 + 2 * n + 12 + k
    for i, row in enumerate(rows):
        if len(row) != width + len(TEXT):
            raise _NotALog(f"row {i + 2} has {len(row)} fields, the header {width + len(TEXT)}")
    numbers = np.array([r[:width] for r in rows], dtype=np.float64).reshape(len(rows), width)
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


def _item(value: Any, name: str, nq: int) -> Any:
    """One record's field from a column of a file, checked.

    Raises:
        _NotALog: A vector of the wrong length, or text where numbers go.
    """
    if name in TEXT:
        return str(value)
    if name in VECTORS:
        out = np.array(value, dtype=np.float64)
        width = nq if name in ("q", "qdot") else 6
        if out.shape != (width,):
            raise _NotALog(f"{name} has shape {out.shape}, expected ({width},)")
        return out
    return float(value)
