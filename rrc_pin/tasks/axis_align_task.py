r"""AxisAlignTask: an axis of a frame turned toward a direction of the world.

A tool kept vertical, a drill along a bore.

With :math:`a = R\,a_\ell` the frame's axis in base axes and :math:`d` the direction, the
task's two rows are the frame's angular velocity relative to the direction, across the
axis (its rotation about the axis itself is left free):

.. math:: A = E^T (J_\omega - J_d), \qquad b = k\,\theta\, E^T n,

with :math:`E = R\,[e_1\ e_2]` two unit vectors across the axis fixed in the frame (so the
rows turn with it, continuously), :math:`\theta = \angle(a, d)`, :math:`n = a\times d /
|a\times d|` the axis that turns :math:`a` onto :math:`d` along the great circle, and
:math:`J_d` the Jacobian of the direction's own angular velocity :math:`d \times \dot d`
(zero for a fixed direction; :class:`~rrc_pin.tasks.LookAtTask`'s moves with the frame).
Since :math:`\dot a = \omega \times a`, :math:`E^T(a \times \dot a - d\times\dot d)` is what
the rows measure: the exact rates, checked against finite differences in the tests. At
:math:`\theta = \pi` (the axis opposite) :math:`n` is any direction across it: :math:`e_1`.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from rrc_pin.errors import InvalidInput
from rrc_pin.kinematics import Kinematics
from rrc_pin.solvers.checks import as_vector, positive
from rrc_pin.solvers.tick.problem import TaskRows
from rrc_pin.tasks.task import Task, check_weight, task_name

Array = npt.NDArray[np.float64]

PARALLEL = 1e-12
"""|a x d| below this: the axis is on the direction's line (aligned, or opposite)."""


class AxisAlignTask(Task):
    """Axis ``axis`` of ``frame`` toward the world direction ``direction`` (module docstring).

    Args:
        frame: A frame of the robot.
        axis: The axis (3,) in the frame's own axes (normalised; default its z).
        direction: The direction (3,) in base axes (normalised; default straight down).
        gain: k > 0 [1/s]: the fraction of the angle turned per second.
        weight: Cost > 0 of the squared residual.
        name: Name in the report (default ``"axis:<frame>"``).

    Raises:
        InvalidInput: A bad frame name, axis or direction (not finite, zero), gain, weight or
            name.
    """

    def __init__(
        self,
        frame: str,
        axis: npt.ArrayLike = (0.0, 0.0, 1.0),
        direction: npt.ArrayLike = (0.0, 0.0, -1.0),
        *,
        gain: float = 5.0,
        weight: float = 1.0,
        name: str | None = None,
    ) -> None:
        if not isinstance(frame, str):
            raise InvalidInput("frame", f"expected a frame name, got {frame!r}")
        self.frame = frame
        self.axis = unit(axis, "axis")
        self.across = across(self.axis)
        self.direction = unit(direction, "direction")
        self.gain = positive(gain, "gain")
        self.weight = check_weight(weight)
        self.name = f"axis:{frame}" if name is None else task_name(name)

    def set_direction(self, direction: npt.ArrayLike) -> None:
        """Turn toward ``direction`` (3,) in base axes from now on (checked, normalised).

        Raises:
            InvalidInput: Not finite, or zero; the task is then unchanged.
        """
        self.direction = unit(direction, "direction")

    def frames(self) -> tuple[str, ...]:
        """The turned frame."""
        return (self.frame,)

    def aim(self, kin: Kinematics) -> tuple[Array, Array]:
        """The direction (3,) in base axes and its angular velocity's Jacobian (3, nv)."""
        return self.direction, np.zeros((3, kin.q.size))

    def angle(self, kin: Kinematics) -> float:
        """The angle [rad] between the axis and the direction at ``kin``."""
        a = kin.pose(self.frame)[:3, :3] @ self.axis
        d = self.aim(kin)[0]
        return float(np.arctan2(np.linalg.norm(np.cross(a, d)), a @ d))

    def rows(self, kin: Kinematics) -> TaskRows:
        """Two rows across the axis (module docstring)."""
        R = kin.pose(self.frame)[:3, :3]
        a, E = R @ self.axis, R @ self.across  # (3,), (3, 2)
        d, Jd = self.aim(kin)
        turn = np.cross(a, d)
        size = float(np.linalg.norm(turn))
        theta = float(np.arctan2(size, a @ d))
        n = turn / size if size > PARALLEL else E[:, 0]
        A = E.T @ (kin.jacobian(self.frame, "world_aligned")[3:] - Jd)
        b = self.gain * theta * (E.T @ n)
        return TaskRows(A, b, self._row_weights(2), self.name)


def unit(v: npt.ArrayLike, name: str) -> Array:
    """``v`` (3,) normalised.

    Raises:
        InvalidInput: Not finite (3,), or shorter than 1e-9.
    """
    x = as_vector(v, name, 3)
    peak = float(np.abs(x).max())
    y = x / peak if peak > 0.0 else x  # the norm of 1e308 entries overflows
    norm = float(np.linalg.norm(y))
    if peak * norm < 1e-9:
        raise InvalidInput(name, f"expected a direction, got {x.tolist()} (no length)")
    out: Array = y / norm
    return out


def across(axis: Array) -> Array:
    """Two unit vectors (3, 2) across ``axis`` (unit), ``e1 x e2 = axis``."""
    helper = np.eye(3)[int(np.argmin(np.abs(axis)))]
    e1 = np.cross(helper, axis)
    e1 /= np.linalg.norm(e1)
    return np.column_stack([e1, np.cross(axis, e1)])
