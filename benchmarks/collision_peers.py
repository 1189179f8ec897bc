"""The two-pandas cell of the collision benchmark in MuJoCo (for mink), from rrc-pin's own model.

:func:`mjcf` writes the Pinocchio model's joint tree (every joint a revolute joint about its
own z axis, as the panda's are) and the collision model's capsules (same radii, axes and
placements) as MJCF: MuJoCo then measures the same shapes as coal. :func:`sites` adds a site
at each tool frame for mink's frame tasks.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pinocchio as pin


def _quat(R: np.ndarray) -> str:
    q = pin.Quaternion(R)
    return f"{q.w:.17g} {q.x:.17g} {q.y:.17g} {q.z:.17g}"


def _vec(v: np.ndarray) -> str:
    return " ".join(f"{x:.17g}" for x in v)


def mjcf(robot: Any, geometry: pin.GeometryModel, tool_frames: tuple[str, ...]) -> str:
    """MJCF of ``robot``'s revolute-z joint tree with ``geometry``'s capsules and tool sites."""
    model = robot.model
    children: dict[int, list[int]] = {}
    for j in range(1, model.njoints):
        if model.joints[j].shortname() != "JointModelRZ":
            raise ValueError(f"joint {model.names[j]} is not revolute about z")
        children.setdefault(model.parents[j], []).append(j)
    geoms: dict[int, list[str]] = {}
    for obj in geometry.geometryObjects:
        shape = obj.geometry
        if type(shape).__name__ != "Capsule":
            raise ValueError(f"{obj.name} is not a capsule")
        M = obj.placement
        geoms.setdefault(obj.parentJoint, []).append(
            f'<geom name="{obj.name}" type="capsule" size="{shape.radius:.17g} '
            f'{shape.halfLength:.17g}" pos="{_vec(M.translation)}" quat="{_quat(M.rotation)}"/>'
        )
    sites: dict[int, list[str]] = {}
    for name in tool_frames:
        f = model.frames[model.getFrameId(name)]
        sites.setdefault(f.parentJoint, []).append(
            f'<site name="{name}" pos="{_vec(f.placement.translation)}" '
            f'quat="{_quat(f.placement.rotation)}"/>'
        )

    def body(j: int) -> str:
        M = model.jointPlacements[j]
        inner = "".join(geoms.get(j, [])) + "".join(sites.get(j, []))
        inner += "".join(body(c) for c in children.get(j, []))
        i = model.idx_qs[j]
        lo, hi = model.lowerPositionLimit[i], model.upperPositionLimit[i]
        return (f'<body name="{model.names[j]}" pos="{_vec(M.translation)}" '
                f'quat="{_quat(M.rotation)}"><joint name="{model.names[j]}" type="hinge" '
                f'axis="0 0 1" range="{lo:.17g} {hi:.17g}" limited="true"/>'
                f'<inertial pos="0 0 0" mass="0.1" diaginertia="1e-3 1e-3 1e-3"/>'
                f"{inner}</body>")  # fmt: skip

    world = "".join(geoms.get(0, [])) + "".join(body(c) for c in children.get(0, []))
    return (f'<mujoco model="{robot.name}"><compiler angle="radian"/>'
            f"<worldbody>{world}</worldbody></mujoco>")  # fmt: skip
