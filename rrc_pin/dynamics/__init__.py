"""Dynamics: simulation on Pinocchio and the control schemes of Nguyen & Zhou section 6.

:class:`Simulator` (ABA, semi-implicit Euler, friction, torque limits, a contact plane, a
payload that can change mid-run); controllers behind one interface (:class:`Controller`:
state and reference in, torques out): baselines :class:`FixedPD` and
:class:`ComputedTorque`, Seraji-style adaptive :class:`JointAdaptivePD` (Fig. 11),
:class:`CartesianAdaptivePD` (Fig. 12) and :class:`HybridForcePosition` (Fig. 13); joint
references from a :class:`HandPath` by :class:`JointTrajectory`; the loop :func:`run`.
"""

from rrc_pin.dynamics.adaptation import SerajiGains, SerajiLaw
from rrc_pin.dynamics.cartesian_adaptive import CartesianAdaptivePD
from rrc_pin.dynamics.computed_torque import ComputedTorque
from rrc_pin.dynamics.controller import Controller
from rrc_pin.dynamics.drives import Drives, drives_of
from rrc_pin.dynamics.environment import ContactPlane
from rrc_pin.dynamics.harness import Record, run
from rrc_pin.dynamics.hybrid import HybridForcePosition
from rrc_pin.dynamics.joint_adaptive import JointAdaptivePD
from rrc_pin.dynamics.pd import FixedPD
from rrc_pin.dynamics.reference import HandPath, JointTrajectory
from rrc_pin.dynamics.simulator import Simulator, StepReport
from rrc_pin.dynamics.state import Reference, State

__all__ = [
    "CartesianAdaptivePD",
    "ComputedTorque",
    "ContactPlane",
    "Controller",
    "Drives",
    "FixedPD",
    "HandPath",
    "HybridForcePosition",
    "JointAdaptivePD",
    "JointTrajectory",
    "Record",
    "Reference",
    "SerajiGains",
    "SerajiLaw",
    "Simulator",
    "State",
    "StepReport",
    "drives_of",
    "run",
]
