"""Joint-space adaptive PD (Nguyen & Zhou Fig. 11): Seraji's law on every joint.

``tau_i = f_i(t) + k_p,i(t) e_i + k_v,i(t) edot_i`` with ``e = q_d - q``, ``edot = qdot_d -
qdot`` and the adaptation of :mod:`rrc_pin.dynamics.adaptation`; the desired joints come from
the resolver integrating the hand path (:class:`~rrc_pin.dynamics.reference.JointTrajectory`).
No dynamic model: each joint is its own loop.
"""

from __future__ import annotations

import numpy.typing as npt

from rrc_pin.dynamics.adaptation import SerajiGains, SerajiLaw
from rrc_pin.dynamics.controller import Array, Controller
from rrc_pin.dynamics.state import Reference, State
from rrc_pin.robot import Robot


class JointAdaptivePD(Controller):
    """Decentralised adaptive PD in joint space.

    Args:
        robot: The arm.
        adaptive: Seraji gains, per joint (scalars broadcast).
        f0: Initial auxiliary signal (nq,) [N m], e.g. the holding torque measured at rest.
        dt: Control period [s].
        torque_limit: Motor limits (nq,) [N m]; default the URDF's.

    Raises:
        InvalidInput: A bad gain (named).
    """

    name = "joint_adaptive_pd"

    def __init__(
        self,
        robot: Robot,
        adaptive: SerajiGains,
        *,
        f0: npt.ArrayLike = 0.0,
        dt: float = 1e-3,
        torque_limit: npt.ArrayLike | None = None,
    ) -> None:
        super().__init__(robot, dt, torque_limit)
        self.adaptation = SerajiLaw(adaptive, robot.nq, self.dt, f0)

    def reset(self) -> None:
        """Back to the initial gains."""
        super().reset()
        self.adaptation.reset()

    def law(self, state: State, ref: Reference) -> Array:
        """Seraji's law on the joint errors."""
        return self.adaptation.update(ref.q - state.q, ref.v - state.v)
