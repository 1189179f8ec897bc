r"""SingularityLimit: a frame's smallest singular values kept above a threshold.

One velocity-damper row (Kanehiro et al. 2008, as :mod:`rrc_pin.limits.collision`) per
singular value :math:`\sigma_i` of the frame's Jacobian, in the resolver's metric
(:mod:`rrc_pin.dexterity`: dimensionless), that is below the detection value
:math:`\sigma_d`:

.. math:: -\nabla\sigma_i^T\,\dot q \le \xi\,\frac{\sigma_i - \sigma_s}{\sigma_d - \sigma_s},

with :math:`\nabla\sigma_i = u_i^T (\partial J/\partial q)\, v_i` exact. Linearised over a
step of ``dt``, :math:`\sigma_i` then loses at most the fraction :math:`\xi\,dt / (\sigma_d -
\sigma_s)` of its margin per step, so :math:`\xi` is capped at :math:`(\sigma_d -
\sigma_s)/dt` and the threshold :math:`\sigma_s` is not crossed in one step (to second
order in the step). Below :math:`\sigma_s` the row asks the value back up. Every singular
value under :math:`\sigma_d` has its own row, so that where two of them cross (their
singular vectors swap) both stay bounded.

A command that would take the frame closer to a singularity than :math:`\sigma_s` is then
scaled (the resolver's direction problem), never obeyed; its damping and slowdown still act
on whatever approach the rows allow.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from rrc_pin.dexterity import dexterity
from rrc_pin.errors import FrameNotFound, InvalidInput
from rrc_pin.limits.limit import Limit
from rrc_pin.solvers.checks import finite_number
from rrc_pin.solvers.tick.problem import Constraints
from rrc_pin.tasks.frame_task import task_rows

if TYPE_CHECKING:
    from rrc_pin.kinematics import Kinematics, Layout

Array = npt.NDArray[np.float64]


class SingularityLimit(Limit):
    r"""Keeps ``frame``'s singular values above ``threshold`` (module docstring).

    Args:
        frame: The frame (e.g. the tool frame).
        threshold: :math:`\sigma_s` >= 0, dimensionless (the resolver's metric).
        detection: :math:`\sigma_d` > threshold: singular values below it get a row.
        gain: :math:`\xi` [1/s] > 0, the rate of decrease allowed at the detection value.
        rows: The twist rows measured, as :class:`~rrc_pin.tasks.FrameTask`'s.
        name: Name in the report; rows are named ``name:sigma<i>`` (i from 1, largest first).

    Raises:
        InvalidInput: A bad frame name, threshold, detection, gain, rows or name.
    """

    def __init__(
        self,
        frame: str,
        threshold: float = 0.02,
        detection: float = 0.06,
        gain: float = 0.5,
        *,
        rows: str | Sequence[int] | Sequence[bool] = "full",
        name: str | None = None,
    ) -> None:
        if not isinstance(frame, str):
            raise InvalidInput("frame", f"expected a frame name, got {frame!r}")
        self.frame = frame
        self.threshold = finite_number(threshold, "threshold", 0.0)
        self.detection = finite_number(detection, "detection", self.threshold, inclusive=False)
        self.gain = finite_number(gain, "gain", 0.0, inclusive=False)
        self.selected = task_rows(rows)
        name = f"singularity:{frame}" if name is None else name
        if not isinstance(name, str) or not name:
            raise InvalidInput("name", f"expected a non-empty string, got {name!r}")
        self.name = name

    def check(self, layout: Layout) -> None:
        """Refuse a frame the robot does not have.

        Raises:
            FrameNotFound: Naming ``frame`` and listing the robot's frames.
        """
        if self.frame not in layout.frames:
            raise FrameNotFound(self.frame, sorted(layout.frames), "frame")

    def constraints(self, kin: Kinematics, dt: float, previous: Array) -> Constraints:
        """One row per singular value below the detection value (module docstring)."""
        d = dexterity(kin, self.frame, self.selected)
        near = np.flatnonzero(d.sigma < self.detection)
        if not near.size:
            return Constraints()
        span = self.detection - self.threshold
        xi = min(self.gain, span / dt)
        G = -d.gradients[near]
        h = xi * (d.sigma[near] - self.threshold) / span
        names = tuple(f"{self.name}:sigma{i + 1}" for i in near.tolist())
        return Constraints(G=G, h=h, names=names)
