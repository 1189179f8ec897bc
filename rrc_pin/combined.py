""":func:`rrc_pin.combine`: several robots, each at its base placement, as one :class:`Robot`.

The multi-arm cells resolve this one model: the arms' models are joined under one base with
``pinocchio.appendModel``, so one ``computeJointJacobians`` serves every arm, and the
resolver's tasks and limits apply to it unchanged (a frame task per tool frame, one QP).

- Names: every joint and frame of the arm under key ``k`` is renamed ``k/<name>``
  (``left/panda_joint1``, ``right/tool0``), so names never clash.
- Order: q is the concatenation of the arms' q, in the order of the mapping; ``lower``,
  ``upper`` and ``velocity_limit`` are concatenated the same way.
- Frames: ``T_base`` (4, 4) is the pose of the arm's base frame in the cell's base frame
  [m]; poses and Jacobians are expressed in the cell's base frame.
- Tool frames: the prefixed tool frames of every arm, in order.
- Sparsity: arms share no joint, so the Jacobian of one arm's frame has zero columns for
  every other arm's joints (block-sparse).
- Parts: the result is a :class:`Combined` robot that keeps its arms and their placements
  (:attr:`Combined.parts`), so that :class:`rrc_pin.geometry.CollisionModel` carries the
  collision geometry of every arm at its base (names prefixed like the frames).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import NamedTuple

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.errors import InvalidInput
from rrc_pin.robot import Robot
from rrc_pin.solvers.checks import rigid_transform


class Part(NamedTuple):
    """One arm of a :class:`Combined` robot.

    Attributes:
        key: Its key: the prefix of its names (``left`` gives ``left/...``).
        robot: The arm as it was given.
        T_base: Pose (4, 4) of its base in the cell's base frame [m].
    """

    key: str
    robot: Robot
    T_base: npt.NDArray[np.float64]


class Combined(Robot):
    """A :class:`Robot` made by :func:`combine`, that remembers its arms.

    Attributes:
        parts: The arms, in the order of q, each with its key and base placement.
    """

    def __init__(self, model: pin.Model, tool_frames: Sequence[str], *, name: str, source: str,
                 poses: Mapping[str, npt.ArrayLike], parts: Sequence[Part]) -> None:  # fmt: skip
        super().__init__(model, tool_frames, name=name, source=source, poses=poses)
        self.parts: tuple[Part, ...] = tuple(parts)


def combine(
    arms: Mapping[str, tuple[Robot, npt.ArrayLike]], name: str | None = None
) -> Combined:
    """One robot made of ``arms``, each at its base placement.

    Args:
        arms: Key -> ``(robot, T_base)``: the robot (any :class:`Robot`, with one tool frame
            or several) and the (4, 4) pose of its base in the cell's base frame [m]. Keys
            prefix the names (``"left"`` gives ``left/...``).
        name: Name of the result; default: the keys joined by ``+``.

    Returns:
        A :class:`Combined` robot with ``tool_frames`` the prefixed tool frames of every arm,
        as its ready configuration the arms' (:meth:`Robot.ready`) side by side, and its
        arms in :attr:`Combined.parts`.

    Raises:
        InvalidInput: ``arms`` is empty or not a mapping, a key is not a non-empty name
            without ``/``, a value is not ``(Robot, T_base)``, ``T_base`` is not a (4, 4)
            rigid transform (within :data:`rrc_pin.solvers.checks.RIGID_TOL`), or ``name`` is not a
            string.

    Example:
        >>> cell = combine({"left": (panda, T_left), "right": (ur5, T_right)})
        >>> cell.tool_frames
        ('left/panda_hand_tcp', 'right/tool0')
    """
    if not isinstance(arms, Mapping) or not arms:
        raise InvalidInput("arms", f"expected a non-empty mapping key -> (Robot, T), got {arms!r}")
    if name is not None and not isinstance(name, str):
        raise InvalidInput("name", f"expected a string, got {name!r}")
    model = pin.Model()
    tools: list[str] = []
    parts: list[str] = []
    ready = []
    kept: list[Part] = []
    for key, value in arms.items():
        robot, placement = _entry(key, value)
        model = pin.appendModel(model, prefixed(robot.model, f"{key}/"), 0, placement)
        tools += [f"{key}/{frame}" for frame in robot.tool_frames]
        parts.append(f"{key}: {robot.name}")
        ready.append(robot.ready())
        kept.append(Part(key, robot, placement.homogeneous))
    return Combined(
        model,
        tools,
        name=name if name is not None else "+".join(arms),
        source=f"combine({', '.join(parts)})",
        poses={"ready": np.concatenate(ready)},
        parts=kept,
    )


def _entry(key: object, value: object) -> tuple[Robot, pin.SE3]:
    """Check one ``key: (robot, T_base)`` entry; return the robot and its placement."""
    if not isinstance(key, str) or not key or "/" in key:
        raise InvalidInput("arms", f"keys must be non-empty names without '/', got {key!r}")
    label = f"arms[{key!r}]"
    if not (isinstance(value, tuple) and len(value) == 2 and isinstance(value[0], Robot)):
        raise InvalidInput(label, f"expected (Robot, T_base (4, 4)), got {value!r}")
    T = rigid_transform(value[1], label)
    return value[0], pin.SE3(T[:3, :3], T[:3, 3])


def prefixed(model: pin.Model, prefix: str) -> pin.Model:
    """A copy of ``model`` with every joint and frame name but the universe's prefixed.

    A fixed joint's frame that shares its name with a body's (a URDF may name a fixed joint
    after its child link, as z1's ``gripperStator``) is named ``<name>_joint``: appending a
    model refuses a frame name it cannot tell apart without its type.
    """
    out = pin.Model(model)
    for j in range(1, out.njoints):
        out.names[j] = prefix + out.names[j]
    bodies = {f.name for f in model.frames if f.type == pin.FrameType.BODY}
    for i in range(1, len(out.frames)):
        frame = out.frames[i]  # a copy: rename it, then store it back
        clash = frame.type == pin.FrameType.FIXED_JOINT and frame.name in bodies
        frame.name = prefix + frame.name + ("_joint" if clash else "")
        out.frames[i] = frame
    return out
