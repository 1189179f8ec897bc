"""mink (MuJoCo differential IK) as a peer of the resolver benchmark: the arm's URDF in MuJoCo.

:func:`mujoco_model` loads the URDF that rrc-pin's arm came from (example-robot-data's for
installed arms, ``urdf/<name>.urdf`` for catalogue arms) into MuJoCo: visuals and
collisions stripped (MuJoCo cannot find example-robot-data's meshes, and kinematics need
none), the joints rrc-pin locks (panda's fingers) made fixed (they are locked at zero, where
a fixed joint's transform is the joint's origin), static bodies kept (``fusestatic="false"``)
so that the tool frame is a body of its own, and bodies without inertia given a small one
(MuJoCo refuses massless moving bodies; masses play no role in kinematics).
:func:`kinematics_gap` compares the tool pose and the world-aligned Jacobian with
Pinocchio's at seeded random configurations; the benchmark refuses mink's rows when they
differ by more than :data:`KINEMATICS_TOL`.

:func:`mink_contenders` gives mink the commands the other peers get: at ``q``, the tool's
target is its pose moved by ``twist * dt`` (translation in the base frame, rotation
``exp(w dt)`` applied in the base frame: the same target as pink's), one ``FrameTask``
(position and orientation cost 1), ``ConfigurationLimit`` and ``VelocityLimit`` (the arm's
velocity limits), ``mink.solve_ik`` with every qpsolvers backend installed.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
from timing import Contender

from rrc_pin.control.drift import advance

CHECKOUT = Path(__file__).resolve().parents[1]
KINEMATICS_TOL = 1e-9
"""Largest accepted difference of the tool pose [m, rad] and Jacobian entries between
MuJoCo and Pinocchio."""

Array = np.ndarray


def available() -> bool:
    """Whether mink and mujoco can be imported."""
    try:
        import mink  # noqa: F401
        import mujoco  # noqa: F401
    except ImportError:
        return False
    return True


def urdf_of(arm: Any) -> Path:
    """The URDF file the arm was built from (catalogue arms: the committed one)."""
    source = Path(str(arm.source))
    if source.suffix.lower() == ".urdf" and source.is_file():
        return source
    committed = CHECKOUT / "urdf" / f"{arm.name}.urdf"
    if committed.is_file():
        return committed
    raise FileNotFoundError(f"no URDF for {arm.name} (source {arm.source})")


def kinematic_urdf(path: Path, moving: list[str]) -> str:
    """The URDF text without visuals and collisions, joints not in ``moving`` fixed, and a
    ``<mujoco>`` compiler block that keeps every link a body."""
    root = ET.parse(path).getroot()
    for link in root.iter("link"):
        for tag in ("visual", "collision"):
            for element in link.findall(tag):
                link.remove(element)
    for joint in root.iter("joint"):
        if joint.get("type") != "fixed" and joint.get("name") not in moving:
            joint.set("type", "fixed")
            for tag in ("limit", "mimic", "dynamics", "axis"):
                for element in joint.findall(tag):
                    joint.remove(element)
    for old in root.findall("mujoco"):
        root.remove(old)
    extension = ET.SubElement(root, "mujoco")
    ET.SubElement(
        extension,
        "compiler",
        {
            "fusestatic": "false",
            "discardvisual": "true",
            "balanceinertia": "true",
            "boundmass": "1e-3",
            "boundinertia": "1e-6",
            "autolimits": "true",
        },
    )
    return ET.tostring(root, encoding="unicode")


def mujoco_model(arm: Any) -> tuple[Any, str, np.ndarray]:
    """MuJoCo model of ``arm`` from its URDF; the tool body's name and the qpos indices of
    rrc-pin's joints (rrc-pin's order)."""
    import mujoco

    model = mujoco.MjModel.from_xml_string(kinematic_urdf(urdf_of(arm), list(arm.joint_names)))
    index = np.array([model.jnt_qposadr[model.joint(name).id] for name in arm.joint_names])
    if model.nq != arm.nq:
        raise ValueError(f"{arm.name}: MuJoCo has {model.nq} coordinates, rrc-pin {arm.nq}")
    model.body(arm.tool_frame)  # raises KeyError when the tool frame is not a body
    return model, arm.tool_frame, index


def kinematics_gap(arm: Any, samples: int = 50, seed: int = 7) -> dict[str, float]:
    """Largest differences between MuJoCo and Pinocchio at ``samples`` random configurations:
    tool position [m], tool rotation (angle of R_mj^T R_pin) [rad], world-aligned Jacobian
    entries (rows [v; w]) [m/rad, 1]."""
    import mujoco

    model, body, index = mujoco_model(arm)
    data = mujoco.MjData(model)
    bid = model.body(body).id
    rng = np.random.default_rng(seed)
    gaps = {"position": 0.0, "rotation": 0.0, "jacobian": 0.0}
    jacp, jacr = np.zeros((3, model.nv)), np.zeros((3, model.nv))
    for _ in range(samples):
        q = arm.random_q(rng)
        data.qpos[index] = q
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        mujoco.mj_jacBody(model, data, jacp, jacr, bid)
        T = arm.fk(q)
        R = data.xmat[bid].reshape(3, 3)
        J = arm.jacobian(q)
        gaps["position"] = max(gaps["position"], float(np.abs(data.xpos[bid] - T[:3, 3]).max()))
        angle = float(np.linalg.norm(pin.log3(R.T @ T[:3, :3])))
        gaps["rotation"] = max(gaps["rotation"], angle)
        J_mj = np.vstack([jacp[:, index], jacr[:, index]])
        gaps["jacobian"] = max(gaps["jacobian"], float(np.abs(J_mj - J).max()))
    return gaps


def mink_backends() -> list[str]:
    """The qpsolvers backends mink is run with (every one installed), or [] without mink."""
    if not available():
        return []
    import qpsolvers

    return list(qpsolvers.available_solvers)


def mink_contenders(arm: Any, dt: float) -> list[Contender]:
    """mink.solve_ik with every qpsolvers backend on the arm's tool frame (module docstring)."""
    if not mink_backends():
        return []
    import mink

    model, body, index = mujoco_model(arm)
    velocities = {
        name: float(v) for name, v in zip(arm.joint_names, arm.velocity_limit, strict=True)
    }
    out = []
    for solver in mink_backends():
        configuration = mink.Configuration(model)
        task = mink.FrameTask(body, "body", position_cost=1.0, orientation_cost=1.0)
        limits = [mink.ConfigurationLimit(model), mink.VelocityLimit(model, velocities)]
        qpos = configuration.q.copy()

        def step(
            q: Array,
            x: Array,
            configuration: Any = configuration,
            task: Any = task,
            limits: Any = limits,
            solver: str = solver,
            qpos: Array = qpos,
        ) -> Array:
            qpos[index] = q
            configuration.update(qpos)
            T = pin.SE3(configuration.get_transform_frame_to_world(body, "body").as_matrix())
            task.set_target(mink.SE3.from_matrix(advance(T, x, dt, local=False).homogeneous))
            v = mink.solve_ik(configuration, [task], dt, solver, limits=limits)
            return v[index]

        out.append(Contender(f"mink {solver}", step))
    return out
