"""PlaCo as a peer of the tasks benchmark: two frame tasks and a joints task on one robot.

PlaCo (Rhoban's whole-body kinematics solver on Pinocchio, ``pip install placo``) pins its
Pinocchio (placo 0.10.2 requires ``pin==3.8.0``), so it cannot share an environment with
rrc-pin's Pinocchio 4. This module therefore imports only numpy, Pinocchio and placo (never
rrc_pin), and runs either in the benchmark's process (when ``import placo`` works there) or
as a worker in PlaCo's own interpreter (``python -m venv .venv-placo && .venv-placo/bin/pip
install placo``), started by :class:`Worker`, which answers over a pipe.

What a step is, as a PlaCo user writes it (:meth:`PlacoPeer.step`, timed whole, in the
worker by its own clock): set the joint positions, ``update_kinematics()``, move each frame
task's target to the frame's current pose moved by the commanded twist times dt (position
``p + v dt``, orientation ``exp3(w dt) R``, world axes), set the joints task's targets to
``q + k dt (q_ref - q)`` (PlaCo's joints task has no gain; these are the targets pink's
posture gain ``k dt`` asks for), ``solve(False)``, and divide the Δq by dt.

PlaCo's frame task is a position task (error ``target - p``, rows of the LOCAL_WORLD_ALIGNED
Jacobian) and an orientation task (error ``log3(R_target R^T)``, rows of the WORLD angular
Jacobian); with the targets above its errors are exactly ``v dt`` and ``w dt``, so its problem
is rrc-pin's velocity problem times dt: ``min sum_i w_i |A_i Δq - b_i|^2 + 1e-8 |Δq|^2``
(weights not squared; PlaCo's default regularisation), joint limits ``q + Δq`` within the
range, velocity limits ``|Δq| <= v_max dt``, the floating base masked.

Protocol (:func:`serve`): a frame is an opcode byte, a little-endian uint32 length and a
payload; numbers travel as float64 arrays, the configuration as JSON.
"""

from __future__ import annotations

import json
import os
import struct
import sys
import time
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any, BinaryIO

import numpy as np
import numpy.typing as npt

Array = npt.NDArray[np.float64]
HEADER = struct.Struct("<cI")


class PlacoPeer:
    """A PlaCo kinematics solver set up like the benchmark's other contenders.

    Args:
        urdf: Path of the robot's URDF, every joint that does not move made fixed and the
            meshes removed (PlaCo's loader wants them otherwise).
        joints: Names of the moving joints, in the order of the benchmark's q.
        frames: Names of the frames of the two frame tasks.
        dt: Control period [s].
        frame_weight: PlaCo weight of each frame task (position and orientation alike).
        posture_weight: PlaCo weight of the joints task.
        posture_gain: k [1/s] of the posture (module docstring).
        q_ref: Posture reference (n,) [rad].
    """

    def __init__(
        self,
        urdf: str,
        joints: list[str],
        frames: list[str],
        dt: float,
        frame_weight: float,
        posture_weight: float,
        posture_gain: float,
        q_ref: list[float],
    ) -> None:
        import pinocchio as pin
        import placo

        self._exp3 = pin.exp3
        self.robot = placo.RobotWrapper(urdf, placo.Flags.ignore_collisions)
        self.joints = list(joints)
        self.frames = list(frames)
        self.dt = dt
        self.gain_dt = posture_gain * dt
        self.q_ref = np.asarray(q_ref, dtype=np.float64)
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
            task.configure(frame, "soft", frame_weight, frame_weight)
            self.tasks.append(task)
        self.posture = solver.add_joints_task()
        self.posture.set_joints(dict(zip(self.joints, self.q_ref.tolist(), strict=True)))
        self.posture.configure("posture", "soft", posture_weight)
        self.solver = solver

    def info(self) -> dict[str, Any]:
        """Versions, joint limits and velocity limits as PlaCo's model has them."""
        import pinocchio as pin
        import placo

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
            "module": placo.__name__,
        }

    def step(self, q: Array, twists: Array) -> Array:
        """Joint rates (n,) [rad/s] for the frames' twists (2 * 6,) [m/s, rad/s] at ``q``."""
        robot, dt = self.robot, self.dt
        robot.state.q[self.q_index] = q
        robot.update_kinematics()
        for i, (frame, task) in enumerate(zip(self.frames, self.tasks, strict=True)):
            T = robot.get_T_world_frame(frame)
            x = twists[6 * i : 6 * i + 6]
            T[:3, :3] = self._exp3(x[3:] * dt) @ T[:3, :3]
            T[:3, 3] += x[:3] * dt
            task.T_world_frame = T
        targets = q + self.gain_dt * (self.q_ref - q)
        self.posture.set_joints(dict(zip(self.joints, targets.tolist(), strict=True)))
        dq = self.solver.solve(False)
        return dq[self.v_index] / dt

    def timed_step(self, q: Array, twists: Array) -> tuple[Array | None, float]:
        """(:meth:`step`'s rates, or None when PlaCo raised; the call's time [s])."""
        t0 = time.perf_counter()
        try:
            rates: Array | None = self.step(q, twists)
        except Exception:  # PlaCo raises QPError (and RuntimeError) when its QP fails
            rates = None
        return rates, time.perf_counter() - t0

    def loop(self, Q: Array, X: Array) -> tuple[Array, Array, Array]:
        """The tight loop: rates (steps, n), seconds (steps,), failed (steps,) as 0/1."""
        steps = Q.shape[0]
        rates = np.zeros((steps, len(self.joints)))
        seconds = np.empty(steps)
        failed = np.zeros(steps)
        for k in range(steps):
            r, seconds[k] = self.timed_step(Q[k], X[k])
            if r is None:
                failed[k] = 1.0
            else:
                rates[k] = r
        return rates, seconds, failed

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


# ---- set-up on the benchmark's side (no placo needed) -------------------------------------------

PLACO_VENV = Path(__file__).resolve().parents[1] / ".venv-placo" / "bin" / "python"
"""The checkout's PlaCo environment, where ``placo_python`` looks last."""


def placo_python(given: str | None) -> tuple[str | None, str]:
    """Where PlaCo runs: ``"in-process"``, an interpreter path, or None; and why.

    Order: ``import placo`` here; ``given`` (``--placo-python``); the environment variable
    ``RRC_PIN_PLACO_PYTHON``; the checkout's ``.venv-placo``.
    """
    try:
        import placo  # noqa: F401
    except ImportError:
        pass
    else:
        return "in-process", "placo imports in this interpreter"
    for path, origin in (
        (given, "--placo-python"),
        (os.environ.get("RRC_PIN_PLACO_PYTHON"), "RRC_PIN_PLACO_PYTHON"),
        (str(PLACO_VENV) if PLACO_VENV.exists() else None, ".venv-placo"),
    ):
        if path:
            return path, f"worker process, interpreter from {origin}"
    return None, (
        "PlaCo not found: its rows are absent. placo pins pin==3.8.0, so give it its own "
        "environment: python -m venv .venv-placo && .venv-placo/bin/pip install placo"
    )


def placo_urdf(robot: Any, folder: Path) -> Path:
    """The robot's URDF for PlaCo: every joint rrc-pin locks made fixed (at zero, as rrc-pin
    locks them), the meshes removed (kinematics only; PlaCo's loader wants them otherwise)."""
    tree = ET.parse(robot.source)
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
        for frame, T in zip(robot.tool_frames, theirs, strict=True):
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


# ---- the worker and its client ----------------------------------------------------------------


def _send(stream: BinaryIO, op: bytes, payload: bytes) -> None:
    stream.write(HEADER.pack(op, len(payload)) + payload)
    stream.flush()


def _receive(stream: BinaryIO) -> tuple[bytes, bytes]:
    head = stream.read(HEADER.size)
    if len(head) < HEADER.size:
        raise EOFError("the other end closed the pipe")
    op, size = HEADER.unpack(head)
    return op, stream.read(size)


def serve(inp: BinaryIO, out: BinaryIO) -> None:
    """Answer the client's frames until it closes the pipe (module docstring).

    ``C`` configure (JSON keyword arguments of :class:`PlacoPeer`) -> ``I`` info (JSON);
    ``S`` step (q, twists) -> rates, seconds, failed; ``L`` loop (steps, n, then Q, X) ->
    rates, seconds, failed; ``P`` poses (q) -> poses. Errors answer ``E`` with the message.
    """
    peer: PlacoPeer | None = None
    n = 0
    while True:
        try:
            op, payload = _receive(inp)
        except EOFError:
            return
        try:
            if op == b"C":
                config = json.loads(payload)
                peer = PlacoPeer(**config)
                n = len(config["joints"])
                _send(out, b"I", json.dumps(peer.info()).encode())
                continue
            if peer is None:
                raise RuntimeError("not configured")
            data = np.frombuffer(payload, dtype="<f8")
            if op == b"S":
                rates, seconds = peer.timed_step(data[:n], data[n:])
                failed = rates is None
                body = np.concatenate([np.zeros(n) if failed else rates, [seconds, failed]])
                _send(out, b"R", body.astype("<f8").tobytes())
            elif op == b"L":
                steps, m = int(data[0]), int(data[1])
                Q = data[2 : 2 + steps * n].reshape(steps, n)
                X = data[2 + steps * n :].reshape(steps, m)
                all_rates, all_seconds, all_failed = peer.loop(Q, X)
                body = np.concatenate([all_rates.ravel(), all_seconds, all_failed])
                _send(out, b"R", body.astype("<f8").tobytes())
            elif op == b"P":
                _send(out, b"R", peer.poses(data).astype("<f8").tobytes())
            else:
                raise RuntimeError(f"unknown opcode {op!r}")
        except Exception as exc:  # reported to the client, which raises it
            _send(out, b"E", f"{type(exc).__name__}: {exc}".encode())


class Worker:
    """A :class:`PlacoPeer` in another interpreter, with the same methods.

    Args:
        python: The interpreter that has placo (e.g. ``.venv-placo/bin/python``).
        config: Keyword arguments of :class:`PlacoPeer`.

    Raises:
        RuntimeError: The worker did not start or refused the configuration.
    """

    def __init__(self, python: str, config: dict[str, Any]) -> None:
        import subprocess

        self.process = subprocess.Popen(
            [python, __file__, "--serve"], stdin=subprocess.PIPE, stdout=subprocess.PIPE
        )
        self.n = len(config["joints"])
        self.frames = len(config["frames"])
        self._info = json.loads(self._ask(b"C", json.dumps(config).encode()))

    def info(self) -> dict[str, Any]:
        """What :meth:`PlacoPeer.info` said, plus the worker's interpreter."""
        return {**self._info, "process": "worker", "pid": self.process.pid}

    def timed_step(self, q: Array, twists: Array) -> tuple[Array | None, float]:
        """:meth:`PlacoPeer.timed_step` in the worker (its time taken by the worker's clock)."""
        body = self._numbers(b"S", np.concatenate([q, twists]))
        return (None if body[-1] else body[: self.n].copy()), float(body[-2])

    def loop(self, Q: Array, X: Array) -> tuple[Array, Array, Array]:
        """:meth:`PlacoPeer.loop` in the worker."""
        steps = Q.shape[0]
        body = self._numbers(b"L", np.concatenate([[steps, X.shape[1]], Q.ravel(), X.ravel()]))
        rates = body[: steps * self.n].reshape(steps, self.n).copy()
        return rates, body[steps * self.n : -steps].copy(), body[-steps:].copy()

    def poses(self, q: Array) -> Array:
        """:meth:`PlacoPeer.poses` in the worker."""
        return self._numbers(b"P", q).reshape(self.frames, 4, 4).copy()

    def close(self) -> None:
        """End the worker (it exits when its input closes)."""
        if self.process.stdin is not None:
            self.process.stdin.close()
        self.process.wait(timeout=30)

    def _numbers(self, op: bytes, values: Array) -> Array:
        return np.frombuffer(self._ask(op, np.asarray(values, "<f8").tobytes()), dtype="<f8")

    def _ask(self, op: bytes, payload: bytes) -> bytes:
        assert self.process.stdin is not None and self.process.stdout is not None
        _send(self.process.stdin, op, payload)  # type: ignore[arg-type]
        answer, body = _receive(self.process.stdout)  # type: ignore[arg-type]
        if answer == b"E":
            raise RuntimeError(f"PlaCo worker: {body.decode()}")
        return body


def _serve_on_stdio() -> None:
    """The worker's main: frames on stdin and on the original stdout; anything PlaCo's C++
    code prints to file descriptor 1 goes to stderr instead."""
    protocol = os.fdopen(os.dup(1), "wb")
    os.dup2(2, 1)
    serve(sys.stdin.buffer, protocol)


if __name__ == "__main__":
    if sys.argv[1:] == ["--serve"]:
        _serve_on_stdio()
    else:
        print(__doc__)
