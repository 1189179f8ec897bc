"""The teleoperation loop: :class:`Controller` and what it is made of.

Its log, deadman, drift correction and singularity strategies
(:mod:`rrc_pin.control.strategies`).
"""

from rrc_pin.control.controller import Controller, Retrace, Step
from rrc_pin.control.deadman import Deadman
from rrc_pin.control.drift import DriftCorrection
from rrc_pin.control.strategies import (
    STRATEGIES,
    AuxiliaryHand,
    Decision,
    Freezing,
    GeneralizedInverse,
    ResolverOnly,
    Situation,
    Slowdown,
    Strategy,
    Uncoupled,
    WristChoice,
    make_strategy,
)
from rrc_pin.control.trajectory_log import LogRecord, TrajectoryLog

__all__ = [
    "STRATEGIES",
    "AuxiliaryHand",
    "Controller",
    "Deadman",
    "Decision",
    "DriftCorrection",
    "Freezing",
    "GeneralizedInverse",
    "LogRecord",
    "ResolverOnly",
    "Retrace",
    "Situation",
    "Slowdown",
    "Step",
    "Strategy",
    "TrajectoryLog",
    "Uncoupled",
    "WristChoice",
    "make_strategy",
]
