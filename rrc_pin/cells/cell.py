"""Cell: several arms on one Pinocchio model, with their names, bases, hands and held objects.

A cell is a :class:`~rrc_pin.robot.Robot` (so the resolver, the limits and the controllers
take it unchanged) that also knows its parts:

- ``arms``: each arm's key, the arm itself, its base placement in the cell's frame and its
  hand (tool) frame, and the slice of q and qdot it owns;
- ``objects``: objects held by two hands, each an object frame fixed to the first hand (the
  grasp) and the second hand's pose relative to the first to keep (the grip);
- ``body``: for a legged cell, the body frame of a free-flyer root joint (a floating base)
  under which the legs hang; its feet are the arms' tool frames.

This module builds the model only (it sits with :mod:`rrc_pin.combined` in the foundation
layer, so that :func:`rrc_pin.load` can build ready-made cells); the cooperative commands,
the controller and the master-slave mapping of :mod:`rrc_pin.cells` sit above the control
layer.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import NamedTuple

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.combined import Combined, Part, prefixed
from rrc_pin.errors import InvalidInput
from rrc_pin.models.cell_spec import CellSpec
from rrc_pin.robot import Robot, frame_index
from rrc_pin.solvers.checks import as_vector, rigid_transform

Array = npt.NDArray[np.float64]


class Arm(NamedTuple):
    """One arm of a cell.

    Attributes:
        key: Its name in the cell (joint and frame names start with ``key/``).
        robot: The arm on its own.
        base: Pose (4, 4) of its base in the cell's base frame (or the body's) [m].
        hand: Its tool frame's name in the cell (``key/tool``).
        q: Slice of the cell's q holding its joints.
        v: Slice of the cell's qdot holding its rates.
    """

    key: str
    robot: Robot
    base: Array
    hand: str
    q: slice
    v: slice


class Grasp(NamedTuple):
    """An object held by two hands.

    Attributes:
        name: The object frame's name (a frame of the cell, fixed to ``hands[0]``).
        hands: The two hands' frame names.
        grip: Pose (4, 4) of ``hands[1]`` in ``hands[0]``'s frame to keep [m].
        in_hand: Pose (4, 4) of the object frame in ``hands[0]``'s frame [m].
    """

    name: str
    hands: tuple[str, str]
    grip: Array
    in_hand: Array


class Cell(Combined):
    """Several arms as one robot, with named parts (module docstring).

    A :class:`~rrc_pin.combined.Combined` robot (its ``parts``: each arm's key, robot and
    base placement), so that what takes a combined robot takes a cell: the collision model
    (:class:`~rrc_pin.geometry.CollisionModel`, each arm's geometry at its base).

    Build one with :func:`make_cell`, or load a ready-made one by name
    (``rrc_pin.load("gsfc_dual")``, ``"yeh_tripod"``).

    Attributes:
        arms: Key -> :class:`Arm`, in q's order.
        objects: Object name -> :class:`Grasp`.
        body: The floating body's frame name, or None for a fixed base.
        cell_spec: The ready-made cell's data, or None.
    """

    arms: dict[str, Arm]
    objects: dict[str, Grasp]
    body: str | None
    cell_spec: CellSpec | None

    def arm(self, key: str, argument: str = "key") -> Arm:
        """The arm ``key``.

        Raises:
            InvalidInput: No such arm (naming ``argument`` and listing the arms).
        """
        found = self.arms.get(key) if isinstance(key, str) else None
        if found is None:
            raise InvalidInput(argument, f"no arm {key!r} in {self.name}; arms: "
                               f"{', '.join(self.arms)}")  # fmt: skip
        return found

    def holder(self, hand: str) -> str | None:
        """The object that hand frame ``hand`` holds, or None.

        Raises:
            InvalidInput: ``hand`` is not a frame name (str).
        """
        if not isinstance(hand, str):
            raise InvalidInput("hand", f"expected a hand frame's name, got {type(hand).__name__}")
        for grasp in self.objects.values():
            if hand in grasp.hands:
                return grasp.name
        return None

    def describe(self) -> str:
        """One line per part: arms with their hands, objects, body (for ``rrc-pin arms``)."""
        parts = [f"{a.key}: {a.robot.name}, hand {a.hand}" for a in self.arms.values()]
        parts += [f"object {g.name} held by {' and '.join(g.hands)}" for g in self.objects.values()]
        if self.body is not None:
            parts.append(f"floating body {self.body}")
        return "; ".join(parts)


def make_cell(
    arms: Mapping[str, tuple[Robot, npt.ArrayLike]],
    *,
    name: str,
    objects: Mapping[str, tuple[str, str]] | None = None,
    ready: Mapping[str, npt.ArrayLike] | None = None,
    body: str | None = None,
    body_velocity: Sequence[float] = (),
    stand: bool = False,
    spec: CellSpec | None = None,
    source: str = "make_cell",
) -> Cell:
    """A cell of ``arms``, each at its base placement.

    Args:
        arms: Key -> ``(arm, T_base)``: a :class:`Robot` with one tool frame (its hand, or
            foot) and the (4, 4) rigid pose of its base in the cell's base frame, or in the
            body's frame for a floating cell [m].
        name: The cell's name.
        objects: Object name -> the keys of the two arms holding it; the object frame is
            placed midway between their hands in the ready pose, with the base's axes.
        ready: Key -> the arm's joint positions in the cell's ready pose (default: each
            arm's :meth:`Robot.ready`).
        body: Name of a floating body: the arms hang from a free-flyer root joint (named
            ``<body>_joint``) whose frame is ``body``; None for a fixed base.
        body_velocity: The body's six speed limits [m/s, rad/s] (floating cells).
        stand: Raise the body so that the lowest hand is at z = 0 in the ready pose.
        spec: The ready-made cell's data, if any.
        source: Where the cell comes from, for messages.

    Raises:
        InvalidInput: Empty ``arms``, a key that is not a name without ``/``, an arm with
            several tool frames, a base pose that is not a rigid transform (named
            ``arms['key']``), an object naming an unknown arm or one arm twice, a ready
            pose of the wrong size or outside the limits, or speed limits that are not six
            finite numbers > 0.
    """
    if not isinstance(arms, Mapping) or not arms:
        raise InvalidInput("arms", f"expected a non-empty mapping key -> (Robot, T), got {arms!r}")
    entries = [_entry(key, value) for key, value in arms.items()]
    model = pin.Model()
    attach = 0
    if body is not None:
        if not isinstance(body, str) or not body or "/" in body:
            raise InvalidInput("body", f"expected a frame name without '/', got {body!r}")
        velocity = as_vector(body_velocity, "body_velocity", 6)
        if (velocity <= 0.0).any():
            raise InvalidInput("body_velocity", f"expected six limits > 0, got {velocity}")
        joint = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), f"{body}_joint")
        attach = model.addBodyFrame(body, joint, pin.SE3.Identity(), 0)
    parts: dict[str, Arm] = {}
    q_at, v_at = 7 if body is not None else 0, 6 if body is not None else 0
    for key, robot, T in entries:
        model = pin.appendModel(model, prefixed(robot.model, f"{key}/"), attach,
                                pin.SE3(T[:3, :3], T[:3, 3]))  # fmt: skip
        parts[key] = Arm(key, robot, T, f"{key}/{robot.tool_frame}",
                         slice(q_at, q_at + robot.nq), slice(v_at, v_at + robot.nv))  # fmt: skip
        q_at, v_at = q_at + robot.nq, v_at + robot.nv
    if body is not None:  # set once the arms are in (appendModel checks limits' consistency)
        model.velocityLimit[:6] = velocity
    q_ready = _ready(parts, ready, body is not None)
    if stand:
        q_ready[2] -= _lowest(model, q_ready, [a.hand for a in parts.values()])
    grasps = _grasps(model, parts, objects, q_ready)
    cell = Cell(model, [a.hand for a in parts.values()], name=name, source=source,
                poses={"ready": q_ready},
                parts=[Part(a.key, a.robot, a.base) for a in parts.values()])  # fmt: skip
    cell.arms, cell.objects, cell.body, cell.cell_spec = parts, grasps, body, spec
    return cell


def from_spec(spec: CellSpec, robots: Mapping[str, Robot]) -> Cell:
    """The ready-made cell of ``spec``, its arms taken from ``robots`` (by catalogue name)."""
    arms = {}
    for m in spec.mounts:
        base = np.eye(4)
        base[:3, :3] = pin.rpy.rpyToMatrix(*m.rpy)
        base[:3, 3] = m.position
        arms[m.key] = (robots[m.key], base)
    return make_cell(
        arms, name=spec.name, objects={o.name: o.hands for o in spec.objects},
        ready={m.key: m.ready for m in spec.mounts}, body=spec.body or None,
        body_velocity=spec.body_velocity, stand=spec.stand, spec=spec, source=spec.source,
    )  # fmt: skip


def _entry(key: object, value: object) -> tuple[str, Robot, Array]:
    """Check one ``key: (robot, T_base)`` entry."""
    if not isinstance(key, str) or not key or "/" in key:
        raise InvalidInput("arms", f"keys must be non-empty names without '/', got {key!r}")
    label = f"arms[{key!r}]"
    if not (isinstance(value, tuple) and len(value) == 2 and isinstance(value[0], Robot)):
        raise InvalidInput(label, f"expected (Robot, T_base (4, 4)), got {value!r}")
    robot = value[0]
    if robot.tool_frame is None or robot.floating:
        raise InvalidInput(label, f"expected a fixed-base arm with one tool frame, got {robot!r}")
    return key, robot, rigid_transform(value[1], label)


def _ready(parts: dict[str, Arm], ready: Mapping[str, npt.ArrayLike] | None,
           floating: bool) -> Array:  # fmt: skip
    """The cell's ready q: the body at the origin, then each arm's ready joints."""
    ready = {} if ready is None else ready
    if not isinstance(ready, Mapping):
        raise InvalidInput("ready", f"expected a mapping key -> q, got {ready!r}")
    unknown = sorted(set(ready) - set(parts))
    if unknown:
        raise InvalidInput("ready", f"no arm {unknown[0]!r}; arms: {', '.join(parts)}")
    q = [np.array([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0])] if floating else []
    for key, arm in parts.items():
        given = ready.get(key)
        q.append(arm.robot.ready() if given is None
                 else arm.robot.check_q(given, f"ready[{key!r}]"))  # fmt: skip
    return np.concatenate(q)


def _lowest(model: pin.Model, q: Array, frames: list[str]) -> float:
    """The lowest z [m] of ``frames`` at ``q`` (Pinocchio's configuration)."""
    data = model.createData()
    pin.framesForwardKinematics(model, data, q)
    index = frame_index(model)
    return min(float(data.oMf[index[f]].translation[2]) for f in frames)


def _grasps(
    model: pin.Model, parts: dict[str, Arm], objects: Mapping[str, tuple[str, str]] | None,
    q: Array,
) -> dict[str, Grasp]:  # fmt: skip
    """Add each object's frame to ``model`` (fixed to its first hand); return the grasps."""
    if objects is None:
        return {}
    if not isinstance(objects, Mapping):
        raise InvalidInput("objects", f"expected a mapping name -> (arm, arm), got {objects!r}")
    data = model.createData()
    pin.framesForwardKinematics(model, data, q)
    index = frame_index(model)
    out = {}
    for name, hands in objects.items():
        label = f"objects[{name!r}]"
        if not isinstance(name, str) or not name or name in index:
            raise InvalidInput("objects", f"expected a new frame name, got {name!r}")
        if not (isinstance(hands, (tuple, list)) and len(hands) == 2 and hands[0] != hands[1]):
            raise InvalidInput(label, f"expected two different arms, got {hands!r}")
        for key in hands:
            if key not in parts:
                raise InvalidInput(label, f"no arm {key!r}; arms: {', '.join(parts)}")
        a, b = parts[hands[0]].hand, parts[hands[1]].hand
        Ta, Tb = data.oMf[index[a]], data.oMf[index[b]]
        T_object = pin.SE3(np.eye(3), 0.5 * (Ta.translation + Tb.translation))
        in_hand = Ta.actInv(T_object)
        frame_a = model.frames[index[a]]
        model.addFrame(pin.Frame(name, frame_a.parentJoint, index[a],
                                 frame_a.placement * in_hand, pin.FrameType.OP_FRAME))  # fmt: skip
        out[name] = Grasp(name, (a, b), Ta.actInv(Tb).homogeneous, in_hand.homogeneous)
    return out
