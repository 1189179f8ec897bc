"""The shapes the console draws for a robot: its URDF's visuals, or a skeleton of its joints.

Each shape is attached to a Pinocchio joint of the robot's model and given in that joint's
frame, so that the scene moves it with one forward-kinematics pass. Where they come from:

- a catalogue arm: the generated URDF's visuals (a cylinder per joint and per link, no
  material: drawn in :data:`PAPER_COLOR`);
- an example-robot-data robot or a URDF file: its visual meshes, with
  ``package://example-robot-data/`` mapped to the installed package's share folder (no
  network); locked joints (panda's fingers) are drawn at zero, where the model holds them;
- anything else (a combination of arms, a URDF without visuals): a skeleton, a cylinder
  from each joint to the next and a ball at each joint, from the kinematics alone.
"""

from __future__ import annotations

import io
import logging
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import Any, Literal

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.loading import robots_directory
from rrc_pin.robot import Robot
from rrc_pin.urdf_export import to_urdf

Array = npt.NDArray[np.float64]
PAPER_COLOR = (45, 105, 215)
"""RGB of the paper arms' links (their URDFs give no material)."""
SKELETON_COLOR = (120, 125, 140)
"""RGB of a skeleton's links."""
PACKAGE = "package://example-robot-data/"


@dataclass(frozen=True)
class LinkShape:
    """One triangle mesh that moves with one joint.

    Attributes:
        joint: Index of the Pinocchio joint it moves with (0: the base, never moves).
        name: A name for the scene (unique within the robot).
        mesh: A ``trimesh.Trimesh`` in the joint's frame [m].
        color: RGB, or None: the mesh's own materials.
    """

    joint: int
    name: str
    mesh: Any
    color: tuple[int, int, int] | None


class Visuals:
    """The shapes of a robot, and where they came from.

    Attributes:
        shapes: Every :class:`LinkShape`.
        source: ``"urdf"`` (the visuals of a URDF) or ``"skeleton"``.
        reach: Largest distance of a joint or tool frame from the base at the neutral
            configuration [m] (the scene's scale).
    """

    def __init__(self, shapes: list[LinkShape], source: Literal["urdf", "skeleton"],
                 reach: float) -> None:  # fmt: skip
        self.shapes = shapes
        self.source = source
        self.reach = reach


def visuals_of(robot: Robot) -> Visuals:
    """The shapes :mod:`rrc_pin.console.scene` draws for ``robot``.

    Never raises for a robot that loaded: a URDF that cannot be read again, or whose meshes
    are missing, gives the skeleton.
    """
    reach = _reach(robot)
    urdf = _urdf_of(robot)
    if urdf is not None:
        color = PAPER_COLOR if robot.spec is not None else None
        shapes = _from_urdf(robot, urdf, color)
        if shapes:
            return Visuals(shapes, "urdf", reach)
    return Visuals(skeleton(robot, radius=max(0.01, 0.02 * reach)), "skeleton", reach)


def _urdf_of(robot: Robot) -> Any:
    """The yourdfpy URDF of ``robot`` with its visual meshes, or None."""
    import yourdfpy

    quiet = logging.getLogger("yourdfpy")
    level = quiet.level
    quiet.setLevel(logging.ERROR)  # a missing mesh is reported by falling back, not logged
    try:
        if robot.spec is not None:
            return yourdfpy.URDF.load(io.StringIO(to_urdf(robot.spec)))
        path = Path(robot.source)
        if not path.is_file():
            return None
        handler = partial(_filename, directory=path.parent)
        return yourdfpy.URDF.load(str(path), filename_handler=handler)
    except Exception:  # yourdfpy raises many kinds on a file it cannot read: fall back
        return None
    finally:
        quiet.setLevel(level)


def _filename(fname: str, directory: Path) -> str:
    """A mesh's file: example-robot-data's ``package://`` in the installed share folder."""
    import yourdfpy

    robots = robots_directory()
    if fname.startswith(PACKAGE) and robots is not None:
        return str(robots.parent / fname[len(PACKAGE):])
    out: str = yourdfpy.filename_handler_magic(fname, dir=str(directory))
    return out


def _from_urdf(robot: Robot, urdf: Any, color: tuple[int, int, int] | None) -> list[LinkShape]:
    """The URDF's visual meshes, each in the frame of the joint its link moves with."""
    scene = urdf.scene
    if scene is None:
        return []
    model = robot.model
    shapes = []
    for name, mesh in scene.geometry.items():
        link = scene.graph.transforms.parents[name]
        if not model.existFrame(link):
            continue
        frame = model.frames[model.getFrameId(link)]
        T = frame.placement.homogeneous @ urdf.get_transform(name, link)
        placed = mesh.copy()
        placed.apply_transform(T)
        own = getattr(placed.visual, "kind", None) is not None
        paint = None if own and color is None else (color or SKELETON_COLOR)
        shapes.append(LinkShape(int(frame.parentJoint), f"{link}/{name}", placed, paint))
    return shapes


def skeleton(robot: Robot, radius: float = 0.02) -> list[LinkShape]:
    """A cylinder from each joint to its child joints and tool frames, a ball at each joint.

    Args:
        robot: The robot (its Pinocchio model only).
        radius: Cylinder radius [m]; balls are 1.6 times it.
    """
    import trimesh

    model = robot.model
    shapes = []

    def rod(joint: int, end: Array, name: str) -> None:
        length = float(np.linalg.norm(end))
        if length < 1e-6:
            return
        mesh = trimesh.creation.cylinder(radius, length, sections=16)
        mesh.apply_translation([0.0, 0.0, length / 2])  # along z from 0 to length
        T = np.eye(4)  # z onto the rod's direction
        T[:3, :3] = pin.Quaternion.FromTwoVectors(np.array([0.0, 0.0, 1.0]),
                                                  end / length).matrix()  # fmt: skip
        mesh.apply_transform(T)
        shapes.append(LinkShape(joint, name, mesh, SKELETON_COLOR))

    for j in range(1, model.njoints):
        rod(model.parents[j], np.array(model.jointPlacements[j].translation), f"rod{j}")
        ball = trimesh.creation.icosphere(subdivisions=2, radius=1.6 * radius)
        shapes.append(LinkShape(j, f"ball{j}", ball, SKELETON_COLOR))
    for tool in robot.tool_frames:
        frame = model.frames[model.getFrameId(tool)]
        rod(int(frame.parentJoint), np.array(frame.placement.translation), f"tool:{tool}")
    return shapes


def _reach(robot: Robot) -> float:
    """Largest distance from the base of a joint or tool frame at the neutral configuration."""
    model = robot.model
    data = model.createData()
    pin.framesForwardKinematics(model, data, robot.to_pinocchio(robot.neutral()))
    points = [data.oMi[j].translation for j in range(1, model.njoints)]
    points += [data.oMf[model.getFrameId(t)].translation for t in robot.tool_frames]
    return max(0.1, max(float(np.linalg.norm(p)) for p in points))
