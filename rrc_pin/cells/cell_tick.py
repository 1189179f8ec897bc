"""CellTick: a cell controller's usual tick, its rows in one compiled call.

A :class:`~rrc_pin.cells.CellController` tick whose top level is the commanded frames' tasks
(each toward its target), with the posture below them, within the joint limits, the closed
chains' rows (the contacts', the grips') and other limits' inequality rows, has its tasks' and
chains' rows written into the resolver's workspace by one compiled call
(:func:`~rrc_pin.cells.cell_kernels.cell_rows`) instead of the tasks' and limits' own calls and
the workspace's loading; the resolver's compiled tick then runs on them
(:meth:`CompiledTick.run_loaded <rrc_pin.compiled_tick.CompiledTick.run_loaded>`). The
resolution is the resolver's (:meth:`CompiledTick.answer
<rrc_pin.compiled_tick.CompiledTick.answer>`), of the rows and constraints the tasks and
limits give, which the limits keep as their own (:meth:`GripLimit.rows_of
<rrc_pin.limits.GripLimit.rows_of>`), and the closure's correction is made from the same
arrays (:func:`~rrc_pin.cells.closure.correct`): the same bits as the tasks' and limits' path.
A tick with a value that is not finite goes that path (its messages).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import cast

import numpy as np
import numpy.typing as npt

from rrc_pin.cells.cell_kernels import cell_rows
from rrc_pin.cells.closure import ChainFrames, correct
from rrc_pin.compiled_tick import CompiledTick, TickSource, asks_apart
from rrc_pin.kinematics import Kinematics
from rrc_pin.limits import ContactLimit, GripLimit, Limit
from rrc_pin.limits.chain_kernels import NO_POSES
from rrc_pin.limits.contact_limit import Closure
from rrc_pin.limits.frame_columns import FrameColumns, frame_poses
from rrc_pin.solvers.tick.problem import Constraints, TaskRows, finite_rows, merged_rows
from rrc_pin.solvers.tick.resolution import Resolution
from rrc_pin.solvers.tick.tick import INVALID_INPUT, LB, POSITION, RATE, UB, VELOCITY
from rrc_pin.tasks import FrameTask, PostureTask, Task
from rrc_pin.tasks.frame_task import row_units

Array = npt.NDArray[np.float64]

_new = tuple.__new__
"""A named tuple made of its fields' tuple (:meth:`~typing.NamedTuple._make` less its check)."""
BOX = np.array([LB, UB, VELOCITY])
"""The workspace's joints rows of the tick's box as the correction reads it (lower and upper
bounds, velocity limits)."""
Within = Callable[[Kinematics, list[list[TaskRows]], list[Constraints | None], bool, float,
                   Array, float, list[list[Task]]], Resolution]  # fmt: skip
"""The resolver's tick once its limits have given their constraints
(:meth:`Resolver.run_compiled <rrc_pin.resolver.Resolver.run_compiled>`)."""
NO_ROWS = Constraints()
"""What a limit without rows gives (:meth:`ContactLimit.constraints
<rrc_pin.limits.ContactLimit.constraints>` without frames)."""


def fits(tasks: Sequence[FrameTask]) -> bool:
    """Whether :class:`CellTick`'s rows are those of ``tasks``: each full rows in
    ``world_aligned``, weight 1, with a target (a cell controller's commanded frames').
    """  # noqa: D205
    return all(len(t.selected) == 6 and t.ref == "world_aligned" and t.target is not None
               and isinstance(t.weight, float) and t.weight == 1.0 for t in tasks)  # fmt: skip


class CellTick:
    """The compiled rows of one set of commanded frames, chains and settings (module docstring).

    Args:
        kin: A tick's kinematics of the cell (its model, data and layout are read).
        tasks: The top level's frame tasks (:func:`fits`).
        posture: The posture task below them (no continuous joint to wrap).
        contact: The cell's contact limit, its anchors measured where it has frames.
        grip: The cell's grip limit, its grips measured where it has pairs.
        gain: The frame tasks' gain [1/s].
        chains: The chains' frames (:class:`~rrc_pin.cells.closure.ChainFrames`), contacts
            first.
        correct: Whether the closure's correction is made (:attr:`corrected`; the
            controller's bound is on).
        others: The resolver's other limits (a :class:`~rrc_pin.limits.CollisionLimit`),
            between the joint limits and the chains': their constraints computed as the
            resolver computes them; rows ``G qdot <= h`` are loaded beside the chains' (a
            collision pair's among them, which the command slides along), and a tick where
            one gives a box, equality rows or a pair asked apart (a slide row below zero)
            goes back to the resolver with the rows and constraints it has.

    Attributes:
        corrected: The last tick's top level (its tasks' rows) and closure correction, as
            :func:`~rrc_pin.cells.closure.close` makes it from the tick's rows, errors, box
            and top level: the chains' error after the step (6 k,) and the rates applied
            (nv,); None where it was not made here (not correcting, or the resolver answered).

    The resolver's limits are the joint limits, ``others``, ``contact`` and ``grip``, in that
    order (the controller's).
    """

    def __init__(
        self, kin: Kinematics, tasks: Sequence[FrameTask], posture: PostureTask,
        contact: ContactLimit, grip: GripLimit, gain: float, chains: ChainFrames,
        correct: bool, others: Sequence[Limit] = (),
    ) -> None:  # fmt: skip
        layout = kin.layout
        ids = layout.frames
        frames = [ids[t.frame] for t in tasks] + [ids[f] for f in contact.frames] + [
            ids[f] for pair in grip.pairs for f in pair]  # fmt: skip
        self.columns = FrameColumns.of(kin.model, kin.data, frames)
        self.frames = tuple(dict.fromkeys(frames))  # each pose read once a tick
        row = {f: i for i, f in enumerate(self.frames)}
        self.chain_rows = np.array([row[f] for f in chains.frames], dtype=np.intp)
        self.chains, self.correct = chains, correct
        self.corrected: tuple[list[TaskRows], Array, Array] | None = None
        self.no_rows = np.zeros((0, layout.nv)), np.zeros(0)  # the correction's G, h: none
        c, g = len(contact.frames), len(grip.pairs)
        self.plan = np.array([len(tasks), c, g, *(row[f] for f in frames)], dtype=np.int64)
        self.units = [row_units(t.selected, layout.reach[t.frame]) for t in tasks]
        _, self.eye, self.weights = posture.constant_rows(layout.continuous)
        n = layout.nv
        self.values = np.concatenate([
            [gain, posture.gain], *self.units,
            np.ones(n) if self.weights is None else self.weights, posture.q_ref,
        ])  # fmt: skip
        self.q_ref = self.values[self.values.size - n :]  # the posture's, copied at every tick
        # each chain limit's place among the resolver's limits, its rows and their units
        at = 1 + len(others)
        chain_limits: tuple[tuple[ContactLimit | GripLimit, int, int], ...] = (
            (contact, 0, c), (grip, 6 * c, g))  # fmt: skip
        self.parts = [(at + i, limit, slice(start, start + 6 * k), limit.columns(kin)[1])
                      for i, (limit, start, k) in enumerate(chain_limits) if k]  # fmt: skip
        self.unit = np.concatenate([unit for *_, unit in self.parts])  # the chains' rows'
        self.others = tuple(others)
        self.anchors = NO_POSES if contact.anchors is None else contact.anchors
        self.tasks, self.posture, self.contact, self.grip = tuple(tasks), posture, contact, grip
        self.rows = 6 * (c + g)

    def __call__(self, compiled: CompiledTick, previous: Array, within: Within, kin: Kinematics,
                 dt: float, start: float) -> Resolution | None:  # fmt: skip
        """The tick at ``kin`` after the rates ``previous`` (nv,), step ``dt`` [s], on the
        resolver's ``compiled`` tick (:meth:`Resolver.run_compiled
        <rrc_pin.resolver.Resolver.run_compiled>`), ``start`` [s] when it began: its
        resolution (the fallbacks' where the top level finds no answer); None where a value
        is not finite (the resolver's path names it). A tick whose other limits give what the
        compiled rows do not take goes on in the resolver (``within``).
        """  # noqa: D205
        self.corrected = None
        others = [limit.constraints(kin, dt, previous) for limit in self.others]
        G = h = slide = None
        if others:
            if not all(_rows_only(c) for c in others):
                return self._within(within, kin, others, dt, previous, start)
            merged = merged_rows(others)
            if merged is not None:
                G, h, slide = merged.G, merged.h, merged.slide
        ws, n, tasks = compiled.workspace, kin.layout.nv, self.tasks
        m_top, r = 6 * len(tasks), self.rows
        compiled.loading()
        if ws.task_rows.shape[0] < m_top + n or ws.E.shape[0] != r:  # room for the rows
            ws.load_levels([[TaskRows(np.zeros((m_top + n, n)), np.zeros(m_top + n), None, "")]],
                           False)  # fmt: skip
            ws.load_equalities(np.zeros((r, n)), np.zeros(r))
            ws.forget()
        data = kin.data
        poses = frame_poses(data, self.frames)
        twists, targets = np.empty((len(tasks), 6)), np.empty((len(tasks), 4, 4))
        for i, task in enumerate(tasks):
            twists[i], targets[i] = task.twist, task.target
        self.q_ref[:] = self.posture.q_ref  # read at every tick, as the posture's rows read it
        C, error = np.zeros((r, n)), np.empty(r)
        ws.joints[POSITION] = kin.q  # the posture's rows read it (the tick writes it again)
        cell_rows(data.J, poses, self.columns.steps, self.columns.starts, self.plan,
                  self.values, twists, targets, self.anchors, self.grip.grips, ws.joints,
                  ws.task_rows, ws.rates, ws.ints, ws.E, C, error)  # fmt: skip
        if h is not None:
            ws.load_rows(G, h, slide)
        code = compiled.run_loaded(kin.q, previous, dt)
        if code == INVALID_INPUT:
            return None
        rows, b = ws.task_rows[:m_top].copy(), ws.rates[RATE, : m_top + n].copy()
        top = [_new(TaskRows, (rows[6 * i : 6 * i + 6], b[6 * i : 6 * i + 6], None, t.name, u))
               for i, (t, u) in enumerate(zip(tasks, self.units, strict=True))]  # fmt: skip
        posture = _new(TaskRows, (self.eye, b[m_top:], self.weights, self.posture.name, None))
        constraints: list[Constraints | None] = [None, *others, NO_ROWS, NO_ROWS]
        for at, limit, part, unit in self.parts:
            constraints[at] = limit.rows_of(C[part], error[part], unit)
        res = compiled.answer(code, [top, [posture]], constraints, dt, False, start)
        source = res.source
        if self.correct and isinstance(source, TickSource):  # not the fallbacks' problem
            G_, h_ = self.no_rows if G is None or h is None else (G, h)
            _, after, applied = correct(data.J, self.chains, poses[self.chain_rows],
                                        _new(Closure, (C, error, self.unit)),
                                        cast(Array, source.stacked), res.qdot, ws.joints[BOX],
                                        G_, h_, dt)  # fmt: skip
            self.corrected = (top, after, applied)
        return res

    def _within(self, within: Within, kin: Kinematics, others: list[Constraints], dt: float,
                previous: Array, start: float) -> Resolution:  # fmt: skip
        """The tick in the resolver, from the tasks' rows, the other limits' ``others`` and the
        chains' constraints (as the resolver computes them; the chains' poses read again).
        """  # noqa: D205
        tasks: list[list[Task]] = [[*self.tasks], [self.posture]]
        rows = [[t.rows(kin) for t in level] for level in tasks]
        finite_rows(rows)
        constraints: list[Constraints | None] = [None, *others]
        constraints += [limit.constraints(kin, dt, previous) for limit in (self.contact,
                                                                           self.grip)]  # fmt: skip
        self.corrected = None
        return within(kin, rows, constraints, False, dt, previous, start, tasks)


def _rows_only(c: Constraints) -> bool:
    """Whether ``c`` is inequality rows at most, none of which the command slides along that
    asks a pair apart (:func:`~rrc_pin.compiled_tick.asks_apart`)."""  # noqa: D205, D209
    return c.box is None and (c.d is None or not c.d.size) and not asks_apart(c)
