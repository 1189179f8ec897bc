r"""Baseline: fixed-gain joint PD with the nominal gravity compensation.

.. math:: \tau = K_p (q_d - q) + K_v (\dot q_d - \dot q) + \hat g(q)

``g`` of the nominal model (no payload): what a controls engineer fits first. It cannot see a
payload change except through its position error.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from rrc_pin.dynamics.controller import Array, Controller, gains
from rrc_pin.dynamics.nominal import NominalModel
from rrc_pin.dynamics.state import Reference, State
from rrc_pin.robot import Robot


class FixedPD(Controller):
    """Joint PD with constant gains plus nominal gravity.

    Args:
        robot: The arm.
        kp: Stiffness (nq,) or scalar [N m/rad], > 0.
        kv: Damping (nq,) or scalar [N m s/rad], > 0.
        gravity: Whether to add the nominal gravity torque.
        dt: Control period [s].
        torque_limit: Motor limits (nq,) [N m]; default the URDF's.

    Raises:
        InvalidInput: A bad gain (named ``kp`` or ``kv``).
    """

    name = "fixed_pd"

    def __init__(
        self,
        robot: Robot,
        kp: npt.ArrayLike,
        kv: npt.ArrayLike,
        *,
        gravity: bool = True,
        dt: float = 1e-3,
        torque_limit: npt.ArrayLike | None = None,
    ) -> None:
        super().__init__(robot, dt, torque_limit)
        self.kp = gains(kp, "kp", robot.nq)
        self.kv = gains(kv, "kv", robot.nq)
        self.nominal = NominalModel(robot) if gravity else None

    def law(self, state: State, ref: Reference) -> Array:
        """``Kp e + Kv edot + g(q)``."""
        tau = self.kp * (ref.q - state.q) + self.kv * (ref.v - state.v)
        if self.nominal is not None:
            tau = tau + self.nominal.gravity(state.q)
        return np.asarray(tau, dtype=float)
