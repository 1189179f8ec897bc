"""rrc-pin: Pinocchio-backed resolved-rate control of robot arms.

Entry points (DESIGN.md, "Public API"): :func:`arms`, :func:`load`, :class:`Robot`.
"""

from rrc_pin.errors import (
    FrameNotFound,
    InvalidInput,
    RrcPinError,
    UnknownArm,
    URDFError,
)
from rrc_pin.loading import arms, load
from rrc_pin.robot import Robot

__all__ = [
    "FrameNotFound",
    "InvalidInput",
    "Robot",
    "RrcPinError",
    "URDFError",
    "UnknownArm",
    "arms",
    "load",
]
