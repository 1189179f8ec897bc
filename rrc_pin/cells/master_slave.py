r"""MasterSlave: a 6-DOF hand controller's pose increments as a slave frame's twist.

Nguyen & Zhou's testbed drives each slave arm from a 6-DOF Kraft mini-master. Each tick the
master's pose change :math:`(\Delta p, \Delta R)` over the period :math:`\Delta t`, in the
master's base axes, becomes a twist of the slave frame (a hand or a held object) in the
cell's base axes (``world_aligned``, a plain command of ``CellController.step``):

.. math:: v = \frac{k_p\, R_{ms}\, \Delta p}{\Delta t}, \qquad
          \omega = \frac{R_{ms} \log(\Delta R)}{\Delta t}

with the position scale :math:`k_p` and the orientation map :math:`R_{ms}` (master axes to
world axes). The clutch indexes: while it is released the slave holds still and the master
can be re-centred; on engaging again, motion counts from the master's pose at that moment.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.errors import InvalidInput
from rrc_pin.solvers.checks import positive, rigid_transform

Array = npt.NDArray[np.float64]


class MasterSlave:
    """The map of one master to one slave frame (module docstring).

    Args:
        scale: Position scale k_p > 0 (slave metres per master metre).
        rotation: Orientation map R_ms (3, 3), master axes to the cell's world axes.
        dt: Control period [s] > 0.

    Raises:
        InvalidInput: A bad scale, rotation (not a rotation matrix) or dt, named.
    """

    def __init__(
        self, scale: float = 1.0, rotation: npt.ArrayLike | None = None, dt: float = 0.01
    ) -> None:
        self.scale = positive(scale, "scale")
        R = np.eye(3) if rotation is None else np.asarray(rotation, dtype=float)
        if R.shape != (3, 3):
            raise InvalidInput("rotation", f"expected a (3, 3) rotation, got shape {R.shape}")
        T = np.eye(4)
        T[:3, :3] = R
        self.rotation = rigid_transform(T, "rotation")[:3, :3]
        self.dt = positive(dt, "dt")
        self._last: Array | None = None

    @property
    def engaged(self) -> bool:
        """Whether the clutch is engaged (the last update moved the slave)."""
        return self._last is not None

    def update(self, master: npt.ArrayLike, clutch: bool) -> Array:
        """The slave's twist (6,) [m/s, rad/s], ``world_aligned``, for the master's pose now.

        Args:
            master: The master's pose (4, 4) in its base frame [m].
            clutch: Whether the operator holds the clutch (the slave follows).

        Returns:
            Zero when the clutch is released or has just been engaged, else the twist.

        Raises:
            InvalidInput: ``master`` not a rigid transform, or ``clutch`` not a bool;
                nothing changes.
        """
        T = rigid_transform(master, "master")
        if not isinstance(clutch, bool):
            raise InvalidInput("clutch", f"expected True or False, got {clutch!r}")
        if not clutch:
            self._last = None
            return np.zeros(6)
        last, self._last = self._last, T
        if last is None:
            return np.zeros(6)
        R = self.rotation
        v = self.scale * (R @ (T[:3, 3] - last[:3, 3])) / self.dt
        w = R @ pin.log3(T[:3, :3] @ last[:3, :3].T) / self.dt
        return np.concatenate([v, w])
