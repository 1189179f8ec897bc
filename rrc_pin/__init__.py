"""rrc-pin: Pinocchio-backed resolved-rate control of robot arms.

Entry points (DESIGN.md, "Public API"): :func:`arms`, :func:`load`, :class:`Robot`,
:class:`Resolver` and its :class:`Resolution`.
"""

from rrc_pin.errors import (
    FrameNotFound,
    InvalidInput,
    RrcPinError,
    UnknownArm,
    URDFError,
)
from rrc_pin.loading import arms, load
from rrc_pin.resolver import Resolver
from rrc_pin.robot import Robot
from solvers.dls import Damping
from solvers.resolution_record import ActiveLimit, Resolution

__all__ = [
    "ActiveLimit",
    "Damping",
    "FrameNotFound",
    "InvalidInput",
    "Resolution",
    "Resolver",
    "Robot",
    "RrcPinError",
    "URDFError",
    "UnknownArm",
    "arms",
    "load",
]
