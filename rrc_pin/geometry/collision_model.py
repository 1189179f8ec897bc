"""``CollisionModel``: a robot's collision geometry, the user's obstacles and walls, and queries.

::

    cm = CollisionModel(robot)                        # capsules where it has them, else hulls
    cm.add_box(T_table, (1.2, 0.8, 0.05), name="table")
    cm.add_halfspace((0, 0, 1), 0.0, name="floor")    # the solid z <= 0
    cm.attach("panda_hand", "box", T_hand_part, size=(0.05, 0.05, 0.2), name="part")
    cm.add_workspace(T_box, (0.8, 1.0, 0.6))          # the tool frame's walls
    data = cm.create_data()                           # one per resolver / thread
    prox = cm.proximity(kin, data, detection=0.10)    # pairs closer than 10 cm, this tick

Every change (an obstacle added, moved, attached or removed) builds a new frozen
:class:`~rrc_pin.geometry.scene.Scene` and swaps it in at once, so queries in other threads are
never torn; a change is not meant for every tick (it costs a millisecond or two, see
docs/api.md). Bad input raises :class:`~rrc_pin.errors.InvalidInput` naming the argument,
before anything changes.
"""

from __future__ import annotations

import threading
from collections.abc import Callable

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.errors import InvalidInput
from rrc_pin.geometry import shapes
from rrc_pin.geometry.pairs import Reason, invariant
from rrc_pin.geometry.proximity import CollisionData, Proximity, Select, query
from rrc_pin.geometry.robot_geometry import VARIANTS, filtered_pairs, robot_geometry
from rrc_pin.geometry.scene import Extra, Scene, build_scene
from rrc_pin.geometry.tree import tree_of
from rrc_pin.geometry.walls import Wall, box_walls, plane_wall
from rrc_pin.kinematics import Kinematics
from rrc_pin.robot import Robot, frame_index
from rrc_pin.solvers.checks import (
    MAX_LENGTH,
    as_array,
    direction,
    finite_number,
    length,
    real_array,
    rigid_transform,
)

Array = npt.NDArray[np.float64]


class CollisionModel:
    """The collision geometry of a robot, obstacles, held objects and virtual walls.

    Args:
        robot: Any :class:`~rrc_pin.robot.Robot` of :func:`rrc_pin.load` or
            :func:`rrc_pin.combine` (a cell carries every arm's geometry at its base).
        geometry: ``"capsules"``, ``"hulls"`` or ``"urdf"`` (see
            :mod:`~rrc_pin.geometry.robot_geometry`), None for the robot's default, or a
            ``pinocchio.GeometryModel`` whose objects hang from joints of ``robot.model``
            (pairs filtered by the ``rigid``, ``adjacent`` and ``ready`` rules).

    Attributes:
        robot: The robot.
        variant: The geometry variant used (per arm for a cell; ``given`` for a
            ``GeometryModel``).

    Raises:
        InvalidInput: ``robot`` is not a Robot, ``geometry`` not one the robot has (the
            message lists those it has), or a ``GeometryModel`` on joints ``robot.model``
            lacks.
        URDFError: The robot's URDF or meshes cannot be read.
    """

    def __init__(self, robot: Robot, geometry: str | pin.GeometryModel | None = None) -> None:
        if not isinstance(robot, Robot):
            raise InvalidInput("robot", f"expected a Robot, got {type(robot).__name__}")
        if isinstance(geometry, pin.GeometryModel):
            for obj in geometry.geometryObjects:
                if not 0 <= obj.parentJoint < robot.model.njoints:
                    raise InvalidInput(
                        "geometry", f"{obj.name!r} hangs from joint {obj.parentJoint}, which "
                        f"{robot.name} does not have ({robot.model.njoints} joints)",
                    )  # fmt: skip
            objects = pin.GeometryModel()
            for obj in geometry.geometryObjects:
                objects.addGeometryObject(obj)
            pairs, excluded = filtered_pairs(robot, objects)
            self.variant = "given"
        elif geometry is None or isinstance(geometry, str):
            if geometry is not None and geometry not in VARIANTS:
                raise InvalidInput(
                    "geometry", f"expected one of {', '.join(VARIANTS)}, a "
                    f"pinocchio.GeometryModel or None, got {geometry!r}",
                )  # fmt: skip
            own = robot_geometry(robot, geometry)
            objects, pairs, excluded, self.variant = own
        else:
            raise InvalidInput(
                "geometry", f"expected a variant name or a pinocchio.GeometryModel, got "
                f"{type(geometry).__name__}",
            )  # fmt: skip
        self.robot = robot
        self._objects = objects
        still = invariant(robot.model, objects, pairs)
        names = [str(o.name) for o in objects.geometryObjects]
        self._robot_invariant = {(names[a], names[b]): d for (a, b), d in still.items()}
        self._robot_pairs = [p for p in pairs if p not in still]
        self._robot_excluded: dict[tuple[str, str], Reason] = {
            **excluded, **dict.fromkeys(self._robot_invariant, "invariant")}
        self._frames = frame_index(robot.model)
        self._tree = tree_of(robot.model, robot.random_q(0))
        self._extras: dict[str, Extra] = {}
        self._decided: dict[tuple[str, str], float | None] = {}  # the extras' pairs: invariant?
        self._walls: dict[str, tuple[Wall, ...]] = {}
        self._lock = threading.Lock()
        self._local = threading.local()
        self._scene = self._build(self._extras)

    # -- what it holds ----------------------------------------------------------------------

    @property
    def pairs(self) -> tuple[tuple[str, str], ...]:
        """The active pairs, ``(name_a, name_b)`` by body name.

        A is a robot body or a held object; B a robot body, a held object or an obstacle.
        """
        return self._scene.pair_names

    @property
    def excluded(self) -> dict[tuple[str, str], Reason]:
        """The pairs left out, by body names, with their reasons (a new dict)."""
        return dict(self._scene.excluded)

    @property
    def invariant(self) -> dict[tuple[str, str], float]:
        """The pairs left out because no joint changes their distance, with that distance.

        By body names, the distance [m] signed (a new dict;
        :func:`~rrc_pin.geometry.pairs.invariant`).
        """
        return dict(self._scene.invariant)

    @property
    def bodies(self) -> tuple[str, ...]:
        """Every body's name: the robot's, then held objects, then obstacles."""
        return self._scene.names

    @property
    def scene(self) -> Scene:
        """The current frozen scene (what :meth:`proximity` reads)."""
        return self._scene

    def walls(self, frame: str | None = None) -> tuple[Wall, ...]:
        """The virtual walls of ``frame`` (None: of every frame), in the order added.

        A :class:`~rrc_pin.geometry.walls.Wall` holds the origin of its frame where
        ``normal . p <= offset`` (world frame).

        Raises:
            InvalidInput: ``frame`` is neither None nor a frame's name (str).
        """
        if frame is not None and not isinstance(frame, str):
            raise InvalidInput("frame", f"expected a frame's name or None, got {frame!r}")
        if not self._walls:
            return ()
        return tuple(w for group in self._walls.values() for w in group
                     if frame is None or w.frame == frame)  # fmt: skip

    # -- obstacles in the world -------------------------------------------------------------

    def add_box(self, T: npt.ArrayLike, size: npt.ArrayLike, name: str | None = None) -> str:
        """A box of sides ``size`` (3,) [m] centred at pose ``T`` (4, 4) in the world; its name."""
        pose = _pose(T, "T")
        return self._add_world("box", shapes.box(size), pose, name)

    def add_sphere(self, center_or_T: npt.ArrayLike, radius: float, name: str | None = None
                   ) -> str:  # fmt: skip
        """A sphere of ``radius`` [m] at a centre (3,) or pose (4, 4) in the world; its name."""
        arr = real_array(center_or_T, "center_or_T", "expected a centre (3,) or a pose (4, 4)")
        if arr.shape == (3,):
            T = np.eye(4)
            T[:3, 3] = arr
            pose = _pose(T, "center_or_T")
        else:
            pose = _pose(center_or_T, "center_or_T")
        return self._add_world("sphere", shapes.sphere(radius), pose, name)

    def add_capsule(self, T: npt.ArrayLike, radius: float, length: float,
                    name: str | None = None) -> str:  # fmt: skip
        """A capsule about the z axis of pose ``T`` (4, 4) in the world; its name.

        ``length`` [m] is its axis (between the centres of its end spheres), ``radius`` [m].
        """
        pose = _pose(T, "T")
        return self._add_world("capsule", shapes.capsule(radius, length), pose, name)

    def add_cylinder(self, T: npt.ArrayLike, radius: float, length: float,
                     name: str | None = None) -> str:  # fmt: skip
        """A cylinder of ``radius`` and height ``length`` [m] about the z axis of pose ``T``.

        Centred on the origin of ``T`` (4, 4, world frame). Returns its name.
        """
        pose = _pose(T, "T")
        return self._add_world("cylinder", shapes.cylinder(radius, length), pose, name)

    def add_convex(self, T: npt.ArrayLike, points: npt.ArrayLike, name: str | None = None) -> str:
        """The convex hull of ``points`` (N, 3) [m], given in the frame of pose ``T``; its name."""
        pose = _pose(T, "T")
        return self._add_world("convex", shapes.convex(points), pose, name)

    def add_halfspace(self, normal: npt.ArrayLike, offset: float, name: str | None = None) -> str:
        """The solid half-space ``normal . x <= offset`` (world frame, [m]); its name.

        The obstacle is on the side ``normal`` points away from: a floor at height h is
        ``(0, 0, 1), h``. ``normal`` need not be unit (both are divided by its norm).
        """
        shape, unit, d = shapes.halfspace(normal, offset)
        label = self._new_name("halfspace", name)
        extra = Extra(label, "halfspace", shape, 0, 0, pin.SE3.Identity(), (unit, d))
        return self._commit(label, extra)

    # -- held objects -----------------------------------------------------------------------

    def attach(
        self,
        link: str,
        kind: str,
        T_link_shape: npt.ArrayLike,
        *,
        name: str | None = None,
        size: npt.ArrayLike | None = None,
        radius: float | None = None,
        length: float | None = None,
        points: npt.ArrayLike | None = None,
    ) -> str:
        """A shape held by ``link`` (it moves with the link); its name.

        Args:
            link: A link (frame) of the robot.
            kind: ``box`` (``size``), ``sphere`` (``radius``), ``capsule`` or ``cylinder``
                (``radius``, ``length``), ``convex`` (``points`` (N, 3) in the shape's frame).
            T_link_shape: The shape's pose (4, 4) in the link's frame [m].
            name: Its name (default: the kind and a number).
            size: Box sides (3,) [m].
            radius: Radius [m].
            length: Capsule axis or cylinder height [m].
            points: Convex points (N, 3) [m].

        The held object is checked against every body but those of its own link's joint
        (the hand that holds it).
        """
        fid = self._link(link, "link")
        if not isinstance(kind, str) or kind not in shapes.ATTACHABLE:
            raise InvalidInput(
                "kind", f"expected one of {', '.join(shapes.ATTACHABLE)}, got {kind!r}"
            )
        given = {"size": size, "radius": radius, "length": length, "points": points}
        wanted = shapes.DIMENSIONS[kind]
        for key, value in given.items():
            if key in wanted and value is None:
                raise InvalidInput(key, f"a {kind} needs {', '.join(wanted)}")
            if key not in wanted and value is not None:
                raise InvalidInput(key, f"a {kind} takes only {', '.join(wanted)}")
        placement = _pose(T_link_shape, "T_link_shape")
        builders: dict[str, Callable[[], object]] = {
            "box": lambda: shapes.box(size),  # type: ignore[arg-type, unused-ignore]
            "sphere": lambda: shapes.sphere(radius),  # type: ignore[arg-type]
            "capsule": lambda: shapes.capsule(radius, length),  # type: ignore[arg-type]
            "cylinder": lambda: shapes.cylinder(radius, length),  # type: ignore[arg-type]
            "convex": lambda: shapes.convex(points),  # type: ignore[arg-type, unused-ignore]
        }
        shape = builders[kind]()
        frame = self.robot.model.frames[fid]
        label = self._new_name(kind, name)
        extra = Extra(label, kind, shape, frame.parentJoint, fid, frame.placement * placement)
        return self._commit(label, extra)

    def remove(self, name: str) -> None:
        """Remove an obstacle, a held object or a group of walls by its name.

        Raises:
            InvalidInput: ``name`` not a string, or no obstacle, held object or walls of that
                name (lists them).
        """
        if not isinstance(name, str):
            raise InvalidInput("name", f"expected a name (str), got {type(name).__name__}")
        with self._lock:
            if name in self._extras:
                extras = {k: v for k, v in self._extras.items() if k != name}
                self._decided = {p: d for p, d in self._decided.items() if name not in p}
                scene = self._build(extras)
                self._extras, self._scene = extras, scene
            elif name in self._walls:
                self._walls = {k: v for k, v in self._walls.items() if k != name}
            else:
                known = [*self._extras, *self._walls]
                raise InvalidInput(
                    "name", f"nothing named {name!r}; added: {', '.join(known) or 'none'}"
                )

    # -- virtual walls ----------------------------------------------------------------------

    def add_workspace(self, T: npt.ArrayLike, size: npt.ArrayLike, frame: str | None = None,
                      name: str | None = None) -> str:  # fmt: skip
        """Six walls keeping ``frame``'s origin inside a box; the group's name.

        The walls are named ``<name>/+x`` ... ``<name>/-z`` (:class:`Wall`).

        Args:
            T: The box's pose (4, 4), world frame [m].
            size: Its sides (3,) [m], each > 0.
            frame: The frame held inside (default: the robot's tool frame).
            name: The group's name (default: ``workspace`` and a number).
        """
        pose = rigid_transform(T, "T")
        sides = as_array(size, "size", (3,))
        if np.any(sides <= 0.0):
            raise InvalidInput("size", f"expected three sides > 0 [m], got {sides.tolist()}")
        held = self._wall_frame(frame)
        with self._lock:
            label = self._new_name("workspace", name)
            self._walls = {**self._walls, label: box_walls(label, held, pose, sides)}
        return label

    def add_wall(self, normal: npt.ArrayLike, offset: float, frame: str | None = None,
                 name: str | None = None) -> str:  # fmt: skip
        """One wall keeping ``frame``'s origin where ``normal . p <= offset``; its name.

        World frame, [m]. ``normal`` need not be unit (both are divided by its norm).
        """
        unit, norm = direction(normal, "normal")
        d = length(offset, "offset", -MAX_LENGTH) / norm
        held = self._wall_frame(frame)
        with self._lock:
            label = self._new_name("wall", name)
            self._walls = {**self._walls, label: (plane_wall(label, held, unit, d),)}
        return label

    # -- queries ----------------------------------------------------------------------------

    def create_data(self) -> CollisionData:
        """A new per-caller query state (one per resolver; never shared between threads)."""
        return CollisionData(self._scene)

    def proximity(self, kin: Kinematics, data: CollisionData, detection: float,
                  ends: bool = False, select: Select | None = None) -> Proximity:  # fmt: skip
        """The pairs whose signed distance is below ``detection`` [m] at ``kin``'s configuration.

        Args:
            kin: The tick's :class:`~rrc_pin.kinematics.Kinematics` of this robot (its
                ``data`` read only where the compiled forward kinematics does not cover the
                model, or coal measures a pair).
            data: This caller's :meth:`create_data`.
            detection: Detection distance [m], >= 0.
            ends: Also a row for each capsule end point within ``detection`` of the other
                body (:mod:`rrc_pin.solvers.collision.narrow_kernels`): what
                :class:`CollisionLimit` constrains.
            select: Gives, from the scene the query reads, the pairs to answer for ((npairs,)
                mask over its pairs); None: every pair.

        Returns:
            A :class:`~rrc_pin.geometry.proximity.Proximity`, one row per pair below
            ``detection`` (in the order of :attr:`pairs`; with ``ends``, a pair's end-point
            rows follow its own).

        Raises:
            InvalidInput: ``kin`` of another robot, ``data`` not a CollisionData, a negative
                or non-finite ``detection``.
        """
        if kin.model is not self.robot.model:
            raise InvalidInput("kin", f"kinematics of another model than {self.robot.name}'s")
        return self._query(kin.q, lambda: kin.data, data, detection, ends, select)

    def proximity_at(self, q: npt.ArrayLike, detection: float, data: CollisionData | None = None,
                     ends: bool = False) -> Proximity:  # fmt: skip
        """:meth:`proximity` at joint positions ``q`` (nq,) [rad or m].

        Forward kinematics computed here (in the calling thread's ``robot.data``); ``data``
        defaults to one kept per thread.
        """
        q_api, q_pin = self.robot.configuration(q)
        pdata = self.robot.data
        pin.forwardKinematics(self.robot.model, pdata, q_pin)
        if data is None:
            data = getattr(self._local, "data", None)
            if data is None:
                data = self._local.data = self.create_data()
        return self._query(q_api, lambda: pdata, data, detection, ends)

    def _query(self, q: Array, placed: Callable[[], pin.Data], data: CollisionData,
               detection: float, ends: bool = False,
               select: Select | None = None) -> Proximity:  # fmt: skip
        if not isinstance(data, CollisionData):
            raise InvalidInput("data", f"expected cm.create_data()'s, got {type(data).__name__}")
        if not (type(detection) is float and 0.0 <= detection < np.inf):
            detection = finite_number(detection, "detection", 0.0)
        return query(self._scene, self.robot.model, q, placed, data, detection, ends is True,
                     select)  # fmt: skip

    # -- internals --------------------------------------------------------------------------

    def _build(self, extras: dict[str, Extra]) -> Scene:
        return build_scene(self.robot.model, self._objects, self._robot_pairs,
                           self._robot_excluded, list(extras.values()), self._tree,
                           self._robot_invariant, self._decided)  # fmt: skip

    def _add_world(self, kind: str, shape: object, pose: pin.SE3, name: str | None) -> str:
        label = self._new_name(kind, name)
        return self._commit(label, Extra(label, kind, shape, 0, 0, pose))

    def _commit(self, label: str, extra: Extra) -> str:
        with self._lock:
            self._new_name(extra.kind, label)  # taken meanwhile by another thread?
            extras = {**self._extras, label: extra}
            scene = self._build(extras)
            self._extras, self._scene = extras, scene
        return label

    def _new_name(self, kind: str, name: str | None) -> str:
        """``name`` checked (a string no body, obstacle or wall has), or a fresh one."""
        taken = set(self._scene.names) | set(self._extras) | set(self._walls)
        taken |= {w.name for w in self.walls()}
        if name is None:
            k = 0
            while f"{kind}{k}" in taken:
                k += 1
            return f"{kind}{k}"
        if not isinstance(name, str) or not name:
            raise InvalidInput("name", f"expected a non-empty string, got {name!r}")
        if name in taken:
            raise InvalidInput("name", f"{name!r} is taken (by a body, an obstacle or a wall)")
        return name

    def _link(self, link: str, argument: str) -> int:
        """The frame index of ``link`` (a frame of the robot's model)."""
        fid = self._frames.get(link) if isinstance(link, str) else None
        if fid is None:
            bodies = [str(f.name) for f in self.robot.model.frames if f.type == pin.FrameType.BODY]
            raise InvalidInput(argument, f"{self.robot.name} has no link {link!r}; links: "
                               f"{', '.join(bodies)}")  # fmt: skip
        return fid

    def _wall_frame(self, frame: str | None) -> str:
        if frame is None:
            if self.robot.tool_frame is None:
                raise InvalidInput(
                    "frame", f"{self.robot.name} has several tool frames: name one of "
                    f"{', '.join(self.robot.tool_frames)}",
                )  # fmt: skip
            return self.robot.tool_frame
        self._link(frame, "frame")
        return frame


def _pose(T: npt.ArrayLike, name: str) -> pin.SE3:
    """``T`` checked as a (4, 4) rigid transform, as a ``pinocchio.SE3``."""
    M = rigid_transform(T, name)
    return pin.SE3(M[:3, :3].copy(), M[:3, 3].copy())
