r"""CellController: one tick of a cell, one command per object, body or free hand.

What each command becomes (the cooperative commands):

- an **object** held by two hands: its frame's twist with a target pose, and the grip (the
  second hand's pose relative to the first, a :class:`~rrc_pin.tasks.RelativeFrameTask`
  with the grasp as its target), both in the top level. The top level is the resolver's
  direction problem, :math:`\max s` with :math:`A\dot q = s\,b`: when an arm meets a limit
  or a singularity, both hands slow together by one common scale along the commanded
  direction and the grip is never stretched. ``coupled=False`` instead resolves each hand on
  its own (weighted least squares, each hand toward its own target): the comparison that
  shows why the coupling is needed;
- the **body** of a legged cell: its twist with a target pose in the top level, the feet in
  support as fixed contacts (:class:`~rrc_pin.limits.ContactLimit`, equality rows that every
  level is solved within); a leg lifted with :meth:`CellController.swing` is commanded like
  a free hand, and :meth:`CellController.land` puts it back in support;
- a **free hand**: its twist with a target pose, in the cell's world axes, its own hand
  axes or its arm's base axes.

Every command is a twist [v; w] (6,) [m/s, rad/s] of the commanded frame's origin, in the
frame named by its ref (``"world"``: the cell's base axes; ``"local"``: the commanded
frame's own axes; ``"base"``: the arm's base axes, for a hand). The target poses are the
drift correction: each advances by the command times the achieved scale, and the tasks feed
their pose error back (gain ``gain``). Below the top level a posture task pulls toward the
ready pose (the redundancy's use).

The loop itself is :class:`~rrc_pin.control.loop.Loop`, the one
:class:`~rrc_pin.control.Controller` is built on: the speed override and the deadman weight
every command, the configuration is integrated on its manifold, the ticks go to a log ring
(:class:`CellLog`) and :meth:`~rrc_pin.control.loop.Loop.reverse` retraces them.
``rrc_pin.Controller(cell)`` makes a ``CellController``.
"""

from __future__ import annotations

import csv
import math
import os
from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path
from typing import Literal, NamedTuple

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.cells.cell import Cell
from rrc_pin.control.deadman import Deadman
from rrc_pin.control.loop import Loop, Step
from rrc_pin.control.trajectory_log import CAPACITY, RecordRing, checked_path, reason
from rrc_pin.errors import InvalidInput
from rrc_pin.limits import ContactLimit, GripLimit, JointLimits, Limit
from rrc_pin.loading import loaded
from rrc_pin.resolver import QPOptions
from rrc_pin.solvers.checks import as_vector, flag, positive
from rrc_pin.solvers.tick.damping import Damping
from rrc_pin.solvers.tick.resolution import Resolution
from rrc_pin.tasks import FrameTask, PostureTask, Task

Array = npt.NDArray[np.float64]
Ref = Literal["world", "local", "base"]
REFS: tuple[str, ...] = ("world", "local", "base")
Command = npt.ArrayLike | tuple[npt.ArrayLike, str]
"""A twist (6,) in the cell's world axes, or ``(twist, ref)``."""
REANCHOR = ("damped", "singular", "least_squares", "recovering", "fallback")
"""Statuses whose motion departs from the command's direction: the targets are reset to the
reached poses instead of pulling back toward poses that could not be followed."""


CellStep = Step
"""One tick's outcome: the configuration after it (nq,) and the resolution."""


class CellRecord(NamedTuple):
    """One tick as the log keeps it.

    Attributes:
        t: Time at the start of the tick [s].
        q: Configuration at the start (nq,).
        qdot: Joint rates (nv,).
        status: The resolution's status.
        scale: The top level's common scale.
        levels: Each level's status, joined by ``/``.
        errors: Pose error [m] of each commanded frame to its target, by command name.
        grip: Grip error [m] of each held object (relative position to the grasp).
        mode: ``"teleop"`` or ``"reverse"``.
    """

    t: float
    q: Array
    qdot: Array
    status: str
    scale: float
    levels: str
    errors: dict[str, float]
    grip: dict[str, float]
    mode: str


class CellLog(RecordRing[CellRecord]):
    """A cell's log: the ring of :class:`CellRecord` every loop keeps, and its CSV.

    Args:
        nq: Length of the cell's q.
        nv: Length of its qdot.
        capacity: Ticks kept (:class:`~rrc_pin.control.trajectory_log.RecordRing`).
    """

    record_type = CellRecord

    def __init__(self, nq: int, nv: int, capacity: int = CAPACITY) -> None:
        super().__init__(None, capacity)
        self.nq, self.nv = nq, nv

    def __iter__(self) -> Iterator[CellRecord]:
        return iter(self.records)

    def save(self, path: str | os.PathLike[str]) -> Path:
        """Write the log as CSV (one row per tick, a header) to ``path``; return the path.

        Raises:
            InvalidInput: Naming ``path``: not a ``.csv`` path, or a file that cannot be
                written (the system's reason).
        """
        out = checked_path(path)
        if out.suffix != ".csv":
            raise InvalidInput("path", f"expected a .csv file, got {str(out)!r}")
        records = self.records
        names = sorted({k for rec in records for k in rec.errors})
        grips = sorted({k for rec in records for k in rec.grip})
        try:
            with out.open("w", newline="") as f:
                w = csv.writer(f)
                w.writerow(["t", "mode", "status", "scale", "levels",
                            *[f"error:{n}" for n in names], *[f"grip:{n}" for n in grips],
                            *[f"q{i}" for i in range(self.nq)],
                            *[f"qdot{i}" for i in range(self.nv)]])  # fmt: skip
                for rec in records:
                    w.writerow([f"{rec.t:.6f}", rec.mode, rec.status, f"{rec.scale:.9g}",
                                rec.levels, *[f"{rec.errors.get(n, math.nan):.9g}" for n in names],
                                *[f"{rec.grip.get(n, math.nan):.9g}" for n in grips],
                                *[f"{x:.12g}" for x in rec.q],
                                *[f"{x:.12g}" for x in rec.qdot]])  # fmt: skip
        except OSError as exc:
            raise InvalidInput("path", f"cannot write {str(out)!r}: {reason(exc)}") from exc
        return out


class CellController(Loop):
    """The teleoperation loop of a cell (module docstring).

    Args:
        cell: A :class:`~rrc_pin.cells.Cell` or a ready-made cell's name.
        dt: Control period [s].
        q0: Initial configuration (nq,); default the ready pose.
        limits: The resolver's limits: joint limits (default ``JointLimits()``), or a list of
            limits (joint limits, a :class:`~rrc_pin.limits.CollisionLimit` on the cell's
            :class:`~rrc_pin.geometry.CollisionModel`, ...); the support's contacts and the
            grip are added.
        qp: The resolver's QP options.
        damping: The resolver's damping, or None.
        deadman: How a command ages (default ``Deadman()``), or None.
        speed: Speed override in [0, 1].
        gain: Feedback gain [1/s] of the target poses and the grip.
        posture_gain: Gain [1/s] of the posture task below the top level.
        coupled: Hold objects as one (the grip in the top level); False: each hand of a held
            object resolved on its own (for comparison).
        project_contacts: After integrating, move each supporting leg's joints by the
            Newton step that puts its foot back on its anchor (removes the integration's
            second-order slip; its size is logged in ``contact_correction``).

    Raises:
        InvalidInput: A bad argument, named.
    """

    passing = 1e-5
    """[rad, m] :meth:`reverse` passes a recorded configuration within this distance: the
    closed chains' projection moved each one off its rates' integral (by 7.5e-7 rad on
    gsfc_dual at 0.17 rad/s, 7.5e-10 on yeh_tripod), so that retracing it takes a second,
    ``exact`` tick otherwise. The segment's start is still reached to rounding."""

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
        project_contacts: bool = True,
    ) -> None:
        if isinstance(cell, (str, os.PathLike)):
            cell = loaded(cell, "cell")  # type: ignore[assignment]
        if not isinstance(cell, Cell):
            raise InvalidInput("cell", f"expected a Cell or a cell's name, got {cell!r}")
        given: list[Limit]
        if limits is None:
            given = [JointLimits()]
        elif isinstance(limits, Sequence):
            given = list(limits)
        else:
            given = [limits]
        gain = positive(gain, "gain")
        posture_gain = positive(posture_gain, "posture_gain")
        coupled = flag(coupled, "coupled")
        project_contacts = flag(project_contacts, "project_contacts")
        self.contact = ContactLimit((), name="contact")
        self.grip = GripLimit((), name="grip")
        super().__init__(cell, dt, q0, limits=[*given, self.contact, self.grip], qp=qp,
                         damping=damping, deadman=deadman, speed=speed)  # fmt: skip
        self.cell = cell
        self.gain = gain
        self.posture = PostureTask(cell.dof_positions(cell.ready()), gain=posture_gain,
                                   weight=1e-3, name="posture")  # fmt: skip
        self.coupled = coupled
        self.project_contacts = project_contacts
        self.log: CellLog = CellLog(cell.nq, cell.nv)
        self.contact_correction = 0.0
        self.support: list[str] = list(cell.tool_frames) if cell.body is not None else []
        self._anchors: dict[str, Array] = {}
        self._commands: dict[str, Array] = {}
        self._targets: dict[str, Array] = {}
        self._reanchor()

    # -- settings -------------------------------------------------------------------------

    def commandable(self) -> list[str]:
        """Names :meth:`step` takes: held objects, the body, free hands and swinging feet."""
        cell = self.cell
        names = list(cell.objects)
        if cell.body is not None:
            names.append(cell.body)
        for arm in cell.arms.values():
            if arm.hand in self.support or cell.holder(arm.hand) is not None:
                continue
            names.append(arm.key)
        return names

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
        self._commands.pop(leg, None)
        self._reanchor()

    def land(self, leg: str) -> None:
        """Put leg ``leg``'s foot in support where it is now (a fixed contact).

        Raises:
            InvalidInput: Not a leg of this cell, or its foot already in support.
        """
        foot = self.cell.arm(leg, "leg").hand
        if foot in self.support:
            raise InvalidInput("leg", f"{leg}'s foot is already in support")
        self.support.append(foot)
        self._commands.pop(leg, None)
        self._reanchor()

    # -- the loop ---------------------------------------------------------------------------

    def step(self, commands: Mapping[str, Command] | None = None) -> Step:
        """Resolve and integrate one tick.

        Args:
            commands: Name (:meth:`commandable`) -> twist (6,) [m/s, rad/s] in the cell's
                world axes, or ``(twist, ref)`` with ref ``"world"``, ``"local"`` (the
                commanded frame's axes) or ``"base"`` (a hand's arm base axes). Names not
                given are held still; None: no new command (the last ones age, see
                ``deadman``).

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
        poses = {name: cell.fk(self._q, self.frame_of(name)) for name in self._targets}
        twists = {name: weight * self._in_world(name, poses[name], self._commands[name])
                  if name in self._commands else np.zeros(6) for name in self._targets}  # fmt: skip
        top: list[Task] = []
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
            top.append(FrameTask(self.frame_of(name), twist, target=self._targets[name],
                                 gain=self.gain, name=name))  # fmt: skip
        self.contact.set_frames(self.support)
        self.grip.set_pairs([] if not self.coupled else
                            [g.hands for g in cell.objects.values()])  # fmt: skip
        levels: list[list[Task]]
        if hands:
            r = self.resolver.solve(self._q, [*top, *hands, self.posture])
        else:
            levels = [top, [self.posture]] if top else [[self.posture]]
            r = self.resolver.solve(self._q, levels, priority="strict")
        self._record(r, poses, "teleop")
        follow = r.scale if hands == [] else 1.0
        if r.status in REANCHOR:
            out = self._advance(r)
            self._reanchor()
        else:
            for name, twist in twists.items():
                self._targets[name] = _moved(self._targets[name], twist * (follow * self.dt))
            out = self._advance(r)
        return out

    # -- what the loop asks of it ---------------------------------------------------------

    def _log_reverse(self, q: Array, r: Resolution) -> None:
        self._record(r, {}, "reverse")

    def _stopped(self) -> None:
        self._commands = {}
        self._reanchor()

    def _configuration_set(self) -> None:
        """Targets and the feet's anchors at the configuration set.

        A cell set elsewhere stays there: the targets' feedback and the projection would
        pull it back to the old poses and anchors.
        """
        self._reanchor()

    def save(self, path: str | os.PathLike[str]) -> Path:
        """Write the log as CSV to ``path`` (:meth:`CellLog.save`); return the path."""
        return self.log.save(path)

    # -- helpers --------------------------------------------------------------------------

    def _check_name(self, name: object, argument: str) -> str:
        allowed = self.commandable()
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

    def _checked(self, commands: Mapping[str, Command]) -> dict[str, Array]:
        """Every command checked and turned into (twist, ref) before anything changes."""
        if not isinstance(commands, Mapping):
            raise InvalidInput("commands", f"expected a mapping name -> twist, got {commands!r}")
        out: dict[str, Array] = {}
        for name, value in commands.items():
            label = f"commands[{name!r}]"
            self._check_name(name, "commands")
            ref = "world"
            if isinstance(value, tuple) and len(value) == 2 and isinstance(value[1], str):
                value, ref = value
            if ref not in REFS or (ref == "base" and name not in self.cell.arms):
                raise InvalidInput(label, f"ref {ref!r}: expected world, local, or base (for a "
                                   "hand)")  # fmt: skip
            twist = as_vector(value, label, 6)
            out[name] = np.concatenate([twist, [REFS.index(ref)]])
        return out

    def _in_world(self, name: str, pose: Array, command: Array) -> Array:
        """A checked command (twist and its ref's index) as a twist in world axes."""
        twist, ref = command[:6], REFS[int(command[6])]
        if ref == "world":
            return twist
        if ref == "local":
            R = pose[:3, :3]
        else:  # the arm's base axes: the body's pose times the base placement
            arm = self.cell.arms[name]
            R = arm.base[:3, :3]
            if self.cell.body is not None:
                R = self.cell.fk(self._q, self.cell.body)[:3, :3] @ R
        return np.concatenate([R @ twist[:3], R @ twist[3:]])

    def _reanchor(self) -> None:
        """Targets at the current poses of every commandable frame; anchors of the feet."""
        q = self._q
        self._targets = {n: self.cell.fk(q, self.frame_of(n)) for n in self.commandable()}
        self._anchors = {f: self.cell.fk(q, f) for f in self.support}

    def _integrate(self, qdot: Array) -> Array:
        """The loop's integration, then the closed chains closed again (``project_contacts``)."""
        q = super()._integrate(qdot)
        if self.project_contacts and (self.support or (self.coupled and self.cell.objects)):
            q = self._projected(q)
        return q

    def _projected(self, q: Array) -> Array:
        """``q`` with the closed chains closed again by a Newton step on every rate.

        A foot in support goes back onto its anchor; the second hand on a held object onto
        the grip (the first hand's pose times the grasp). One least-norm step over every rate
        (the body's too), then one more without the joints it pushed past a limit (held
        there). The step is the integration's second-order remainder (about 1e-8 rad at
        100 Hz): within rounding of the rates the resolver gave; its largest entry is kept
        in ``contact_correction``.
        """
        cell = self.cell
        goals = [(f, T) for f, T in self._anchors.items()]
        if self.coupled:
            goals += [(g.hands[1], cell.fk(q, g.hands[0]) @ g.grip) for g in cell.objects.values()]
        free = cell.actuated | ~cell.actuated  # every rate
        step = np.zeros(cell.nv)
        for _ in range(2):
            errors, rows = [], []
            for frame, goal in goals:
                pose = cell.fk(q, frame)
                errors.append(np.concatenate([goal[:3, 3] - pose[:3, 3],
                                              pin.log3(goal[:3, :3] @ pose[:3, :3].T)]))
                rows.append(cell.jacobian(q, "world_aligned", frame))
            J = np.vstack(rows)
            J[:, ~free] = 0.0
            step = np.linalg.lstsq(J, np.concatenate(errors), rcond=None)[0]
            moved = cell.integrate(q, step, 1.0)
            dof = cell.dof_positions(moved)
            past = (dof < cell.dof_lower) | (dof > cell.dof_upper)
            if not past.any():
                q = moved
                break
            free = free & ~past
        else:
            q = moved
            q[~np.isinf(cell.lower)] = np.clip(q, cell.lower, cell.upper)[~np.isinf(cell.lower)]
        self.contact_correction = float(np.abs(step).max())
        return q

    def _record(self, r: Resolution, poses: dict[str, Array], mode: str) -> None:
        errors = {n: float(np.linalg.norm(self._targets[n][:3, 3] - T[:3, 3]))
                  for n, T in poses.items()}  # fmt: skip
        grip = {}
        for name, g in self.cell.objects.items():
            Ta, Tb = self.cell.fk(self._q, g.hands[0]), self.cell.fk(self._q, g.hands[1])
            rel = _inverse(Ta) @ Tb
            grip[name] = float(np.linalg.norm(rel[:3, 3] - g.grip[:3, 3]))
        self.log.append(CellRecord(self.t, self._q, np.array(r.qdot), r.status, r.scale,
                                   "/".join(r.levels), errors, grip, mode))  # fmt: skip


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
    out: Array = T.copy()
    out[:3, 3] += delta[:3]
    out[:3, :3] = pin.exp3(delta[3:]) @ T[:3, :3]
    return out
