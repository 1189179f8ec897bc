"""rrc-pin: Pinocchio-backed resolved-rate control of robot arms.

Entry points: :func:`arms`, :func:`load`, :class:`Robot`; :class:`Resolver` with its options
(:class:`JointLimits`, :class:`CollisionLimit` on a :class:`CollisionModel`,
:class:`QPOptions`, :class:`Damping`), tasks (:class:`FrameTask`,
:class:`RelativeFrameTask`, :class:`PostureTask`, :class:`JointTask`, :class:`DampingTask`)
and its answer, :class:`Resolution`; the teleoperation loop :class:`Controller` (with
:class:`Deadman`, :class:`DriftCorrection`, :class:`TrajectoryLog`; strategies in
:mod:`rrc_pin.control.strategies`).
"""

from rrc_pin.cells import Cell, CellController, MasterSlave, make_cell
from rrc_pin.combine import combine
from rrc_pin.control import Controller, Deadman, DriftCorrection, TrajectoryLog
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
from rrc_pin.limits import CollisionLimit, ContactLimit, GripLimit, JointLimits, Limit
from rrc_pin.loading import arms, load
from rrc_pin.resolver import QPOptions, Resolver
from rrc_pin.robot import Robot
from rrc_pin.tasks import (
    DampingTask,
    FrameTask,
    JointTask,
    PostureTask,
    RelativeFrameTask,
    Task,
    TaskRows,
)
from solvers.damping import Damping
from solvers.problem import Constraints
from solvers.resolution import ActiveLimit, ActiveRow, Resolution, TaskReport

__all__ = [
    "ActiveLimit",
    "ActiveRow",
    "Cell",
    "CellController",
    "CollisionLimit",
    "CollisionModel",
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
    "JointLimits",
    "JointTask",
    "Limit",
    "MasterSlave",
    "PostureTask",
    "QPOptions",
    "RelativeFrameTask",
    "Resolution",
    "Resolver",
    "Robot",
    "RrcPinError",
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
