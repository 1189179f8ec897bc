"""rrc-pin: Pinocchio-backed resolved-rate control of robot arms.

Entry points: :func:`arms`, :func:`load`, :class:`Robot`; :class:`Resolver` with its options
(:class:`JointLimits`, :class:`CollisionLimit` on a :class:`CollisionModel`,
:class:`QPOptions`, :class:`Damping`), tasks (:class:`FrameTask`,
:class:`RelativeFrameTask`, :class:`PostureTask`, :class:`JointTask`, :class:`DampingTask`)
and its answer, :class:`Resolution`; the teleoperation loop :class:`Controller` (with
:class:`Deadman`, :class:`DriftCorrection`, :class:`TrajectoryLog`; strategies in
:mod:`rrc_pin.control.strategies`).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from rrc_pin.cells import Cell, CellController, MasterSlave, make_cell
    from rrc_pin.combined import combine
    from rrc_pin.control import Controller, Deadman, DriftCorrection, TrajectoryLog
    from rrc_pin.control.pose_stream import PoseStream, StreamOptions
    from rrc_pin.control.smoothing import JerkLimiter, SmoothingOptions
    from rrc_pin.errors import (
        FrameNotFound,
        InvalidInput,
        RrcPinError,
        ToolFrameRequired,
        UnknownArm,
        UnknownBackend,
        URDFError,
    )
    from rrc_pin.geometry import CollisionModel
    from rrc_pin.limits import (
        CollisionLimit,
        ContactLimit,
        GripLimit,
        JointLimits,
        Limit,
        SingularityLimit,
        SupportPolygonLimit,
    )
    from rrc_pin.loading import arms, load
    from rrc_pin.resolver import QPOptions, Resolver
    from rrc_pin.robot import Robot
    from rrc_pin.solvers.tick.damping import Damping
    from rrc_pin.solvers.tick.problem import Constraints
    from rrc_pin.solvers.tick.resolution import ActiveLimit, ActiveRow, Resolution, TaskReport
    from rrc_pin.tasks import (
        AxisAlignTask,
        ComTask,
        DampingTask,
        FrameTask,
        JointTask,
        LookAtTask,
        ManipulabilityTask,
        PostureTask,
        RelativeFrameTask,
        Task,
        TaskRows,
    )

__all__ = [
    "ActiveLimit",
    "ActiveRow",
    "AxisAlignTask",
    "Cell",
    "CellController",
    "CollisionLimit",
    "CollisionModel",
    "ComTask",
    "Constraints",
    "ContactLimit",
    "Controller",
    "Damping",
    "DampingTask",
    "Deadman",
    "DriftCorrection",
    "FrameNotFound",
    "FrameTask",
    "GripLimit",
    "InvalidInput",
    "JerkLimiter",
    "JointLimits",
    "JointTask",
    "Limit",
    "LookAtTask",
    "ManipulabilityTask",
    "MasterSlave",
    "PoseStream",
    "PostureTask",
    "QPOptions",
    "RelativeFrameTask",
    "Resolution",
    "Resolver",
    "Robot",
    "RrcPinError",
    "SingularityLimit",
    "SmoothingOptions",
    "StreamOptions",
    "SupportPolygonLimit",
    "Task",
    "TaskReport",
    "TaskRows",
    "ToolFrameRequired",
    "TrajectoryLog",
    "URDFError",
    "UnknownArm",
    "UnknownBackend",
    "arms",
    "combine",
    "load",
    "make_cell",
]

_HOME: dict[str, str] = {
    "ActiveLimit": "rrc_pin.solvers.tick.resolution",
    "ActiveRow": "rrc_pin.solvers.tick.resolution",
    "AxisAlignTask": "rrc_pin.tasks",
    "Cell": "rrc_pin.cells",
    "CellController": "rrc_pin.cells",
    "CollisionLimit": "rrc_pin.limits",
    "CollisionModel": "rrc_pin.geometry",
    "ComTask": "rrc_pin.tasks",
    "Constraints": "rrc_pin.solvers.tick.problem",
    "ContactLimit": "rrc_pin.limits",
    "Controller": "rrc_pin.control",
    "Damping": "rrc_pin.solvers.tick.damping",
    "DampingTask": "rrc_pin.tasks",
    "Deadman": "rrc_pin.control",
    "DriftCorrection": "rrc_pin.control",
    "FrameNotFound": "rrc_pin.errors",
    "FrameTask": "rrc_pin.tasks",
    "GripLimit": "rrc_pin.limits",
    "InvalidInput": "rrc_pin.errors",
    "JerkLimiter": "rrc_pin.control.smoothing",
    "JointLimits": "rrc_pin.limits",
    "JointTask": "rrc_pin.tasks",
    "Limit": "rrc_pin.limits",
    "LookAtTask": "rrc_pin.tasks",
    "ManipulabilityTask": "rrc_pin.tasks",
    "MasterSlave": "rrc_pin.cells",
    "PoseStream": "rrc_pin.control.pose_stream",
    "PostureTask": "rrc_pin.tasks",
    "QPOptions": "rrc_pin.resolver",
    "RelativeFrameTask": "rrc_pin.tasks",
    "Resolution": "rrc_pin.solvers.tick.resolution",
    "Resolver": "rrc_pin.resolver",
    "Robot": "rrc_pin.robot",
    "RrcPinError": "rrc_pin.errors",
    "SingularityLimit": "rrc_pin.limits",
    "SmoothingOptions": "rrc_pin.control.smoothing",
    "StreamOptions": "rrc_pin.control.pose_stream",
    "SupportPolygonLimit": "rrc_pin.limits",
    "Task": "rrc_pin.tasks",
    "TaskReport": "rrc_pin.solvers.tick.resolution",
    "TaskRows": "rrc_pin.tasks",
    "ToolFrameRequired": "rrc_pin.errors",
    "TrajectoryLog": "rrc_pin.control",
    "URDFError": "rrc_pin.errors",
    "UnknownArm": "rrc_pin.errors",
    "UnknownBackend": "rrc_pin.errors",
    "arms": "rrc_pin.loading",
    "combine": "rrc_pin.combined",
    "load": "rrc_pin.loading",
    "make_cell": "rrc_pin.cells",
}
"""Where each public name lives, imported on its first use: ``import rrc_pin`` itself loads
neither Pinocchio nor the compiled kernels (the command line's ``--help`` stays fast, and
``rrc_pin.solvers`` imports nothing above it)."""


def __getattr__(name: str) -> Any:
    home = _HOME.get(name)
    if home is None:
        raise AttributeError(f"module 'rrc_pin' has no attribute {name!r}")
    value = getattr(importlib.import_module(home), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted([*globals(), *__all__])
