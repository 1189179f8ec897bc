"""GripLimit: two frames held rigidly together (two hands on one object), as equality rows."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from rrc_pin.errors import FrameNotFound, InvalidInput
from rrc_pin.limits.chain_kernels import NO_POSES, UNMEASURED, grip_rows
from rrc_pin.limits.contact_limit import AXES, Closure
from rrc_pin.limits.frame_columns import FrameColumns
from rrc_pin.limits.limit import Limit
from rrc_pin.solvers.checks import names, rigid_transform
from rrc_pin.solvers.tick.problem import Constraints
from rrc_pin.tasks.frame_task import ROWS, row_units
from rrc_pin.tasks.relative_frame_task import RelativeFrameTask

if TYPE_CHECKING:
    from rrc_pin.kinematics import Kinematics, Layout

Array = npt.NDArray[np.float64]


class GripLimit(Limit):
    """Grips: for each pair ``(a, b)``, b's twist relative to a is zero (six equality rows).

    The rows are :class:`~rrc_pin.tasks.RelativeFrameTask`'s (its class docstring), held
    exactly at every answer, whatever the levels do (scaled, damped, traded): two hands on
    one object keep their grip to first order. With grips (b's pose in a to keep), every tick
    also measures how far each pair is from its grip (:attr:`last`, in a's axes): the
    integration's second-order remainder, which a cell's controller closes inside the step
    (:mod:`rrc_pin.cells.closure`).

    Args:
        pairs: ``(frame_a, frame_b)`` pairs.
        name: Name in the report; rows are named ``name:frame_b/frame_a:axis``.
        grips: Each pair's grip, b's pose in a (4, 4) [m], in ``pairs``' order, or None.

    Raises:
        InvalidInput: Not pairs of two different frame names, or grips that are not one
            rigid transform per pair.
    """

    def __init__(
        self, pairs: Sequence[tuple[str, str]] = (), name: str = "grip",
        grips: Sequence[npt.ArrayLike] | None = None,
    ) -> None:  # fmt: skip
        if not isinstance(name, str):
            raise InvalidInput("name", f"expected a string, got {name!r}")
        self.name = name
        self._layout: Layout | None = None
        self.set_pairs(pairs, grips)

    def set_pairs(
        self, pairs: Sequence[tuple[str, str]], grips: Sequence[npt.ArrayLike] | None = None
    ) -> None:
        """The pairs held from now on (an object grasped or released), and their grips.

        Args:
            pairs: ``(frame_a, frame_b)`` pairs.
            grips: Each pair's grip, b's pose in a (4, 4) [m], or None (no error measured).

        Raises:
            InvalidInput: Not pairs of two different frame names, or not one grip per pair;
                the limit is unchanged.
            FrameNotFound: A frame the robot (of the resolver holding it) does not have.
        """
        if not isinstance(pairs, (list, tuple)):
            raise InvalidInput("pairs", f"expected (frame_a, frame_b) pairs, got {pairs!r}")
        items = tuple(names(p, "pairs", 2) if not isinstance(p, str) else (p,) for p in pairs)
        for p in items:
            if len(p) != 2 or p[0] == p[1]:
                raise InvalidInput("pairs", f"expected (frame_a, frame_b) pairs, got {pairs!r}")
            if self._layout is not None:
                for frame in p:
                    if frame not in self._layout.frames:
                        raise FrameNotFound(frame, sorted(self._layout.frames), "pairs")
        if grips is not None and len(grips) != len(items):
            raise InvalidInput("grips", f"expected {len(items)} poses, got {len(grips)}")
        targets = [None] * len(items) if grips is None else [
            rigid_transform(T, f"grips[{i}]") for i, T in enumerate(grips)]  # fmt: skip
        self.pairs: tuple[tuple[str, str], ...] = items  # type: ignore[assignment]
        # gain 1: the rows' rates are then the grip's error itself (RelativeFrameTask.rows)
        self._tasks = tuple(RelativeFrameTask(a, b, target=T, gain=1.0)
                            for (a, b), T in zip(self.pairs, targets, strict=True))  # fmt: skip
        self._measured = grips is not None and bool(items)
        self._names = tuple(f"{self.name}:{b}/{a}:{x}" for a, b in self.pairs for x in AXES)
        self._grips = NO_POSES if grips is None else np.array(targets).reshape(-1, 4, 4)
        # the robot's layout, the frames' columns on its model and the rows' units
        self._prepared_for: tuple[Layout, FrameColumns, Array] | None = None
        self._zero = np.zeros(6 * len(items))
        self.last: Closure | None = None
        """The rows and the grips' errors at the last configuration the limit saw (None
        without grips or pairs)."""

    def check(self, layout: Layout) -> None:
        """Refuse frames the robot does not have.

        Raises:
            FrameNotFound: Naming ``pairs`` and listing the robot's frames.
        """
        for pair in self.pairs:
            for frame in pair:
                if frame not in layout.frames:
                    raise FrameNotFound(frame, sorted(layout.frames), "pairs")
        self._layout = layout

    def constraints(self, kin: Kinematics, dt: float, previous: Array) -> Constraints:
        """The grip rows ``C qdot = 0`` (C: (6 k, nv)).

        One compiled call (:func:`~rrc_pin.limits.chain_kernels.grip_rows`) on the tick's
        joint Jacobians.
        """
        if not self.pairs:
            return Constraints()
        data = kin.data
        columns, unit = self.columns(kin)
        C = np.zeros((6 * len(self.pairs), kin.layout.nv))
        error = np.empty(C.shape[0]) if self._measured else UNMEASURED
        grip_rows(data.J, columns.steps, columns.starts, columns.poses(data), self._grips, C,
                  error)  # fmt: skip
        return self.rows_of(C, error, unit)

    @property
    def grips(self) -> Array:
        """The pairs' grips (k, 4, 4) [m], b's pose in a; (0, 4, 4) where none is measured."""
        return self._grips

    def rows_of(self, C: Array, error: Array, unit: Array) -> Constraints:
        """The constraints of the rows ``C`` (6 k, nv) and the grips' errors ``error`` (6 k,)
        [m, rad] of units ``unit`` (:meth:`columns`) at a tick: those :meth:`constraints`
        computes, or a cell's compiled tick (:mod:`rrc_pin.cells.cell_kernels`); kept in
        :attr:`last` where the grips are measured.
        """  # noqa: D205
        if self._measured:
            self.last = Closure(C, error, unit)
        return Constraints(C=C, d=self._zero, names=self._names)

    def columns(self, kin: Kinematics) -> tuple[FrameColumns, Array]:
        """The pairs' frames' columns on the tick's model (a, b of each pair) and the rows'
        units (each pair's :meth:`~rrc_pin.tasks.RelativeFrameTask.reach`), made once per
        robot layout."""  # noqa: D205, D209
        prepared = self._prepared_for
        if prepared is None or prepared[0] is not kin.layout:
            layout = kin.layout
            frames = [layout.frames[f] for pair in self.pairs for f in pair]
            unit = np.concatenate([row_units(ROWS["full"], t.reach(layout)) for t in self._tasks])
            prepared = self._prepared_for = (layout, FrameColumns.of(kin.model, kin.data, frames),
                                             unit)  # fmt: skip
        return prepared[1], prepared[2]
