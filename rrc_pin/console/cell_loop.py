"""CellLoop: the console's control loop driving a cell's :class:`~rrc_pin.CellController`.

The loop of :class:`~rrc_pin.console.loop.ControlLoop` (the mailbox drained at every tick,
STOP applied ahead of the tick's other commands, the deadman, the record, the device's pose
stream, the snapshot), with one :class:`~rrc_pin.cells.controller.CellController` for the
whole cell instead of a one-hand ``Controller``: the operator's controls command one of its
names at a time (:meth:`CellController.commandable`: each held object, the body, each free
hand; :class:`~rrc_pin.console.commands.Hand` switches among them), every other name is held
still, and the closed chains (grips, feet in support) stay closed inside each tick.

A tick whose closed chain opened beyond its bound (``grip_lost`` / ``contact_lost``) stops the
cell as STOP does (the operator's deadman released, a zero command from the next tick), says so
in a notice and shows the status in the snapshot
(:attr:`~rrc_pin.console.snapshot.Snapshot.lost`) until a command closes the chain.

What a cell's controller does not take is refused by name: a singularity strategy (a cell is
resolved by its damped resolver) and replaying a loaded record (a cell's record is saved and
reversed, not replayed).
"""

from __future__ import annotations

from typing import cast

from rrc_pin.cells.cell import Cell
from rrc_pin.cells.controller import CellController
from rrc_pin.console import commands as cmd
from rrc_pin.console.loop import Array, ControlLoop
from rrc_pin.console.snapshot import Mode, Snapshot
from rrc_pin.control.loop import Loop
from rrc_pin.errors import InvalidInput
from rrc_pin.limits import JointLimits
from rrc_pin.resolver import QPOptions
from rrc_pin.solvers.tick.resolution import Resolution

NO_STRATEGY = "none"
"""The strategy a cell's snapshot shows: its controller takes none (its resolver damps)."""


class CellLoop(ControlLoop):
    """The console's control loop of a cell (module docstring); :class:`ControlLoop`'s arguments.

    Args:
        cell: The cell (:class:`~rrc_pin.cells.Cell`).
        **options: :class:`~rrc_pin.console.loop.ControlLoop`'s keyword arguments (``rate``,
            ``q0``, ``mailbox``, ``settings``, ``backend``, ``record_limit``, ``priority``,
            ``realtime``); ``strategy`` only ``"resolver"`` (the default: a cell takes no
            strategy).

    Attributes:
        hands: The names the controls may command (:meth:`CellController.commandable`).
        strategies: Empty: a cell's controller takes no singularity strategy.

    Raises:
        InvalidInput: A bad argument, named.
    """

    def __init__(self, cell: Cell, **options: object) -> None:
        if not isinstance(cell, Cell):
            raise InvalidInput("cell", f"expected a rrc_pin Cell, got {cell!r}")
        if options.get("strategy", "resolver") != "resolver":
            raise InvalidInput("strategy", f"{cell.name} is a cell: its controller takes no "
                               f"singularity strategy, got {options['strategy']!r}")  # fmt: skip
        self._lost: str | None = None
        super().__init__(cell, **options)  # type: ignore[arg-type]
        self.strategies = ()
        self._strategy = NO_STRATEGY
        self._snapshot = self._snap(None, None, "held", False)

    def _commandable(self) -> tuple[str, ...]:
        return tuple(self.cell_ctl.commandable())

    @property
    def cell_ctl(self) -> CellController:
        """The controller (the loop's ``ctl``), a cell's."""
        return cast(CellController, self.ctl)

    def _controller(self, q: Array, hand: str, speed: float = 1.0) -> Loop:
        """A new cell controller at ``q`` with the loop's settings (an empty log).

        Its grips and its feet's anchors are the chains as they are at ``q``; ``hand`` is
        not its business (every name is commanded through the same controller).
        """
        return CellController(cast(Cell, self.robot), self.dt, q, limits=JointLimits(),
                              qp=QPOptions(backend=self._backend), speed=speed)  # fmt: skip

    def _step(self, twist: Array | None, frame: cmd.Frame) -> tuple[Resolution, Array | None]:
        """One ``CellController.step``: ``twist`` to the commanded name, the others held."""
        commands = None if twist is None else {self._hand: (twist, frame)}
        r = self.cell_ctl.step(commands).resolution
        lost = self.cell_ctl.lost
        if lost is not None and lost != self._lost:
            self.operator.stop()  # as a STOP: the cell held still from the next tick on,
            self._stop_now = True  # not by a fading command (which may move it to close)
            self.notice("error", f"{lost}: a closed chain opened beyond its bound; the cell "
                        "holds (STOP, then command it to close)")  # fmt: skip
        self._lost = lost
        return r, twist

    def robot_pose(self) -> Array:
        """The commanded name's frame's pose (4, 4) at the controller's q (base frame) [m]."""
        ctl = self.cell_ctl
        pose: Array = self.robot.fk(ctl.q, ctl.frame_of(self._hand))
        return pose

    def _snap(self, resolution: Resolution | None, twist: Array | None, mode: Mode,
              enabled: bool, q: Array | None = None) -> Snapshot:  # fmt: skip
        """The arm's snapshot, its hand the commanded name's frame, with the chains' state."""
        snap = super()._snap(resolution, twist, mode, enabled, q)
        return snap._replace(hand=self.cell_ctl.frame_of(self._hand), lost=self._lost)

    def _set_strategy(self, name: str) -> None:
        raise InvalidInput("strategy", f"{self.robot.name} is a cell: its controller takes no "
                           f"singularity strategy (its resolver damps), got {name!r}")  # fmt: skip

    def _set_hand(self, frame: str) -> None:
        """Command another name of the cell (the old one held still).

        The same controller goes on (its targets, chains and record): no jump, so allowed
        while recording.
        """
        cmd.one_of(frame, "hand", self.hands)
        if frame == self._hand:
            return
        if self._busy():
            raise InvalidInput("command", "cannot switch what is commanded: the cell is busy")
        self.operator.stop()
        self._end_stream()
        self._hand = frame
        self._stop_now = True  # the next tick commands it still: the old name's command dropped

    def _load(self, path: str) -> None:
        raise InvalidInput("path", f"{self.robot.name} is a cell: replaying a loaded record is "
                           "for an arm (a cell's record is saved and reversed, not replayed)")


def loop_of(robot: object, **options: object) -> ControlLoop:
    """The console's loop of ``robot``: a :class:`CellLoop` for a cell, else a ControlLoop."""
    if isinstance(robot, Cell):
        return CellLoop(robot, **options)
    return ControlLoop(robot, **options)  # type: ignore[arg-type]

