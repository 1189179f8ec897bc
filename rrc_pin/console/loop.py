"""ControlLoop: the controller's thread, at its own rate, fed only through the mailbox.

One thread owns the :class:`~rrc_pin.Controller`. Every tick it drains the
:class:`~rrc_pin.console.mailbox.Mailbox` (the page's commands, checked when they were made),
applies them, asks the :class:`~rrc_pin.console.operator.Operator` for the twist (or, while
a device streams poses, lets the controller follow the hand's stream: ``Controller.stream``,
clutched while the deadman is released), steps the controller once and publishes a
:class:`~rrc_pin.console.snapshot.Snapshot` (one reference assignment: a reader gets the old
one or the new one). Nothing else touches the controller,
except a worker thread the loop starts for a long job (reverse, save, load) while it holds the
arm still and keeps ticking.

A command the loop cannot honour (a strategy the arm refuses, a reverse longer than the
record) is refused with a :class:`Notice`; an unexpected error in a tick stops the arm, is
reported the same way, and the loop goes on ticking: a page can neither stop nor corrupt it.
"""

from __future__ import annotations

import collections
import os
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Literal, NamedTuple, cast

import numpy as np
import numpy.typing as npt

from rrc_pin.cells.cell_log import CellLog
from rrc_pin.console import commands as cmd
from rrc_pin.console.mailbox import Mailbox, urgent
from rrc_pin.console.operator import Operator, OperatorSettings
from rrc_pin.console.rate import Rate, TickClock
from rrc_pin.console.snapshot import Mode, Snapshot
from rrc_pin.control import STRATEGIES, Controller, TrajectoryLog, make_strategy
from rrc_pin.control.loop import Loop
from rrc_pin.errors import InvalidInput, RrcPinError
from rrc_pin.limits import JointLimits
from rrc_pin.resolver import QPOptions, Resolver
from rrc_pin.robot import Robot
from rrc_pin.solvers.checks import finite_number
from rrc_pin.solvers.qp_backends import installed_backends
from rrc_pin.solvers.tick.resolution import Resolution

Array = npt.NDArray[np.float64]
LOOP_NICE = -10
"""The nice value the loop's thread asks for: ahead of the view, the page's callbacks and other
processes where the OS allows it (the GIL is still shared: see the switch interval of
:mod:`rrc_pin.console.app`)."""


class Notice(NamedTuple):
    """A message of the loop for the page.

    Attributes:
        id: Increasing number (the page shows each once).
        level: ``"info"`` or ``"error"``.
        text: One line.
    """

    id: int
    level: Literal["info", "error"]
    text: str


class _Job:
    """A long job on the controller in a worker thread; the loop holds the arm meanwhile."""

    def __init__(self, name: str, work: Callable[[], object]) -> None:
        self.name = name
        self.result: object = None
        self.error: BaseException | None = None
        self.done = threading.Event()

        def run() -> None:
            try:
                self.result = work()
            except Exception as exc:  # reported by the loop as a notice, never raised
                self.error = exc
            finally:
                self.done.set()

        self.thread = threading.Thread(target=run, name=f"rrc-pin console {name}", daemon=True)
        self.thread.start()


class ControlLoop:
    """The console's control loop: a :class:`~rrc_pin.Controller` ticking in its own thread.

    Args:
        robot: The robot; with several tool frames the first is commanded first
            (:class:`~rrc_pin.console.commands.Hand` switches).
        rate: Loop rate [1/s], > 0: the controller's period is ``1 / rate``.
        q0: Start configuration (nq,) [rad or m]; default :func:`start_pose`.
        mailbox: Where the page's commands arrive (default a new one).
        settings: Limits of the operator's controls.
        strategy: Singularity strategy's name (``rrc_pin.control.STRATEGIES``).
        backend: QP backend's name (``installed_backends()``).
        record_limit: Longest record [s], > 0: a full record holds the arm until saved or
            dropped (full also at the log's capacity, ``TrajectoryLog.capacity`` ticks).
        priority: Nice value asked for the loop's thread (Linux: per thread; a negative one
            needs root or CAP_SYS_NICE, else the thread keeps its priority), or None.
        realtime: Run the loop's thread under real-time scheduling (``SCHED_FIFO`` at
            :data:`REALTIME_PRIORITY`, Linux, root or CAP_SYS_NICE), sleeping at least
            :data:`MIN_SLEEP` per tick; where it is not permitted, ``priority`` instead (and
            a notice says so).

    Attributes:
        scheduling: How the loop's thread is scheduled once it runs (``"SCHED_FIFO 10"``,
            ``"nice -10"``...).
        clock: The ticks' periods and work times (:class:`~rrc_pin.console.rate.TickClock`).
        skipped: Deadlines given up after a stall of more than a period.
        errors: Ticks that raised (each reported as a notice; the arm stopped).
        halted: The tick (``clock.ticks``) that applied the last STOP or release of the arm
            (:func:`~rrc_pin.console.mailbox.urgent`), or -1.

    Raises:
        InvalidInput: A bad argument, named (a strategy the arm cannot take included).
    """

    def __init__(
        self,
        robot: Robot,
        *,
        rate: float = 100.0,
        q0: npt.ArrayLike | None = None,
        mailbox: Mailbox | None = None,
        settings: OperatorSettings | None = None,
        strategy: str = "resolver",
        backend: str = "daqp",
        record_limit: float = 120.0,
        priority: int | None = LOOP_NICE,
        realtime: bool = False,
    ) -> None:
        if not isinstance(robot, Robot):
            raise InvalidInput("robot", f"expected a rrc_pin.Robot, got {robot!r}")
        if priority is not None and (isinstance(priority, bool) or not isinstance(priority, int)):
            raise InvalidInput("priority", f"expected a nice value (int) or None, got {priority!r}")
        self.robot = robot
        self.priority = priority
        self.realtime = bool(realtime)
        self.scheduling = "not started"
        self.rate = finite_number(rate, "rate", 0.0, inclusive=False)
        self.dt = 1.0 / self.rate
        self.mailbox = Mailbox() if mailbox is None else mailbox
        self.operator = Operator(settings)
        self.record_limit = finite_number(record_limit, "record_limit", 0.0, inclusive=False)
        self.hands: tuple[str, ...] = robot.tool_frames
        self.start_q = start_pose(robot) if q0 is None else robot.check_q(q0, "q0").copy()
        self.clock = TickClock()
        self.backends = tuple(installed_backends())
        self.strategies = tuple(name for name in STRATEGIES if _takes(robot, name))
        cmd.one_of(backend, "backend", self.backends)
        cmd.one_of(strategy, "strategy", tuple(STRATEGIES))
        self._strategy, self._backend, self._hand = strategy, backend, self.hands[0]
        self.ctl: Loop = self._controller(self.start_q, self._hand)
        self.hands = self._commandable()
        self._hand = self.hands[0]
        self.recording = False
        self.notices: collections.deque[Notice] = collections.deque(maxlen=50)
        self.errors = 0
        self.skipped = 0
        self.halted = -1
        self._notice_id = 0
        self._job: _Job | None = None
        self._held_q: Array = self.ctl.q
        self._playback: collections.deque[Array] = collections.deque()
        self._replay: collections.deque[Array] = collections.deque()
        self._stop_now = False
        self._clutch = False
        self._full = False
        self._thread: threading.Thread | None = None
        self._stop = threading.Event()
        self._snapshot = self._snap(None, None, "held", False)

    # -- the thread ---------------------------------------------------------------------------

    def start(self) -> None:
        """Start ticking in a new thread (once)."""
        if self._thread is not None:
            return
        self._thread = threading.Thread(target=self._run, name="rrc-pin control loop", daemon=True)
        self._thread.start()

    def stop(self, timeout: float = 2.0) -> None:
        """Stop the thread and wait for it (up to ``timeout`` [s])."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout)

    @property
    def alive(self) -> bool:
        """Whether the loop's thread is running."""
        return self._thread is not None and self._thread.is_alive()

    @property
    def snapshot(self) -> Snapshot:
        """The state after the last tick (any thread)."""
        return self._snapshot

    def _run(self) -> None:
        self.scheduling = self._schedule()
        rate = Rate(self.rate, min_sleep=MIN_SLEEP if self.realtime else 0.0)
        while not self._stop.is_set():
            now = self.clock.tick()
            try:
                self.tick(now)
            except Exception as exc:  # a loop must outlive one bad tick: stop the arm, say why
                self.errors += 1
                self.operator.stop()
                self._stop_now = True
                self.notice("error", f"tick failed ({type(exc).__name__}: {exc}); arm stopped")
            self.clock.done()
            self.skipped = rate.skipped
            rate.sleep(self._stop)

    def _schedule(self) -> str:
        """Ask the OS to schedule this (the loop's) thread as configured; say how it is."""
        how, refused = schedule(self.realtime, REALTIME_PRIORITY, self.priority)
        if refused is not None:
            self.notice("error", f"real-time scheduling refused ({refused}): a nice loop instead")
        return how

    # -- one tick -----------------------------------------------------------------------------

    def tick(self, now: float | None = None) -> Snapshot:
        """Apply the waiting commands, step the controller once, publish the snapshot.

        The loop's thread calls it at every deadline; a test may call it directly instead
        of starting the thread.

        Args:
            now: Time of the tick [s] (``time.perf_counter``); default now.
        """
        now = time.perf_counter() if now is None else now
        for command in self.mailbox.drain():
            if urgent(command):
                self.halted = self.clock.ticks
            try:
                self._apply(command, now)
            except RrcPinError as exc:
                self.notice("error", " ".join(str(exc).split()))
        if self._job is not None:
            if not self._finish_job():
                self._snapshot = self._snap(None, None, "held", False, self._held_q)
                return self._snapshot
            if self._replay:  # the arm placed at the record's start: shown before it moves
                return self._publish(None, None, "replay")
        if self._playback:  # the retrace computed by the worker, shown at the loop's rate
            q = self._playback.popleft()
            self._snapshot = self._snap(None, None, "reverse", False, q)
            return self._snapshot
        if self._stop_now:
            self._stop_now = False
            self._replay.clear()
            self._end_stream()
            return self._publish(*self._step(np.zeros(6), "local"), "teleop", False)
        if self._replay:
            twist = self._replay.popleft()
            if not self._replay:
                self.notice("info", "replay done")
            return self._publish(*self._step(twist, "world_aligned"), "replay")
        if self._full:
            return self._publish(None, None, "held")
        stream = self.ctl.streams.get(self._hand)
        if stream is not None:  # the device's: held (clutched) while the deadman is released
            enabled = self.operator.enabled(now)
            stream.clutch(self._clutch or not enabled, self.ctl.t)
            return self._publish(self._step(None, "local")[0], None, "stream", enabled)
        pose = self.robot_pose() if self.operator.needs_pose() else None
        wanted = self.operator.twist(now, pose)
        mode: Mode = "target" if wanted is not None and pose is not None else "teleop"
        if wanted is None:
            return self._publish(*self._step(None, "local"), mode)
        return self._publish(*self._step(*wanted), mode)

    def _step(self, twist: Array | None, frame: cmd.Frame) -> tuple[Resolution, Array | None]:
        """The one call of ``Controller.step``: ``twist`` (None: no new command) to the hand."""
        step = self._arm().step(twist, ref=frame)
        return step.resolution, twist

    def _arm(self) -> Controller:
        """The controller, an arm's (:class:`~rrc_pin.console.cell_loop.CellLoop` a cell's)."""
        return cast(Controller, self.ctl)

    def _publish(self, resolution: Resolution | None, twist: Array | None, mode: Mode,
                 enabled: bool | None = None) -> Snapshot:  # fmt: skip
        log = self.ctl.log
        if not self.recording:
            log.clear()  # nothing kept: the log stays empty between records
        elif not self._full and (len(log) * self.dt >= self.record_limit
                                 or len(log) >= log.capacity):  # fmt: skip
            self._full = True  # (a full log, a ring, would forget the record's start)
            self.operator.stop()
            self.notice(
                "error",
                f"record full ({len(log) * self.dt:g} s): the arm holds; save it or stop recording",
            )
        if enabled is None:
            enabled = twist is not None and mode in ("teleop", "target")
        self._snapshot = self._snap(resolution, twist, mode, enabled)
        return self._snapshot

    def _snap(self, resolution: Resolution | None, twist: Array | None, mode: Mode, enabled: bool,
              q: Array | None = None) -> Snapshot:  # fmt: skip
        ctl = self.ctl
        return Snapshot(
            tick=self.clock.ticks,
            t=ctl.t,
            q=ctl.q if q is None else q,
            resolution=resolution,
            twist=twist,
            frame=self.operator.frame,
            hand=self._hand,
            enabled=enabled,
            mode=mode,
            recording=self.recording,
            recorded=len(ctl.log) * self.dt if self.recording else 0.0,
            speed=ctl.speed,
            strategy=self._strategy,
            backend=self._backend,
            target=self.operator.target,
            latched=self.operator.latched,
            stops=self.operator.stops,
            name=self._hand,
        )

    def _commandable(self) -> tuple[str, ...]:
        """The names the controls command (:class:`~rrc_pin.console.commands.Hand`): tool frames."""
        return self.robot.tool_frames

    def robot_pose(self) -> Array:
        """The commanded hand's pose (4, 4) at the controller's q (base frame) [m]."""
        pose: Array = self.ctl.robot.fk(self.ctl.q)
        return pose

    def notice(self, level: Literal["info", "error"], text: str) -> None:
        """Say something to the page (kept among the last 50)."""
        self._notice_id += 1
        self.notices.append(Notice(self._notice_id, level, text))

    # -- commands ---------------------------------------------------------------------------

    def _apply(self, c: cmd.Command, now: float) -> None:
        """Apply one command (raises RrcPinError to refuse it; nothing changed then)."""
        if isinstance(c, (cmd.Velocity, cmd.Jog, cmd.Hold, cmd.Latch, cmd.Target)):
            self.operator.apply(c, now)  # busy or not: the controls' state, read when stepping
        elif isinstance(c, cmd.Pose):
            self._device(c)
        elif isinstance(c, (cmd.Stop, cmd.Released)):
            self.operator.stop()
            self._stop_now = True
            self._playback.clear()
            if isinstance(c, cmd.Released):
                self.notice("info", "no page connected: deadman released")
        elif isinstance(c, cmd.Speed):
            self.ctl.speed = c.value
        elif isinstance(c, cmd.Strategy):
            self._set_strategy(c.name)
        elif isinstance(c, cmd.Backend):
            self._set_backend(c.name)
        elif isinstance(c, cmd.Hand):
            self._set_hand(c.frame)
        elif isinstance(c, cmd.Record):
            self._record(c.on)
        elif isinstance(c, cmd.Home):
            self._no_jump("go home")
            self.operator.stop()
            self.ctl = self._controller(self.start_q, self._hand, self.ctl.speed)
        elif isinstance(c, cmd.Reverse):
            self._reverse(c.seconds)
        elif isinstance(c, cmd.Save):
            self._save(c)
        else:
            self._load(c.path)

    def _device(self, c: cmd.Pose) -> None:
        """A device's sample into the hand's stream (the first opens it); None ends it.

        Samples are timed at the tick that takes them (the controller's clock); while the arm
        is busy (reverse, load, replay) they are dropped.
        """
        if c.pose is None:
            self._end_stream()
            return
        if self._busy() or self._replay or self._full:
            return
        stream = self.ctl.streams.get(self._hand) or self.ctl.stream(self._hand)
        self._clutch = c.clutch
        stream.push(self.ctl.t, c.pose)

    def _end_stream(self) -> None:
        if self._hand in self.ctl.streams:
            self.ctl.close_stream(self._hand)

    def _busy(self) -> bool:
        return self._job is not None or bool(self._playback)

    def _no_jump(self, what: str) -> None:
        if self._busy():
            raise InvalidInput("command", f"cannot {what}: the arm is busy")
        if self.recording:
            raise InvalidInput("command", f"cannot {what} while recording: stop recording first")

    def _set_strategy(self, name: str) -> None:
        if name not in self.strategies:
            raise InvalidInput(
                "strategy", f"{self.robot.name} takes {', '.join(self.strategies)}; got {name!r}"
            )
        strategy = make_strategy(name)
        strategy.check(self.ctl.robot)
        self._arm().strategy = strategy
        self._strategy = name

    def _set_backend(self, name: str) -> None:
        cmd.one_of(name, "backend", self.backends)
        # A resolver of the same robot, period and limits (its default task: the controller's
        # task rows are unchanged); the controller keeps its q, log and reference pose.
        self.ctl.resolver = Resolver(self.ctl.robot, self.dt, limits=self.ctl.resolver.limits,
                                     qp=QPOptions(backend=name),
                                     damping=self.ctl.resolver.options.damping)  # fmt: skip
        self._backend = name

    def _set_hand(self, frame: str) -> None:
        cmd.one_of(frame, "hand", self.hands)
        if frame == self._hand:
            return
        self._no_jump("switch hands")
        self.operator.stop()
        self.ctl = self._controller(self.ctl.q, frame, self.ctl.speed)
        self._hand = frame

    def _record(self, on: bool) -> None:
        if self._busy():
            raise InvalidInput("command", "the arm is busy")
        self.ctl.log.clear()
        self.recording, self._full = on, False
        self.notice("info", "recording" if on else "record dropped")

    def _reverse(self, seconds: float) -> None:
        if self._busy():
            raise InvalidInput("command", "the arm is busy")
        if not self.recording:
            raise InvalidInput("seconds", "nothing recorded: start recording first")
        n = max(1, round(seconds / self.dt))
        if n > len(self.ctl.log):
            raise InvalidInput(
                "seconds",
                f"asked for {seconds:g} s; the record holds {len(self.ctl.log) * self.dt:.3g} s",
            )
        self.operator.stop()
        ctl = self.ctl

        def work() -> list[Array]:
            done = ctl.reverse(seconds)
            return [*ctl.log.positions(done.steps)[1:], ctl.q]

        self._start_job("reverse", work)

    def _save(self, c: cmd.Save) -> None:
        if self._busy():
            raise InvalidInput("command", "the arm is busy")
        if not self.recording or len(self.ctl.log) == 0:
            raise InvalidInput("path", "nothing recorded: start recording first")
        log = cast("TrajectoryLog | CellLog", self.ctl.log)  # (an arm's or a cell's: both save)

        def work() -> Path:
            try:
                path = log.save(c.path)
            except (RrcPinError, OSError) as exc:
                if c.reply is not None:
                    c.reply(None, str(exc))
                raise
            if c.reply is not None:
                c.reply(path, "")
            return path

        self._start_job("save", work)

    def _load(self, path: str) -> None:
        self._no_jump("replay")
        names = tuple(self.ctl.robot.joint_names)

        def work() -> tuple[Array, Array]:
            log = TrajectoryLog.load(path)
            if log.joint_names != names:
                raise InvalidInput(
                    "path",
                    f"{path} records joints {', '.join(log.joint_names)}; "
                    f"this arm has {', '.join(names)}",
                )
            teleop = log.column("mode") == "teleop"
            if not teleop.any():
                raise InvalidInput("path", f"{path} holds no teleoperation ticks")
            q = np.asarray(log.column("q"), np.float64)[teleop]
            twists = np.asarray(log.column("commanded"), np.float64)[teleop]
            return q[0], twists

        self.operator.stop()
        self._start_job("load", work)

    def _start_job(self, name: str, work: Callable[[], object]) -> None:
        """Hand the controller to a worker; the loop shows the arm still meanwhile."""
        self._held_q = self.ctl.q
        self._job = _Job(name, work)

    def _finish_job(self) -> bool:
        """Whether the worker is done (then its result is taken over)."""
        job = self._job
        assert job is not None
        if not job.done.is_set():
            return False
        self._job = None
        if job.error is not None:
            text = " ".join(str(job.error).split())
            self.notice("error", f"{job.name} failed: {text}")
            return True
        if job.name == "reverse":
            self._playback.extend(cast(list[Array], job.result))
            self.notice("info", f"reversed {len(self._playback) * self.dt:.3g} s")
        elif job.name == "save":
            self.notice("info", f"saved {job.result}")
        else:
            q0, twists = cast(tuple[Array, Array], job.result)
            self.ctl = self._controller(self.robot.check_q(q0, "q"), self._hand, self.ctl.speed)
            self._replay.extend(twists)
            self.notice("info", f"replaying {len(twists)} ticks from the record's start")
        return True

    def _controller(self, q: Array, hand: str, speed: float = 1.0) -> Loop:
        """A new controller of ``hand`` at ``q`` with the loop's settings (an empty log).

        A new one rather than setting ``q``: the controller's reference pose (its drift
        correction's) is the pose it starts at.
        """
        robot = self.robot
        if len(self.hands) > 1:  # a Controller commands one tool frame: this hand's
            robot = Robot(robot.model, hand, name=robot.name, source=robot.source, spec=robot.spec)
        return Controller(
            robot,
            self.dt,
            q,
            strategy=self._strategy,
            limits=JointLimits(),
            qp=QPOptions(backend=self._backend),
            speed=speed,
        )


REALTIME_PRIORITY = 10
"""``SCHED_FIFO`` priority of a real-time loop (1 to 99; kernel threads sit at 50)."""
MIN_SLEEP = 5e-5
"""Shortest sleep [s] of a real-time loop's tick: an overrunning loop still yields its core."""


def schedule(realtime: bool, priority: int, nice: int | None) -> tuple[str, str | None]:
    """Ask the OS to schedule the calling thread as the console's threads are scheduled.

    ``SCHED_FIFO`` at ``priority`` if ``realtime`` and permitted (Linux, root or
    CAP_SYS_NICE), else at ``nice`` (if not None).

    Returns:
        How the thread is scheduled (``"SCHED_FIFO 10"``, ``"nice -10"``, ``"normal"``), and
        why real-time scheduling was refused (None if it was not asked or was granted).
    """
    refused = None
    if realtime:
        try:
            os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(priority))
            return f"SCHED_FIFO {priority}", None
        except (OSError, AttributeError) as exc:
            refused = str(exc)
    value = set_nice(nice) if nice is not None else None
    return ("normal" if value is None else f"nice {value}"), refused


def set_nice(value: int) -> int | None:
    """Set the calling thread's nice value (Linux); returns the value it has, or None.

    A value the process may not take (a negative one without the rights) leaves it as it was.
    """
    if not hasattr(os, "setpriority") or not hasattr(threading, "get_native_id"):
        return None
    thread = threading.get_native_id()
    try:
        os.setpriority(os.PRIO_PROCESS, thread, value)
    except OSError:
        pass
    try:
        return os.getpriority(os.PRIO_PROCESS, thread)
    except OSError:
        return None


def _takes(robot: Robot, name: str) -> bool:
    """Whether strategy ``name`` works on ``robot`` (its ``check`` passes)."""
    try:
        make_strategy(name).check(robot)
    except RrcPinError:
        return False
    return True


def start_pose(robot: Robot, near: float = 0.05) -> Array:
    """A start configuration away from limits and singularities, for the console.

    The robot's named ready pose (:meth:`Robot.ready`: every arm and robot loaded by name has
    one). Any other robot at the middle of its joint ranges (0 for a continuous joint) when the
    smallest singular value of its task rows is at least ``near`` there; else at the best of
    64 seeded draws from the middle half of the ranges (the same robot, the same pose).
    """
    if "ready" in robot.poses:
        return robot.ready()
    bounded = np.isfinite(robot.lower) & np.isfinite(robot.upper)
    lower, upper = np.where(bounded, robot.lower, -np.pi), np.where(bounded, robot.upper, np.pi)
    middle: Array = 0.5 * (lower + upper)
    rows = slice(0, 6 if robot.nq >= 6 else 3)
    frame = robot.tool_frames[0]

    def sigma(q: Array) -> float:
        J = robot.jacobian(q, frame=frame)[rows]
        return float(np.linalg.svd(J, compute_uv=False)[-1])

    if sigma(middle) >= near:
        return middle
    rng = np.random.default_rng(0)
    draws = middle + 0.25 * (upper - lower) * rng.uniform(-1.0, 1.0, (64, robot.nq))
    best: Array = max(draws, key=sigma)
    return best
