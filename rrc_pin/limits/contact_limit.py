"""ContactLimit: frames held fixed in the world (feet in support), as equality rows."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from rrc_pin.errors import FrameNotFound, InvalidInput
from rrc_pin.limits.limit import Limit
from rrc_pin.solvers.checks import names
from rrc_pin.solvers.tick.problem import Constraints

if TYPE_CHECKING:
    from rrc_pin.kinematics import Kinematics, Layout

Array = npt.NDArray[np.float64]

AXES = ("vx", "vy", "vz", "wx", "wy", "wz")


class ContactLimit(Limit):
    r"""Fixed contacts: the full twist of each frame is zero, :math:`J_c\,\dot q = 0`.

    Six equality rows per frame (its world_aligned Jacobian: the contact point does not
    slide, the foot does not turn), kept at every answer: the resolver's levels are solved
    within them, so that a body command that would need a foot to slip is scaled, never
    obeyed by slipping.

    Args:
        frames: The frames in contact (e.g. the feet in support).
        name: Name in the report; rows are named ``name:frame:axis``.

    Raises:
        InvalidInput: ``frames`` not distinct frame names, or ``name`` not a string.
    """

    def __init__(self, frames: Sequence[str], name: str = "contact") -> None:
        if not isinstance(name, str):
            raise InvalidInput("name", f"expected a string, got {name!r}")
        self.name = name
        self._layout: Layout | None = None
        self.set_frames(frames)

    def set_frames(self, frames: Sequence[str]) -> None:
        """The frames in contact from now on (a foot lifted or landed); checked.

        Raises:
            InvalidInput: Not distinct frame names; the limit is then unchanged.
            FrameNotFound: A frame the robot (of the resolver holding it) does not have.
        """
        items = names(frames, "frames")
        if len(set(items)) != len(items):
            raise InvalidInput("frames", f"expected distinct frame names, got {frames!r}")
        if self._layout is not None:
            for frame in items:
                if frame not in self._layout.frames:
                    raise FrameNotFound(frame, sorted(self._layout.frames), "frames")
        self.frames: tuple[str, ...] = items
        self._names = tuple(f"{self.name}:{f}:{a}" for f in items for a in AXES)
        self._zero = np.zeros(6 * len(items))

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
        """The contact rows ``C qdot = 0`` (C: (6 k, nv), world_aligned Jacobians)."""
        if not self.frames:
            return Constraints()
        C = np.vstack([kin.jacobian(f) for f in self.frames])
        return Constraints(C=C, d=self._zero, names=self._names)
