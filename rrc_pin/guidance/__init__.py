"""Nadkarni's guidance: the screw of a finite displacement (chapter III)."""

from rrc_pin.guidance.screw import (
    Screw,
    displacement,
    frames_from_points,
    screw_from_points,
    screw_from_poses,
    screw_of_displacement,
    screw_twist,
)

__all__ = [
    "Screw",
    "displacement",
    "frames_from_points",
    "screw_from_points",
    "screw_from_poses",
    "screw_of_displacement",
    "screw_twist",
]
