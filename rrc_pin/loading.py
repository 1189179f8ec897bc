"""``rrc_pin.load``: catalogue arms, example-robot-data robots and URDF files, as a Robot.

example-robot-data's URDFs are found inside the installed package (no network); only the
kinematic model is built, so meshes are never needed. Robots with several arms (baxter, pr2,
tiago_pro, the upper bodies of talos and g1) load with every arm and a tool frame per hand;
the joints that do not move an arm, the torso or (baxter) the head are locked at zero.
"""

from __future__ import annotations

import importlib.metadata
import os
import xml.etree.ElementTree as ET
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import pinocchio as pin

from rrc_pin import models
from rrc_pin.errors import InvalidInput, UnknownArm, URDFError
from rrc_pin.models.arm_spec import ArmSpec
from rrc_pin.robot import Robot
from rrc_pin.urdf_compare import compare_urdf
from rrc_pin.urdf_export import TOOL_FRAME, to_urdf

ToolFrames = str | Sequence[str] | None
"""A tool frame, several (a robot with several end effectors), or None for the default."""


@dataclass(frozen=True)
class InstalledArm:
    """A robot that example-robot-data installs.

    Attributes:
        path: URDF path relative to the package's ``robots`` folder.
        tool_frames: Default tool frames, one per end effector.
        keep: Joints kept moving (the others are locked at zero); empty keeps all.
        locked: What the locked joints are, in words (for ``rrc-pin arms``).
    """

    path: str
    tool_frames: tuple[str, ...]
    keep: tuple[str, ...] = ()
    locked: str = ""


def _arm(prefix: str, joints: Sequence[str], suffix: str = "") -> tuple[str, ...]:
    return tuple(f"{prefix}{j}{suffix}" for j in joints)


_BAXTER = ("s0", "s1", "e0", "e1", "w0", "w1", "w2")
_PR2 = (
    "shoulder_pan",
    "shoulder_lift",
    "upper_arm_roll",
    "elbow_flex",
    "forearm_roll",
    "wrist_flex",
    "wrist_roll",
)
_SEVEN = tuple(str(i) for i in range(1, 8))
_G1 = (
    "shoulder_pitch",
    "shoulder_roll",
    "shoulder_yaw",
    "elbow",
    "wrist_roll",
    "wrist_pitch",
    "wrist_yaw",
)
_ROMEO = (
    "ShoulderPitch",
    "ShoulderYaw",
    "ElbowRoll",
    "ElbowYaw",
    "WristRoll",
    "WristYaw",
    "WristPitch",
)
INSTALLED: dict[str, InstalledArm] = {
    "panda": InstalledArm(
        "panda_description/urdf/panda.urdf",
        ("panda_hand_tcp",),
        _arm("panda_joint", _SEVEN),
        "fingers",
    ),
    "ur3": InstalledArm("ur_description/urdf/ur3_robot.urdf", ("tool0",)),
    "ur5": InstalledArm("ur_description/urdf/ur5_robot.urdf", ("tool0",)),
    "ur10": InstalledArm("ur_description/urdf/ur10_robot.urdf", ("tool0",)),
    "kinova": InstalledArm("kinova_description/robots/kinova.urdf", ("j2s6s200_end_effector",)),
    "xarm7": InstalledArm("xarm_description/urdf/xarm7.urdf", ("link_eef",)),
    "z1": InstalledArm(
        "z1_description/urdf/z1.urdf",
        ("gripperStator",),
        _arm("joint", ("1", "2", "3", "4", "5", "6")),
        "gripper",
    ),
    "so101": InstalledArm(
        "so_arm_description/urdf/so101.urdf",
        ("gripper_frame_link",),
        ("shoulder_pan", "shoulder_lift", "elbow_flex", "wrist_flex", "wrist_roll"),
        "gripper",
    ),
    "baxter_left": InstalledArm(
        "baxter_description/urdf/baxter.urdf",
        ("left_gripper",),
        _arm("left_", _BAXTER),
        "head, right arm, fingers",
    ),
    "baxter_right": InstalledArm(
        "baxter_description/urdf/baxter.urdf",
        ("right_gripper",),
        _arm("right_", _BAXTER),
        "head, left arm, fingers",
    ),
    "baxter": InstalledArm(
        "baxter_description/urdf/baxter.urdf",
        ("left_gripper", "right_gripper"),
        ("head_pan", *_arm("left_", _BAXTER), *_arm("right_", _BAXTER)),
        "fingers",
    ),
    "pr2": InstalledArm(
        "pr2_description/urdf/pr2.urdf",
        ("l_gripper_tool_frame", "r_gripper_tool_frame"),
        ("torso_lift_joint", *_arm("l_", _PR2, "_joint"), *_arm("r_", _PR2, "_joint")),
        "head, laser tilt, grippers (base and casters are fixed in this URDF)",
    ),
    "tiago_pro": InstalledArm(
        "tiago_pro_description/robots/tiago_pro.urdf",
        ("arm_left_tool_link", "arm_right_tool_link"),
        (
            "torso_lift_joint",
            *_arm("arm_left_", _SEVEN, "_joint"),
            *_arm("arm_right_", _SEVEN, "_joint"),
        ),
        "wheels, head, grippers",
    ),
    "tiago_dual": InstalledArm(
        "tiago_description/robots/tiago_dual.urdf",
        ("hand_left_grasping_frame", "hand_right_grasping_frame"),
        (
            "torso_lift_joint",
            *_arm("arm_left_", _SEVEN, "_joint"),
            *_arm("arm_right_", _SEVEN, "_joint"),
        ),
        "casters, suspension, head, hands",
    ),
    "talos_upper": InstalledArm(
        "talos_data/robots/talos_reduced.urdf",
        ("wrist_left_ft_tool_link", "wrist_right_ft_tool_link"),
        (
            "torso_1_joint",
            "torso_2_joint",
            *_arm("arm_left_", _SEVEN, "_joint"),
            *_arm("arm_right_", _SEVEN, "_joint"),
        ),
        "legs (base: the pelvis), head, grippers",
    ),
    "g1_upper": InstalledArm(
        "g1_description/urdf/g1_29dof_rev_1_0.urdf",
        ("left_rubber_hand", "right_rubber_hand"),
        (
            "waist_yaw_joint",
            "waist_roll_joint",
            "waist_pitch_joint",
            *_arm("left_", _G1, "_joint"),
            *_arm("right_", _G1, "_joint"),
        ),
        "legs (base: the pelvis)",
    ),
    "centauro_upper": InstalledArm(
        "centauro_description/urdf/centauro.urdf",
        ("ball1_tip", "ball2_tip"),
        ("torso_yaw", *_arm("j_arm1_", _SEVEN[:6]), *_arm("j_arm2_", _SEVEN[:6])),
        "legs and wheels (base: the pelvis), head camera, lidar",
    ),
    "romeo_upper": InstalledArm(
        "romeo_description/urdf/romeo_small.urdf",
        ("l_gripper", "r_gripper"),
        (
            "TrunkYaw",
            *_arm("L", _ROMEO),
            *_arm("R", _ROMEO),
        ),
        "legs (base: the hips), neck and head",
    ),
}
"""example-robot-data robots that :func:`load` knows by name."""

BUILDERS: dict[str, Callable[..., ArmSpec]] = {
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
    """Names :func:`load` accepts: the catalogue, then the installed example-robot-data robots."""
    folder = robots_directory()
    installed = [
        n for n, a in INSTALLED.items() if folder is not None and (folder / a.path).is_file()
    ]
    return list(models.CATALOGUE) + installed


def parameters_of(name: str) -> list[str]:
    """Geometry parameters that :func:`load` passes to the builder of catalogue arm ``name``.

    Raises:
        InvalidInput: ``name`` is not a catalogue arm.
    """
    if name not in models.CATALOGUE:
        raise InvalidInput(
            "name", f"{name!r} is not a catalogue arm; catalogue: {', '.join(models.CATALOGUE)}"
        )
    return list(models.CATALOGUE[name].parameters)


def load(
    name_or_path: str | os.PathLike[str] | ArmSpec,
    tool_frame: ToolFrames = None,
    **parameters: float,
) -> Robot:
    """Load an arm, or a robot with several arms, as a :class:`Robot`.

    Args:
        name_or_path: A catalogue name (``"barker6"``, ...), an example-robot-data robot
            (``"panda"``, ``"ur5"``, ``"baxter"``, ...), an :class:`ArmSpec` (e.g. a variant
            from ``rrc_pin.models.barker6.build(alpha3=...)``), or the path of any URDF. A
            committed catalogue URDF (its robot name is a catalogue name and its content
            equals the generated URDF as numbers, see :mod:`rrc_pin.urdf_compare`) loads as
            that catalogue arm.
        tool_frame: Frame to control, or several; default: the robot's tool frames, or the
            one end link of a URDF's tree.
        **parameters: Geometry of a catalogue arm, passed to its builder (e.g.
            ``alpha3=1.53`` [rad]); catalogue names only.

    Raises:
        UnknownArm: Not a known name nor a file; the message lists the available names.
        InvalidInput: Parameters for anything but a catalogue name, a parameter its builder
            does not take (the message lists those it takes), or a value that is not a
            finite real number (named).
        URDFError: A missing or malformed URDF, with the path and the parser's message; a
            model with no moving joint or with a joint that is not one coordinate.
        ToolFrameRequired: A URDF whose tree has several end links, loaded without
            ``tool_frame`` (the message lists them).
        FrameNotFound: ``tool_frame`` is not a frame of the model.
    """
    if isinstance(name_or_path, ArmSpec):
        _refuse_parameters(parameters, "an ArmSpec: build the variant with its module's build()")
        return _from_spec(name_or_path, tool_frame)
    if not isinstance(name_or_path, (str, os.PathLike)):
        raise InvalidInput(
            "name_or_path", f"expected a name, a path or an ArmSpec, got {name_or_path!r}"
        )
    key = os.fspath(name_or_path)
    if key in BUILDERS:
        return _from_spec(_build(key, parameters), tool_frame)
    _refuse_parameters(parameters, f"{key!r}, which is not a catalogue arm")
    if key in INSTALLED:
        return _from_installed(key, INSTALLED[key], tool_frame)
    path = Path(key)
    if path.suffix.lower() in (".urdf", ".xml") or path.exists():
        return _from_file(path, tool_frame)
    raise UnknownArm(key, arms())


def _refuse_parameters(parameters: dict[str, float], what: str) -> None:
    if parameters:
        raise InvalidInput(
            ", ".join(sorted(parameters)),
            f"geometry parameters apply to catalogue names only ({', '.join(BUILDERS)}), "
            f"not to {what}",
        )


def _build(name: str, parameters: dict[str, float]) -> ArmSpec:
    if not parameters:
        return models.CATALOGUE[name]
    accepted = parameters_of(name)
    unknown = sorted(set(parameters) - set(accepted))
    if unknown:
        raise InvalidInput(
            ", ".join(unknown),
            f"not a parameter of {name}; it takes: {', '.join(accepted) or 'none'}",
        )
    return BUILDERS[name](**parameters)


def _from_spec(spec: ArmSpec, tool_frame: ToolFrames) -> Robot:
    try:
        model = pin.buildModelFromXML(to_urdf(spec))
    except (RuntimeError, ValueError) as exc:
        raise URDFError(f"<{spec.name}>", f"Pinocchio could not build it: {exc}") from exc
    return Robot(model, _catalogue_tool(tool_frame), name=spec.name, source="catalogue", spec=spec)


def _from_installed(name: str, arm: InstalledArm, tool_frame: ToolFrames) -> Robot:
    folder = robots_directory()
    if folder is None or not (folder / arm.path).is_file():
        raise URDFError(
            arm.path, "example-robot-data is not installed (pip install example-robot-data)"
        )
    model = _parse(folder / arm.path)
    if arm.keep:
        locked = [j for j in range(1, model.njoints) if model.names[j] not in arm.keep]
        model = pin.buildReducedModel(model, locked, pin.neutral(model))
    tools = arm.tool_frames if tool_frame is None else tool_frame
    return Robot(model, tools, name=name, source=str(folder / arm.path))


def _from_file(path: Path, tool_frame: ToolFrames) -> Robot:
    try:
        text = path.read_text()
    except FileNotFoundError as exc:
        raise URDFError(str(path), "no such file") from exc
    except (OSError, UnicodeDecodeError) as exc:
        raise URDFError(str(path), f"cannot read it: {exc}") from exc
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        raise URDFError(str(path), f"not XML: {exc}") from exc
    if root.tag != "robot":
        raise URDFError(str(path), f"not a URDF: the root element is <{root.tag}>, not <robot>")
    model = _parse(path)
    spec = models.CATALOGUE.get(root.get("name", ""))
    if spec is not None and not compare_urdf(text, to_urdf(spec)):
        tools = _catalogue_tool(tool_frame)
        return Robot(model, tools, name=spec.name, source=str(path), spec=spec)
    return Robot(model, tool_frame, name=path.stem, source=str(path))


def _catalogue_tool(tool_frame: ToolFrames) -> ToolFrames:
    """A catalogue arm's tool frame: the generated URDF's ``tool`` unless one is given."""
    return TOOL_FRAME if tool_frame is None else tool_frame


def _parse(path: Path) -> pin.Model:
    if not path.is_file():
        raise URDFError(str(path), "no such file")
    try:
        return pin.buildModelFromUrdf(str(path))
    except (RuntimeError, ValueError) as exc:
        raise URDFError(str(path), f"Pinocchio could not parse it: {exc}") from exc
