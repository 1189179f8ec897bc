"""FrameTask: a commanded twist of one frame of the robot, optionally toward a target pose."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from rrc_pin.errors import InvalidInput
from rrc_pin.kinematics import Kinematics, Layout
from rrc_pin.solvers.checks import all_finite, as_vector, positive, real_array, rigid_transform
from rrc_pin.solvers.exp_log import pose_error
from rrc_pin.solvers.spatial import Reference, check_reference
from rrc_pin.solvers.tick.problem import TaskRows
from rrc_pin.tasks.task import Task, check_weight, task_name

Array = npt.NDArray[np.float64]

_F64 = np.dtype(np.float64)

ROWS: dict[str, tuple[int, ...]] = {
    "full": (0, 1, 2, 3, 4, 5),
    "position": (0, 1, 2),
    "orientation": (3, 4, 5),
}
"""Named row selections of the [v; w] twist."""


class FrameTask(Task):
    r"""The twist ``[v; w]`` of frame ``frame``, in the reference frame ``ref``.

    With a ``target`` pose :math:`T^* = (R^*, p^*)` (pink's and mink's ``set_target``) the
    commanded twist is a feed-forward, and the pose error is fed back:

    .. math:: b = \nu_{ff} + k\,[p^* - p;\ \log(R^* R^T)]

    (the error in base axes at the frame's origin, expressed in ``ref`` like the twist), so
    that a commanded frame follows its target without drift. Advance the target with the
    feed-forward each tick (:meth:`set_target`), or hold it still with a zero twist.

    Args:
        frame: Name of a frame of the robot (e.g. its tool frame).
        twist: Commanded twist (6,) [m/s, rad/s], or only the selected rows; default zero
            (hold the frame still).
        ref: ``world_aligned`` (default: velocity of the frame's origin in base axes),
            ``local`` (the same in the frame's axes; Barker's hand-frame commands) or
            ``world`` (spatial velocity at the base origin, full rows only: its linear part
            is not the frame's velocity).
        rows: ``"full"``, ``"position"`` (rows 0:3), ``"orientation"`` (3:6), a boolean
            mask (6,) or row indices.
        weight: Cost > 0 of the squared residual, scalar or one per selected row.
        name: Name in the report (default the frame's).
        target: Pose (4, 4) of the frame in the base frame to hold [m], or None.
        gain: k > 0 [1/s], the fraction of the pose error corrected per second.

    Raises:
        InvalidInput: A bad twist, ref, rows, weight, target or gain, or ``world`` with
            partial rows.
    """

    def __init__(
        self,
        frame: str,
        twist: npt.ArrayLike | None = None,
        *,
        ref: Reference = "world_aligned",
        rows: str | Sequence[int] | Sequence[bool] = "full",
        weight: float | npt.ArrayLike = 1.0,
        name: str | None = None,
        target: npt.ArrayLike | None = None,
        gain: float = 10.0,
    ) -> None:
        if not isinstance(frame, str):
            raise InvalidInput("frame", f"expected a frame name, got {frame!r}")
        self.target: Array | None = None if target is None else rigid_transform(target, "target")
        self.gain = positive(gain, "gain")
        self.frame = frame
        self.selected = task_rows(rows)
        self.ref = self.check_ref(ref)
        self.weight = check_weight(weight, len(self.selected))
        self.name = frame if name is None else task_name(name)
        self.twist = np.zeros(len(self.selected)) if twist is None else self.check_twist(twist)

    def set_twist(self, twist: npt.ArrayLike) -> None:
        """Command a new twist (checked as at construction): keep a task across ticks.

        Raises:
            InvalidInput: Wrong shape or a non-finite entry; the task is then unchanged.
        """
        self.twist = self.check_twist(twist)

    def set_target(self, target: npt.ArrayLike | None) -> None:
        """Hold the frame at pose ``target`` (4, 4) in the base frame [m], or None for none.

        Raises:
            InvalidInput: Not a rigid transform; the task is then unchanged.
        """
        self.target = None if target is None else rigid_transform(target, "target")

    def error(self, pose: Array) -> Array:
        """The pose error (6,) ``[p* - p; log(R* R^T)]`` [m, rad] in base axes.

        Zero without a target; ``pose`` (4, 4) is the frame's.
        """
        out = np.zeros(6)
        if self.target is not None:
            pose_error(self.target, pose, out)
        return out

    def check_twist(self, twist: npt.ArrayLike) -> Array:
        """``twist`` as the selected rows: (6,) or (rows,) finite, a new array (the task's own).

        Raises:
            InvalidInput: Wrong shape or a non-finite entry.
        """
        m = len(self.selected)
        if (type(twist) is np.ndarray and twist.dtype is _F64 and twist.shape == (m,)
                and all_finite(twist)):  # the common case  # fmt: skip
            checked: Array = twist.copy()
            return checked
        twist = real_array(twist, "twist", "expected a real (6,) twist")
        size = twist.shape
        if size == (6,) and m != 6:
            return self.selected_rates(as_vector(twist, "twist", 6))
        if size != (m,):
            want = "(6,)" if m == 6 else f"(6,) or ({m},)"
            raise InvalidInput("twist", f"expected shape {want}, got {size}")
        own: Array = as_vector(twist, "twist", m).copy()
        return own

    def selected_rates(self, twist: Array) -> Array:
        """The selected rows' rates of a checked twist (6,), a new array."""
        rates: Array = twist.copy() if len(self.selected) == 6 else twist[list(self.selected)]
        return rates

    def check_ref(self, ref: str) -> Reference:
        """``ref`` if it names a reference frame that this task's rows can use.

        Raises:
            InvalidInput: An unknown name, or ``world`` with partial rows.
        """
        checked = check_reference(ref)
        if checked == "world" and len(self.selected) != 6:
            raise InvalidInput(
                "ref",
                "'world' is the spatial velocity at the base origin: its linear part is not "
                "the frame's velocity, so partial rows cannot use it; use 'world_aligned'",
            )
        return checked

    def frames(self) -> tuple[str, ...]:
        """The commanded frame."""
        return (self.frame,)

    def check(self, layout: Layout) -> None:
        """Refuse a frame the robot does not have (:meth:`Task.check`, its one frame first).

        Raises:
            FrameNotFound: The error lists the robot's frames.
        """
        if self.frame not in layout.frames:
            super().check(layout)

    def rows(self, kin: Kinematics) -> TaskRows:
        """The frame's Jacobian rows and the commanded twist."""
        return self.rows_at(kin, self.twist, self.ref)

    def rows_at(self, kin: Kinematics, b: Array, ref: Reference) -> TaskRows:
        """The task's rows in frame ``ref`` with the selected rates ``b`` (checked by the caller).

        What :meth:`rows` gives for a twist ``b`` of this tick (``Resolver.solve(q, twist)``),
        plus the target's feedback (class docstring) when the task holds one.
        """
        if self.target is not None:
            pose = kin.pose(self.frame)
            error = self.error(pose)  # base axes, at the frame's origin
            if ref == "local":
                R = pose[:3, :3]
                error = np.concatenate([R.T @ error[:3], R.T @ error[3:]])
            elif ref == "world":  # spatial velocity at the base origin
                error[:3] += np.cross(pose[:3, 3], error[3:])
            b = b + self.gain * (error if len(self.selected) == 6 else self.selected_rates(error))
        return self.rows_from(kin.jacobian(self.frame, ref), b, kin.layout.reach[self.frame])

    def rows_from(self, J: Array, b: Array, reach: float) -> TaskRows:
        """The task's rows from a full (6, nv) Jacobian ``J`` and the selected rates ``b``.

        Args:
            J: The frame's Jacobian (6, nv).
            b: The selected rates.
            reach: The frame's reach [m], the unit of the linear rows.
        """
        selected = self.selected
        if len(selected) != 6:
            J = _picked(J, selected)
        weights = self._row_weights(len(selected))
        return TaskRows(J, b, weights, self.name, row_units(selected, reach))


_RUNS: dict[tuple[int, ...], slice | None] = {}


def _picked(J: Array, selected: tuple[int, ...]) -> Array:
    """The ``selected`` rows of ``J`` (6, nv), a new array: ``J[list(selected)]``, as a slice's
    copy (the same values and layout) where they are consecutive and ``J`` C-contiguous."""  # noqa: D205, D209
    run = _RUNS.get(selected, False)
    if run is False:
        consecutive = bool(selected) and list(selected) == list(range(selected[0],
                                                                      selected[-1] + 1))
        run = _RUNS[selected] = slice(selected[0], selected[-1] + 1) if consecutive else None
    if run is not None and J.flags.c_contiguous:
        rows: Array = J[run].copy()
        return rows
    return J[list(selected)]


_UNITS: dict[tuple[tuple[int, ...], float], Array] = {}


def row_units(selected: tuple[int, ...], reach: float) -> Array:
    """The rows' units: the reach [m] for linear rows, 1 for angular ones.

    Read-only, made once per selection and reach: the tasks built at every tick share them.
    """
    unit = _UNITS.get((selected, reach))
    if unit is None:
        unit = np.array([reach if r < 3 else 1.0 for r in selected])
        unit.flags.writeable = False
        _UNITS[(selected, reach)] = unit
    return unit


def task_rows(rows: str | Sequence[int] | Sequence[bool]) -> tuple[int, ...]:
    """Row indices of a row selection (:class:`FrameTask`).

    Raises:
        InvalidInput: An unknown name, a mask not of shape (6,), repeated or out-of-range rows.
    """
    if isinstance(rows, str):
        if rows not in ROWS:
            raise InvalidInput(
                "rows", f"expected one of {', '.join(ROWS)} or indices, got {rows!r}"
            )
        return ROWS[rows]
    try:
        arr = np.asarray(rows)
    except (TypeError, ValueError) as exc:  # a ragged sequence
        raise InvalidInput("rows", f"expected row indices, got {rows!r}") from exc
    if arr.dtype == bool:
        if arr.shape != (6,):
            raise InvalidInput("rows", f"a boolean mask must have shape (6,), got {arr.shape}")
        selected = tuple(int(i) for i in np.flatnonzero(arr))
    elif arr.ndim == 1 and np.issubdtype(arr.dtype, np.integer):
        selected = tuple(int(i) for i in arr)
    else:
        raise InvalidInput("rows", f"expected row indices, got {rows!r}")
    repeated = len(set(selected)) != len(selected)
    if not selected or repeated or not all(0 <= r < 6 for r in selected):
        raise InvalidInput("rows", f"expected distinct rows in 0..5, got {rows!r}")
    return selected
