r"""Baseline: computed torque (inverse dynamics) with Pinocchio's RNEA on the nominal model.

.. math::
    \tau = \mathrm{RNEA}_{nominal}(q, \dot q,
           \ddot q_d + K_v (\dot q_d - \dot q) + K_p (q_d - q))

Exact linearisation when the model is right; a payload it does not know shows up as a
disturbance ``(M - \hat M) \ddot q + (g - \hat g)``.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from rrc_pin.dynamics.controller import Array, Controller, gains
from rrc_pin.dynamics.nominal import NominalModel
from rrc_pin.dynamics.state import Reference, State
from rrc_pin.robot import Robot


class ComputedTorque(Controller):
    """Computed torque: PD on the error dynamics, through the nominal inverse dynamics.

    Args:
        robot: The arm.
        kp: Error stiffness (nq,) or scalar [1/s^2], > 0 (``omega^2``).
        kv: Error damping (nq,) or scalar [1/s], > 0 (``2 zeta omega``).
        dt: Control period [s].
        torque_limit: Motor limits (nq,) [N m]; default the URDF's.

    Raises:
        InvalidInput: A bad gain (named ``kp`` or ``kv``).
    """

    name = "computed_torque"

    def __init__(
        self,
        robot: Robot,
        kp: npt.ArrayLike,
        kv: npt.ArrayLike,
        *,
        dt: float = 1e-3,
        torque_limit: npt.ArrayLike | None = None,
    ) -> None:
        super().__init__(robot, dt, torque_limit)
        self.kp = gains(kp, "kp", robot.nq)
        self.kv = gains(kv, "kv", robot.nq)
        self.nominal = NominalModel(robot)

    def law(self, state: State, ref: Reference) -> Array:
        """RNEA of the servoed acceleration."""
        a = ref.a + self.kv * (ref.v - state.v) + self.kp * (ref.q - state.q)
        return np.asarray(self.nominal.inverse_dynamics(state.q, state.v, a), dtype=float)
