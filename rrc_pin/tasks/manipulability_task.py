r"""ManipulabilityTask: joint rates up the gradient of a frame's manipulability."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from rrc_pin.dexterity import dexterity
from rrc_pin.errors import InvalidInput
from rrc_pin.kinematics import Kinematics
from rrc_pin.solvers.checks import positive
from rrc_pin.solvers.tick.problem import TaskRows
from rrc_pin.tasks.frame_task import task_rows
from rrc_pin.tasks.task import Task, check_weight, identity, task_name

Array = npt.NDArray[np.float64]

FLOOR = 1e-3
r"""The smallest singular value (dimensionless, :mod:`rrc_pin.dexterity`) the gradient of
:math:`\log w` divides by: at a singularity itself the gradient stays finite, pointing away."""


class ManipulabilityTask(Task):
    r"""Rates that raise Yoshikawa's measure of ``frame``: :math:`\dot q \approx k\,\nabla \log w`.

    :math:`w = \sqrt{\det(J J^T)}` of the frame's Jacobian rows in the resolver's metric
    (:mod:`rrc_pin.dexterity`: the exact gradient from the Jacobian's derivative, no finite
    differences). The logarithm makes the task independent of units and of the arm's size:
    :math:`\nabla \log w = \sum_i \nabla\sigma_i / \sigma_i` [1/rad], each :math:`\sigma_i`
    floored at :data:`FLOOR`. Its rows are the identity on the joints' rates (a floating
    base's six are not asked), so below a frame task in strict priorities
    (``[[frame_task], [manipulability]]``) it is the classic gradient projection (Liégeois
    1977): the top level is unchanged, its null space climbs the measure. Beside a posture
    task on the same level, their weights trade them.

    Args:
        frame: The frame whose dexterity is raised (e.g. the tool frame).
        gain: k > 0 [rad^2/s]: joint rates asked per unit of the gradient [1/rad].
        rows: The twist rows measured: ``"full"``, ``"position"``, ``"orientation"`` or
            indices (as :class:`~rrc_pin.tasks.FrameTask`).
        weight: Cost > 0 of the squared residual.
        name: Name in the report (default ``"manipulability:<frame>"``).

    Raises:
        InvalidInput: A bad frame name, gain, rows, weight or name.
    """

    def __init__(
        self,
        frame: str,
        gain: float = 0.05,
        *,
        rows: str | Sequence[int] | Sequence[bool] = "full",
        weight: float = 1.0,
        name: str | None = None,
    ) -> None:
        if not isinstance(frame, str):
            raise InvalidInput("frame", f"expected a frame name, got {frame!r}")
        self.frame = frame
        self.gain = positive(gain, "gain")
        self.selected = task_rows(rows)
        self.weight = check_weight(weight)
        self.name = f"manipulability:{frame}" if name is None else task_name(name)

    def frames(self) -> tuple[str, ...]:
        """The measured frame."""
        return (self.frame,)

    def gradient(self, kin: Kinematics) -> Array:
        r"""The gradient of :math:`\log w` (nv,) [1/rad or 1/m] at ``kin`` (class docstring)."""
        d = dexterity(kin, self.frame, self.selected)
        out: Array = (1.0 / np.maximum(d.sigma, FLOOR)) @ d.gradients
        return out

    def rows(self, kin: Kinematics) -> TaskRows:
        """Identity rows on the joints' rates, ``gain`` times the gradient."""
        b = self.gain * self.gradient(kin)
        actuated = kin.layout.actuated
        n = b.size
        if actuated is None:
            return TaskRows(identity(n), b, self._row_weights(n), self.name)
        m = int(actuated.sum())
        return TaskRows(identity(n)[actuated], b[actuated], self._row_weights(m), self.name)
