"""A ready-made cell as data: which arms, where their bases are, what it holds or stands on.

Every dimension the source papers do not give is stated with its reason in ``assumed``, as
the arms' :class:`~rrc_pin.models.arm_spec.ArmSpec` do.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Mount:
    """One arm of a cell.

    Attributes:
        key: The arm's name in the cell (its joints and frames are prefixed ``key/``).
        arm: Catalogue name of the arm (:func:`rrc_pin.load`).
        position: Base origin (3,) in the cell's base (or body) frame [m].
        rpy: Base orientation as roll, pitch, yaw about fixed x, y, z [rad].
        tool: The arm's frame used as its hand (or foot).
        ready: The arm's joint positions in the cell's ready pose [rad].
    """

    key: str
    arm: str
    position: tuple[float, float, float]
    rpy: tuple[float, float, float]
    tool: str
    ready: tuple[float, ...]


@dataclass(frozen=True)
class HeldObject:
    """An object held by two hands of a cell.

    The object frame is placed, in the ready pose, midway between the two hands with the
    cell's base axes; it is a frame fixed to the first hand (the grasp), and the second hand
    keeps its ready pose relative to the first (the grip).

    Attributes:
        name: Name of the object frame.
        hands: Keys of the two arms holding it (first: the one the frame is fixed to).
    """

    name: str
    hands: tuple[str, str]


@dataclass(frozen=True)
class CellSpec:
    """A ready-made cell.

    Attributes:
        name: Name :func:`rrc_pin.load` takes.
        mounts: The arms.
        source: Document the layout comes from.
        assumed: Every value the source does not give, with its reason.
        objects: Objects held by two hands.
        body: Name of the floating body frame (a free-flyer root joint carries the arms), or
            "" for a fixed base.
        body_velocity: The body's speed limits [m/s, m/s, m/s, rad/s, rad/s, rad/s] (the
            free-flyer's velocity limits), for a floating body.
        stand: Whether the ready pose puts the lowest tool frame at z = 0 (feet on the
            ground): the body's height is computed from the legs' ready pose.
    """

    name: str
    mounts: tuple[Mount, ...]
    source: str
    assumed: tuple[str, ...]
    objects: tuple[HeldObject, ...] = ()
    body: str = ""
    body_velocity: tuple[float, ...] = ()
    stand: bool = False
