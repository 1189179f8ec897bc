"""ContactLimit: frames held fixed in the world (feet in support), as equality rows."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
import numpy.typing as npt

from rrc_pin.errors import FrameNotFound, InvalidInput
from rrc_pin.limits.chain_kernels import NO_POSES, UNMEASURED, contact_rows
from rrc_pin.limits.frame_columns import FrameColumns
from rrc_pin.limits.limit import Limit
from rrc_pin.solvers.checks import names, rigid_transform
from rrc_pin.solvers.tick.problem import Constraints

if TYPE_CHECKING:
    from rrc_pin.kinematics import Kinematics, Layout

Array = npt.NDArray[np.float64]

AXES = ("vx", "vy", "vz", "wx", "wy", "wz")


class Closure(NamedTuple):
    r"""Closed chains at one tick's configuration: their rows and how far each is open.

    Attributes:
        C: The chains' equality rows (6 k, nv), ``C qdot = 0``.
        error: Each chain's pose error to its goal (6 k,) [m, rad], ``[p* - p; log(R* R^T)]``
            in the rows' axes: a step of rates :math:`\dot q` changes it by
            :math:`-C\dot q\,\Delta t` to first order.
        unit: Each row's unit (6 k,): the chain's reach [m] for its position rows, 1 for its
            rotation rows (the resolver's metric, :class:`~rrc_pin.solvers.tick.problem.TaskRows`).
    """

    C: Array
    error: Array
    unit: Array


class ContactLimit(Limit):
    r"""Fixed contacts: the full twist of each frame is zero, :math:`J_c\,\dot q = 0`.

    Six equality rows per frame (its world_aligned Jacobian: the contact point does not
    slide, the foot does not turn), kept at every answer: the resolver's levels are solved
    within them, so that a body command that would need a foot to slip is scaled, never
    obeyed by slipping. With anchors (each frame's pose in support), every tick also measures
    how far each frame is from its anchor (:attr:`last`): what a cell's controller closes
    inside the step (:mod:`rrc_pin.cells.closure`).

    Args:
        frames: The frames in contact (e.g. the feet in support).
        name: Name in the report; rows are named ``name:frame:axis``.
        anchors: Each frame's pose in support (4, 4) [m], in ``frames``' order, or None.

    Raises:
        InvalidInput: ``frames`` not distinct frame names, ``name`` not a string, or anchors
            that are not one rigid transform per frame.
    """

    def __init__(
        self, frames: Sequence[str], name: str = "contact",
        anchors: Sequence[npt.ArrayLike] | None = None,
    ) -> None:  # fmt: skip
        if not isinstance(name, str):
            raise InvalidInput("name", f"expected a string, got {name!r}")
        self.name = name
        self._layout: Layout | None = None
        self.set_frames(frames, anchors)

    def set_frames(
        self, frames: Sequence[str], anchors: Sequence[npt.ArrayLike] | None = None
    ) -> None:
        """The frames in contact from now on (a foot lifted or landed), and their anchors.

        Args:
            frames: The frames in contact.
            anchors: Each frame's pose in support (4, 4) [m], in ``frames``' order, or None
                (no error measured).

        Raises:
            InvalidInput: Not distinct frame names, or not one anchor per frame; the limit is
                then unchanged.
            FrameNotFound: A frame the robot (of the resolver holding it) does not have.
        """
        items = names(frames, "frames")
        if len(set(items)) != len(items):
            raise InvalidInput("frames", f"expected distinct frame names, got {frames!r}")
        if self._layout is not None:
            for frame in items:
                if frame not in self._layout.frames:
                    raise FrameNotFound(frame, sorted(self._layout.frames), "frames")
        poses = None
        if anchors is not None:
            if len(anchors) != len(items):
                raise InvalidInput("anchors", f"expected {len(items)} poses, got {len(anchors)}")
            poses = np.array([rigid_transform(T, f"anchors[{i}]")
                              for i, T in enumerate(anchors)]).reshape(-1, 4, 4)  # fmt: skip
        self.frames: tuple[str, ...] = items
        self._anchors: Array | None = poses  # (k, 4, 4), None: no error measured
        self._names = tuple(f"{self.name}:{f}:{a}" for f in items for a in AXES)
        self._zero = np.zeros(6 * len(items))
        # the robot's layout, the frames' columns on its model and the rows' units
        self._prepared_for: tuple[Layout, FrameColumns, Array] | None = None
        self.last: Closure | None = None
        """The rows and the anchors' errors at the last configuration the limit saw (None
        without anchors or frames)."""

    def check(self, layout: Layout) -> None:
        """Refuse frames the robot does not have.

        Raises:
            FrameNotFound: Naming ``frames`` and listing the robot's frames.
        """
        for frame in self.frames:
            if frame not in layout.frames:
                raise FrameNotFound(frame, sorted(layout.frames), "frames")
        self._layout = layout

    def constraints(self, kin: Kinematics, dt: float, previous: Array) -> Constraints:
        """The contact rows ``C qdot = 0`` (C: (6 k, nv), world_aligned Jacobians).

        One compiled call (:func:`~rrc_pin.limits.chain_kernels.contact_rows`) on the tick's
        joint Jacobians.
        """
        if not self.frames:
            return Constraints()
        data = kin.data
        columns, unit = self.columns(kin)
        measured = self._anchors is not None
        C = np.zeros((6 * len(self.frames), kin.layout.nv))
        error = np.empty(C.shape[0]) if measured else UNMEASURED
        contact_rows(data.J, columns.steps, columns.starts, columns.poses(data),
                     NO_POSES if self._anchors is None else self._anchors, C, error)  # fmt: skip
        return self.rows_of(C, error, unit)

    @property
    def anchors(self) -> Array | None:
        """The frames' anchors (k, 4, 4) [m] in ``frames``' order, or None."""
        return self._anchors

    def rows_of(self, C: Array, error: Array, unit: Array) -> Constraints:
        """The constraints of the rows ``C`` (6 k, nv) and the anchors' errors ``error`` (6 k,)
        [m, rad] of units ``unit`` (:meth:`columns`) at a tick: those :meth:`constraints`
        computes, or a cell's compiled tick (:mod:`rrc_pin.cells.cell_kernels`); kept in
        :attr:`last` where the anchors are measured.
        """  # noqa: D205
        if self._anchors is not None:
            self.last = Closure(C, error, unit)
        return Constraints(C=C, d=self._zero, names=self._names)

    def columns(self, kin: Kinematics) -> tuple[FrameColumns, Array]:
        """The frames' columns on the tick's model and the rows' units (its frames' reach [m]
        for the position rows, 1 for the rotation rows), made once per robot layout."""  # noqa: D205, D209
        prepared = self._prepared_for
        if prepared is None or prepared[0] is not kin.layout:
            layout = kin.layout
            columns = FrameColumns.of(kin.model, kin.data, [layout.frames[f] for f in self.frames])
            unit = np.array([[layout.reach[f]] * 3 + [1.0] * 3 for f in self.frames],
                            dtype=np.float64).ravel()  # fmt: skip
            prepared = self._prepared_for = (layout, columns, unit)
        return prepared[1], prepared[2]
