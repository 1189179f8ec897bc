"""Limits of a resolution, one per module: each gives a box and named constraint rows a tick."""

from rrc_pin.limits.collision import CollisionLimit, InvariantPairWarning
from rrc_pin.limits.contact_limit import ContactLimit
from rrc_pin.limits.grip_limit import GripLimit
from rrc_pin.limits.joint_limits import JointLimits
from rrc_pin.limits.limit import Limit
from rrc_pin.limits.singularity_limit import SingularityLimit
from rrc_pin.limits.support_polygon_limit import SupportPolygonLimit

__all__ = [
    "CollisionLimit",
    "ContactLimit",
    "GripLimit",
    "InvariantPairWarning",
    "JointLimits",
    "Limit",
    "SingularityLimit",
    "SupportPolygonLimit",
]
