r"""Loop: what every teleoperation loop shares, for one arm or a cell of several.

:class:`~rrc_pin.control.Controller` (one tool frame, Barker's loop) and
:class:`~rrc_pin.cells.CellController` (one command per held object, body or free hand) are
both built on it; ``rrc_pin.Controller(cell)`` makes the second. A loop holds the
configuration, the resolver and the clock, and owns:

- the **speed override** and the **deadman** (:meth:`Loop._weight`: every command is
  multiplied by the speed, and by the deadman's fade once it is older than its timeout);
- the **integration** of one period on the configuration manifold (Barker eq. (21)):

  .. math:: q_{k+1} = q_k \oplus \dot q_k\, \Delta t \quad (\texttt{pinocchio.integrate});

- the **log** (a :class:`~rrc_pin.control.trajectory_log.RecordRing`) and **reverse**, which
  retraces the recorded configurations back in time;
- the **pose streams** (:meth:`Loop.stream`): a device's poses for a frame (a hand, a held
  object, a body), each a :class:`~rrc_pin.control.pose_stream.PoseStream` turned into that
  frame's bounded twist at every tick;
- the optional **jerk stage** after the resolver (:attr:`Loop.smoothing`, a
  :class:`~rrc_pin.control.smoothing.JerkLimiter`): the rates integrated are the resolver's
  with each joint's acceleration and jerk bounded, inside the tick's box.

What a subclass adds: how a tick's command becomes tasks (its ``step``), how a tick and a
reverse tick are logged (:meth:`Loop._log_reverse`), and what reverse resets
(:meth:`Loop._stopped`).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from typing import Any, NamedTuple

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.control.deadman import Deadman
from rrc_pin.control.pose_stream import PoseStream, StreamOptions
from rrc_pin.control.rates_task import RatesTask
from rrc_pin.control.smoothing import JerkLimiter, Smoothed, SmoothingOptions
from rrc_pin.control.trajectory_log import RecordRing
from rrc_pin.errors import InvalidInput
from rrc_pin.limits import JointLimits, Limit
from rrc_pin.resolver import QPOptions, Resolver
from rrc_pin.robot import Robot
from rrc_pin.solvers.checks import all_finite, finite_number
from rrc_pin.solvers.tick.damping import Damping
from rrc_pin.solvers.tick.resolution import Resolution

Array = npt.NDArray[np.float64]


class Step(NamedTuple):
    """One tick's outcome.

    Attributes:
        q: Joint positions after the tick (nq,) [rad or m] (read-only).
        resolution: The resolver's answer for the tick.
    """

    q: Array
    resolution: Resolution


class Retrace(NamedTuple):
    """What :meth:`Loop.reverse` did.

    Attributes:
        steps: Ticks taken.
        reached: Whether every recorded configuration was reached (no limit intervened
            beyond the extra ticks allowed).
        error: Largest joint distance [rad or m] from the segment's start at the end.
    """

    steps: int
    reached: bool
    error: float


class Loop:
    """The shared state and steps of a teleoperation loop (module docstring).

    Args:
        robot: The robot (a :class:`rrc_pin.Robot`, a cell included), already checked.
        dt: Control period [s], >= 1e-6 (:data:`rrc_pin.resolver.MIN_DT`).
        q0: Initial configuration (nq,) [rad or m]; default ``robot.ready()``.
        limits: The resolver's limits (None: ``JointLimits()``).
        qp: The resolver's QP backend and fallbacks.
        damping: The resolver's damping near singularities, or None.
        deadman: How a command ages, or None: a command stays in force until the next.
        speed: Speed override in [0, 1], settable.
        smoothing: The jerk stage's bounds, or None: the resolver's rates as they are.

    Attributes:
        smoothing: The jerk stage (its ``stop()``, ``stop_time()``, ``rates``), or None.
        smoothed: What the stage did at the last tick (:class:`Smoothed`: its ``changed``
            mask says where it changed the resolver's rates), or None.
        streams: The pose streams by the name they command (:meth:`stream`).

    Raises:
        InvalidInput: A bad argument, named; nothing is built.
    """

    log: RecordRing[Any]
    """The ticks recorded (a subclass makes it before its first tick)."""
    passing: float = 0.0
    """Distance [rad or m] within which :meth:`reverse` passes a recorded configuration
    other than the last without its tick being ``exact`` (0: exact ticks only)."""

    def __init__(
        self,
        robot: Robot,
        dt: float,
        q0: npt.ArrayLike | None,
        *,
        limits: Limit | Sequence[Limit] | None,
        qp: QPOptions | None,
        damping: Damping | None,
        deadman: Deadman | None,
        speed: float,
        smoothing: SmoothingOptions | None = None,
    ) -> None:
        if deadman is not None and not isinstance(deadman, Deadman):
            raise InvalidInput("deadman", f"expected a Deadman or None, got {deadman!r}")
        if smoothing is not None and not isinstance(smoothing, SmoothingOptions):
            raise InvalidInput("smoothing", f"expected SmoothingOptions or None, got {smoothing!r}")
        self.robot = robot
        # its ticks go through solve_at and tasks: the twist entry is not built
        self.resolver = Resolver(robot, dt, limits=limits, qp=qp, damping=damping,
                                 twists=False)
        self.dt = self.resolver.dt
        self._q = self._checked_q(robot.ready() if q0 is None else q0, "q0")
        self.speed = speed
        self.deadman = deadman
        self.t = 0.0
        self._command_time = -math.inf
        # Continuous joints as (cos, sin) or a floating base: q is not Pinocchio's q.
        self._manifold = robot.model.nq != robot.model.nv
        self._floating = robot.nq != robot.nv
        # A floating base and one-coordinate joints only: q is Pinocchio's q but the base's
        # quaternion normalised, each joint's coordinate at the same index.
        self._base_only = self._floating and robot.model.nq == robot.model.nv + 1
        self._q_pin: tuple[Array | None, Array] = (None, self._q)
        """The loop's ``q`` of the last conversion and Pinocchio's configuration of it."""
        margin = max((lim.margin for lim in self.resolver.limits if isinstance(lim, JointLimits)),
                     default=0.0)  # fmt: skip
        self.smoothing: JerkLimiter | None = (None if smoothing is None else
                                              smoothing.limiter(robot, self.dt, margin))
        self.smoothed: Smoothed | None = None
        self.streams: dict[str, PoseStream] = {}
        self._rates: Array = np.zeros(robot.nv)  # the rates of the last tick integrated

    # -- settings ---------------------------------------------------------------------------

    @property
    def q(self) -> Array:
        """Joint positions (nq,) [rad or m], read-only: set the attribute to move the robot."""
        return self._q

    @q.setter
    def q(self, value: npt.ArrayLike) -> None:
        self._q = self._checked_q(value, "q")
        self._configuration_set()
        self._hold_streams()

    def _checked_q(self, value: npt.ArrayLike, name: str) -> Array:
        """``value`` as a read-only copy of a valid configuration (nq,).

        Raises:
            InvalidInput: Not a finite (nq,) vector, naming ``name``.
        """
        q: Array = self.robot.check_q(value, name).copy()
        q.flags.writeable = False
        return q

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
    def masked(self) -> tuple[str, ...]:
        """The joints held still by the mask (:meth:`mask`), in the robot's order."""
        return self.resolver.masked

    def mask(self, joints: str | Iterable[str]) -> None:
        """Hold ``joints`` still from the next tick on (:meth:`~rrc_pin.resolver.Resolver.mask`).

        Raises:
            InvalidInput: ``joints`` is not names of the robot's joints, or names a mimic
                joint; the mask is then unchanged.
        """
        self.resolver.mask(joints)

    def unmask(self, joints: str | Iterable[str] | None = None) -> None:
        """Let ``joints`` move again from the next tick on, default every masked joint
        (:meth:`~rrc_pin.resolver.Resolver.unmask`)."""  # noqa: D205, D209
        self.resolver.unmask(joints)

    # -- reverse ----------------------------------------------------------------------------

    def reverse(self, seconds: float, extra: float = 1.0) -> Retrace:
        """Retrace the last ``seconds`` of the record back to where that segment started.

        Each tick aims at the previous recorded configuration, at the rates that reach it in
        one period, kept inside the limits by the resolver (scaled when they do not fit;
        then further ticks aim at the same configuration). When no limit intervenes the
        robot passes through the recorded configurations up to rounding. The commands are
        cleared (the operator must command again) and the reference poses reset.

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
        for i, target in enumerate(targets):
            passing = self.passing if i < n - 1 else 0.0
            while steps < budget:
                q = self.q
                rates = self._difference(q, target) / self.dt
                r = self.resolver.solve(q, [RatesTask(rates, "reverse")], priority="strict")
                self._log_reverse(q, r)
                self._advance(r)
                steps += 1
                if r.status == "exact":  # reached (to rounding): on to the next one
                    break
                if passing > 0.0 and np.abs(self._difference(self.q, target)).max() <= passing:
                    break
        self._command_time = -math.inf
        self._stopped()
        if self.smoothing is not None:  # retraced unsmoothed: the stage goes on from there
            self.smoothing.reset(self._rates)
        self._hold_streams()
        error = float(np.max(np.abs(self._difference(self.q, targets[-1]))))
        return Retrace(steps, error <= 1e-9 and steps <= budget, error)

    # -- pose streams -----------------------------------------------------------------------

    def stream(self, name: str | None = None, options: StreamOptions | None = None) -> PoseStream:
        """Stream a device's poses to ``name``'s frame; the stream (a new one each call).

        From the next :meth:`step` on, that frame's twist is the stream's
        (:meth:`PoseStream.twist`, base axes, times the speed override) at every tick, toward
        the target the device's samples give: push them with :meth:`PoseStream.push` (times on
        this loop's clock, :attr:`t`) and press the clutch with :meth:`PoseStream.clutch`,
        from any thread (open and close streams between ticks, in the loop's own). The stream
        starts anchored at the frame's pose now.

        Args:
            name: A frame of the robot (``Controller``: default its tool frame) or a command's
                name (``CellController``: an object, the body, a free hand).
            options: How it maps, bounds and judges the poses (default ``StreamOptions()``).

        Raises:
            InvalidInput: A name that cannot be streamed (the choices listed), bad options.
        """
        name = self._stream_name(name)
        made = PoseStream(self._pose_of(name), options)
        self.streams[name] = made
        return made

    def close_stream(self, name: str | None = None) -> None:
        """End ``name``'s stream (default: the tool frame's); its frame is commanded again.

        Raises:
            InvalidInput: ``name`` has no stream (the streamed ones listed).
        """
        name = self._stream_name(name)
        if name not in self.streams:
            raise InvalidInput("name", f"{name!r} has no stream; streamed: "
                               f"{', '.join(self.streams) or 'none'}")  # fmt: skip
        del self.streams[name]

    def _streamed(self, poses: dict[str, Array]) -> dict[str, Array]:
        """The streamed frames' twists (6,) in base axes at their ``poses`` (4, 4), this tick
        (before the speed override)."""  # noqa: D205, D209
        return {name: s.twist(self.t, poses[name])
                for name, s in self.streams.items() if name in poses}  # fmt: skip

    def _hold_streams(self) -> None:
        """Every stream's hand held where its frame is (the robot moved otherwise)."""
        for name, s in self.streams.items():
            s.reset(self._pose_of(name))

    # -- the jerk stage ----------------------------------------------------------------------

    def _previous_rates(self) -> Array | None:
        """The rates the joints have (the stage's) for the resolver, or None (its own)."""
        return None if self.smoothing is None else self.smoothing.rates

    def _smooth(self, r: Resolution) -> Resolution:
        """``r`` with the jerk stage's rates (inside its box), if there is a stage."""
        stage = self.smoothing
        if stage is None:
            return r
        self.smoothed = out = stage.step(r.qdot, r.box, self.robot.dof_positions(self._q))
        out.qdot.flags.writeable = False
        return r._replace(qdot=out.qdot)

    # -- what subclasses provide ---------------------------------------------------------

    def _stream_name(self, name: str | None) -> str:
        """``name`` checked as a streamable name (or the default for None)."""
        raise NotImplementedError

    def _pose_of(self, name: str) -> Array:
        """The pose (4, 4) in the base frame of the frame ``name`` commands, now."""
        raise NotImplementedError

    def _log_reverse(self, q: Array, r: Resolution) -> None:
        """Record one reverse tick from ``q`` (before it is integrated)."""
        raise NotImplementedError

    def _stopped(self) -> None:
        """Forget the commands and reset the reference poses (after :meth:`reverse`)."""
        raise NotImplementedError

    def _configuration_set(self) -> None:
        """The configuration was set from outside (``q = ...``); nothing by default."""

    # -- shared steps -----------------------------------------------------------------------

    def _weight(self) -> float:
        """The factor in [0, 1] of this tick's command.

        The speed override times the deadman's fade of a command older than its timeout (the
        time since the last one).
        """
        weight = self._speed
        age = self.t - self._command_time
        if self.deadman is not None and age > self.deadman.timeout:  # the command fades
            weight *= self.deadman.factor(age)
        return weight

    def _pinocchio_q(self, q: Array) -> Array:
        """Pinocchio's configuration of the loop's own ``q`` (valid: not checked again).

        The loop's current ``q`` is converted once (:attr:`_q_pin`, which a tick's kinematics
        may have set already): never write into the array returned.
        """
        if not self._manifold:
            return q
        known, q_pin = self._q_pin
        if known is not q:
            q_pin = self.robot.to_pinocchio(q)
            if q is self._q:
                self._q_pin = (q, q_pin)
        return q_pin

    def _difference(self, q: Array, target: Array) -> Array:
        """The displacement (nv,) [rad or m] from ``q`` to ``target`` on the manifold.

        ``target - q`` without a floating base (continuous joints as angles), else
        ``pinocchio.difference`` (the base's in body axes).
        """
        if not self._floating:
            out: Array = target - q
            return out
        model = self.robot.model
        moved: Array = pin.difference(model, self._pinocchio_q(q), self._pinocchio_q(target))
        return moved

    def _integrate(self, qdot: Array) -> Array:
        """The configuration (nq,) one period on from ``q`` at rates ``qdot`` (nv,).

        A new array (Barker eq. (21), ``pinocchio.integrate``), the floats of
        :meth:`~rrc_pin.robot.Robot.integrate` without checking the loop's own ``q`` again:
        one-coordinate joints move by ``q + qdot dt`` (Pinocchio's integration of a vector
        space); with a floating base, Pinocchio's integration of Pinocchio's configuration
        (:meth:`_pinocchio_q`) places the base, and each joint moves by the difference it made
        of the joint's coordinate (Pinocchio's difference of a vector space).
        """
        q = self._q
        self._rates = qdot
        if not self._manifold:
            out: Array = q + qdot * self.dt
            return out
        if not self._base_only or not all_finite(qdot):  # continuous joints, or refused
            return self.robot.integrate(q, qdot, self.dt)
        q_pin = self._pinocchio_q(q)
        moved: Array = pin.integrate(self.robot.model, q_pin, qdot * self.dt)
        moved[7:] = q[7:] + (moved[7:] - q_pin[7:])
        return moved

    def _advance(self, r: Resolution) -> Step:
        """Integrate ``r.qdot`` over one period and move the clock on."""
        q = self._integrate(r.qdot)
        q.flags.writeable = False  # the log and the Step hold it: never changed, replaced
        self._q = q
        self.t += self.dt
        return Step(q, r)
