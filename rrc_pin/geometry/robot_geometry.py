"""The collision geometry of a robot, on its own model, with the pairs a check leaves out.

Where the geometry comes from (:func:`robot_geometry`):

- a paper arm (``robot.spec``): the ``<collision>`` elements of its generated URDF, the
  capsules of :mod:`rrc_pin.link_capsules`;
- a robot that example-robot-data installs, loaded by name: its URDF's collision geometry
  (meshes read from the package, no network), or its capsule variant where the package ships
  one (:data:`CAPSULE_URDFS`), and its SRDF's disabled pairs where it has an SRDF
  (:data:`COLLISION_SRDFS`);
- any other URDF file (``robot.source``): its collision geometry, meshes found beside it or in
  example-robot-data's package folder;
- a :func:`rrc_pin.combine` cell: every arm's geometry at its base, names prefixed like the
  frames (``left/panda_link3_0``); each arm keeps its own active pairs, and every pair of
  bodies of two different arms is active (but for two bodies fixed to the world).

Variants (``geometry=``): ``"capsules"`` (the cylinder-and-sphere triples of a capsule model
merged into capsules, other cylinders and boxes bounded by capsules, meshes as hulls,
:mod:`~rrc_pin.geometry.capsules`; the paper arms, panda and baxter), ``"hulls"``
(every mesh made its convex hull, :mod:`~rrc_pin.geometry.hulls`), ``"urdf"`` (the URDF's
geometry as it is: meshes stay triangle meshes, which coal cannot sign in penetration). The
default is ``"capsules"`` where the robot has them, else ``"hulls"``.

The geometry is read against the URDF's own model and moved onto ``robot.model`` by frame name
(:func:`rehome`), so it follows the joints :func:`rrc_pin.load` locked (a locked finger rides
on the hand's joint) and the prefixes and base placements of :func:`rrc_pin.combine`. What is
read from files is kept in memory per process (keyed by file and variant).
"""

from __future__ import annotations

import threading
from pathlib import Path
from typing import Literal, NamedTuple

import pinocchio as pin

from rrc_pin.combined import Combined
from rrc_pin.errors import InvalidInput, URDFError
from rrc_pin.geometry.capsules import to_capsules
from rrc_pin.geometry.hulls import with_hulls
from rrc_pin.geometry.pairs import Pair, Reason, all_pairs, in_contact, kinematic_reason
from rrc_pin.link_capsules import always_touching
from rrc_pin.loading import INSTALLED, robots_directory
from rrc_pin.robot import Robot
from rrc_pin.urdf_export import to_urdf

Variant = Literal["capsules", "hulls", "urdf"]
VARIANTS: tuple[str, ...] = ("capsules", "hulls", "urdf")

CAPSULE_URDFS: dict[str, str] = {
    "panda": "panda_description/urdf/panda_collision.urdf",
    "baxter": "baxter_description/urdf/baxter.urdf",
    "baxter_left": "baxter_description/urdf/baxter.urdf",
    "baxter_right": "baxter_description/urdf/baxter.urdf",
}
"""The URDFs of the capsule variants, by robot name: panda's capsule model that
example-robot-data ships (cylinders between spheres), baxter's own URDF (its links are
cylinders and boxes, bounded by capsules; its torso and pedestal meshes become hulls)."""

COLLISION_SRDFS: dict[str, str] = {
    "panda": "panda_description/srdf/panda.srdf",
    "ur5": "ur_description/srdf/ur5.srdf",
    "xarm7": "xarm_description/srdf/xarm7.srdf",
    "baxter": "baxter_description/srdf/baxter_manipulation.srdf",
    "baxter_left": "baxter_description/srdf/baxter_manipulation.srdf",
    "baxter_right": "baxter_description/srdf/baxter_manipulation.srdf",
    "pr2": "pr2_description/srdf/pr2.srdf",
    "talos_upper": "talos_data/srdf/talos.srdf",
}
"""SRDFs whose ``disable_collisions`` apply to a robot's geometry, by robot name (the others
have none, or none with disabled pairs)."""


class RobotGeometry(NamedTuple):
    """A robot's collision geometry on its model, and its active and excluded pairs.

    Attributes:
        objects: The geometry objects, each on a joint of ``robot.model``.
        pairs: The active pairs, indices into ``objects`` (i < j).
        excluded: Every pair left out, by object names, with its reason.
        variant: The variant used (``capsules``, ``hulls``, ``urdf``; for a cell, per arm:
            ``left: capsules, right: hulls``).
    """

    objects: pin.GeometryModel
    pairs: list[Pair]
    excluded: dict[tuple[str, str], Reason]
    variant: str


class _Source(NamedTuple):
    """A robot's geometry as read, against the model of its URDF."""

    model: pin.Model
    objects: pin.GeometryModel
    srdf_removed: frozenset[tuple[str, str]]  # object-name pairs the SRDF disables
    always: frozenset[tuple[str, str]]  # link-name pairs of always_touching


_LOCK = threading.Lock()
_READ: dict[tuple[str, str], _Source] = {}


def variants_of(robot: Robot) -> tuple[str, ...]:
    """The geometry variants ``robot`` has (an empty tuple: none known)."""
    if isinstance(robot, Combined):
        common = set(VARIANTS)
        for part in robot.parts:
            common &= set(variants_of(part.robot))
        return tuple(v for v in VARIANTS if v in common)
    if robot.spec is not None:
        return VARIANTS
    installed = _installed_name(robot)
    if installed is not None:
        return VARIANTS if installed in CAPSULE_URDFS else ("hulls", "urdf")
    if Path(robot.source).is_file():
        return ("hulls", "urdf")
    return ()


def default_variant(robot: Robot) -> str:
    """``capsules`` where ``robot`` has them, else ``hulls``."""
    return "capsules" if "capsules" in variants_of(robot) else "hulls"


def robot_geometry(robot: Robot, variant: str | None = None) -> RobotGeometry:
    """The collision geometry of ``robot`` on ``robot.model`` (module docstring).

    Args:
        robot: Any robot :func:`rrc_pin.load` or :func:`rrc_pin.combine` made.
        variant: ``capsules``, ``hulls`` or ``urdf``; None for the robot's default (per arm,
            for a cell).

    Raises:
        InvalidInput: ``variant`` is not one ``robot`` has (the message lists those it has),
            or the robot's geometry is unknown (a model built in code: pass a
            ``pinocchio.GeometryModel`` to :class:`~rrc_pin.geometry.CollisionModel`).
        URDFError: A URDF or mesh that cannot be read, or a link the robot's model lacks.
    """
    have = variants_of(robot)
    if not have:
        raise InvalidInput(
            "robot", f"no collision geometry is known for {robot.name!r} (source "
            f"{robot.source!r}): pass geometry=<pinocchio.GeometryModel> on its model",
        )  # fmt: skip
    if variant is not None and variant not in have:
        raise InvalidInput(
            "geometry", f"{robot.name} has no {variant!r} geometry; it has: {', '.join(have)}"
        )
    if isinstance(robot, Combined):
        return _cell_geometry(robot, variant)
    chosen = variant if variant is not None else default_variant(robot)
    source = _source(robot, chosen)
    objects = rehome(source.objects, source.model, robot.model)
    return _filtered(robot, objects, source, chosen)


def filtered_pairs(
    robot: Robot, objects: pin.GeometryModel, use_ready: bool = True
) -> tuple[list[Pair], dict[tuple[str, str], Reason]]:
    """Active and excluded pairs of ``objects`` (on ``robot.model``) by the kinematic rules.

    ``rigid`` and ``adjacent`` always; ``ready`` when ``use_ready`` (see
    :mod:`~rrc_pin.geometry.pairs`).
    """
    return _split(robot, objects, frozenset(), frozenset(), use_ready)


def _filtered(
    robot: Robot, objects: pin.GeometryModel, source: _Source, variant: str
) -> RobotGeometry:
    pairs, excluded = _split(robot, objects, source.srdf_removed, source.always, True)
    return RobotGeometry(objects, pairs, excluded, variant)


def _split(
    robot: Robot,
    objects: pin.GeometryModel,
    srdf: frozenset[tuple[str, str]],
    always: frozenset[tuple[str, str]],
    use_ready: bool,
) -> tuple[list[Pair], dict[tuple[str, str], Reason]]:
    model = robot.model
    objs = list(objects.geometryObjects)
    links = [str(model.frames[o.parentFrame].name) for o in objs]
    active: list[Pair] = []
    excluded: dict[tuple[str, str], Reason] = {}
    for i, j in all_pairs(len(objs)):
        names = (str(objs[i].name), str(objs[j].name))
        reason = kinematic_reason(model, objs[i].parentJoint, objs[j].parentJoint)
        if reason is None and (names in srdf or names[::-1] in srdf):
            reason = "srdf"
        if reason is None and ((links[i], links[j]) in always or (links[j], links[i]) in always):
            reason = "always"
        if reason is None:
            active.append((i, j))
        else:
            excluded[names] = reason
    if use_ready and active:
        touching = in_contact(model, objects, active, robot.to_pinocchio(robot.ready()))
        for (i, j), touch in zip(list(active), touching, strict=True):
            if touch:
                active.remove((i, j))
                excluded[(str(objs[i].name), str(objs[j].name))] = "ready"
    return active, excluded


def _cell_geometry(cell: Combined, variant: str | None) -> RobotGeometry:
    """Every arm's geometry at its base in the cell's model, pairs as the module says."""
    objects = pin.GeometryModel()
    pairs: list[Pair] = []
    excluded: dict[tuple[str, str], Reason] = {}
    owner: list[int] = []  # the part of each object
    used: list[str] = []
    for k, part in enumerate(cell.parts):
        own = robot_geometry(part.robot, variant)
        prefix = f"{part.key}/"
        moved = rehome(own.objects, part.robot.model, cell.model, prefix)
        first = objects.ngeoms
        for obj in moved.geometryObjects:
            objects.addGeometryObject(obj)
            owner.append(k)
        pairs += [(first + i, first + j) for i, j in own.pairs]
        excluded.update({(prefix + a, prefix + b): r for (a, b), r in own.excluded.items()})
        used.append(f"{part.key}: {own.variant}")
    objs = list(objects.geometryObjects)
    for i, j in all_pairs(len(objs)):
        if owner[i] == owner[j]:
            continue
        if objs[i].parentJoint == 0 and objs[j].parentJoint == 0:
            excluded[(str(objs[i].name), str(objs[j].name))] = "rigid"
        else:
            pairs.append((i, j))
    pairs.sort()
    return RobotGeometry(objects, pairs, excluded, ", ".join(used))


def rehome(
    objects: pin.GeometryModel, source: pin.Model, target: pin.Model, prefix: str = ""
) -> pin.GeometryModel:
    """``objects`` (on ``source``) moved onto ``target``'s frames of the same names.

    Each object keeps its pose in its parent frame (the link it belongs to): in ``target``
    it hangs from the frame named ``prefix + name`` of the same type, on that frame's joint.

    Raises:
        URDFError: ``target`` has no such frame.
    """
    out = pin.GeometryModel()
    for obj in objects.geometryObjects:
        frame = source.frames[obj.parentFrame]
        name = prefix + str(frame.name)
        if not target.existFrame(name, frame.type):
            raise URDFError(str(obj.name), f"its link {name!r} is not a frame of the robot's model")
        fid = target.getFrameId(name, frame.type)
        placement = target.frames[fid].placement * frame.placement.inverse() * obj.placement
        out.addGeometryObject(
            pin.GeometryObject(
                prefix + str(obj.name), target.frames[fid].parentJoint, fid, placement,
                obj.geometry,
            )
        )  # fmt: skip
    return out


def _installed_name(robot: Robot) -> str | None:
    """The example-robot-data name ``robot`` was loaded by, or None."""
    arm = INSTALLED.get(robot.name)
    folder = robots_directory()
    if arm is None or folder is None or robot.source != str(folder / arm.path):
        return None
    return robot.name


def _source(robot: Robot, variant: str) -> _Source:
    """The robot's geometry as read from its URDF, in ``variant`` (cached per process)."""
    folder = robots_directory()
    srdf = None
    if robot.spec is not None:
        text, path = to_urdf(robot.spec), None
        always = frozenset(always_touching(robot.spec))
        key = (text, variant)
    else:
        name = _installed_name(robot)
        always = frozenset()
        if name is not None and folder is not None:
            relative = CAPSULE_URDFS[name] if variant == "capsules" else INSTALLED[name].path
            path = folder / relative
            srdf = folder / COLLISION_SRDFS[name] if name in COLLISION_SRDFS else None
        else:
            path = Path(robot.source)
        text = None
        key = (str(path), variant)
    with _LOCK:
        cached = _READ.get(key)
    if cached is not None:
        return cached
    model, objects = _read(text, path, folder)
    srdf_removed = _srdf_pairs(model, objects, srdf) if srdf is not None else frozenset()
    if variant == "capsules":
        objects = with_hulls(to_capsules(objects))
    elif variant == "hulls":
        objects = with_hulls(objects)
    source = _Source(model, objects, srdf_removed, always)
    with _LOCK:
        _READ.setdefault(key, source)
    return source


def _read(
    text: str | None, path: Path | None, folder: Path | None
) -> tuple[pin.Model, pin.GeometryModel]:
    """The model and collision geometry of a URDF text or file."""
    label = str(path) if path is not None else "<generated>"
    packages = [] if folder is None else [str(folder.parent.parent)]
    try:
        if text is not None:
            model = pin.buildModelFromXML(text)
            objects = pin.buildGeomFromUrdfString(model, text, pin.GeometryType.COLLISION)
        else:
            assert path is not None
            if not path.is_file():
                raise URDFError(label, "no such file")
            packages.insert(0, str(path.parent))
            model = pin.buildModelFromUrdf(str(path))
            objects = pin.buildGeomFromUrdf(
                model, str(path), pin.GeometryType.COLLISION, package_dirs=packages
            )
    except (RuntimeError, ValueError) as exc:
        raise URDFError(label, f"cannot read its collision geometry: {exc}") from exc
    return model, objects


def _srdf_pairs(
    model: pin.Model, objects: pin.GeometryModel, srdf: Path
) -> frozenset[tuple[str, str]]:
    """Object-name pairs of ``objects`` that the SRDF at ``srdf`` disables."""
    probe = pin.GeometryModel()
    for obj in objects.geometryObjects:
        probe.addGeometryObject(obj)
    probe.addAllCollisionPairs()
    before = {(p.first, p.second) for p in probe.collisionPairs}
    try:
        pin.removeCollisionPairs(model, probe, str(srdf))
    except (RuntimeError, ValueError) as exc:
        raise URDFError(str(srdf), f"cannot read the SRDF: {exc}") from exc
    after = {(p.first, p.second) for p in probe.collisionPairs}
    names = [str(o.name) for o in objects.geometryObjects]
    return frozenset((names[i], names[j]) for i, j in before - after)
