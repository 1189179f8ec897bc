"""Snapshot: what the control loop publishes after every tick, for the view to read."""

from __future__ import annotations

from typing import Literal, NamedTuple

import numpy as np
import numpy.typing as npt

from rrc_pin.console.commands import Frame
from rrc_pin.solvers.tick.resolution import Resolution

Array = npt.NDArray[np.float64]
Mode = Literal["teleop", "target", "stream", "reverse", "replay", "held"]
"""What the loop did at the tick: the operator's twist, the servo to the target, following a
device's pose stream, playing back
a retrace, replaying a loaded trajectory, or holding the arm still (a worker has the
controller: reversing, saving, loading; or the record is full)."""


class Snapshot(NamedTuple):
    """The state after one tick: immutable, replaced whole (one reference assignment).

    Attributes:
        tick: Ticks of the loop since it started.
        t: The controller's time [s] (its ticks times its period).
        q: Joint positions (nq,) [rad or m] (read-only).
        resolution: The tick's resolution, or None (no step at this tick).
        twist: The operator's twist given to the controller at this tick (6,) [m/s, rad/s]
            in ``frame``, or None (deadman released: the last command ages).
        frame: The twist's frame.
        hand: The commanded tool frame.
        enabled: Whether the deadman was held or latched.
        mode: What the tick did (:data:`Mode`).
        recording: Whether the log keeps the ticks.
        recorded: Length of the record [s].
        speed: The speed override in [0, 1].
        strategy: The singularity strategy's name.
        backend: The QP backend's name.
        target: The pose (4, 4) the hand servoes to, or None.
        latched: Whether the deadman is latched.
        stops: The operator's stop count (every stop, from the page or from the loop).
        name: What the controls command: the hand's tool frame (an arm), or a cell's
            commanded name (an object, the body, a free hand's arm: ``hand`` its frame).
        lost: ``"grip_lost"`` or ``"contact_lost"`` while a cell's closed chain is open
            beyond its bound (the cell holds), else None.
    """

    tick: int
    t: float
    q: Array
    resolution: Resolution | None
    twist: Array | None
    frame: Frame
    hand: str
    enabled: bool
    mode: Mode
    recording: bool
    recorded: float
    speed: float
    strategy: str
    backend: str
    target: Array | None
    latched: bool
    stops: int
    name: str = ""
    lost: str | None = None
