"""The teleoperation loop: :class:`Controller` and what it is made of.

The loop every controller is built on (:class:`Loop`: speed, deadman, integration, log
ring, reverse), its log, deadman, drift correction and singularity strategies
(:mod:`rrc_pin.control.strategies`).
"""

from rrc_pin.control.controller import Controller
from rrc_pin.control.deadman import Deadman
from rrc_pin.control.drift import DriftCorrection
from rrc_pin.control.loop import Loop, Retrace, Step
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
from rrc_pin.control.trajectory_log import LogRecord, RecordRing, TrajectoryLog

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
    "Loop",
    "RecordRing",
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
