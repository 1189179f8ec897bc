r"""Controller: Barker's operator loop on the resolver, one tick per call.

Every :meth:`Controller.step` takes the operator's twist in the hand frame (Barker eq. (20),
``ref="local"``) or in base axes (``"world_aligned"``), weights it by the speed override
and the deadman (:class:`~rrc_pin.control.deadman.Deadman`), adds the bounded pull back to
the commanded pose (:class:`~rrc_pin.control.drift.DriftCorrection`), lets the singularity
strategy adjust it (:mod:`rrc_pin.control.strategies`), resolves it with the
:class:`~rrc_pin.resolver.Resolver` (joint limits, margins) and integrates the rates for one
period (Barker eq. (21)) on the configuration manifold:

.. math:: q_{k+1} = q_k \oplus \dot q_k\, \Delta t \quad (\texttt{pinocchio.integrate}),

recording the tick in a :class:`~rrc_pin.control.trajectory_log.TrajectoryLog`.
:meth:`Controller.reverse` retraces the recorded joint positions back in time (Barker's
"speedy and effortless evacuation of the robot hand from a congested workspace").
"""

from __future__ import annotations

import math
from typing import Any, Literal, NamedTuple

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.control.deadman import Deadman
from rrc_pin.control.drift import DriftCorrection, advance, pose_error
from rrc_pin.control.rates_task import RatesTask
from rrc_pin.control.singularity import SingularityLabel
from rrc_pin.control.strategies import Situation, Strategy, make_strategy
from rrc_pin.control.strategies.base import KEEP, to_base_axes
from rrc_pin.control.trajectory_log import LogRecord, TrajectoryLog
from rrc_pin.errors import InvalidInput
from rrc_pin.limits import JointLimits
from rrc_pin.loading import load
from rrc_pin.resolver import QPOptions, Resolver
from rrc_pin.robot import Robot
from solvers.damping import Damping
from solvers.resolution import Resolution
from solvers.validation import as_vector, finite_number

Array = npt.NDArray[np.float64]
Frame = Literal["local", "world_aligned"]
LINEAR = np.array([1.0, 1.0, 1.0, 0.0, 0.0, 0.0])
FRAMES: tuple[str, ...] = ("local", "world_aligned")
REANCHOR = ("damped", "singular", "least_squares", "recovering", "fallback", "partial")
"""Statuses whose motion departs from the command's direction: the reference pose is reset to
the reached pose instead of pulling the hand back to a pose it could not follow."""
NO_ERROR = np.zeros(6)
"""The pose error of a tick without a reference (``reverse``)."""
NO_ERROR.flags.writeable = False


class Step(NamedTuple):
    """One tick's outcome.

    Attributes:
        q: Joint positions after the tick (nq,) [rad or m] (read-only).
        resolution: The resolver's answer for the tick.
    """

    q: Array
    resolution: Resolution


class Retrace(NamedTuple):
    """What :meth:`Controller.reverse` did.

    Attributes:
        steps: Ticks taken.
        reached: Whether every recorded configuration was reached (no limit intervened
            beyond the extra ticks allowed).
        error: Largest joint distance [rad or m] from the segment's start at the end.
    """

    steps: int
    reached: bool
    error: float


class Tick(NamedTuple):
    """One tick as the controller keeps it; the log derives its :class:`LogRecord` when read.

    Attributes:
        t: Time at the start of the tick [s].
        q: Joint positions at the start of the tick (nq,) [rad or m].
        resolution: The resolver's answer.
        command: The operator's command (6,) [m/s, rad/s] (speed override, deadman).
        hand: The tool's pose when ``command`` is in hand axes, else None (base axes).
        factor: The strategy's speed factor.
        error: The pose error to the reference (6,) [m, rad]
            (:func:`~rrc_pin.control.drift.pose_error`).
        mode: ``"teleop"`` or ``"reverse"``.
        note: What the strategy did.
    """

    t: float
    q: Array
    resolution: Resolution
    command: Array
    hand: pin.SE3 | None
    factor: float
    error: Array
    mode: str
    note: str


class Controller:
    """A resolved-rate teleoperation loop holding the arm's configuration.

    Args:
        robot: A :class:`rrc_pin.Robot` with one tool frame, or a name :func:`rrc_pin.load`
            takes.
        dt: Control period [s], >= 1e-6 (:data:`rrc_pin.resolver.MIN_DT`).
        q0: Initial joint positions (nq,) [rad or m]; default ``robot.ready()``.
        strategy: A singularity strategy: a :class:`Strategy` or its name
            (:data:`~rrc_pin.control.strategies.STRATEGIES`); default ``"resolver"`` (the
            resolver's own handling).
        limits: Joint limits and margins of the resolver (default ``JointLimits()``).
        qp: QP backend and fallbacks of the resolver.
        damping: Damping of the resolver near singularities, or None.
        deadman: How a command ages (default ``Deadman()``), or None: a command stays in
            force until the next.
        drift: Pose-drift correction (default ``DriftCorrection()``), or None for none.
        speed: Speed override in [0, 1] (a teach pendant's percentage), settable.
        near: Width of the neighbourhood in which singularities are named in the log
            (:class:`~rrc_pin.control.singularity.SingularityLabel`).

    Raises:
        InvalidInput: A bad argument, named (a robot with several tool frames included).
        UnknownArm, URDFError: ``robot`` is a name or path that does not load.
    """

    def __init__(
        self,
        robot: Robot | str,
        dt: float = 0.01,
        q0: npt.ArrayLike | None = None,
        *,
        strategy: Strategy | str | None = None,
        limits: JointLimits | None = None,
        qp: QPOptions | None = None,
        damping: Damping | None = Damping(),  # noqa: B008 - immutable
        deadman: Deadman | None = Deadman(),  # noqa: B008 - immutable
        drift: DriftCorrection | None = DriftCorrection(),  # noqa: B008 - immutable
        speed: float = 1.0,
        near: float = 0.05,
    ) -> None:
        if isinstance(robot, str):
            robot = load(robot)
        if not isinstance(robot, Robot):
            raise InvalidInput("robot", f"expected a rrc_pin.Robot or a name, got {robot!r}")
        if robot.tool_frame is None:
            raise InvalidInput(
                "robot", f"{robot.name} has several tool frames ({', '.join(robot.tool_frames)}); "
                "load it with tool_frame=... for one hand",
            )
        if deadman is not None and not isinstance(deadman, Deadman):
            raise InvalidInput("deadman", f"expected a Deadman or None, got {deadman!r}")
        if drift is not None and not isinstance(drift, DriftCorrection):
            raise InvalidInput("drift", f"expected a DriftCorrection or None, got {drift!r}")
        self.robot = robot
        self.resolver = Resolver(robot, dt, limits=limits, qp=qp, damping=damping)
        self.dt = self.resolver.dt
        self.strategy = make_strategy(strategy)
        self.strategy.check(robot)
        self.q = robot.ready() if q0 is None else robot.check_q(q0, "q0")
        self.speed = speed
        self.deadman = deadman
        self.drift = drift
        self.label = SingularityLabel(robot, finite_number(near, "near", 0.0, inclusive=False))
        self.log = TrajectoryLog(robot.joint_names, self._log_record)
        self.t = 0.0
        assert self.resolver.task is not None  # one tool frame: the resolver has its task
        self._rows = tuple(self.resolver.task.selected)
        self._full = len(self._rows) == 6
        self._data = robot.model.createData()
        self._frame_id = robot.model.getFrameId(robot.tool_frame)
        self._manifold = robot.model.nq != robot.model.nv  # continuous joints as (cos, sin)
        self._command: Array = np.zeros(6)
        self._command_frame: Frame = "local"
        self._command_time = -math.inf
        self._reference = self._pose(self._pinocchio_q(self._q))
        self._reanchor = False

    # -- settings ---------------------------------------------------------------------------

    @property
    def q(self) -> Array:
        """Joint positions (nq,) [rad or m], read-only: set the attribute to move the arm."""
        return self._q

    @q.setter
    def q(self, value: npt.ArrayLike) -> None:
        q: Array = self.robot.check_q(value, "q").copy()
        q.flags.writeable = False
        self._q = q

    @property
    def speed(self) -> float:
        """Speed override in [0, 1]: every command is multiplied by it."""
        return self._speed

    @speed.setter
    def speed(self, value: float) -> None:
        value = finite_number(value, "speed", 0.0)
        if value > 1.0:
            raise InvalidInput("speed", f"expected a finite number in [0, 1], got {value}")
        self._speed = value

    @property
    def reference(self) -> Array:
        """The commanded pose (4, 4) the drift correction pulls toward (a copy)."""
        out: Array = self._reference.homogeneous
        return out

    # -- the loop ---------------------------------------------------------------------------

    def step(self, twist: npt.ArrayLike | None = None, ref: Frame = "local") -> Step:
        """Resolve and integrate one tick of the operator's command.

        Args:
            twist: Commanded twist [v; w] (6,) [m/s, rad/s] of the tool frame in ``ref``,
                or None: no new command this tick (the last one ages, see ``deadman``).
            ref: ``"local"`` (hand axes, Barker eq. (20)) or ``"world_aligned"`` (base
                axes), as tasks name their frames.

        Returns:
            The new configuration and the tick's resolution.

        Raises:
            InvalidInput: A bad ``twist`` (shape, NaN, inf) or ``ref``, raised before any
                state changes.
        """
        if not isinstance(ref, str) or ref not in FRAMES:
            raise InvalidInput("ref", f"expected one of {', '.join(FRAMES)}, got {ref!r}")
        if twist is not None:
            command = _checked_twist(twist)
            self._command, self._command_frame, self._command_time = command, ref, self.t
        age = self.t - self._command_time
        weight = self._speed
        if self.deadman is not None and age > self.deadman.timeout:  # the command fades
            weight *= self.deadman.factor(age)
        command = self._command if weight == 1.0 else weight * self._command
        local = self._command_frame == "local"

        q = self._q
        q_pin = self._pinocchio_q(q)
        pose = self._pose(q_pin)
        if self._reanchor:
            self._reference, self._reanchor = pose, False
        error = pose_error(pose, self._reference)  # hand axes
        if not self._full:  # position rows only: the orientation is not commanded
            error[3:] = 0.0
        # What to serve, in the command's frame: the command plus the correction.
        if self.drift is None or weight == 0.0:  # an arm stopped or let go stands still
            wanted = command
        else:
            correction = weight * self.drift.twist(error)  # hand axes
            wanted = command + (correction if local else to_base_axes(pose.rotation, correction))
        hand = pose if local else None
        if self.strategy.passive:  # it keeps the command: no Situation to build
            decision = KEEP
        else:
            decision = self.strategy.decide(Situation(self.robot, q, wanted, self.dt, command,
                                                      self._rows, hand))
        factor = decision.factor
        if decision.rates is None:
            r = self.resolver.solve(q, wanted if factor == 1.0 else factor * wanted,
                                    self._command_frame)
        else:
            r = self.resolver.solve(q, [RatesTask(decision.rates)], priority="strict")
        # q itself, not a copy: read-only, replaced at every tick.
        self.log.append_tick(Tick(self.t, q, r, command, hand, factor, error, "teleop",
                                  decision.note))
        fraction = None if decision.rates is not None else _followed(r)
        if fraction is None:
            self._reanchor = True
        elif self._full:  # the command, for the time it was followed
            self._reference = advance(self._reference, command, factor * fraction * self.dt,
                                      local)
        else:  # the commanded position, at the orientation reached
            moved = to_base_axes(pose.rotation, command) if local else command
            self._reference = advance(self._reference, moved * LINEAR,
                                      factor * fraction * self.dt, False)
        return self._advance(r)

    def reverse(self, seconds: float, extra: float = 1.0) -> Retrace:
        """Retrace the last ``seconds`` of the record back to where that segment started.

        Each tick aims at the previous recorded configuration, at the rates that reach it in
        one period, kept inside the joint limits by the resolver (scaled when they do not
        fit; then further ticks aim at the same configuration). When no limit intervenes the
        arm passes through the recorded configurations up to rounding. The command is
        cleared (the operator must command again) and the reference pose reset.

        Args:
            seconds: Length of the segment [s], > 0, at most the recorded time.
            extra: Extra ticks allowed, as a fraction of the segment's, for configurations a
                limit delays, >= 0.

        Returns:
            What was done (:class:`Retrace`).

        Raises:
            InvalidInput: ``seconds`` not > 0 or longer than the record, or a bad ``extra``;
                raised before any state changes.
        """
        seconds = finite_number(seconds, "seconds", 0.0, inclusive=False)
        extra = finite_number(extra, "extra", 0.0, upper=1e6)
        ticks = seconds / self.dt
        if ticks > len(self.log) + 0.5:
            raise InvalidInput(
                "seconds", f"asked to reverse {seconds:.6g} s ({ticks:.6g} ticks); the record "
                f"holds {len(self.log)} ticks ({len(self.log) * self.dt:.6g} s)",
            )
        n = max(1, round(ticks))
        targets = self.log.positions(n)[::-1]
        budget = n + math.ceil(extra * n)
        steps = 0
        for target in targets:
            while steps < budget:
                q = self.q
                rates = (target - q) / self.dt
                r = self.resolver.solve(q, [RatesTask(rates, "reverse")], priority="strict")
                self.log.append_tick(Tick(self.t, q, r, np.zeros(6), None, 1.0, NO_ERROR,
                                          "reverse", ""))
                self._advance(r)
                steps += 1
                if r.status == "exact":  # reached (to rounding): on to the next one
                    break
        self._command, self._command_time = np.zeros(6), -math.inf
        self._reanchor = True
        error = float(np.max(np.abs(self.q - targets[-1])))
        return Retrace(steps, error <= 1e-9 and steps <= budget, error)

    # -- helpers ----------------------------------------------------------------------------

    def _pinocchio_q(self, q: Array) -> Array:
        """Pinocchio's configuration of the controller's own ``q`` (valid: not checked again)."""
        return self.robot.to_pinocchio(q) if self._manifold else q

    def _pose(self, q_pin: Array) -> pin.SE3:
        """Tool pose at ``q_pin``, Pinocchio's configuration (one FK pass, own data)."""
        model, data = self.robot.model, self._data
        pin.forwardKinematics(model, data, q_pin)
        pose: pin.SE3 = pin.updateFramePlacement(model, data, self._frame_id)
        return pose

    def _advance(self, r: Resolution) -> Step:
        """Integrate ``r.qdot`` over one period (Barker eq. (21), ``pinocchio.integrate``)."""
        model, q = self.robot.model, self._q
        q_pin = self._pinocchio_q(q)
        moved = pin.integrate(model, q_pin, r.qdot * self.dt)
        # Continuous joints: back to angles by the manifold's difference (= qdot dt).
        q = q + pin.difference(model, q_pin, moved) if self._manifold else moved
        q.flags.writeable = False  # the log and the Step hold it: never changed, replaced
        self._q = q
        self.t += self.dt
        return Step(q, r)

    def _log_record(self, values: tuple[Any, ...]) -> LogRecord:
        """The log's record of a tick (:class:`Tick`'s fields), computed now.

        The kinematics and the resolution's lazily computed fields.
        """
        tick = Tick(*values)
        r = tick.resolution
        J = self.robot.jacobian(tick.q)  # world_aligned, the tick's start
        J_task = J if self._full else J[list(self._rows)]
        sv: Array = np.asarray(np.linalg.svd(J_task, compute_uv=False), np.float64)
        active = ";".join(f"{a.name or a.joint}:{a.side}:{a.kind}" for a in r.active)
        commanded = tick.command
        if tick.hand is not None:
            commanded = to_base_axes(tick.hand.rotation, commanded)
        return LogRecord(
            t=tick.t, q=tick.q, qdot=r.qdot.copy(), commanded=commanded, achieved=J @ r.qdot,
            scale=r.scale, factor=tick.factor, sigma_min=float(sv[-1]),
            manipulability=float(np.prod(sv)), drift_position=math.hypot(*tick.error[:3]),
            drift_rotation=math.hypot(*tick.error[3:]), mode=tick.mode, method=r.method,
            status=r.status, active=active, singularity=self.label(tick.q, J_task, sv),
            note=tick.note,
        )


def _checked_twist(twist: npt.ArrayLike) -> Array:
    """``twist`` as a new finite (6,) float array.

    Raises:
        InvalidInput: Naming ``twist``: not a real (6,) vector, or NaN or inf in it.
    """
    out: Array = as_vector(twist, "twist", 6).copy()
    return out


def _followed(r: Resolution) -> float | None:
    """Fraction in [0, 1] of a twist's command the resolution achieved along its direction.

    None when the answer departs from the command's direction (:data:`REANCHOR`).
    """
    return None if r.status in REANCHOR else r.scale
