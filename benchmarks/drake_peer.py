"""Drake's ``DoDifferentialInverseKinematics``, a peer of the resolver and tasks benchmarks.

The arm's URDF (the one rrc-pin loaded) is parsed into a ``MultibodyPlant`` (visuals and
collisions stripped, the joints rrc-pin locks made fixed, the root link welded to the world);
:func:`kinematics_gap` compares its task-frame poses and Jacobians with Pinocchio's first.

Drake's differential IK is a direction-preserving QP, as rrc-pin's default (Drake's
documentation of ``DoDifferentialInverseKinematics``)::

    min_{v, a}  -100 a + |P (v - K (q_nominal - q))|^2
    s.t.        J v = a V,  0 <= a <= 1,  position limits over dt,  velocity limits,

with P a basis of J's null space: the command's direction is kept and its speed scaled,
the rest of the rates least-norm (K = 0) or toward a nominal posture (K > 0). One frame
(:func:`one_frame`): the plant overload, Drake computing J at ``q`` itself, the twist given
as Drake's spatial velocity [w; v] of the frame's origin in world axes (rrc-pin's
``world_aligned``).
Two frames and a posture (:func:`two_frames`): Drake's Jacobians of both frames stacked
(12 rows), the J-and-V overload, the posture as Drake's joint centering (K = gain, the
nominal the posture's reference): a strict priority of the hands over the posture, the
hands with one common scale, as rrc-pin's ``priority="strict"``. Drake has no weighted mode.
A step fails (raises) where Drake finds no solution (``kNoSolutionFound``); ``kStuck`` (a scale
below 0.01) still answers, and its rates are used, as Drake's own controllers do.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import numpy as np

Array = np.ndarray
KINEMATICS_TOL = 1e-9
"""Largest accepted difference of a task frame's pose [m, rad] and Jacobian entries between
Drake and Pinocchio."""


def kinematic_urdf(path: Path, moving: list[str]) -> tuple[str, str]:
    """The URDF text without visuals and collisions, joints not in ``moving`` fixed; and the
    root link's name (to weld to the world)."""
    root = ET.parse(path).getroot()
    for link in root.iter("link"):
        for tag in ("visual", "collision"):
            for element in link.findall(tag):
                link.remove(element)
    for joint in root.iter("joint"):
        if joint.get("type") != "fixed" and joint.get("name") not in moving:
            joint.set("type", "fixed")
            for tag in ("limit", "mimic", "dynamics", "axis", "safety_controller"):
                for element in joint.findall(tag):
                    joint.remove(element)
    for tag in ("transmission", "gazebo", "mujoco"):
        for element in root.findall(tag):
            root.remove(element)
    children = {j.find("child").get("link") for j in root.iter("joint")}  # type: ignore[union-attr]
    names = [link.get("name") for link in root.findall("link")]
    base = next(name for name in names if name not in children)
    return ET.tostring(root, encoding="unicode"), str(base)


class DrakeArm:
    """A ``MultibodyPlant`` of ``arm`` and the maps between rrc-pin's joints and Drake's.

    Attributes:
        plant: The finalised plant.
        context: Its context (positions set by :meth:`set`).
        q_index: Drake's position index of each of rrc-pin's joints (rrc-pin's order).
        v_index: Drake's velocity index of each of rrc-pin's joints.
    """

    def __init__(self, arm: Any, urdf: Path) -> None:
        from pydrake.multibody.parsing import Parser
        from pydrake.multibody.plant import MultibodyPlant

        text, base = kinematic_urdf(urdf, list(arm.joint_names))
        plant = MultibodyPlant(0.0)
        parser = Parser(plant)
        (model,) = parser.AddModelsFromString(text, "urdf")
        plant.WeldFrames(plant.world_frame(), plant.GetFrameByName(base, model))
        plant.Finalize()
        if plant.num_positions() != arm.nq:
            raise ValueError(f"{arm.name}: Drake has {plant.num_positions()} positions, "
                             f"rrc-pin {arm.nq}")  # fmt: skip
        self.plant, self.context = plant, plant.CreateDefaultContext()
        joints = [plant.GetJointByName(name) for name in arm.joint_names]
        self.q_index = np.array([j.position_start() for j in joints])
        self.v_index = np.array([j.velocity_start() for j in joints])
        self.n = arm.nq

    def set(self, q: Array) -> None:
        """Set rrc-pin's configuration ``q`` in the context."""
        x = np.empty(self.n)
        x[self.q_index] = q
        self.plant.SetPositions(self.context, x)

    def frame(self, name: str) -> Any:
        """Drake's frame of that name (a link's body frame)."""
        return self.plant.GetFrameByName(name)

    def jacobian(self, frame: Any) -> Array:
        """The frame's Jacobian (6, n) [v; w] in world axes at its origin, rrc-pin's joint
        order (Drake's is [w; v])."""
        from pydrake.multibody.tree import JacobianWrtVariable

        plant = self.plant
        J = plant.CalcJacobianSpatialVelocity(
            self.context, JacobianWrtVariable.kV, frame, np.zeros(3), plant.world_frame(),
            plant.world_frame(),
        )  # fmt: skip
        return np.vstack([J[3:], J[:3]])[:, self.v_index]

    def parameters(self, arm: Any, dt: float) -> Any:
        """Drake's parameters with the arm's position and velocity limits, in Drake's order."""
        from pydrake.multibody.inverse_kinematics import DifferentialInverseKinematicsParameters

        params = DifferentialInverseKinematicsParameters(self.n, self.n)
        params.set_time_step(dt)
        lower, upper = np.empty(self.n), np.empty(self.n)
        lower[self.q_index], upper[self.q_index] = arm.lower, arm.upper
        params.set_joint_position_limits((lower, upper))
        v = np.empty(self.n)
        v[self.v_index] = arm.velocity_limit
        params.set_joint_velocity_limits((-v, v))
        return params


def kinematics_gap(arm: Any, drake: DrakeArm, samples: int = 30, seed: int = 7) -> dict[str, float]:
    """Largest differences between Drake and Pinocchio at ``samples`` random configurations,
    over the arm's tool frames: position [m], rotation entries [1], Jacobian entries."""
    rng = np.random.default_rng(seed)
    gaps = {"position": 0.0, "rotation": 0.0, "jacobian": 0.0}
    frames = {name: drake.frame(name) for name in arm.tool_frames}
    for _ in range(samples):
        q = arm.random_q(rng)
        drake.set(q)
        for name, frame in frames.items():
            X = drake.plant.CalcRelativeTransform(
                drake.context, drake.plant.world_frame(), frame
            ).GetAsMatrix4()
            T = arm.fk(q, name)
            gaps["position"] = max(gaps["position"], float(np.abs(X[:3, 3] - T[:3, 3]).max()))
            gaps["rotation"] = max(gaps["rotation"], float(np.abs(X[:3, :3] - T[:3, :3]).max()))
            J = arm.jacobian(q, frame=name)
            gaps["jacobian"] = max(gaps["jacobian"], float(np.abs(drake.jacobian(frame) - J).max()))
    return gaps


def one_frame(arm: Any, drake: DrakeArm, dt: float) -> Any:
    """``step(q, twist) -> rates`` (raises when Drake finds no solution): the plant overload
    on the arm's tool frame, K = 0."""
    from pydrake.multibody.inverse_kinematics import (
        DifferentialInverseKinematicsStatus,
        DoDifferentialInverseKinematics,
    )

    params = drake.parameters(arm, dt)
    frame = drake.frame(arm.tool_frame)
    plant, context, v_index = drake.plant, drake.context, drake.v_index
    failed = DifferentialInverseKinematicsStatus.kNoSolutionFound

    def step(q: Array, x: Array) -> Array:
        drake.set(q)
        result = DoDifferentialInverseKinematics(
            plant, context, np.concatenate([x[3:], x[:3]]), frame, params
        )
        if result.status == failed:
            raise RuntimeError(f"Drake: {result.status}")
        return result.joint_velocities[v_index]

    return step


def two_frames(arm: Any, drake: DrakeArm, dt: float, gain: float, nominal: Array) -> Any:
    """``step(q, twists (12,)) -> rates``: both tool frames' Jacobians stacked, the J-and-V
    overload, the posture as joint centering toward ``nominal`` with gain ``gain`` [1/s]."""
    from pydrake.multibody.inverse_kinematics import (
        DifferentialInverseKinematicsStatus,
        DoDifferentialInverseKinematics,
    )

    params = drake.parameters(arm, dt)
    n = drake.n
    q_nominal = np.empty(n)
    q_nominal[drake.q_index] = nominal
    params.set_nominal_joint_position(q_nominal)
    params.set_joint_centering_gain(gain * np.eye(n))
    frames = [drake.frame(f) for f in arm.tool_frames]
    zero = np.zeros(n)
    failed = DifferentialInverseKinematicsStatus.kNoSolutionFound
    q_index, v_index = drake.q_index, drake.v_index

    def step(q: Array, x: Array) -> Array:
        drake.set(q)
        J = np.vstack([_drake_order(drake.jacobian(f), v_index) for f in frames])
        q_drake = np.empty(n)
        q_drake[q_index] = q
        result = DoDifferentialInverseKinematics(q_drake, zero, x, J, params)
        if result.status == failed:
            raise RuntimeError(f"Drake: {result.status}")
        return result.joint_velocities[v_index]

    return step


def _drake_order(J: Array, v_index: Array) -> Array:
    """Columns of a Jacobian in rrc-pin's joint order put back in Drake's velocity order."""
    out = np.empty_like(J)
    out[:, v_index] = J
    return out
