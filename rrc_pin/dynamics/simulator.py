r"""Forward dynamics of an arm on Pinocchio: ABA, semi-implicit Euler at a fixed step.

One step of length ``dt`` from ``(q, v)`` under the commanded torque ``tau``:

.. math::
    \tau_a &= \mathrm{clip}(\tau, -\tau_{max}, \tau_{max}) \\
    \dot v &= \mathrm{ABA}(q, v, \tau_a - \tau_f(v) + J_p(q)^T F) \\
    v^+ &= v + dt\, \dot v, \qquad q^+ = q + dt\, v^+

(semi-implicit, or symplectic, Euler: first order, and for a conservative system its energy
error stays bounded, of order ``dt``, instead of drifting). ``tau_f`` is the optional joint
friction ``B v + Tc tanh(v / v_s)`` (Coulomb smoothed over :data:`STICTION_SPEED`), ``J_p`` the
linear rows of the tool Jacobian (base axes) and ``F`` the contact force of the
:class:`ContactPlane`. The reflected rotor inertia (:mod:`rrc_pin.dynamics.drives`) is the
model's ``armature``; a :class:`~rrc_pin.models.inertia.LinkInertial` payload held in the tool
frame adds to the last link's inertia, and may change between two steps.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.dynamics.drives import Drives, drives_of
from rrc_pin.dynamics.environment import ContactPlane
from rrc_pin.dynamics.state import State
from rrc_pin.errors import InvalidInput
from rrc_pin.models.inertia import LinkInertial
from rrc_pin.robot import Robot
from rrc_pin.solvers.checks import as_vector, finite_number

Array = npt.NDArray[np.float64]
RATE = 1000.0
"""Default simulation rate [Hz]."""
STICTION_SPEED = 0.01
"""Speed [rad/s] over which the Coulomb friction changes sign (tanh smoothing)."""


@dataclass(frozen=True)
class StepReport:
    """What the last step applied.

    Attributes:
        tau: Torque the motors applied (nq,) [N m], after the limits.
        clipped: Whether any commanded torque was beyond its limit.
        contact: Force the plane applied to the tool (3,) [N], base axes.
    """

    tau: Array
    clipped: bool
    contact: Array


class Simulator:
    """A simulated arm: state, payload, environment, and one :meth:`step` at a time.

    Args:
        robot: A one-tool-frame arm whose joints have one coordinate each (catalogue arms).
        dt: Step [s], > 0 (default 1 ms: 1 kHz).
        drives: Armature and friction; default :func:`~rrc_pin.dynamics.drives.drives_of`
            the robot's name.
        friction: Whether the drives' friction acts.
        torque_limit: Motor torque limits (nq,) [N m], > 0; default the URDF's efforts.
        plane: Contact plane, or None for free space.
        payload: Body held in the tool frame, or None.

    Raises:
        InvalidInput: A bad argument (named), before anything is built.
    """

    def __init__(
        self,
        robot: Robot,
        dt: float = 1.0 / RATE,
        *,
        drives: Drives | None = None,
        friction: bool = False,
        torque_limit: npt.ArrayLike | None = None,
        plane: ContactPlane | None = None,
        payload: LinkInertial | None = None,
    ) -> None:
        if robot.tool_frame is None or robot.model.nq != robot.model.nv:
            raise InvalidInput("robot", "expected an arm with one tool frame and 1-DOF joints")
        self.dt = finite_number(dt, "dt", 0.0, inclusive=False)
        n = robot.nq
        drives = drives_of(robot.name, n) if drives is None else drives
        if drives.armature.shape != (n,):
            raise InvalidInput("drives", f"expected {n} joints, got {drives.armature.shape[0]}")
        limit = robot.model.effortLimit if torque_limit is None else torque_limit
        self.torque_limit = as_vector(limit, "torque_limit", n)
        if np.any(self.torque_limit <= 0.0):
            raise InvalidInput("torque_limit", "every limit must be > 0")
        self.robot = robot
        self.drives = drives
        self.friction = bool(friction)
        self.plane = plane
        self.model = robot.model.copy()
        self.model.armature[:] = drives.armature
        self.data = self.model.createData()
        self._tool = self.model.getFrameId(robot.tool_frame)
        self._last_joint = self.model.frames[self._tool].parentJoint
        self._bare = self.model.inertias[self._last_joint].copy()
        self.payload: LinkInertial | None = None
        self.set_payload(payload)
        self.t = 0.0
        self.q = robot.neutral()
        self.v: Array = np.zeros(n)
        self.report = StepReport(np.zeros(n), False, np.zeros(3))

    def reset(self, q: npt.ArrayLike, v: npt.ArrayLike | None = None, t: float = 0.0) -> State:
        """Put the arm at ``q`` [rad] with speed ``v`` [rad/s] (default rest) at time ``t``."""
        position = as_vector(q, "q", self.robot.nq).copy()
        speed: Array = (
            np.zeros(self.robot.nq) if v is None else as_vector(v, "v", self.robot.nq)
        )
        self.t = finite_number(t, "t")
        self.q, self.v = position, speed.copy()
        self.report = StepReport(np.zeros(self.robot.nq), False, np.zeros(3))
        return self.state()

    def set_payload(self, payload: LinkInertial | None) -> None:
        """Hold ``payload`` (its centre of mass and inertia in tool-frame axes), or nothing."""
        if payload is not None and not isinstance(payload, LinkInertial):
            raise InvalidInput("payload", f"expected a LinkInertial or None, got {payload!r}")
        inertia = self._bare.copy()
        if payload is not None:
            body = pin.Inertia(payload.mass, payload.com_array, payload.inertia_array)
            inertia += self.model.frames[self._tool].placement.act(body)
        self.model.inertias[self._last_joint] = inertia
        self.payload = payload

    def set_plane(self, plane: ContactPlane | None) -> None:
        """Put a contact plane in the scene, or remove it (None)."""
        if plane is not None and not isinstance(plane, ContactPlane):
            raise InvalidInput("plane", f"expected a ContactPlane or None, got {plane!r}")
        self.plane = plane

    def state(self) -> State:
        """The current :class:`State`.

        Its force is minus the plane's push during the last step (computed at the step's
        start, so it lags the position by one step).
        """
        return State(t=self.t, q=self.q.copy(), v=self.v.copy(), force=-self.report.contact)

    def step(self, tau: npt.ArrayLike) -> State:
        """Advance one step under the commanded motor torques ``tau`` (nq,) [N m].

        Raises:
            InvalidInput: ``tau`` is not a finite (nq,) vector (the state is unchanged).
        """
        tau = as_vector(tau, "tau", self.robot.nq)
        applied = np.clip(tau, -self.torque_limit, self.torque_limit)
        total = applied.copy()
        if self.friction:
            d = self.drives
            total -= d.viscous * self.v + d.coulomb * np.tanh(self.v / STICTION_SPEED)
        contact: Array = np.zeros(3)
        if self.plane is not None:
            pin.forwardKinematics(self.model, self.data, self.q, self.v)
            pin.updateFramePlacements(self.model, self.data)
            p = self.data.oMf[self._tool].translation
            pdot = pin.getFrameVelocity(
                self.model, self.data, self._tool, pin.LOCAL_WORLD_ALIGNED
            ).linear
            contact = self.plane.force_on_tool(p, pdot)
            if contact.any():
                J = pin.computeFrameJacobian(
                    self.model, self.data, self.q, self._tool, pin.LOCAL_WORLD_ALIGNED
                )
                total += J[:3].T @ contact
        acceleration = pin.aba(self.model, self.data, self.q, self.v, total)
        self.v = self.v + self.dt * acceleration
        self.q = self.q + self.dt * self.v
        self.t += self.dt
        self.report = StepReport(applied, bool(np.any(applied != tau)), contact)
        return self.state()

    def energy(self) -> float:
        """Kinetic plus gravitational potential energy [J] of the current state."""
        M = pin.crba(self.model, self.data, self.q)
        M = np.triu(M) + np.triu(M, 1).T
        potential = pin.computePotentialEnergy(self.model, self.data, self.q)
        return float(0.5 * self.v @ M @ self.v + potential)
