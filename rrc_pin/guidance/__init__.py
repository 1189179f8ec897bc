"""Nadkarni's guidance (M.S. thesis, 1977).

The screw of a finite displacement (chapter III), guidance Types I-IV on any arm (chapter
IV), the velocity analysis and the second-order correction (chapter V).
"""

from rrc_pin.guidance.general import general, general_axes
from rrc_pin.guidance.operator import Command, operator
from rrc_pin.guidance.screw import (
    Screw,
    displacement,
    frames_from_points,
    screw_from_points,
    screw_from_poses,
    screw_of_displacement,
    screw_twist,
)
from rrc_pin.guidance.screw_motion import disp_step, screw_motion
from rrc_pin.guidance.stepping import GuidancePath, Step, ThesisSolver, run_steps
from rrc_pin.guidance.straight_line import straight_line, straight_line_points
from rrc_pin.guidance.velocity import joint_rates

__all__ = [
    "Command",
    "GuidancePath",
    "Screw",
    "Step",
    "ThesisSolver",
    "disp_step",
    "displacement",
    "frames_from_points",
    "general",
    "general_axes",
    "joint_rates",
    "operator",
    "run_steps",
    "screw_from_points",
    "screw_from_poses",
    "screw_motion",
    "screw_of_displacement",
    "screw_twist",
    "straight_line",
    "straight_line_points",
]
