"""The peers beside rrc-pin in one process: which of them import here, and their steps.

The peers: PlaCo (:mod:`placo_peer`), pink, mink (:mod:`mink_peer`) and Drake's
DifferentialInverseKinematics (:mod:`drake_peer`). PlaCo 0.10 pins ``pin==3.8.0``, so the
full comparison runs in an environment where all of them and rrc-pin import together
(docs/benchmarks.md, "The peers' environment"). :func:`check` refuses a full run where a peer
does not import, naming it; a quick run (``--quick``, the CI's smoke run in the bench extra)
goes on and records each missing peer as "not in this environment", never as run.

pink and mink are run with quadprog, their fastest qpsolvers backend in this project's
earlier recordings (against daqp, proxqp, osqp and clarabel; docs/benchmarks.md).
"""

from __future__ import annotations

import importlib
import logging
import shutil
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

Array = np.ndarray

PEERS = {
    "PlaCo": ("placo",),
    "pink": ("pink",),
    "mink": ("mink", "mujoco"),
    "Drake": ("pydrake.multibody.inverse_kinematics",),
}
"""Peer: the modules it needs."""
INSTALL = {
    "PlaCo": "placo (pins pin==3.8.0)",
    "pink": "pin-pink",
    "mink": "mink and mujoco",
    "Drake": "drake",
}
"""Peer: what to install for it."""
QP_SOLVER = "quadprog"
"""The qpsolvers backend of pink and mink."""
NOT_HERE = "not in this environment"


def availability() -> dict[str, str]:
    """Each peer: ``"ran"`` when its modules import here, else ``"not in this environment:
    <the import error>"``."""
    out = {}
    for peer, modules in PEERS.items():
        try:
            for module in modules:
                importlib.import_module(module)
        except Exception as exc:  # an ImportError, or a binary that does not load
            out[peer] = f"{NOT_HERE}: {type(exc).__name__}: {exc}"
        else:
            out[peer] = "ran"
    logging.getLogger().setLevel(logging.ERROR)  # pink logs near-limit configurations
    logging.getLogger("drake").setLevel(logging.ERROR)  # Drake warns of unused URDF tags
    return out


def check(status: dict[str, str], quick: bool) -> None:
    """Refuse a full run where a peer does not import (SystemExit naming each missing one and
    how to build the peers' environment); a quick run goes on."""
    missing = [p for p, s in status.items() if s != "ran"]
    if missing and not quick:
        names = "; ".join(f"{p} ({INSTALL[p]}): {status[p]}" for p in missing)
        raise SystemExit(
            f"the peers comparison needs every peer in this interpreter; missing: {names}. "
            "Build the peers' environment as docs/benchmarks.md says (\"The peers' "
            "environment\"), or pass --quick for a smoke run without them."
        )


class Models:
    """The URDFs the peers load for one robot (a temporary folder, removed by :meth:`close`)."""

    def __init__(self, robot: Any) -> None:
        from mink_peer import urdf_of

        self.robot = robot
        self.source = urdf_of(robot)
        self.folder = Path(tempfile.mkdtemp(prefix="rrc-pin-peers-"))
        self._placo: Path | None = None
        self._drake: Any = None

    def placo_urdf(self) -> Path:
        """The URDF PlaCo loads (:func:`placo_peer.placo_urdf`)."""
        from placo_peer import placo_urdf

        if self._placo is None:
            self._placo = placo_urdf(self.robot, self.source, self.folder)
        return self._placo

    def drake(self) -> Any:
        """Drake's plant of the robot (:class:`drake_peer.DrakeArm`), built once."""
        from drake_peer import DrakeArm

        if self._drake is None:
            self._drake = DrakeArm(self.robot, self.source)
        return self._drake

    def close(self) -> None:
        shutil.rmtree(self.folder, ignore_errors=True)


def gaps(robot: Any, models: Models, status: dict[str, str]) -> dict[str, Any]:
    """Each peer's kinematics against Pinocchio's (poses and Jacobians, largest differences);
    the benchmark refuses a peer whose model differs by more than 1e-9 (it would solve
    another robot's problem)."""
    out: dict[str, Any] = {}
    rng = np.random.default_rng(11)
    if status["mink"] == "ran":
        import mink_peer

        out["mink"] = mink_peer.kinematics_gap(robot)
    if status["Drake"] == "ran":
        import drake_peer

        out["Drake"] = drake_peer.kinematics_gap(robot, models.drake())
    if status["PlaCo"] == "ran":
        from placo_peer import PlacoPeer, placo_checks

        peer = PlacoPeer(str(models.placo_urdf()), list(robot.joint_names),
                         list(robot.tool_frames), 0.01)  # fmt: skip
        out["PlaCo"] = placo_checks(robot, peer, rng)
    for peer, gap in out.items():
        if max(gap.values()) > 1e-9:
            raise SystemExit(f"{robot.name}: {peer}'s model differs from Pinocchio's: {gap}")
    return out


def pink_step(
    robot: Any,
    dt: float,
    frame_cost: float = 1.0,
    posture: tuple[float, float, Array] | None = None,
) -> Callable[[Array, Array], Array]:
    """``step(q, x) -> rates``: ``pink.solve_ik`` with a FrameTask per tool frame (its target
    the frame's pose moved by its twist times dt, world axes), with ``posture`` = (cost, gain
    [1/s], reference) a PostureTask (gain ``k dt``), ``ConfigurationLimit(gain=1)`` and
    ``VelocityLimit``, quadprog. pink raises when its QP has no solution."""
    import pink
    from pink.limits import ConfigurationLimit, VelocityLimit
    from pink.tasks import FrameTask, PostureTask

    from rrc_pin.control.drift import advance

    model = robot.model
    configuration = pink.Configuration(model, model.createData(), robot.neutral())
    frames = list(robot.tool_frames)
    hands = [FrameTask(f, position_cost=frame_cost, orientation_cost=frame_cost) for f in frames]
    tasks: list[Any] = list(hands)
    if posture is not None:
        cost, gain, reference = posture
        task = PostureTask(cost=cost, gain=gain * dt)
        task.set_target(reference)
        tasks.append(task)
    limits = [ConfigurationLimit(model, config_limit_gain=1.0), VelocityLimit(model)]

    def step(q: Array, x: Array) -> Array:
        configuration.update(q)
        for i, (frame, task) in enumerate(zip(frames, hands, strict=True)):
            T = configuration.get_transform_frame_to_world(frame)
            task.set_target(advance(T, x[6 * i : 6 * i + 6], dt, "world_aligned"))
        return pink.solve_ik(
            configuration, tasks, dt, solver=QP_SOLVER, limits=limits, safety_break=False
        )

    return step
