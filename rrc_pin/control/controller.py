r"""Controller: Barker's operator loop on the resolver, one tick per call.

Every :meth:`Controller.step` takes the operator's twist in base axes (``ref="world_aligned"``,
the default), in the hand frame (Barker eq. (20), ``"local"``) or as the spatial twist at the
base origin (``"world"``), weights it by the speed override
and the deadman (:class:`~rrc_pin.control.deadman.Deadman`), adds the bounded pull back to
the commanded pose (:class:`~rrc_pin.control.drift.DriftCorrection`), lets the singularity
strategy adjust it (:mod:`rrc_pin.control.strategies`), resolves it with the
:class:`~rrc_pin.resolver.Resolver` (joint limits, margins) and integrates the rates for one
period (Barker eq. (21)) on the configuration manifold:

.. math:: q_{k+1} = q_k \oplus \dot q_k\, \Delta t \quad (\texttt{pinocchio.integrate}),

recording the tick in a :class:`~rrc_pin.control.trajectory_log.TrajectoryLog`.
:meth:`Controller.reverse` retraces the recorded joint positions back in time (Barker's
"speedy and effortless evacuation of the robot hand from a congested workspace").

A device's poses may command the tool frame, and any other frame of the robot (baxter's
second hand), instead of twists (:meth:`~rrc_pin.control.loop.Loop.stream`): each tick the
stream's bounded twist toward its target is the frame's command (the tool's through the same
path as a twist in base axes; another frame's as a :class:`~rrc_pin.tasks.FrameTask` in the
top level beside the tool's, one common scale; a strategy that chooses the joint rates
itself, Barker's on barker6, moves the arm alone and the other frames wait). The optional
jerk stage (``smoothing=``) runs after the resolver.
"""

from __future__ import annotations

import math
import os
import warnings
from typing import Any, NamedTuple

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.control.deadman import Deadman
from rrc_pin.control.drift import DriftCorrection, advance, pose_error
from rrc_pin.control.loop import Loop, Step
from rrc_pin.control.rates_task import RatesTask
from rrc_pin.control.record_ring import SHARED_TEXTS
from rrc_pin.control.singularity import SingularityLabel
from rrc_pin.control.smoothing import SmoothingOptions
from rrc_pin.control.strategies import Situation, Strategy, make_strategy
from rrc_pin.control.strategies.base import KEEP, to_base_axes
from rrc_pin.control.trajectory_log import LogRecord, TrajectoryLog
from rrc_pin.deprecated import warn_renamed
from rrc_pin.errors import InvalidInput
from rrc_pin.kinematics import Kinematics
from rrc_pin.limits import JointLimits
from rrc_pin.loading import cells, loaded
from rrc_pin.resolver import QPOptions
from rrc_pin.robot import Robot
from rrc_pin.solvers.checks import as_vector, finite_number
from rrc_pin.solvers.compiled import kernel
from rrc_pin.solvers.spatial import Reference, check_reference, to_world_aligned
from rrc_pin.solvers.tick.damping import Damping
from rrc_pin.solvers.tick.problem import LARGE
from rrc_pin.solvers.tick.resolution import ACTIVE_TOL, Resolution
from rrc_pin.tasks import FrameTask

Array = npt.NDArray[np.float64]
LINEAR = np.array([1.0, 1.0, 1.0, 0.0, 0.0, 0.0])
REANCHOR = ("damped", "singular", "least_squares", "recovering", "fallback")
"""Statuses whose motion departs from the command's direction: the reference pose is reset to
the reached pose instead of pulling the hand back to a pose it could not follow."""
NO_ERROR = np.zeros(6)
"""The pose error of a tick without a reference (``reverse``)."""
NO_ERROR.flags.writeable = False


class Tick(NamedTuple):
    """A tick as the log keeps it: the fields of its :class:`LogRecord` the tick knows.

    Its record is derived from it when the log is read (``_log_record``: the rest comes from
    the kinematics at q).

    Attributes:
        t: Time at the start of the tick [s].
        q: Joint positions at the start of the tick (nq,) [rad or m].
        qdot: Joint rates applied over the tick (nq,) [rad/s or m/s].
        commanded: The operator's command (6,) [m/s, rad/s], in hand axes where ``local``
            (turned to base axes when the record is derived), else in base axes.
        scale: The resolution's scale.
        factor: The strategy's speed factor.
        drift_position: Distance [m] from the reference pose.
        drift_rotation: Angle [rad] from the reference orientation.
        mode: ``"teleop"`` or ``"reverse"``.
        method: The resolution's method.
        status: The resolution's status.
        active: The active limits, ``joint:side:kind`` joined by ``;``.
        note: What the strategy did.
        local: Whether ``commanded`` is in the axes of the tool at q.
    """

    t: float
    q: Array
    qdot: Array
    commanded: Array
    scale: float
    factor: float
    drift_position: float
    drift_rotation: float
    mode: str
    method: str
    status: str
    active: str
    note: str
    local: bool


class Controller(Loop):
    """A resolved-rate teleoperation loop holding the arm's configuration.

    Built on :class:`~rrc_pin.control.loop.Loop` (speed override, deadman, integration,
    log ring, ``reverse``). ``Controller(cell)`` with a :class:`~rrc_pin.cells.Cell` (or a
    cell's name) makes a :class:`~rrc_pin.cells.CellController` instead: the same loop with
    one command per held object, body or free hand (its own keyword arguments).

    Args:
        robot: A :class:`rrc_pin.Robot` with one tool frame, or a name :func:`rrc_pin.load`
            takes; a cell (or a cell's name) makes a ``CellController``.
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
        smoothing: Bounds of the jerk stage after the resolver
            (:class:`~rrc_pin.control.smoothing.SmoothingOptions`), or None (no stage).

    Raises:
        InvalidInput: A bad argument, named; a robot with several tool frames that is not a
            cell names ``tool_frame`` (load one hand) and ``make_cell`` (a cell of them).
        UnknownArm, URDFError: ``robot`` is a name or path that does not load.
    """

    def __new__(cls, robot: Robot | str, *args: Any, **kwargs: Any) -> Controller:
        """A ``Controller``, or a ``CellController`` for a cell or a cell's name.

        The cell's controller is built here with the same arguments (its own keywords:
        ``gain``, ``coupled``, ...; ``strategy``, ``drift`` and ``near`` are one arm's).
        Statically it reads as a ``Controller``: annotate with ``CellController`` (or
        build one directly) where its own methods are used.
        """
        if cls is Controller and ((isinstance(robot, str) and robot in cells())
                                  or _is_cell(robot)):  # fmt: skip
            from rrc_pin.cells.controller import CellController  # the cells sit above

            made: Any = CellController(robot, *args, **kwargs)  # type: ignore[arg-type]
            return made  # type: ignore[no-any-return]
        return super().__new__(cls)

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
        smoothing: SmoothingOptions | None = None,
    ) -> None:
        robot = _loaded(robot)
        if robot.tool_frame is None:
            raise InvalidInput(
                "robot", f"{robot.name} has several tool frames ({', '.join(robot.tool_frames)}); "
                "load it with tool_frame=... for one hand, or make a cell of its arms "
                "(rrc_pin.make_cell) for one command per hand",
            )
        if drift is not None and not isinstance(drift, DriftCorrection):
            raise InvalidInput("drift", f"expected a DriftCorrection or None, got {drift!r}")
        super().__init__(robot, dt, q0, limits=limits, qp=qp, damping=damping, deadman=deadman,
                         speed=speed, smoothing=smoothing)  # fmt: skip
        self.strategy = make_strategy(strategy)
        self.strategy.check(robot)
        self.drift = drift
        self.label = SingularityLabel(robot, finite_number(near, "near", 0.0, inclusive=False))
        self.log: TrajectoryLog = TrajectoryLog(robot.joint_names, self._log_record)
        self._active_texts: dict[bytes, str] = {}
        self._codes = np.zeros(robot.nv, np.int8)  # the last tick's bounds touched
        fixed = np.zeros(robot.nv)
        fixed.flags.writeable = False  # as a Resolution's rates are (compiled now for both)
        for qdot in (fixed, np.zeros(robot.nv)):
            active_codes(qdot, np.zeros(robot.nv), np.zeros(robot.nv),
                         np.zeros((2, robot.nv), np.int8), self._codes)  # fmt: skip
        assert self.resolver.task is not None  # one tool frame: the resolver has its task
        self._rows = tuple(self.resolver.task.selected)
        self._full = len(self._rows) == 6
        self._data = robot.model.createData()
        self._log_data = robot.model.createData()  # the records' kinematics, when read
        self._tool: str = robot.tool_frame
        self._command: Array = np.zeros(6)
        self._command_frame: Reference = "world_aligned"
        self._default_warned = False
        self._reference = self._kinematics(self._q).placement(self._tool)
        self._reanchor = False

    # -- settings ---------------------------------------------------------------------------

    @property
    def reference(self) -> Array:
        """The commanded pose (4, 4) the drift correction pulls toward (a copy)."""
        out: Array = self._reference.homogeneous
        return out

    # -- the loop ---------------------------------------------------------------------------

    def step(
        self,
        twist: npt.ArrayLike | None = None,
        ref: Reference | None = None,
        *,
        frame: Reference | None = None,
    ) -> Step:
        """Resolve and integrate one tick of the operator's command.

        Args:
            twist: Commanded twist [v; w] (6,) [m/s, rad/s] of the tool frame in ``ref``,
                or None: no new command this tick (the last one ages, see ``deadman``; a
                streamed tool frame follows its stream, and takes no twist).
            ref: The twist's frame, as everywhere in rrc-pin (:mod:`rrc_pin.solvers.spatial`):
                ``"world_aligned"`` (default: the hand's velocity in base axes), ``"local"``
                (hand axes, Barker eq. (20)) or ``"world"`` (the spatial twist at the base
                origin; full twists only). A command keeps its frame while it ages.
            frame: The old name of ``ref`` (deprecated).

        Returns:
            The new configuration and the tick's resolution (its ``qdot`` the rates
            integrated: the jerk stage's where there is one, :attr:`smoothed` saying where
            it changed the resolver's).

        Raises:
            InvalidInput: A bad ``twist`` (shape, NaN, inf) or ``ref``, or a twist for a
                streamed tool frame, raised before any state changes.
        """
        if twist is not None and self._tool in self.streams:
            raise InvalidInput("twist", f"{self._tool} follows its pose stream: give no twist, "
                               "or close_stream() first")  # fmt: skip
        self._take(twist, ref, frame)
        q = self._q
        kin = self._kinematics(q)  # the tick's one: pose, strategy, resolver and log read it
        kin.jacobian(self._tool, "world_aligned")  # first: it places the hand too
        pose = kin.placement(self._tool)
        others = self._follow_streams(kin, pose) if self.streams else []
        weight = self._weight()
        given = self._command if weight == 1.0 else weight * self._command  # in ``ref``
        ref = self._command_frame
        local = ref == "local"
        command = given  # served in hand axes (local) or base axes; a world twist turned so:
        if ref == "world":
            command = to_world_aligned(given, pose.rotation, pose.translation, "world")
        if self._reanchor:
            self._reference, self._reanchor = pose, False
        error = pose_error(pose, self._reference)  # hand axes
        if not self._full:  # position rows only: the orientation is not commanded
            error[3:] = 0.0
        # What to serve, in the command's axes: the command plus the correction.
        if self.drift is None or weight == 0.0:  # an arm stopped or let go stands still
            wanted = command
        else:
            correction = weight * self.drift.twist(error)  # hand axes
            wanted = command + (correction if local else to_base_axes(pose.rotation, correction))
        hand = pose if local else None
        if self.strategy.passive:  # it keeps the command: no Situation to build
            decision = KEEP
        else:  # (a command beyond LARGE divided down along itself: no rates overflow)
            down = _within_large(wanted)
            decision = self.strategy.decide(Situation(
                self.robot, q, wanted * down, self.dt, command * down, self._rows, hand, kin))
        factor = decision.factor
        before = self._previous_rates()
        if decision.rates is not None:
            r = self.resolver.solve_at(kin, [RatesTask(decision.rates)], priority="strict",
                                       qdot_prev=before)  # fmt: skip
        else:
            served = wanted if factor == 1.0 else factor * wanted
            frame_ref: Reference = "local" if local else "world_aligned"
            if others:  # the tool and the streamed frames: one level, one common scale
                top = [FrameTask(self._tool, served, ref=frame_ref, rows=self._rows), *others]
                r = self.resolver.solve_at(kin, [top], priority="strict", qdot_prev=before)
            else:
                r = self.resolver.solve_at(kin, served, frame_ref, qdot_prev=before)
        r = self._smooth(r)
        # q itself, not a copy: read-only, replaced at every tick.
        self._log_tick(q, r, command, hand, factor, error, "teleop", decision.note)
        fraction = None if decision.rates is not None else _followed(r)
        if fraction is None or self._tool in self.streams:  # (a stream's target: the reference)
            self._reanchor = True
        elif self._full:  # the command, for the time it was followed
            self._reference = advance(self._reference, given, factor * fraction * self.dt, ref)
        else:  # the commanded position, at the orientation reached
            moved = to_base_axes(pose.rotation, command) if local else command
            self._reference = advance(self._reference, moved * LINEAR,
                                      factor * fraction * self.dt, "world_aligned")
        return self._advance(r)

    def _follow_streams(self, kin: Kinematics, pose: pin.SE3) -> list[FrameTask]:
        """The streamed commands of this tick: the tool's taken as its command, others' tasks.

        A streamed tool frame's command is its stream's twist (base axes), new every tick
        (the deadman does not age it: the stream fades its own dropouts), and its reference
        is the pose reached at every tick (the stream's target is the reference).
        """
        poses = {f: pose.homogeneous if f == self._tool else kin.pose(f) for f in self.streams}
        twists = self._streamed(poses)
        tool = twists.pop(self._tool, None)
        if tool is not None:
            self._command, self._command_frame = tool, "world_aligned"
            self._command_time = self.t
        return [FrameTask(f, self.speed * twist, name=f) for f, twist in twists.items()]

    def _take(
        self, twist: npt.ArrayLike | None, ref: Reference | None, frame: Reference | None
    ) -> None:
        """Keep a new command and its frame, checked (the old keyword ``frame`` mapped).

        Raises:
            InvalidInput: A bad ``twist`` or ``ref``, or both ``ref`` and ``frame``, before
                anything is kept.
        """
        if frame is not None:
            warn_renamed("Controller.step(frame=)", "Controller.step(ref=)", stacklevel=4)
            if ref is not None:
                raise InvalidInput("frame", "the old name of ref: pass ref alone")
            ref = frame
        if twist is None:
            if ref is not None:
                self._checked_ref(ref)
            return
        command = _checked_twist(twist)
        self._command_frame = self._checked_ref("world_aligned" if ref is None else ref)
        self._command, self._command_time = command, self.t
        if ref is None:
            self._warn_default()

    def _checked_ref(self, ref: object) -> Reference:
        """``ref`` if it names a frame this controller's task can be commanded in.

        Raises:
            InvalidInput: Naming ``ref``: not a frame's name, or ``world`` on an arm whose
                task has position rows only (a spatial twist needs its angular rows).
        """
        checked = check_reference(ref)  # type: ignore[arg-type]
        if checked == "world" and not self._full:
            raise InvalidInput(
                "ref", f"{self.robot.name} is commanded in position only (below six joints); "
                "a 'world' twist is the spatial twist of the whole hand: use 'world_aligned'",
            )
        return checked

    def _warn_default(self) -> None:
        """Warn once per controller that a twist without ``ref`` is now ``world_aligned``."""
        if not self._default_warned:
            self._default_warned = True
            warnings.warn(
                "Controller.step(twist) without ref: the twist is in 'world_aligned' (base "
                "axes), the default of every entry point; before this release the "
                "controller's default was 'local' (hand axes). Pass ref= to choose and "
                "silence this", FutureWarning, stacklevel=4,
            )

    # -- what the loop asks of it -----------------------------------------------------------

    def _log_reverse(self, q: Array, r: Resolution) -> None:
        self._log_tick(q, r, np.zeros(6), None, 1.0, NO_ERROR, "reverse", "")

    def _stopped(self) -> None:
        self._command = np.zeros(6)
        self._reanchor = True

    def close_stream(self, name: str | None = None) -> None:
        """End ``name``'s stream (default: the tool frame's); the tool frame then holds.

        Raises:
            InvalidInput: ``name`` has no stream (the streamed ones listed).
        """
        super().close_stream(name)
        if name is None or name == self._tool:  # its last twist does not age on
            self._stopped()

    def _stream_name(self, name: str | None) -> str:
        if name is None:
            return self._tool
        if not isinstance(name, str) or name not in self.resolver.layout.frames:
            raise InvalidInput("name", f"expected a frame of {self.robot.name} (the tool frame "
                               f"{self._tool!r} by default), got {name!r}")  # fmt: skip
        return name

    def _pose_of(self, name: str) -> Array:
        return self._kinematics(self._q).pose(name)

    # -- helpers ----------------------------------------------------------------------------

    def _kinematics(self, q: Array) -> Kinematics:
        """The kinematics of the loop's own ``q`` (valid: not checked again), on own data."""
        return Kinematics(self.robot.model, self._data, self.resolver.layout,
                          self.robot.dof_positions(q), self._pinocchio_q(q))  # fmt: skip

    def _log_tick(self, q: Array, r: Resolution, command: Array, hand: pin.SE3 | None,
                  factor: float, error: Array, mode: str, note: str) -> None:  # fmt: skip
        """Write the tick into the log's rows as it comes (its record derived when read).

        Args:
            q: Joint positions at the start of the tick (nq,) [rad or m] (kept, read-only).
            r: The resolver's answer.
            command: The operator's command (6,) [m/s, rad/s] (speed override, deadman).
            hand: The tool's pose when ``command`` is in hand axes, else None (base axes).
            factor: The strategy's speed factor.
            error: The pose error to the reference (6,) [m, rad]
                (:func:`~rrc_pin.control.drift.pose_error`).
            mode: ``"teleop"`` or ``"reverse"``.
            note: What the strategy did.
        """
        e = error.tolist()
        box = r.box
        touched = active_codes(r.qdot, box.lb, box.ub, box.kind, self._codes)
        self.log.append_tick(Tick(
            self.t, q, r.qdot, command, r.scale, factor,
            math.sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]),
            math.sqrt(e[3] * e[3] + e[4] * e[4] + e[5] * e[5]), mode, r.method, r.status,
            self._active_text(self._codes, r) if touched else "", note, hand is not None,
        ))  # fmt: skip

    def _active_text(self, codes: npt.NDArray[np.int8], r: Resolution) -> str:
        """The active limits of ``r`` as the log writes them, ``joint:side:kind;...``."""
        key = codes.tobytes()
        text = self._active_texts.get(key)
        if text is None:
            text = ";".join(f"{a.name or a.joint}:{a.side}:{a.kind}" for a in r.active)
            if len(self._active_texts) < SHARED_TEXTS:
                self._active_texts[key] = text
        return text

    def _log_record(self, tick: Tick) -> LogRecord:
        """The log's record of a tick: the tick and the kinematics at its q, computed now (a
        command in hand axes turned to base axes by the tool's orientation at q).
        """  # noqa: D205
        J = self.robot.jacobian(tick.q)  # world_aligned, the tick's start
        commanded = tick.commanded
        if tick.local:
            kin = Kinematics(self.robot.model, self._log_data, self.resolver.layout,
                             self.robot.dof_positions(tick.q), self._pinocchio_q(tick.q))
            commanded = to_base_axes(kin.placement(self._tool).rotation, commanded)
        J_task = J if self._full else J[list(self._rows)]
        sv: Array = np.asarray(np.linalg.svd(J_task, compute_uv=False), np.float64)
        return LogRecord(
            t=tick.t, q=tick.q, qdot=tick.qdot, commanded=commanded,
            achieved=J @ tick.qdot, scale=tick.scale, factor=tick.factor,
            sigma_min=float(sv[-1]), manipulability=float(np.prod(sv)),
            drift_position=tick.drift_position, drift_rotation=tick.drift_rotation,
            mode=tick.mode, method=tick.method, status=tick.status, active=tick.active,
            singularity=self.label(tick.q, J_task, sv), note=tick.note,
        )


@kernel
def active_codes(qdot: Array, lb: Array, ub: Array, kind: npt.NDArray[np.int8],
                 codes: npt.NDArray[np.int8]) -> bool:  # fmt: skip
    """The bounds ``qdot`` (n,) touches within :data:`ACTIVE_TOL` into ``codes`` (n,), and
    whether it touches any: per joint ``1 + kind[0]`` for its lower bound ``lb``, plus ``4 (1 +
    kind[1])`` for its upper one ``ub`` (``kind`` (2, n): what sets each bound, ``Box.kind``).
    """  # noqa: D205
    touched = False
    for j in range(qdot.size):
        code = 0
        if qdot[j] - lb[j] <= ACTIVE_TOL:
            code += 1 + kind[0, j]
        if ub[j] - qdot[j] <= ACTIVE_TOL:
            code += 4 * (1 + kind[1, j])
        codes[j] = code
        touched = touched or code != 0
    return touched


def _loaded(robot: Robot | str) -> Robot:
    """``robot``, loaded when it is a name.

    Raises:
        InvalidInput: Neither a Robot nor a name, naming ``robot``.
    """
    if isinstance(robot, (str, os.PathLike)):
        robot = loaded(robot, "robot")
    if not isinstance(robot, Robot):
        raise InvalidInput("robot", f"expected a rrc_pin.Robot or a name, got {robot!r}")
    return robot


def _is_cell(robot: object) -> bool:
    """Whether ``robot`` is a :class:`~rrc_pin.cells.Cell`.

    Imported here: the cells' package imports their controller, which imports this module.
    """
    from rrc_pin.cells.cell import Cell

    return isinstance(robot, Cell)


def _checked_twist(twist: npt.ArrayLike) -> Array:
    """``twist`` as a new finite (6,) float array.

    Raises:
        InvalidInput: Naming ``twist``: not a real (6,) vector, or NaN or inf in it.
    """
    out: Array = as_vector(twist, "twist", 6).copy()
    return out


def _within_large(twist: Array) -> float:
    """The factor (1, or less) that brings ``twist`` within :data:`LARGE` [m/s, rad/s].

    The strategies' closed forms divide a command by the arm's singular values: beyond it
    their rates overflow (a NaN configuration, before). The resolver divides its own commands
    down the same way (:mod:`rrc_pin.solvers.tick.problem`).
    """
    peak = float(np.abs(twist).max())
    return 1.0 if peak <= LARGE else LARGE / peak


def _followed(r: Resolution) -> float | None:
    """Fraction in [0, 1] of a twist's command the resolution achieved along its direction.

    None when the answer departs from the command's direction (:data:`REANCHOR`).
    """
    return None if r.status in REANCHOR else r.scale
