"""mink (MuJoCo differential IK) as a peer of the benchmarks: the arm's URDF in MuJoCo.

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

:func:`mink_step` gives mink the commands the other peers get: at ``q``, each tool frame's
target is its pose moved by its twist times dt (translation in the base frame, rotation
``exp(w dt)`` applied in the base frame: the same target as pink's), a ``FrameTask`` per
frame (position and orientation cost 1), a ``PostureTask`` where the workload has one,
``ConfigurationLimit`` and ``VelocityLimit`` (the arm's velocity limits), ``mink.solve_ik``
with the qpsolvers backend given.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

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


def mujoco_model(arm: Any) -> tuple[Any, str | None, np.ndarray]:
    """MuJoCo model of ``arm`` from its URDF; the tool body's name (None with several tool
    frames) and the qpos indices of rrc-pin's joints (rrc-pin's order)."""
    import mujoco

    model = mujoco.MjModel.from_xml_string(kinematic_urdf(urdf_of(arm), list(arm.joint_names)))
    index = np.array([model.jnt_qposadr[model.joint(name).id] for name in arm.joint_names])
    if model.nq != arm.nq:
        raise ValueError(f"{arm.name}: MuJoCo has {model.nq} coordinates, rrc-pin {arm.nq}")
    for frame in arm.tool_frames:
        model.body(frame)  # raises KeyError when a tool frame is not a body
    return model, arm.tool_frame, index


def kinematics_gap(arm: Any, samples: int = 50, seed: int = 7) -> dict[str, float]:
    """Largest differences between MuJoCo and Pinocchio at ``samples`` random configurations,
    over the tool frames: position [m], rotation (angle of R_mj^T R_pin) [rad], world-aligned
    Jacobian entries (rows [v; w]) [m/rad, 1]."""
    import mujoco

    model, _, index = mujoco_model(arm)
    data = mujoco.MjData(model)
    rng = np.random.default_rng(seed)
    gaps = {"position": 0.0, "rotation": 0.0, "jacobian": 0.0}
    jacp, jacr = np.zeros((3, model.nv)), np.zeros((3, model.nv))
    for _ in range(samples):
        q = arm.random_q(rng)
        data.qpos[index] = q
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        for frame in arm.tool_frames:
            bid = model.body(frame).id
            mujoco.mj_jacBody(model, data, jacp, jacr, bid)
            T = arm.fk(q, frame)
            R = data.xmat[bid].reshape(3, 3)
            J = arm.jacobian(q, frame=frame)
            gap = float(np.abs(data.xpos[bid] - T[:3, 3]).max())
            gaps["position"] = max(gaps["position"], gap)
            angle = float(np.linalg.norm(pin.log3(R.T @ T[:3, :3])))
            gaps["rotation"] = max(gaps["rotation"], angle)
            J_mj = np.vstack([jacp[:, index], jacr[:, index]])
            gaps["jacobian"] = max(gaps["jacobian"], float(np.abs(J_mj - J).max()))
    return gaps


def mink_step(
    arm: Any,
    dt: float,
    solver: str,
    frame_cost: float = 1.0,
    posture: tuple[float, float, np.ndarray] | None = None,
) -> Any:
    """``step(q, x) -> rates``: ``mink.solve_ik`` with a FrameTask per tool frame (its target
    the frame's pose moved by its twist (6 entries of x each) times dt, as pink's),
    ``ConfigurationLimit`` and ``VelocityLimit``, and with ``posture`` = (cost, gain [1/s],
    reference) a PostureTask (gain ``k dt``, as pink's)."""
    import mink

    model, _, index = mujoco_model(arm)
    velocities = {
        name: float(v) for name, v in zip(arm.joint_names, arm.velocity_limit, strict=True)
    }
    configuration = mink.Configuration(model)
    frames = list(arm.tool_frames)
    hands = [
        mink.FrameTask(f, "body", position_cost=frame_cost, orientation_cost=frame_cost)
        for f in frames
    ]
    tasks: list[Any] = list(hands)
    if posture is not None:
        cost, gain, reference = posture
        target = configuration.q.copy()
        target[index] = reference
        task = mink.PostureTask(model, cost=cost, gain=gain * dt)
        task.set_target(target)
        tasks.append(task)
    limits = [mink.ConfigurationLimit(model), mink.VelocityLimit(model, velocities)]
    qpos = configuration.q.copy()

    def step(q: Array, x: Array) -> Array:
        qpos[index] = q
        configuration.update(qpos)
        for i, (frame, task) in enumerate(zip(frames, hands, strict=True)):
            T = pin.SE3(configuration.get_transform_frame_to_world(frame, "body").as_matrix())
            moved = advance(T, x[6 * i : 6 * i + 6], dt, "world_aligned").homogeneous
            task.set_target(mink.SE3.from_matrix(moved))
        v = mink.solve_ik(configuration, tasks, dt, solver, limits=limits)
        return v[index]

    return step
