"""``rrc_pin.load``: catalogue arms, example-robot-data arms and any URDF file, as a :class:`Robot`.

example-robot-data's URDFs are found inside the installed package (no network); only the
kinematic model is built, so meshes are never needed.
"""

from __future__ import annotations

import importlib.metadata
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pinocchio as pin

from rrc_pin import models
from rrc_pin.errors import UnknownArm, URDFError
from rrc_pin.models.arm_spec import ArmSpec
from rrc_pin.robot import Robot
from rrc_pin.urdf_export import TOOL_FRAME, to_urdf


@dataclass(frozen=True)
class InstalledArm:
    """An arm that example-robot-data installs.

    Attributes:
        path: URDF path relative to the package's ``robots`` folder.
        tool_frame: Default tool frame.
        keep: Joints kept moving (the others are locked at zero); empty keeps all.
    """

    path: str
    tool_frame: str
    keep: tuple[str, ...] = ()


_BAXTER = ("s0", "s1", "e0", "e1", "w0", "w1", "w2")
INSTALLED: dict[str, InstalledArm] = {
    "panda": InstalledArm(
        "panda_description/urdf/panda.urdf",
        "panda_hand_tcp",
        tuple(f"panda_joint{i}" for i in range(1, 8)),
    ),
    "ur3": InstalledArm("ur_description/urdf/ur3_robot.urdf", "tool0"),
    "ur5": InstalledArm("ur_description/urdf/ur5_robot.urdf", "tool0"),
    "ur10": InstalledArm("ur_description/urdf/ur10_robot.urdf", "tool0"),
    "kinova": InstalledArm("kinova_description/robots/kinova.urdf", "j2s6s200_end_effector"),
    "xarm7": InstalledArm("xarm_description/urdf/xarm7.urdf", "link_eef"),
    "z1": InstalledArm(
        "z1_description/urdf/z1.urdf", "gripperStator", tuple(f"joint{i}" for i in range(1, 7))
    ),
    "so101": InstalledArm(
        "so_arm_description/urdf/so101.urdf",
        "gripper_frame_link",
        ("shoulder_pan", "shoulder_lift", "elbow_flex", "wrist_flex", "wrist_roll"),
    ),
    "baxter_left": InstalledArm(
        "baxter_description/urdf/baxter.urdf", "left_gripper", tuple(f"left_{j}" for j in _BAXTER)
    ),
    "baxter_right": InstalledArm(
        "baxter_description/urdf/baxter.urdf", "right_gripper", tuple(f"right_{j}" for j in _BAXTER)
    ),
}
"""example-robot-data arms that :func:`load` knows by name."""

BUILDERS = {
    "barker6": models.barker6.build,
    "rrc_k1607": models.rrc_k1607.build,
    "kr5_3r": models.kr5_3r.build,
    "nadkarni_c1": models.nadkarni_c1.build,
    "nadkarni_c2": models.nadkarni_c2.build,
}


def robots_directory() -> Path | None:
    """The ``robots`` folder inside the installed example-robot-data package, or None."""
    try:
        dist = importlib.metadata.distribution("example-robot-data")
    except importlib.metadata.PackageNotFoundError:
        return None
    folder = Path(str(dist.locate_file("cmeel.prefix/share/example-robot-data/robots")))
    return folder if folder.is_dir() else None


def arms() -> list[str]:
    """Names :func:`load` accepts: the catalogue, then the installed example-robot-data arms."""
    folder = robots_directory()
    installed = [
        n for n, a in INSTALLED.items() if folder is not None and (folder / a.path).is_file()
    ]
    return list(models.CATALOGUE) + installed


def load(
    name_or_path: str | Path | ArmSpec, tool_frame: str | None = None, **parameters: Any
) -> Robot:
    """Load an arm as a :class:`Robot`.

    Args:
        name_or_path: A catalogue name (``"barker6"``, ...), an example-robot-data arm
            (``"panda"``, ``"ur5"``, ...), an :class:`ArmSpec` (e.g. a variant from
            ``rrc_pin.models.barker6.build(alpha3=...)``), or the path of any URDF.
        tool_frame: Frame to control; default: the arm's tool frame, or the last link of a URDF.
        **parameters: Geometry of a catalogue arm, passed to its builder (e.g. ``alpha3=1.53``).

    Raises:
        UnknownArm: Not a known name nor a file; the message lists the available names.
        URDFError: A missing or malformed URDF, with the path and the parser's message.
        FrameNotFound: ``tool_frame`` is not a frame of the model.
        InvalidInput: Bad geometry parameters.
    """
    if isinstance(name_or_path, ArmSpec):
        return _from_spec(name_or_path, tool_frame)
    key = str(name_or_path)
    if key in BUILDERS:
        spec = BUILDERS[key](**parameters) if parameters else models.CATALOGUE[key]
        return _from_spec(spec, tool_frame)
    if parameters:
        raise URDFError(
            key, f"geometry parameters {sorted(parameters)} apply to catalogue arms only"
        )
    if key in INSTALLED:
        return _from_installed(key, INSTALLED[key], tool_frame)
    path = Path(key)
    if path.suffix.lower() in (".urdf", ".xml") or path.exists():
        return _from_file(path, tool_frame)
    raise UnknownArm(key, arms())


def _from_spec(spec: ArmSpec, tool_frame: str | None) -> Robot:
    model = pin.buildModelFromXML(to_urdf(spec))
    return Robot(model, tool_frame or TOOL_FRAME, name=spec.name, source="catalogue", spec=spec)


def _from_installed(name: str, arm: InstalledArm, tool_frame: str | None) -> Robot:
    folder = robots_directory()
    if folder is None or not (folder / arm.path).is_file():
        raise URDFError(
            arm.path, "example-robot-data is not installed (pip install example-robot-data)"
        )
    model = _parse(folder / arm.path)
    if arm.keep:
        locked = [j for j in range(1, model.njoints) if model.names[j] not in arm.keep]
        model = pin.buildReducedModel(model, locked, pin.neutral(model))
    return Robot(model, tool_frame or arm.tool_frame, name=name, source=str(folder / arm.path))


def _from_file(path: Path, tool_frame: str | None) -> Robot:
    model = _parse(path)
    if tool_frame is None:
        bodies = [f.name for f in model.frames if f.type == pin.FrameType.BODY]
        tool_frame = bodies[-1]
    return Robot(model, tool_frame, name=path.stem, source=str(path))


def _parse(path: Path) -> pin.Model:
    if not path.is_file():
        raise URDFError(str(path), "no such file")
    try:
        return pin.buildModelFromUrdf(str(path))
    except (RuntimeError, ValueError) as exc:
        raise URDFError(str(path), f"Pinocchio could not parse it: {exc}") from exc
