"""PlaCo as a peer of the resolver and tasks benchmarks, in the benchmark's own process.

PlaCo (Rhoban's whole-body kinematics solver on Pinocchio, ``pip install placo``) pins its
Pinocchio (placo 0.10.2 requires ``pin==3.8.0``): the comparison runs in an environment
where PlaCo, rrc-pin and the other peers all import (docs/benchmarks.md, "The peers'
environment"), so that every contender meets the same process, caches and load.

What a step is, as a PlaCo user writes it (:meth:`PlacoPeer.step`, timed whole): set the
joint positions, ``update_kinematics()``, move each frame task's target to the frame's
current pose moved by the commanded twist times dt (position ``p + v dt``, orientation
``exp3(w dt) R``, world axes), set the joints task's targets (if any) to
``q + k dt (q_ref - q)`` (PlaCo's joints task has no gain; these are the targets pink's
posture gain ``k dt`` asks for), ``solve(False)``, and divide the Δq by dt.

PlaCo's frame task is a position task (error ``target - p``, rows of the LOCAL_WORLD_ALIGNED
Jacobian) and an orientation task (error ``log3(R_target R^T)``, rows of the WORLD angular
Jacobian); with the targets above its errors are exactly ``v dt`` and ``w dt``, so its problem
is rrc-pin's velocity problem times dt: ``min sum_i w_i |A_i Δq - b_i|^2 + 1e-8 |Δq|^2``
(weights not squared; PlaCo's default regularisation), joint limits ``q + Δq`` within the
range, velocity limits ``|Δq| <= v_max dt``, the floating base masked. ``strict``: the frame
tasks ``hard`` (equality constraints of PlaCo's QP: met exactly, or the QP fails and PlaCo
raises; PlaCo has no scale along them), the joints task soft below them.
"""

from __future__ import annotations

import sys
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

Array = npt.NDArray[np.float64]


class PlacoPeer:
    """A PlaCo kinematics solver set up like the benchmark's other contenders.

    Args:
        urdf: Path of the robot's URDF, every joint that does not move made fixed and the
            meshes removed (:func:`placo_urdf`).
        joints: Names of the moving joints, in the order of the benchmark's q.
        frames: Names of the frames of the frame tasks (one or two).
        dt: Control period [s].
        frame_weight: PlaCo weight of each frame task (position and orientation alike).
        posture_weight: PlaCo weight of the joints task, or None for no joints task.
        posture_gain: k [1/s] of the posture (module docstring).
        q_ref: Posture reference (n,) [rad] (with a joints task).
        strict: The frame tasks hard, the joints task soft (module docstring).
    """

    def __init__(
        self,
        urdf: str,
        joints: list[str],
        frames: list[str],
        dt: float,
        frame_weight: float = 1.0,
        posture_weight: float | None = None,
        posture_gain: float = 0.0,
        q_ref: Array | None = None,
        strict: bool = False,
    ) -> None:
        import pinocchio as pin
        import placo

        self._exp3 = pin.exp3
        self.robot = placo.RobotWrapper(urdf, placo.Flags.ignore_collisions)
        self.joints = list(joints)
        self.frames = list(frames)
        self.dt = dt
        self.gain_dt = posture_gain * dt
        self.q_index = np.array([self.robot.get_joint_offset(j) for j in self.joints])
        self.v_index = np.array([self.robot.get_joint_v_offset(j) for j in self.joints])
        solver = placo.KinematicsSolver(self.robot)
        solver.mask_fbase(True)
        solver.dt = dt
        solver.enable_joint_limits(True)
        solver.enable_velocity_limits(True)
        self.robot.update_kinematics()
        self.tasks = []
        for frame in self.frames:
            task = solver.add_frame_task(frame, self.robot.get_T_world_frame(frame))
            task.configure(frame, "hard" if strict else "soft", frame_weight, frame_weight)
            self.tasks.append(task)
        self.posture = None
        self.q_ref = np.zeros(len(self.joints)) if q_ref is None else np.asarray(q_ref, float)
        if posture_weight is not None:
            self.posture = solver.add_joints_task()
            self.posture.set_joints(dict(zip(self.joints, self.q_ref.tolist(), strict=True)))
            self.posture.configure("posture", "soft", posture_weight)
        self.solver = solver

    def info(self) -> dict[str, Any]:
        """Versions, joint limits and velocity limits as PlaCo's model has them."""
        import pinocchio as pin

        model = self.robot.model
        return {
            "placo": _version("placo"),
            "pinocchio": pin.__version__,
            "numpy": np.__version__,
            "python": sys.version.split()[0],
            "lower": model.lowerPositionLimit[self.q_index].tolist(),
            "upper": model.upperPositionLimit[self.q_index].tolist(),
            "velocity": model.velocityLimit[self.v_index].tolist(),
            "regularization": float(self.solver.problem.regularization),
        }

    def step(self, q: Array, twists: Array) -> Array:
        """Joint rates (n,) [rad/s] for the frames' twists (6 per frame) [m/s, rad/s] at ``q``.

        Raises:
            RuntimeError: PlaCo's QP failed (PlaCo raises).
        """
        robot, dt = self.robot, self.dt
        robot.state.q[self.q_index] = q
        robot.update_kinematics()
        for i, (frame, task) in enumerate(zip(self.frames, self.tasks, strict=True)):
            T = robot.get_T_world_frame(frame)
            x = twists[6 * i : 6 * i + 6]
            T[:3, :3] = self._exp3(x[3:] * dt) @ T[:3, :3]
            T[:3, 3] += x[:3] * dt
            task.T_world_frame = T
        if self.posture is not None:
            targets = q + self.gain_dt * (self.q_ref - q)
            self.posture.set_joints(dict(zip(self.joints, targets.tolist(), strict=True)))
        dq = self.solver.solve(False)
        return dq[self.v_index] / dt

    def poses(self, q: Array) -> Array:
        """Poses (frames, 4, 4) of the task frames at ``q`` [m]."""
        self.robot.state.q[self.q_index] = q
        self.robot.update_kinematics()
        return np.array([self.robot.get_T_world_frame(f) for f in self.frames])


def _version(name: str) -> str | None:
    from importlib import metadata

    try:
        return metadata.version(name)
    except metadata.PackageNotFoundError:
        return None


# ---- set-up ------------------------------------------------------------------------------------


def placo_urdf(robot: Any, source: Path, folder: Path) -> Path:
    """The robot's URDF (``source``) for PlaCo, written in ``folder``: every joint rrc-pin
    locks made fixed (at zero, as rrc-pin locks them), the meshes removed (kinematics only;
    PlaCo's loader wants them otherwise)."""
    tree = ET.parse(source)
    root = tree.getroot()
    for link in root.findall("link"):
        for tag in ("visual", "collision"):
            for element in link.findall(tag):
                link.remove(element)
    moving = set(robot.joint_names)
    for joint in root.findall("joint"):
        if joint.get("type") != "fixed" and joint.get("name") not in moving:
            joint.set("type", "fixed")
            for tag in ("limit", "mimic", "dynamics", "safety_controller", "axis"):
                for element in joint.findall(tag):
                    joint.remove(element)
    path = folder / f"{robot.name}_placo.urdf"
    tree.write(path)
    return path


def placo_checks(robot: Any, peer: Any, rng: np.random.Generator) -> dict[str, float]:
    """PlaCo's model against rrc-pin's: task-frame poses at 20 random configurations [m],
    joint and velocity limits [rad, rad/s] (largest differences)."""
    info = peer.info()
    worst = 0.0
    for _ in range(20):
        q = robot.random_q(rng)
        theirs = peer.poses(q)
        for frame, T in zip(peer.frames, theirs, strict=True):
            worst = max(worst, float(np.abs(robot.fk(q, frame) - T).max()))
    return {
        "max_pose_difference": worst,
        "max_position_limit_difference": float(
            max(
                np.abs(np.array(info["lower"]) - robot.lower).max(),
                np.abs(np.array(info["upper"]) - robot.upper).max(),
            )
        ),
        "max_velocity_limit_difference": float(
            np.abs(np.array(info["velocity"]) - robot.velocity_limit).max()
        ),
    }
