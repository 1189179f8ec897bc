"""Tasks of a resolution, one per module: each gives Jacobian rows and desired rates."""

from rrc_pin.solvers.tick.problem import TaskRows
from rrc_pin.tasks.axis_align_task import AxisAlignTask
from rrc_pin.tasks.com_task import ComTask
from rrc_pin.tasks.damping_task import DampingTask
from rrc_pin.tasks.frame_task import FrameTask
from rrc_pin.tasks.joint_task import JointTask
from rrc_pin.tasks.look_at_task import LookAtTask
from rrc_pin.tasks.manipulability_task import ManipulabilityTask
from rrc_pin.tasks.posture_task import PostureTask
from rrc_pin.tasks.relative_frame_task import RelativeFrameTask
from rrc_pin.tasks.task import Task

__all__ = [
    "AxisAlignTask",
    "ComTask",
    "DampingTask",
    "FrameTask",
    "JointTask",
    "LookAtTask",
    "ManipulabilityTask",
    "PostureTask",
    "RelativeFrameTask",
    "Task",
    "TaskRows",
]
