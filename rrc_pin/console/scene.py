"""Scene: the robot in 3-D, its hands' axes, the twist arrows and the target gizmo (viser).

The robot is a tree of frame nodes, one per Pinocchio joint, nested as the joints are; its
shapes (:mod:`rrc_pin.console.visuals`) hang under their joint's node. Moving the robot sets
the pose of each joint node whose angle changed by more than :data:`SHOWN` since it was last
sent, relative to its parent (``data.liMi`` after one forward-kinematics pass): at most one
message per joint and pose field, however many meshes the links have, none for a still arm.

- Hand axes ("painting the hand", Barker): x red, y green, z blue at every tool frame, the
  commanded hand's drawn larger; they hang under the joint nodes and cost nothing to move.
- Twist arrows from the commanded hand: the commanded linear velocity (orange) and angular
  velocity (yellow), and what the joint rates achieved (``J qdot``: blue and cyan), in base
  axes, a slider's full value (``full``) :data:`ARROW` of the robot's reach long.
- The target gizmo: dragging it asks the hand to servo there (``on_target``); while no target
  is set it follows the commanded hand.
- Obstacles and active collision pairs: drawn by :meth:`Scene.set_obstacles` and
  :meth:`Scene.set_pairs` when the robot's resolution reports them (none yet).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.console.visuals import Visuals
from rrc_pin.robot import Robot

Array = npt.NDArray[np.float64]
ARROW = 0.4
"""Length of the arrow of a slider's full value (linear or angular), in the robot's reach."""
COMMANDED = ((255, 140, 0), (230, 200, 0))
ACHIEVED = ((30, 90, 230), (0, 190, 210))
SHOWN = 1e-4
"""A joint node is moved when its angle [rad] (or position [m]) changed by more than this."""
DRAG_QUIET = 0.5
"""The gizmo follows the hand again only this long [s] after it was last dragged."""


def pose_of(position: npt.ArrayLike, quaternion: npt.ArrayLike) -> Array | None:
    """The pose (4, 4) of a position (3,) [m] and a quaternion (w, x, y, z), or None.

    None when either is not finite or the quaternion is far from unit length (norm outside
    [0.5, 2]); a quaternion near unit length is normalised.
    """
    try:
        p = np.asarray(position, np.float64).reshape(3)
        w, x, y, z = np.asarray(quaternion, np.float64).reshape(4)
    except (TypeError, ValueError):
        return None
    size = math.sqrt(w * w + x * x + y * y + z * z)
    if not (np.all(np.isfinite(p)) and 0.5 <= size <= 2.0):
        return None
    pose = np.eye(4)
    pose[:3, :3] = pin.Quaternion(w / size, x / size, y / size, z / size).matrix()
    pose[:3, 3] = p
    return pose


def wxyz(R: Array) -> Array:
    """Unit quaternion (w, x, y, z) of a rotation matrix (3, 3)."""
    x, y, z, w = pin.Quaternion(R).coeffs()
    return np.array([w, x, y, z])


def _stage(server: Any, reach: float) -> None:
    """The scene around the robot: up along +z, lights, the ground's grid and the camera."""
    scene = server.scene
    scene.set_up_direction("+z")
    # Plain lights, no image-based lighting and no shadows: a frame renders several times
    # faster where the page has no GPU (a software renderer, as in the tests' chromium).
    scene.configure_environment_map(None)
    scene.configure_default_lights(enabled=True, cast_shadow=False)
    scene.add_light_ambient("/light/ambient", intensity=1.2)
    scene.add_grid("/ground", width=4 * reach, height=4 * reach, cell_size=0.1 * reach,
                   section_size=0.5 * reach, shadow_opacity=0.0)  # fmt: skip
    server.initial_camera.position = (1.3 * reach, -1.1 * reach, 0.9 * reach)
    server.initial_camera.look_at = (0.15 * reach, 0.0, 0.35 * reach)


class Scene:
    """The console's 3-D view of one robot.

    Args:
        server: A ``viser.ViserServer``.
        robot: The robot.
        visuals: Its shapes.
        on_target: Called with the gizmo's pose (4, 4) when the operator drags it, on viser's
            event loop as the page's message arrives (it must not block).
        full: The sliders' full values [m/s, rad/s], drawn :data:`ARROW` of the reach long.

    Attributes:
        scale: Arrow lengths [m] per m/s and per rad/s.
        refused: Gizmo poses from a page that were not poses (NaN, a zero quaternion).
    """

    def __init__(self, server: Any, robot: Robot, visuals: Visuals,
                 on_target: Callable[[Array], None] | None = None,
                 full: tuple[float, float] = (0.1, 0.5)) -> None:  # fmt: skip
        self.server = server
        self.robot = robot
        self.model = robot.model
        self.data = robot.model.createData()  # the view's own: the Robot's is per thread
        reach = visuals.reach
        self.reach = reach
        self.scale = (ARROW * reach / full[0], ARROW * reach / full[1])
        scene = server.scene
        _stage(server, reach)
        self.robot_root = scene.add_frame("/robot", show_axes=False)
        self._nodes = self._joint_tree(scene)
        self._coordinate = [int(self.model.joints[j].idx_v) for j in range(self.model.njoints)]
        self._shown = [math.nan] * robot.nq  # the joint coordinates the nodes show
        # What a joint's motion changes of its node's pose: a revolute joint turns about an
        # axis through the joint's origin (only the rotation changes), a prismatic one slides
        # (only the translation); half the messages of setting both.
        kinds = [joint.shortname()[len("JointModel"):] for joint in self.model.joints]
        self._turns = [k in ("RX", "RY", "RZ") or k.startswith(("RUB", "Revolute")) for k in kinds]
        self._slides = [k in ("PX", "PY", "PZ") or k.startswith("Prismatic") for k in kinds]
        self._add_shapes(scene, visuals)
        self.hands: dict[str, Any] = self._hands(scene)
        self.arrows = scene.add_arrows("/twist", np.zeros((4, 2, 3)),
                                       np.array([*COMMANDED, *ACHIEVED], np.uint8),
                                       shaft_radius=0.006 * reach, head_radius=0.015 * reach,
                                       head_length=0.04 * reach)  # fmt: skip
        self._points = np.zeros((4, 2, 3), np.float32)
        self.gizmo = scene.add_transform_controls("/target", scale=0.18 * reach)
        self._following = True
        self._dragged = -math.inf
        self.refused = 0
        self._obstacles: list[Any] = []
        self._pairs: Any = None
        if on_target is not None:
            callback = on_target

            async def dragged(event: Any) -> None:  # on viser's event loop, in order
                self._dragged = time.perf_counter()
                pose = pose_of(self.gizmo.position, self.gizmo.wxyz)
                if pose is None:  # a page sent a position or rotation that is not one
                    self.refused += 1
                    return
                callback(pose)

            self.gizmo.on_update(dragged)

        self.hand = robot.tool_frames[0]
        self.set_hand(self.hand)

    def _add_shapes(self, scene: Any, visuals: Visuals) -> None:
        """Each visual shape under its joint's node."""
        for k, shape in enumerate(visuals.shapes):
            name = f"{self._paths[shape.joint]}/shape{k}"
            if shape.color is None:
                scene.add_mesh_trimesh(name, shape.mesh)
            else:
                scene.add_mesh_simple(name, np.asarray(shape.mesh.vertices, np.float32),
                                      np.asarray(shape.mesh.faces, np.uint32),
                                      color=shape.color)  # fmt: skip

    def _hands(self, scene: Any) -> dict[str, Any]:
        """A frame node per tool frame, under its joint's node."""
        reach = self.reach
        hands: dict[str, Any] = {}
        for tool in self.robot.tool_frames:
            frame = self.model.frames[self.model.getFrameId(tool)]
            hands[tool] = scene.add_frame(
                f"{self._paths[int(frame.parentJoint)]}/hand{len(hands)}",
                axes_length=0.15 * reach, axes_radius=0.008 * reach,
                wxyz=wxyz(frame.placement.rotation), position=frame.placement.translation,
            )  # fmt: skip
        return hands

    def _joint_tree(self, scene: Any) -> list[Any]:
        """A frame node per joint, nested as the joints are (index 0: the base)."""
        model = self.model
        self._paths = ["/robot"]
        nodes = [None]
        for j in range(1, model.njoints):
            self._paths.append(f"{self._paths[model.parents[j]]}/j{j}")
            nodes.append(scene.add_frame(self._paths[j], show_axes=False))
        return nodes

    def set_hand(self, tool: str) -> None:
        """Draw ``tool``'s axes as the commanded hand (larger) and the others smaller."""
        self.hand = tool
        for name, handle in self.hands.items():
            handle.axes_length = (0.15 if name == tool else 0.08) * self.reach

    def update(self, q: Array) -> Array:
        """Move the robot to ``q`` (nq,); returns the commanded hand's pose (4, 4) [m]."""
        model, data = self.model, self.data
        pin.forwardKinematics(model, data, self.robot.to_pinocchio(q))
        values, shown = q.tolist(), self._shown
        for j in range(1, model.njoints):
            k = self._coordinate[j]
            if abs(values[k] - shown[k]) <= SHOWN:  # (False for the first: nan)
                continue
            first = math.isnan(shown[k])
            shown[k] = values[k]
            placement = data.liMi[j]  # this joint's motion only: its children are unchanged
            node = self._nodes[j]
            if first or not self._slides[j]:
                node.wxyz = wxyz(placement.rotation)
            if first or not self._turns[j]:
                node.position = placement.translation
        frame = model.getFrameId(self.hand)
        pose: Array = pin.updateFramePlacement(model, data, frame).homogeneous
        if self._following and time.perf_counter() - self._dragged > DRAG_QUIET:
            self.gizmo.position = pose[:3, 3]
            self.gizmo.wxyz = wxyz(pose[:3, :3])
        return pose

    def set_arrows(self, origin: Array, commanded: Array | None, achieved: Array | None) -> None:
        """Twist arrows at ``origin`` (3,): commanded and achieved [v; w] (6,), base axes."""
        zero = np.zeros(6)
        points = np.zeros((4, 2, 3))
        for k, twist in enumerate((zero if commanded is None else commanded,
                                   zero if achieved is None else achieved)):  # fmt: skip
            points[2 * k, 0] = points[2 * k + 1, 0] = origin
            points[2 * k, 1] = origin + self.scale[0] * twist[:3]
            points[2 * k + 1, 1] = origin + self.scale[1] * twist[3:]
        if not np.array_equal(points.astype(np.float32), self._points):  # unchanged: not re-sent
            self._points = points.astype(np.float32)
            self.arrows.points = self._points

    def follow(self, following: bool) -> None:
        """Whether the gizmo follows the hand (no target set) or stays where it was dragged."""
        self._following = following

    def set_obstacles(self, boxes: Sequence[tuple[Array, Array]]) -> None:
        """Draw obstacles: each a box (pose (4, 4) in the base frame, size (3,) [m])."""
        for handle in self._obstacles:
            handle.remove()
        self._obstacles = [
            self.server.scene.add_box(f"/obstacles/box{k}", dimensions=tuple(size),
                                      color=(200, 80, 80), opacity=0.4,
                                      wxyz=wxyz(T[:3, :3]), position=T[:3, 3])
            for k, (T, size) in enumerate(boxes)
        ]

    def set_pairs(self, segments: Array) -> None:
        """Draw active collision pairs: (N, 2, 3) closest points [m], red lines."""
        points = np.asarray(segments, np.float32).reshape(-1, 2, 3)
        if self._pairs is not None:
            self._pairs.remove()
            self._pairs = None
        if len(points):
            self._pairs = self.server.scene.add_line_segments(
                "/pairs", points, colors=(230, 30, 30), thickness=3.0, thickness_units="screen")
