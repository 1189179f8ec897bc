r"""CellController: one tick of a cell, one command per object, body or free hand.

What each command becomes (the cooperative commands):

- an **object** held by two hands: its frame's twist with a target pose in the top level,
  the grip (the second hand's relative twist zero, :class:`~rrc_pin.limits.GripLimit`)
  equality rows that every level is solved within. The top level is the resolver's
  direction problem, :math:`\max s` with :math:`A\dot q = s\,b`: when an arm meets a limit
  or a singularity, both hands slow together by one common scale along the commanded
  direction and the grip is never stretched. ``coupled=False`` instead resolves each hand on
  its own (weighted least squares, each hand toward its own target): the comparison that
  shows why the coupling is needed;
- the **body** of a legged cell: its twist with a target pose in the top level, the feet in
  support as fixed contacts (:class:`~rrc_pin.limits.ContactLimit`, equality rows that every
  level is solved within); a leg lifted with :meth:`CellController.swing` is commanded like
  a free hand, and :meth:`CellController.land` puts it back in support;
- a **free hand**: its twist with a target pose, in any of the frames below or its arm's
  base axes.

Every command is a twist [v; w] (6,) [m/s, rad/s] in the frame named by its ref, the words of
every entry point (:mod:`rrc_pin.solvers.spatial`, Pinocchio's ``ReferenceFrame``):
``"world_aligned"`` (the default: the commanded frame's velocity in the cell's base axes),
``"local"`` (the same in the commanded frame's own axes) or ``"world"`` (the spatial twist at
the cell's base origin); a hand also takes ``"base"`` (its velocity in its arm's base axes).
The target poses are the drift correction: each advances by the command times the achieved
scale, and the tasks feed their pose error back (gain ``gain``). Below the top level a
posture task pulls toward the ready pose (the redundancy's use).

The closed chains (grips, feet in support) are kept closed inside each tick: the error
each shows at the tick's configuration and the step's second order are taken out by a
correction inside the tick's box (:mod:`rrc_pin.cells.closure`), and a chain open beyond its
bound stops the cell (``grip_lost`` / ``contact_lost``) until a command closes it.

A command's name may follow a device's poses instead (:meth:`~rrc_pin.control.loop.Loop.stream`:
its twist each tick the stream's, its target the pose reached), and a cell of free hands
may have the jerk stage after its resolver (``smoothing=``; bounding each joint apart would
open a grip or a foot's contact). The loop itself is
:class:`~rrc_pin.control.loop.Loop`, the one
:class:`~rrc_pin.control.Controller` is built on: the speed override and the deadman weight
every command, the configuration is integrated on its manifold, the ticks go to a log ring
(:class:`CellLog`) and :meth:`~rrc_pin.control.loop.Loop.reverse` retraces them.
``rrc_pin.Controller(cell)`` makes a ``CellController``.
"""

from __future__ import annotations

import math
import operator
import os
import time
import warnings
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Literal

import numpy as np
import numpy.typing as npt

from rrc_pin.cells.cell import Cell
from rrc_pin.cells.cell_log import CellLog
from rrc_pin.cells.cell_resolution import CellResolution
from rrc_pin.cells.cell_tick import CellTick, fits
from rrc_pin.cells.closure import ChainFrames, ClosureBound, close, compile_correction, largest
from rrc_pin.compiled_tick import TickSource
from rrc_pin.control.deadman import Deadman
from rrc_pin.control.loop import Loop, Step
from rrc_pin.control.smoothing import SmoothingOptions
from rrc_pin.deprecated import warn_renamed
from rrc_pin.errors import InvalidInput
from rrc_pin.kinematics import Kinematics
from rrc_pin.limits import ContactLimit, GripLimit, JointLimits, Limit
from rrc_pin.limits.contact_limit import Closure
from rrc_pin.loading import loaded
from rrc_pin.resolver import QPOptions
from rrc_pin.robot import frame_index
from rrc_pin.solvers.checks import as_vector, flag, positive
from rrc_pin.solvers.exp_log import displaced, pose_error
from rrc_pin.solvers.spatial import to_world_aligned
from rrc_pin.solvers.tick.damping import Damping
from rrc_pin.solvers.tick.pipeline import solve
from rrc_pin.solvers.tick.problem import Rows, TaskRows
from rrc_pin.solvers.tick.resolution import Resolution
from rrc_pin.solvers.tick.statuses import scale_and_veer
from rrc_pin.tasks import FrameTask, PostureTask, Task

Array = npt.NDArray[np.float64]
Ref = Literal["world_aligned", "local", "world", "base"]
REFS: tuple[Ref, ...] = ("world_aligned", "local", "world", "base")
"""The frames a command's twist may be given in: every entry point's, and a hand's ``base``."""
Command = npt.ArrayLike | tuple[npt.ArrayLike, str]
"""A twist (6,) in ``world_aligned``, or ``(twist, ref)``."""
REANCHOR = ("singular", "least_squares", "recovering", "fallback")
"""Statuses whose motion is not the command's (part of it out of reach, or another problem's
answer): the targets are reset to the reached poses instead of pulling back toward poses
that could not be followed."""
HOLD = (5e-3, 5e-3)
"""[m, rad] How far a ``damped`` tick's target may lead its frame. A damped tick (past the
damping threshold, near a singular pose) advances its target along the command by what its
frame made along it, and the motion's veer off the command is fed back up to this distance;
beyond it the target follows the frame. Reset to the reached pose at every damped tick (the
former rule), the veer added up (the tripod's body 63 mm off its line, turned 0.45 rad); fed
back without a bound, the feedback and the damping were at odds near a singular pose
(gsfc_dual's object held 0.85 m from its target)."""
Lost = Literal["grip_lost", "contact_lost"]
LOST: tuple[Lost, ...] = ("grip_lost", "contact_lost")
"""The statuses of a cell whose closed chain is open beyond its bound (:mod:`.closure`)."""


CellStep = Step
"""One tick's outcome: the configuration after it (nq,) and its resolution (a
:class:`~rrc_pin.cells.cell_resolution.CellResolution`)."""


class CellController(Loop):
    """The teleoperation loop of a cell (module docstring).

    Args:
        cell: A :class:`~rrc_pin.cells.Cell` or a ready-made cell's name.
        dt: Control period [s].
        q0: Initial configuration (nq,); default the ready pose. The grips and the feet's
            anchors are the chains as they are there.
        limits: The resolver's limits: joint limits (default ``JointLimits()``), or a list of
            limits (joint limits, a :class:`~rrc_pin.limits.CollisionLimit` on the cell's
            :class:`~rrc_pin.geometry.CollisionModel`, ...); the support's contacts and the
            grip are added.
        qp: The resolver's QP options.
        damping: The resolver's damping, or None.
        deadman: How a command ages (default ``Deadman()``), or None.
        speed: Speed override in [0, 1].
        gain: Feedback gain [1/s] of the target poses.
        posture_gain: Gain [1/s] of the posture task below the top level.
        coupled: Hold objects as one (the grip in the top level); False: each hand of a held
            object resolved on its own (for comparison).
        closure: The bound the closed chains (grips, feet in support) are kept within, each
            tick's error taken out inside the step (:mod:`rrc_pin.cells.closure`); None: no
            correction and no bound (for comparison: the integration's remainder then adds
            up).
        project_contacts: Deprecated (goes in the next release): False is ``closure=None``.
        smoothing: Bounds of the jerk stage after the resolver, or None (no stage); a cell of
            free hands only (bounding each joint apart opens a grip or a foot's contact).

    Raises:
        InvalidInput: A bad argument, named.
    """

    passing = 1e-5
    """[rad, m] :meth:`reverse` passes a recorded configuration within this distance: the
    closed chains' correction moved each one off the rates the chains' rows allow (by up to
    the correction's size), so that retracing it takes a second, ``exact`` tick otherwise.
    The segment's start is still reached to rounding."""

    def __init__(
        self,
        cell: Cell | str,
        dt: float = 0.01,
        q0: npt.ArrayLike | None = None,
        *,
        limits: Limit | Sequence[Limit] | None = None,
        qp: QPOptions | None = None,
        damping: Damping | None = Damping(),  # noqa: B008 - immutable
        deadman: Deadman | None = Deadman(),  # noqa: B008 - immutable
        speed: float = 1.0,
        gain: float = 10.0,
        posture_gain: float = 0.1,
        coupled: bool = True,
        closure: ClosureBound | None = ClosureBound(),  # noqa: B008 - immutable
        project_contacts: bool | None = None,
        smoothing: SmoothingOptions | None = None,
    ) -> None:
        cell, given, closure, coupled = _settings(cell, limits, closure, project_contacts,
                                                  coupled, smoothing)  # fmt: skip
        gain = positive(gain, "gain")
        posture_gain = positive(posture_gain, "posture_gain")
        self.contact = ContactLimit((), name="contact")
        self.grip = GripLimit((), name="grip")
        super().__init__(cell, dt, q0, limits=[*given, self.contact, self.grip], qp=qp,
                         damping=damping, deadman=deadman, speed=speed,
                         smoothing=smoothing)  # fmt: skip
        self.cell = cell
        self.gain = gain
        self.posture = PostureTask(cell.dof_positions(cell.ready()), gain=posture_gain,
                                   weight=1e-3, name="posture")  # fmt: skip
        self.coupled = coupled
        self.closure = closure
        commands = [*cell.objects, *([cell.body] if cell.body else []), *cell.arms]
        self.log: CellLog = CellLog(cell.nq, cell.nv, commands, list(cell.objects))
        self.chain_error = (0.0, 0.0)
        """The closed chains' largest position [m] and rotation [rad] error at the last
        tick's start (zero without chains)."""
        self.lost: Lost | None = None
        """``"grip_lost"`` or ``"contact_lost"`` while a chain is open beyond its bound (the
        cell then holds still until a command closes it), else None."""
        self.support: list[str] = list(cell.tool_frames) if cell.body is not None else []
        self._commandable_of: tuple[tuple[str, ...] | None, tuple[str, ...]] = (None, ())
        self._anchors: dict[str, Array] = {}
        self._grips: dict[str, Array] = {}
        self._commands: dict[str, tuple[Array, Ref]] = {}
        self._world_warned = False
        self._targets: dict[str, Array] = {}
        self._tick: tuple[str, bool, dict[str, Array]] = ("teleop", False, {})
        self._applied: Array = np.zeros(cell.nv)
        self._corrected: tuple[Array, Array] | None = None  # applied, resolved: a corrected tick's
        self._kin_data = cell.model.createData()  # the tick's kinematics (:meth:`_kinematics`)
        self._kin: Kinematics | None = None
        self._kin_q: Array | None = None  # the configuration _kin is of
        self._top_tasks: Sequence[TaskRows] = ()  # the last tick's top level (:meth:`_closed`)
        self._frame_tasks: dict[str, FrameTask] = {}
        self._frames = frame_index(cell.model)
        self._frame_ids: dict[str, int] = {}  # a command's frame's index (:meth:`_frame_id`)
        self._chain_frames = ChainFrames.of(cell.model, (), ())
        # a tick's rows in one compiled call (:meth:`_compiled_tick`) where the resolver's
        # limits are the joint limits first, then others (collision) and the chains, and the
        # posture wraps no joint
        limits = self.resolver.limits
        self._compiles = (isinstance(limits[0], JointLimits)
                          and not any(isinstance(lim, JointLimits) for lim in limits[1:])
                          and not self.resolver.layout.continuous.any())  # fmt: skip
        self._cell_tick: tuple[tuple[object, ...], CellTick | None] = ((), None)
        # that tick's top level and correction (:meth:`_closed`)
        self._in_tick: tuple[Sequence[TaskRows], Array, Array] | None = None
        if closure is not None:
            compile_correction(cell.nv)
        scale_and_veer(np.zeros(6), np.zeros(6), np.ones(6))  # compiled now: damped ticks use it
        _moved(np.eye(4), np.zeros(6))  # compiled now: every tick moves the targets
        self._close_at()
        self._compile_tick()

    # -- settings -------------------------------------------------------------------------

    def commandable(self) -> list[str]:
        """Names :meth:`step` takes: held objects, the body, free hands and swinging feet."""
        return list(self._commandable())

    def _commandable(self) -> tuple[str, ...]:
        """:meth:`commandable`'s names, made again only when the feet in support change (the
        cell's objects and arms are fixed).
        """  # noqa: D205
        support = tuple(self.support)
        if self._commandable_of[0] == support:
            return self._commandable_of[1]
        cell = self.cell
        names = list(cell.objects)
        if cell.body is not None:
            names.append(cell.body)
        for arm in cell.arms.values():
            if arm.hand in support or cell.holder(arm.hand) is not None:
                continue
            names.append(arm.key)
        self._commandable_of = (support, tuple(names))
        return self._commandable_of[1]

    def target(self, name: str) -> Array:
        """The target pose (4, 4) of command ``name`` in the cell's base frame (a copy).

        Raises:
            InvalidInput: Not a name :meth:`commandable` lists.
        """
        self._check_name(name, "name")
        out: Array = self._targets[name].copy()
        return out

    def frame_of(self, name: str) -> str:
        """The frame command ``name`` moves (the object's, the body's or the hand's).

        Raises:
            InvalidInput: ``name`` is no command of this cell (not an object, body or arm).
        """
        cell = self.cell
        if not isinstance(name, str):
            raise InvalidInput("name", f"expected a command's name, got {type(name).__name__}")
        if name in cell.objects or name == cell.body:
            return name
        return cell.arm(name, "name").hand

    # -- support ----------------------------------------------------------------------------

    def swing(self, leg: str) -> None:
        """Lift leg ``leg``'s foot out of support: it is then commanded like a free hand.

        Raises:
            InvalidInput: Not a leg of this cell, or its foot not in support.
        """
        foot = self.cell.arm(leg, "leg").hand
        if foot not in self.support:
            raise InvalidInput("leg", f"{leg}'s foot is not in support; in support: "
                               f"{', '.join(self.support) or 'none'}")  # fmt: skip
        self.support.remove(foot)
        self._anchors.pop(foot)
        self._commands.pop(leg, None)
        self._chains()
        self._retarget()

    def land(self, leg: str) -> None:
        """Put leg ``leg``'s foot in support where it is now (a fixed contact).

        Raises:
            InvalidInput: Not a leg of this cell, or its foot already in support.
        """
        foot = self.cell.arm(leg, "leg").hand
        if foot in self.support:
            raise InvalidInput("leg", f"{leg}'s foot is already in support")
        self.support.append(foot)
        self._anchors[foot] = self.cell.fk(self._q, foot)
        self._commands.pop(leg, None)
        self._chains()
        self._retarget()

    # -- the loop ---------------------------------------------------------------------------

    def step(self, commands: Mapping[str, Command] | None = None) -> Step:
        """Resolve and integrate one tick.

        Args:
            commands: Name (:meth:`commandable`) -> twist (6,) [m/s, rad/s] of the
                commanded frame in ``world_aligned``, or ``(twist, ref)`` with ref
                ``"world_aligned"``, ``"local"``, ``"world"`` (module docstring; ``"world"``
                meant ``"world_aligned"`` before this release and warns once) or, for a hand,
                ``"base"`` (its arm's base axes). Names not given are held still; None: no
                new command (the last ones age, in their frames, see ``deadman``). A
                streamed name (:meth:`stream`) follows its stream whatever is given here.

        Returns:
            The configuration after the tick and its resolution: the rates applied (the
            closed chains' correction included), and ``grip_lost`` or ``contact_lost``
            where a chain is open beyond its bound (:attr:`lost`).

        Raises:
            InvalidInput: An unknown name (the commandable ones listed), a hand that holds an
                object or a foot in support, a bad twist (shape, NaN, inf) or ref, naming
                ``commands[name]``; raised before any state changes.
        """
        if commands is not None:
            self._commands = self._checked(commands)
            self._command_time = self.t
        weight = self._weight()
        cell = self.cell
        kin = self._kinematics()
        oMf = kin.data.oMf  # one pass: every frame placed
        poses = {name: oMf[self._frame_id(name)].homogeneous for name in self._targets}
        twists = {name: weight * self._world_aligned(name, poses[name], self._commands[name])
                  if name in self._commands else np.zeros(6) for name in self._targets}  # fmt: skip
        if self.streams:
            for name, twist in self._streamed(poses).items():  # the stream's target: the reference
                twists[name], self._targets[name] = self.speed * twist, poses[name]
        top: list[FrameTask] = []
        hands: list[Task] = []
        for name, twist in twists.items():
            grasp = cell.objects.get(name)
            if grasp is not None and not self.coupled:  # each hand on its own
                for hand in grasp.hands:
                    T = poses[name] @ _inverse(grasp.in_hand) if hand == grasp.hands[0] else (
                        poses[name] @ _inverse(grasp.in_hand) @ grasp.grip)  # fmt: skip
                    target = self._targets[name] @ _inverse(grasp.in_hand)
                    if hand != grasp.hands[0]:
                        target = target @ grasp.grip
                    hands.append(FrameTask(hand, _transport(twist, poses[name], T),
                                           target=target, gain=self.gain))  # fmt: skip
                continue
            top.append(self._task(name, twist))
        before = self._previous_rates()
        self._in_tick = None
        r = None if hands or before is not None else self._compiled_tick(kin, top)
        if r is None:
            if hands:
                r = self.resolver.solve_at(kin, [*top, *hands, self.posture], qdot_prev=before)
            else:
                levels: list[list[Task]] = [[*top], [self.posture]] if top else [[self.posture]]
                r = self.resolver.solve_at(kin, levels, priority="strict", qdot_prev=before)
            r = self._smooth(r)
        commanded = any(map(np.count_nonzero, twists.values()))  # a twist not zero
        self._tick = ("teleop", commanded, poses)
        out = self._advance(r)
        r = out.resolution
        if r.status in LOST and not r.qdot.any():  # held still: the targets wait
            return out
        if r.status in REANCHOR:
            self._retarget()
            return out
        if r.status == "damped" and not hands:
            self._held_back(r, twists)
            return out
        follow = r.scale if hands == [] else 1.0
        for name, twist in twists.items():
            self._targets[name] = _moved(self._targets[name], twist * (follow * self.dt))
        return out

    def _compile_tick(self) -> None:
        """Run the resolver's stages once now: no tick compiles a kernel or loads it.

        On this cell's tasks and limits, from numba's cache or compiled: an exact tick, one
        after it (the previous rates read-only), a command too fast to meet (scaled), a
        posture level the box cuts (the projected least squares), and a command one of whose
        rows is weighted past the damping threshold (damped,
        :class:`~rrc_pin.solvers.tick.damping.Damping`), each tick's top level read as the
        correction reads it (:func:`_top_level`), and each tick's problem answered by the Python
        pipeline (:func:`~rrc_pin.solvers.tick.pipeline.solve`; its shrink into the rows is
        compiled with the resolver's general tick); the rows of the cell's compiled tick
        (:meth:`_compiled_tick`); the resolver then reset.
        """
        kin, names = self._kinematics(), list(self._targets)
        far = PostureTask(self.posture.q_ref + 1.0, gain=1e6, name="compiling")
        ticks: list[tuple[float | None, Task]] = [(0.0, self.posture), (0.0, self.posture),
                                                  (1e6, self.posture), (0.0, far)]  # fmt: skip
        damping = self.resolver.options.damping
        weight = np.ones(6)
        if damping is not None:
            weight[-1] = (0.1 / damping.threshold) ** 2
            ticks.append((None, self.posture))
        for speed, lower in ticks:
            top: list[Task] = (
                [self._task(name, np.full(6, speed)) for name in names] if speed is not None
                else [FrameTask(self.frame_of(name), np.full(6, 1e6), weight=weight)
                      for name in names]
            )  # fmt: skip
            r = self.resolver.solve_at(kin, [top, [lower]] if top else [[lower]],
                                       priority="strict", qdot_prev=self._previous_rates())
            _top_level(r)  # the correction's read of the top level's rows (its kernels)
            # the Python pipeline's stages too: it answers equality rows beside a collision
            # pair asked apart (a slide row below zero)
            solve(r.problem, self.resolver.backend, self.resolver.options)
        self._compiled_tick(kin, [self._task(name, np.zeros(6)) for name in names])
        still = np.zeros(self.cell.nv)
        for previous in (still, r.qdot):  # the pipeline's box after rates of either kind
            for limit in self.resolver.limits:
                if isinstance(limit, JointLimits):
                    limit.constraints(kin, self.resolver.dt, previous)
        self.resolver.reset()
        self._kin, self._in_tick = None, None

    def _kinematics(self) -> Kinematics:
        """The tick's one :class:`~rrc_pin.kinematics.Kinematics` at the current q.

        Read by the commands' poses, the resolver's tasks and limits (the closed chains' rows
        and errors) and the closure's correction; on the controller's own Data, so that it
        holds until the next tick.
        """
        if self._kin is not None and self._kin_q is self._q:  # made ahead (:meth:`_held_back`)
            return self._kin
        _, dof, q_pin = self.cell.positions(self._q)
        self._kin = Kinematics(self.cell.model, self._kin_data, self.resolver.layout, dof, q_pin)
        self._kin_q = self._q
        self._q_pin = (self._q, q_pin)  # the loop's integration reads it (:meth:`_pinocchio_q`)
        return self._kin

    def _compiled_tick(self, kin: Kinematics, top: list[FrameTask]) -> Resolution | None:
        """The resolver's tick of the frame tasks ``top`` and the posture within the limits, their
        rows and the chains' in one compiled call (:class:`~rrc_pin.cells.cell_tick.CellTick`);
        None where the tick is not one (no chain, as many chain rows as rates, a continuous
        joint) or it finds no answer: the resolver answers from the tasks and limits.
        """  # noqa: D205
        if not self._compiles or not top:
            return None
        posture, contact, grip = self.posture, self.contact, self.grip
        key = (*top, posture, posture.q_ref, posture.gain, posture.weight, contact.frames,
               contact.anchors, grip.pairs, grip.grips, self._chain_frames, self.gain,
               self.closure is None)  # fmt: skip
        known, tick = self._cell_tick
        if len(known) != len(key) or not all(map(operator.is_, known, key)):
            posture.check(kin.layout)  # a posture replaced: refused as the resolver refuses it
            chains = 6 * (len(contact.frames) + len(grip.pairs))
            measured = ((not contact.frames or contact.anchors is not None)
                        and grip.grips.shape[0] == len(grip.pairs))  # fmt: skip
            tick = CellTick(kin, top, posture, contact, grip, self.gain, self._chain_frames,
                            self.closure is not None, self.resolver.limits[1:-2]) if (
                0 < chains < self.cell.nv and measured and fits(top)) else None  # fmt: skip
            self._cell_tick = (key, tick)
        if tick is None:
            return None
        r = self.resolver.run_compiled(tick, kin, self.resolver.dt, time.perf_counter())
        if r is not None:
            self._in_tick = tick.corrected
        return r

    def _frame_id(self, name: str) -> int:
        """The Pinocchio index of the frame command ``name`` moves (:meth:`frame_of`), kept
        (the cell's frames are fixed).
        """  # noqa: D205
        index = self._frame_ids.get(name)
        if index is None:
            index = self._frame_ids[name] = self._frames[self.frame_of(name)]
        return index

    def _task(self, name: str, twist: Array) -> FrameTask:
        """Command ``name``'s frame task of this tick: ``twist`` (6,) toward its target.

        One task per command, kept across ticks: its twist, target and gain are the
        controller's own, checked already (the target a rigid transform it moved), so set
        without a second check.
        """
        task = self._frame_tasks.get(name)
        if task is None:
            task = self._frame_tasks[name] = FrameTask(self.frame_of(name), name=name)
        task.twist, task.target, task.gain = twist, self._targets[name], self.gain
        return task

    def _held_back(self, r: Resolution, twists: dict[str, Array]) -> None:
        """A damped tick's targets, fed back within a bound (:data:`HOLD`).

        Each moves along its command by what its frame made along it, then to at most
        :data:`HOLD` from the frame: the frames' poses of the next tick's kinematics (at the
        configuration the tick reached), which that tick then reads.
        """
        tasks = {t.name: t for t in self._top_tasks}  # the tick's, read by :meth:`_closed`
        kin = self._kinematics()
        oMf, index = kin.data.oMf, kin.layout.frames
        for name, twist in twists.items():
            task = tasks[name]
            factor = None if task.unit is None else 1.0 / task.unit
            made = scale_and_veer(task.A @ r.qdot, twist, factor)[0] if twist.any() else 0.0
            target = _moved(self._targets[name], twist * (made * self.dt))
            pose = oMf[index[self.frame_of(name)]].homogeneous
            error = np.empty(6)
            pose_error(target, pose, error)
            for part, hold in zip((slice(0, 3), slice(3, 6)), HOLD, strict=True):
                size = float(np.linalg.norm(error[part]))
                if size > hold:
                    error[part] *= hold / size
            self._targets[name] = _moved(pose, error)

    # -- what the loop asks of it ---------------------------------------------------------

    def _log_reverse(self, q: Array, r: Resolution) -> None:
        """A reverse tick: logged, closed and integrated by :meth:`_advance` (a command)."""
        self._tick = ("reverse", True, {})
        self._kin = None  # the resolver made its own: the closure makes the tick's

    def _advance(self, r: Resolution) -> Step:
        """One tick: the closed chains' correction (:meth:`_closed`), the log, the integration."""
        closed = self._closed(r)
        self._record(closed)
        self._kin = None  # of this tick's q only
        return super()._advance(closed)

    def _integrate(self, qdot: Array) -> Array:
        """The loop's integration of the tick's applied rates (:meth:`_closed`).

        The resolver's ``qdot`` and the closed chains' correction (the argument is the first).
        """
        return super()._integrate(self._applied)

    def _stopped(self) -> None:
        self._commands = {}
        self._retarget()

    def _stream_name(self, name: str | None) -> str:
        return self._check_name(name, "name")

    def _pose_of(self, name: str) -> Array:
        return self.cell.fk(self._q, self.frame_of(name))

    def _configuration_set(self) -> None:
        """Targets, grips and the feet's anchors at the configuration set.

        A cell set elsewhere stays there: the targets' feedback and the closure would pull
        it back to the old poses, grips and anchors.
        """
        self._close_at()

    def save(self, path: str | os.PathLike[str]) -> Path:
        """Write the log as CSV to ``path`` (:meth:`CellLog.save`); return the path."""
        return self.log.save(path)

    @property
    def contact_correction(self) -> float:
        """The former closure step's size (deprecated: goes in the next release).

        The largest rate of the last tick's correction [rad/s or m/s]; each tick's whole
        correction is its resolution's ``correction`` (:class:`CellResolution`).
        """
        warn_renamed("CellController.contact_correction",
                     "CellController.step(...).resolution.correction", stacklevel=2)  # fmt: skip
        if self._corrected is None:
            return 0.0
        applied, resolved = self._corrected
        return float(np.abs(applied - resolved).max())

    # -- the closed chains ------------------------------------------------------------------

    def _close_at(self) -> None:
        """The grips and the feet's anchors as they are at the current q; targets there too."""
        q, cell = self._q, self.cell
        self._anchors = {f: cell.fk(q, f) for f in self.support}
        self._grips = {}
        if self.coupled:
            for name, g in cell.objects.items():
                self._grips[name] = _inverse(cell.fk(q, g.hands[0])) @ cell.fk(q, g.hands[1])
        self.lost = None
        self._chains()
        self._retarget()

    def _chains(self) -> None:
        """The contact and grip limits set to the support's anchors and the grips."""
        self.contact.set_frames(self.support, [self._anchors[f] for f in self.support])
        grasps = [self.cell.objects[n] for n in self._grips]
        self.grip.set_pairs([g.hands for g in grasps], [self._grips[g.name] for g in grasps])
        ids = self._frames
        self._chain_frames = ChainFrames.of(self.cell.model,
                                            tuple(ids[f] for f in self.contact.frames),
                                            tuple((ids[a], ids[b]) for a, b in self.grip.pairs))

    def _closed(self, r: Resolution) -> CellResolution:
        """``r`` with the closed chains' correction, or held still while one is lost.

        The correction (:func:`~rrc_pin.cells.closure.close`, or made with the tick's compiled
        rows, :class:`~rrc_pin.cells.cell_tick.CellTick`) takes the error measured at the
        tick's configuration (the resolver's kinematics, by the contact and grip limits) and
        the step's second order out inside the tick's box. A tick that starts with a chain
        beyond its bound holds still (``grip_lost`` / ``contact_lost``, zero rates), and so
        does every tick after it until one whose command, with the correction, closes the
        chain (its predicted error after the step below the error now); the status stays
        until the chain is back within the bound.
        """
        self._applied = r.qdot
        self._corrected = None
        self.chain_error = (0.0, 0.0)
        in_tick, self._in_tick = self._in_tick, None
        if in_tick is not None:  # the top level and the correction made with the tick's rows
            tasks = in_tick[0]
        else:
            tasks, stacked, rows = _top_level(r)
        self._top_tasks = tasks
        hands = self._hands(tasks)
        measured: list[tuple[Closure | None, Lost]] = [(self.contact.last, "contact_lost"),
                                                      (self.grip.last, "grip_lost")]  # fmt: skip
        parts = [(last, kind) for last, kind in measured if last is not None]
        if not parts:
            return CellResolution.of_tick(r, r.qdot.copy(), hands)
        closure = parts[0][0] if len(parts) == 1 else Closure(
            *(np.concatenate([c[i] for c, _ in parts]) for i in range(3)))  # fmt: skip
        self.chain_error = largest(closure.error)
        bound = self.closure
        if bound is None:
            return CellResolution.of_tick(r, r.qdot.copy(), hands)
        mode, commanded, _ = self._tick
        if in_tick is not None:  # made with the tick's compiled rows (CellTick)
            _, after, applied = in_tick
        else:  # stacked and rows: the top level's, read above
            top = stacked if mode == "teleop" else np.zeros((0, self.cell.nv))
            kin = self._kin if self._kin is not None else self._kinematics()
            _, after, applied = close(kin, self._chain_frames, closure, r.qdot, top, r.box,
                                      rows, self.dt)  # fmt: skip
        level = max(self.chain_error[0] / bound.position, self.chain_error[1] / bound.rotation)
        if level <= 1.0:
            self.lost = None
        elif self.lost is not None and commanded and bound.level(after) < level:
            r = r._replace(status=self.lost)  # a command that closes the chain: taken
        else:  # held still
            if self.lost is None:
                self.lost = max(parts, key=lambda p: bound.level(p[0].error))[1]
            still = np.zeros(self.cell.nv)
            still.flags.writeable = False
            self._applied = still
            return CellResolution.of_tick(r._replace(qdot=still, status=self.lost, scale=0.0,
                                                veer=0.0), still.copy(), hands)  # fmt: skip
        self._applied = applied  # inside the box as the resolver's rates are
        self._corrected = (self._applied, r.qdot)
        return CellResolution.of_tick(r, self._applied, hands)

    def _hands(self, level: Sequence[TaskRows]) -> Callable[[], tuple[TaskRows, ...]] | None:
        """The held objects' hands as rows of the top level (``level``, the tick's), made when
        read (or None).
        """  # noqa: D205
        mode, _, poses = self._tick
        objects = [t for t in level if t.name in self._grips]
        if mode != "teleop" or not objects:
            return None
        cell, q = self.cell, self._q

        def rows() -> tuple[TaskRows, ...]:
            out = []
            for task in objects:
                for hand in cell.objects[task.name].hands:
                    twist = _transport(task.b, poses[task.name], cell.fk(q, hand))
                    out.append(TaskRows(cell.jacobian(q, "world_aligned", hand), twist, None,
                                        hand, task.unit))  # fmt: skip
            return tuple(out)

        return rows

    # -- helpers --------------------------------------------------------------------------

    def _check_name(self, name: object, argument: str) -> str:
        allowed = self._commandable()
        if not isinstance(name, str) or name not in allowed:
            why = ""
            cell = self.cell
            if isinstance(name, str) and name in cell.arms:
                hand = cell.arms[name].hand
                held = cell.holder(hand)
                why = (f" ({name}'s hand holds {held!r}: command the object)" if held
                       else f" ({name}'s foot is in support: swing({name!r}) first)")
            raise InvalidInput(argument, f"{name!r} is not commandable in {cell.name}{why}; "
                               f"commandable: {', '.join(allowed)}")  # fmt: skip
        return name

    def _checked(self, commands: Mapping[str, Command]) -> dict[str, tuple[Array, Ref]]:
        """Every command checked and turned into (twist, ref) before anything changes.

        Each value is checked as ``commands[name]``: the label is made when one is refused
        (:func:`_twist`).
        """
        if type(commands) is not dict and not isinstance(commands, Mapping):
            raise InvalidInput("commands", f"expected a mapping name -> twist, got {commands!r}")
        out: dict[str, tuple[Array, Ref]] = {}
        allowed = self._commandable()
        world = False
        for name, value in commands.items():
            if not isinstance(name, str) or name not in allowed:
                self._check_name(name, "commands")
            ref = "world_aligned"
            if isinstance(value, tuple) and len(value) == 2 and isinstance(value[1], str):
                value, ref = value
            if ref not in REFS:
                raise InvalidInput(f"commands[{name!r}]", f"ref {ref!r}: expected world_aligned, "
                                   "local, world, or base (a hand's arm base axes)")  # fmt: skip
            if ref == "base" and name not in self.cell.arms:
                raise InvalidInput(f"commands[{name!r}]", f"ref 'base' is a hand's arm base "
                                   f"axes; {name!r} is "
                                   f"{'the body' if name == self.cell.body else 'an object'}: "
                                   "expected world_aligned, local or world")  # fmt: skip
            out[name] = (_twist(value, name).copy(), ref)
            world = world or ref == "world"
        if world:
            self._warn_world()
        return out

    def _warn_world(self) -> None:
        """Warn once per controller that a ``"world"`` command now means Pinocchio's WORLD."""
        if not self._world_warned:
            self._world_warned = True
            warnings.warn(
                "CellController.step: ref 'world' is the spatial twist at the cell's base "
                "origin, as at every entry point; before this release it meant 'world_aligned' "
                "(the commanded frame's velocity in base axes, the default): pass "
                "'world_aligned' or a plain twist for that motion",
                FutureWarning,
                stacklevel=4,
            )

    def _world_aligned(self, name: str, pose: Array, command: tuple[Array, Ref]) -> Array:
        """A checked command (twist and its ref) in ``world_aligned`` at ``pose`` (4, 4)."""
        twist, ref = command
        if ref == "world_aligned":
            return twist
        if ref != "base":
            return to_world_aligned(twist, pose[:3, :3], pose[:3, 3], ref)
        R = self.cell.arms[name].base[:3, :3]  # the arm's base axes: on the body, if any
        if self.cell.body is not None:
            R = self.cell.fk(self._q, self.cell.body)[:3, :3] @ R
        return to_world_aligned(twist, R, pose[:3, 3], "local")  # the hand's velocity in axes R

    def _retarget(self) -> None:
        """Targets at the current poses of every commandable frame."""
        q = self._q
        self._targets = {n: self.cell.fk(q, self.frame_of(n)) for n in self._commandable()}

    def _record(self, r: CellResolution) -> None:
        """Log the tick: its rates, status, the commands' pose errors, the grips' errors."""
        mode, _, poses = self._tick
        errors = {n: _length(self._targets[n][:3, 3] - T[:3, 3]) for n, T in poses.items()}
        grip = {}
        measured = self.grip.last
        for k, (name, g) in enumerate(self.cell.objects.items()):
            if measured is not None and name in self._grips:  # the tick's, by the grip limit
                grip[name] = _length(measured.error[6 * k : 6 * k + 3])
                continue
            rel = _inverse(self.cell.fk(self._q, g.hands[0])) @ self.cell.fk(self._q, g.hands[1])
            grip[name] = float(np.linalg.norm(rel[:3, 3] - g.grip[:3, 3]))
        self.log.add(self.t, self._q, r.applied, r.status, r.scale, r.levels, errors, grip,
                     self.chain_error, mode)  # fmt: skip


def _settings(cell: Cell | str, limits: Limit | Sequence[Limit] | None,
              closure: ClosureBound | None, project_contacts: bool | None, coupled: bool,
              smoothing: SmoothingOptions | None,
              ) -> tuple[Cell, list[Limit], ClosureBound | None, bool]:  # fmt: skip
    """:class:`CellController`'s cell (loaded where named), limits (a list, the joint limits by
    default), closure bound (None where ``project_contacts`` is False, deprecated) and
    ``coupled``, checked with the smoothing they allow.

    Raises:
        InvalidInput: A bad argument, named.
    """  # noqa: D205
    if project_contacts is not None:  # the former closure step's switch
        project_contacts = flag(project_contacts, "project_contacts")
        warn_renamed("CellController(project_contacts=)", "CellController(closure=)")
        closure = closure if project_contacts else None
    if isinstance(cell, (str, os.PathLike)):
        cell = loaded(cell, "cell")  # type: ignore[assignment]
    if not isinstance(cell, Cell):
        raise InvalidInput("cell", f"expected a Cell or a cell's name, got {cell!r}")
    if closure is not None and not isinstance(closure, ClosureBound):
        raise InvalidInput("closure", f"expected a ClosureBound or None, got {closure!r}")
    given: list[Limit]
    if limits is None:
        given = [JointLimits()]
    elif isinstance(limits, Sequence):
        given = list(limits)
    else:
        given = [limits]
    coupled = flag(coupled, "coupled")
    if smoothing is not None and (cell.body is not None or (cell.objects and coupled)):
        raise InvalidInput("smoothing", f"{cell.name} has closed chains (a held object, feet "
                           "in support) that a jerk stage bounding each joint apart would "
                           "open: a cell of free hands only")  # fmt: skip
    return cell, given, closure, coupled


def _top_level(r: Resolution) -> tuple[Sequence[TaskRows], Array, Rows | None]:
    """The top level's task rows, its stacked rows (the metric it was solved in) and the
    constraint rows of ``r``'s problem, read without building a compiled tick's whole problem
    (:meth:`~rrc_pin.compiled_tick.TickSource.top`).
    """  # noqa: D205
    source = r.source
    if isinstance(source, TickSource):
        return source.top()
    problem = r.problem
    return problem.levels[0], problem.stacked[0][0], problem.rows


def _twist(value: npt.ArrayLike, name: str) -> Array:
    """Command ``name``'s twist checked (6,), refused as ``commands[name]``
    (:func:`~rrc_pin.solvers.checks.as_vector`, checked again with its label to refuse it).
    """  # noqa: D205
    try:
        return as_vector(value, "commands", 6)
    except InvalidInput:
        pass
    return as_vector(value, f"commands[{name!r}]", 6)


def _length(v: Array) -> float:
    """The Euclidean length of ``v`` (1-D): ``numpy.linalg.norm``'s floats, one call."""
    return math.sqrt(float(v @ v))


def _inverse(T: Array) -> Array:
    out = np.eye(4)
    out[:3, :3] = T[:3, :3].T
    out[:3, 3] = -T[:3, :3].T @ T[:3, 3]
    return out


def _transport(twist: Array, frm: Array, to: Array) -> Array:
    r"""A world-axes twist of ``frm``'s origin moved to ``to``'s origin on one rigid body.

    :math:`v_b = v_a + \omega \times (p_b - p_a)`.
    """
    v, w = twist[:3], twist[3:]
    return np.concatenate([v + np.cross(w, to[:3, 3] - frm[:3, 3]), w])


def _moved(T: Array, delta: Array) -> Array:
    """Pose ``T`` moved by the world-axes displacement ``delta`` (6,) [m, rad] of its origin."""
    out: Array = np.empty((4, 4))
    displaced(T, delta, out)
    return out
