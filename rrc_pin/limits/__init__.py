"""Limits of a resolution: joint limits (velocity, one-step position, acceleration)."""

from rrc_pin.limits.joint_limits import JointLimits

__all__ = ["JointLimits"]
