"""``rrc_pin.load``: catalogue arms, example-robot-data robots, URDF and MJCF files, as a Robot.

example-robot-data's URDFs are found inside the installed package (no network); only the
kinematic model is built, so meshes are never needed. Robots with several arms (baxter, pr2,
tiago_pro, the upper bodies of talos and g1) load with every arm and a tool frame per hand;
the joints that do not move an arm, the torso or (baxter) the head are locked at zero. Every
robot loaded by name has a ``"ready"`` configuration (:meth:`Robot.ready`): example-robot-data's
SRDF group state where it gives a usable one, else chosen here, each with its reason
(:class:`Ready`). URDF mimic joints follow their primary joint (Pinocchio's mimic support).
"""

from __future__ import annotations

import importlib.metadata
import os
import xml.etree.ElementTree as ET
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin import models
from rrc_pin.errors import InvalidInput, UnknownArm, URDFError
from rrc_pin.models.arm_spec import ArmSpec
from rrc_pin.robot import Robot, moving_joints
from rrc_pin.urdf_checks import check_tree, parser_messages, readable, replay
from rrc_pin.urdf_compare import compare_urdf
from rrc_pin.urdf_export import TOOL_FRAME, to_urdf

ToolFrames = str | Sequence[str] | None
"""A tool frame, several (a robot with several end effectors), or None for the default."""


@dataclass(frozen=True)
class Ready:
    """Where the ready configuration of a robot loaded by name comes from.

    Attributes:
        reason: Why this configuration, in words (for ``rrc-pin arms`` and the docs).
        srdf: An SRDF of example-robot-data (path relative to its ``robots`` folder) whose
            group state gives the joint values, or "" for none.
        state: The group state's name in ``srdf``.
        joints: ``(joint name, value [rad or m])`` pairs, over the SRDF's values; a joint
            named nowhere is at zero.
    """

    reason: str
    srdf: str = ""
    state: str = ""
    joints: tuple[tuple[str, float], ...] = ()


@dataclass(frozen=True)
class InstalledArm:
    """A robot that example-robot-data installs.

    Attributes:
        path: URDF path relative to the package's ``robots`` folder.
        tool_frames: Default tool frames, one per end effector.
        ready: Its ready configuration (:meth:`Robot.ready`).
        keep: Joints kept moving (the others are locked at zero); empty keeps all.
        locked: What the locked joints are, in words (for ``rrc-pin arms``).
    """

    path: str
    tool_frames: tuple[str, ...]
    ready: Ready
    keep: tuple[str, ...] = ()
    locked: str = ""


def _arm(prefix: str, joints: Sequence[str], suffix: str = "") -> tuple[str, ...]:
    return tuple(f"{prefix}{j}{suffix}" for j in joints)


def _deg(names: Sequence[str], degrees: Sequence[float]) -> tuple[tuple[str, float], ...]:
    """``(joint, value [rad])`` pairs from values in degrees (the one place they appear)."""
    return tuple(
        (n, float(np.deg2rad(v))) for n, v in zip(names, degrees, strict=True)
    )


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
_SO101 = ("shoulder_pan", "shoulder_lift", "elbow_flex", "wrist_flex", "wrist_roll")
_UR_READY = Ready(
    "chosen: shoulder lift -90 deg, elbow 90 deg, wrists 1 and 2 at -90 deg (upper arm up, "
    "forearm forward, tool down; no SRDF state)",
    joints=_deg(
        ("shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint",
         "wrist_2_joint", "wrist_3_joint"),
        (0, -90, 90, -90, -90, 0),
    ),
)  # fmt: skip
_BAXTER_READY = Ready(
    "chosen: elbows bent 111 deg, hands in front at waist height (the SRDF's 'neutral' has "
    "the arms straight, a singular start)",
    joints=(
        *zip(_arm("left_", _BAXTER), (0.08, -1.0, -1.19, 1.94, 0.67, 1.03, -0.5), strict=True),
        *zip(_arm("right_", _BAXTER), (-0.08, -1.0, 1.19, 1.94, -0.67, 1.03, 0.5), strict=True),
    ),
)
INSTALLED: dict[str, InstalledArm] = {
    "panda": InstalledArm(
        "panda_description/urdf/panda.urdf",
        ("panda_hand_tcp",),
        Ready("the SRDF's state 'default'", "panda_description/srdf/panda.srdf", "default"),
        _arm("panda_joint", _SEVEN),
        "fingers",
    ),
    "ur3": InstalledArm("ur_description/urdf/ur3_robot.urdf", ("tool0",), _UR_READY),
    "ur5": InstalledArm("ur_description/urdf/ur5_robot.urdf", ("tool0",), _UR_READY),
    "ur10": InstalledArm("ur_description/urdf/ur10_robot.urdf", ("tool0",), _UR_READY),
    "kinova": InstalledArm(
        "kinova_description/robots/kinova.urdf",
        ("j2s6s200_end_effector",),
        Ready(
            "the SRDF's state 'arm_up', joint 3's -90 deg taken as 270 deg (its limits are "
            "19 to 341 deg)",
            "kinova_description/srdf/kinova.srdf",
            "arm_up",
        ),
    ),
    "xarm7": InstalledArm(
        "xarm_description/urdf/xarm7.urdf",
        ("link_eef",),
        Ready(
            "chosen: elbow (joint 4) and wrist (joint 6) bent 60 deg, the rest at zero (the "
            "SRDF's 'home' is stretched out, singular; its 'hold-up' keeps joint 6 7 deg from "
            "its limit)",
            joints=_deg(_arm("joint", _SEVEN), (0, 0, 0, 60, 0, 60, 0)),
        ),
    ),
    "z1": InstalledArm(
        "z1_description/urdf/z1.urdf",
        ("gripperStator",),
        Ready(
            "chosen: shoulder (joint 2) 60 deg, elbow (joint 3) -60 deg, the rest at zero "
            "(the SRDF's 'home' sits on joints 2 and 3's limits; its 'arm_up' is near a "
            "singularity, smallest singular value 0.035)",
            joints=_deg(_arm("joint", _SEVEN[:6]), (0, 60, -60, 0, 0, 0)),
        ),
        _arm("joint", _SEVEN[:6]),
        "gripper",
    ),
    "so101": InstalledArm(
        "so_arm_description/urdf/so101.urdf",
        ("gripper_frame_link",),
        Ready(
            "chosen: shoulder lift -45 deg, elbow and wrist flex 45 deg (no SRDF)",
            joints=_deg(_SO101, (0, -45, 45, 45, 0)),
        ),
        _SO101,
        "gripper",
    ),
    "baxter_left": InstalledArm(
        "baxter_description/urdf/baxter.urdf",
        ("left_gripper",),
        _BAXTER_READY,
        _arm("left_", _BAXTER),
        "head, right arm, fingers",
    ),
    "baxter_right": InstalledArm(
        "baxter_description/urdf/baxter.urdf",
        ("right_gripper",),
        _BAXTER_READY,
        _arm("right_", _BAXTER),
        "head, left arm, fingers",
    ),
    "baxter": InstalledArm(
        "baxter_description/urdf/baxter.urdf",
        ("left_gripper", "right_gripper"),
        _BAXTER_READY,
        ("head_pan", *_arm("left_", _BAXTER), *_arm("right_", _BAXTER)),
        "fingers",
    ),
    "pr2": InstalledArm(
        "pr2_description/urdf/pr2.urdf",
        ("l_gripper_tool_frame", "r_gripper_tool_frame"),
        Ready(
            "chosen: torso lift 0.15 m; each arm's shoulder lift 60 deg, elbow flex -45 deg, "
            "wrist flex -15 deg: hands forward, grippers level (the SRDF's tucked arms keep "
            "the left wrist 0.1 rad from its limit)",
            joints=(
                ("torso_lift_joint", 0.15),
                *_deg(_arm("l_", _PR2, "_joint"), (0, 60, 0, -45, 0, -15, 0)),
                *_deg(_arm("r_", _PR2, "_joint"), (0, 60, 0, -45, 0, -15, 0)),
            ),
        ),
        ("torso_lift_joint", *_arm("l_", _PR2, "_joint"), *_arm("r_", _PR2, "_joint")),
        "head, laser tilt, grippers (base and casters are fixed in this URDF)",
    ),
    "tiago_pro": InstalledArm(
        "tiago_pro_description/robots/tiago_pro.urdf",
        ("arm_left_tool_link", "arm_right_tool_link"),
        Ready(
            "chosen: torso lift 0.15 m; arms mirrored, elbows bent 90 deg, hands 0.5 m to "
            "each side in front (no SRDF)",
            joints=(
                ("torso_lift_joint", 0.15),
                *_deg(_arm("arm_left_", _SEVEN, "_joint"), (30, 0, -45, -90, 0, 45, 105)),
                *_deg(_arm("arm_right_", _SEVEN, "_joint"), (-30, 0, 45, -90, 0, 45, -105)),
            ),
        ),
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
        Ready(
            "chosen: torso lift 0.15 m; both arms (60, -15, 45, 45, -45, -45, 0) deg, hands "
            "in front at chest height (no SRDF)",
            joints=(
                ("torso_lift_joint", 0.15),
                *_deg(_arm("arm_left_", _SEVEN, "_joint"), (60, -15, 45, 45, -45, -45, 0)),
                *_deg(_arm("arm_right_", _SEVEN, "_joint"), (60, -15, 45, 45, -45, -45, 0)),
            ),
        ),
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
        Ready("the SRDF's state 'half_sitting'", "talos_data/srdf/talos.srdf", "half_sitting"),
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
        Ready(
            "chosen: elbows bent 90 deg, shoulders rolled 15 deg outward (no SRDF)",
            joints=(
                *_deg(_arm("left_", _G1, "_joint"), (0, 15, 0, 90, 0, 0, 0)),
                *_deg(_arm("right_", _G1, "_joint"), (0, -15, 0, 90, 0, 0, 0)),
            ),
        ),
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
        Ready(
            "the SRDF's state 'homing_nominal'",
            "centauro_description/srdf/centauro.srdf",
            "homing_nominal",
        ),
        ("torso_yaw", *_arm("j_arm1_", _SEVEN[:6]), *_arm("j_arm2_", _SEVEN[:6])),
        "legs and wheels (base: the pelvis), head camera, lidar",
    ),
    "romeo_upper": InstalledArm(
        "romeo_description/urdf/romeo_small.urdf",
        ("l_gripper", "r_gripper"),
        Ready(
            "the SRDF's state 'half_sitting'",
            "romeo_description/srdf/romeo_small.srdf",
            "half_sitting",
        ),
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


def cells() -> list[str]:
    """Names of the ready-made cells :func:`load` accepts (``gsfc_dual``, ``yeh_tripod``)."""
    return list(models.CELLS)


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
        name_or_path: A catalogue name (``"barker6"``, ...), a ready-made cell
            (``"gsfc_dual"``, ``"yeh_tripod"``: a :class:`~rrc_pin.cells.Cell`), an
            example-robot-data robot
            (``"panda"``, ``"ur5"``, ``"baxter"``, ...), an :class:`ArmSpec` (e.g. a variant
            from ``rrc_pin.models.barker6.build(alpha3=...)``), or the path of any URDF or
            MJCF (a ``<mujoco>`` file, Pinocchio's MJCF parser; MJCF gives no velocity
            limits: pass ``JointLimits(velocity=...)``). A
            committed catalogue URDF (its robot name is a catalogue name and its content
            equals the generated URDF as numbers, see :mod:`rrc_pin.urdf_compare`) loads as
            that catalogue arm.
        tool_frame: Frame to control, or several; default: the robot's tool frames, or the
            one end link of a URDF's tree.
        **parameters: Geometry of a catalogue arm, passed to its builder (e.g.
            ``alpha3=1.53`` [rad]); catalogue names only.

    Raises:
        UnknownArm: Not a known name nor a file; the message lists the available names.
        InvalidInput: An empty ``name_or_path``, parameters for anything but a catalogue
            name, a parameter its builder does not take (the message lists those it takes),
            or a value that is not a finite real number (named).
        URDFError: A folder, a missing or malformed URDF, with the path and the reason: the
            joint and link of a broken tree (:func:`rrc_pin.urdf_checks.check_tree`), else
            the parser's own message; a model with no moving joint or with a joint that is
            not one coordinate.
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
    if not key.strip():
        raise InvalidInput("name_or_path", f"empty ({key!r}): expected an arm's name (one of "
                           f"{', '.join(arms() + cells())}) or a URDF file's path")  # fmt: skip
    if key in models.CELLS:
        _refuse_parameters(parameters, f"the cell {key!r}")
        if tool_frame is not None:
            raise InvalidInput("tool_frame",
                               f"a cell's tool frames are its hands; got {tool_frame!r}")
        from rrc_pin.cells.cell import from_spec  # here: the cells package imports load

        spec = models.CELLS[key]
        return from_spec(spec, {m.key: _from_spec(models.CATALOGUE[m.arm], m.tool)
                                for m in spec.mounts})  # fmt: skip
    if key in BUILDERS:
        return _from_spec(_build(key, parameters), tool_frame)
    _refuse_parameters(parameters, f"{key!r}, which is not a catalogue arm")
    if key in INSTALLED:
        return _from_installed(key, INSTALLED[key], tool_frame)
    path = Path(key)
    if path.suffix.lower() in (".urdf", ".xml") or path.exists():
        return _from_file(path, tool_frame)
    raise UnknownArm(key, arms() + cells())


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
    ready = ready_configuration(model, folder, arm.ready)
    return Robot(model, tools, name=name, source=str(folder / arm.path), poses={"ready": ready})


def ready_configuration(model: pin.Model, folder: Path, ready: Ready) -> npt.NDArray[np.float64]:
    """The configuration (nq,) that ``ready`` describes for the moving joints of ``model``.

    The SRDF group state's values, then ``ready.joints`` over them, zero for a joint named
    nowhere. A revolute value outside its limits is taken modulo 2 pi into them where a turn
    brings it inside (an SRDF written for another angle range: kinova's joint 3).

    Raises:
        URDFError: The SRDF is missing, unreadable or has no such group state.
    """
    values: dict[str, float] = {}
    if ready.srdf:
        values.update(srdf_state(folder / ready.srdf, ready.state))
    values.update(ready.joints)
    names = moving_joints(model)
    q = np.array([values.get(n, 0.0) for n in names], dtype=np.float64)
    for i, n in enumerate(names):
        j = model.getJointId(n)
        if not model.joints[j].shortname().startswith("JointModelR"):  # revolute only
            continue
        lo, hi = model.lowerPositionLimit[model.joints[j].idx_q], model.upperPositionLimit[
            model.joints[j].idx_q
        ]
        if model.joints[j].nq == 1 and not lo <= q[i] <= hi:
            turned = lo + np.mod(q[i] - lo, 2.0 * np.pi)
            q[i] = turned if turned <= hi else q[i]
    return q


def srdf_state(path: Path, state: str) -> dict[str, float]:
    """Joint values of the group state ``state`` in the SRDF at ``path`` [rad or m].

    Joints given by several numbers (a free-flyer's pose) are left out; a joint name's
    ``prefix/`` (baxter's SRDF) is dropped.

    Raises:
        URDFError: The file is missing or not XML, or has no group state ``state``.
    """
    try:
        root = ET.parse(path).getroot()
    except (OSError, ET.ParseError) as exc:
        raise URDFError(str(path), f"cannot read the SRDF: {exc}") from exc
    for group_state in root.iter("group_state"):
        if group_state.get("name") == state:
            out: dict[str, float] = {}
            for joint in group_state.iter("joint"):
                numbers = (joint.get("value") or "").split()
                if len(numbers) == 1:
                    out[(joint.get("name") or "").split("/")[-1]] = float(numbers[0])
            return out
    raise URDFError(str(path), f"no group state {state!r} in the SRDF")


def _from_file(path: Path, tool_frame: ToolFrames) -> Robot:
    if path.is_dir():
        raise URDFError(str(path), "name_or_path is a folder, not a URDF file")
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
    if root.tag == "mujoco":  # MJCF: Pinocchio's parser, the same tool frame and limits rules
        return Robot(_parse(path, mjcf=True), tool_frame, name=root.get("model") or path.stem,
                     source=str(path))  # fmt: skip
    if root.tag != "robot":
        raise URDFError(str(path), f"not a URDF: the root element is <{root.tag}>, not <robot> "
                        "(nor <mujoco>, an MJCF)")  # fmt: skip
    check_tree(root, str(path))
    model = _parse(path)
    spec = models.CATALOGUE.get(root.get("name", ""))
    if spec is not None and not compare_urdf(text, to_urdf(spec)):
        tools = _catalogue_tool(tool_frame)
        return Robot(model, tools, name=spec.name, source=str(path), spec=spec)
    return Robot(model, tool_frame, name=path.stem, source=str(path))


def _catalogue_tool(tool_frame: ToolFrames) -> ToolFrames:
    """A catalogue arm's tool frame: the generated URDF's ``tool`` unless one is given."""
    return TOOL_FRAME if tool_frame is None else tool_frame


def _parse(path: Path, mjcf: bool = False) -> pin.Model:
    """The model of the URDF at ``path``, its mimic joints following their primary joints.

    With ``mjcf``, the model of the MJCF file at ``path`` (``pinocchio.buildModelFromMJCF``).

    Raises:
        URDFError: No such file, a file Pinocchio cannot parse, or mimic joints with a
            Pinocchio too old to honour them (named).
    """
    if not path.is_file():
        raise URDFError(str(path), "no such file")
    with parser_messages() as said:
        try:
            try:
                if mjcf:
                    model, mimic = pin.buildModelFromMJCF(str(path)), True
                else:
                    model, mimic = pin.buildModelFromUrdf(str(path), mimic=True), True
            except TypeError:  # a Pinocchio without mimic support (before 3.4)
                model, mimic = pin.buildModelFromUrdf(str(path)), False
            failure = None
        except (RuntimeError, ValueError) as exc:
            failure = exc
    if failure is not None:
        reason = readable(said) or str(failure)
        raise URDFError(str(path), f"Pinocchio could not parse it: {reason}") from failure
    replay(said)
    if not mimic:
        refuse_mimic(path)
    return model


def refuse_mimic(path: Path) -> None:
    """Refuse a URDF with mimic joints (for a Pinocchio that cannot honour them).

    Raises:
        URDFError: Naming the first mimic joint and its primary.
    """
    try:
        root = ET.parse(path).getroot()
    except (OSError, ET.ParseError):
        return  # Pinocchio parsed it; nothing more to learn here
    for joint in root.iter("joint"):
        mimic = joint.find("mimic")
        if mimic is not None:
            raise URDFError(
                str(path),
                f"joint {joint.get('name')!r} mimics {mimic.get('joint')!r}: this Pinocchio "
                f"({pin.__version__}) cannot honour mimic joints (pip install 'pin>=3.4'), "
                "and loading it as an independent joint would let it move apart",
            )
