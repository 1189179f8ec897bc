"""Loop: the integration of one period against the robot's own, float for float."""

from __future__ import annotations

import numpy as np
import pytest

import rrc_pin
from rrc_pin.cells import CellController
from rrc_pin.control import Controller
from rrc_pin.control.loop import Loop
from rrc_pin.errors import InvalidInput


def _loops(dual, tripod):
    """A loop of each integration: one-coordinate joints (panda, gsfc_dual), continuous joints
    (kinova), a floating base (yeh_tripod)."""
    return [Controller(rrc_pin.load("panda")), Controller(rrc_pin.load("kinova")),
            CellController(dual, 0.01), CellController(tripod, 0.01)]  # fmt: skip


def test_the_loop_integrates_as_the_robot_does_to_the_last_bit(dual, tripod, rng):
    """Each loop's period, from q moved off its ready pose (the base's quaternion off unit
    length, as Pinocchio's integration leaves it), is ``Robot.integrate``'s, bit for bit."""
    for loop in _loops(dual, tripod):
        robot = loop.robot
        for _ in range(20):
            q = robot.integrate(loop.q, rng.normal(size=robot.nv), 0.3)
            if robot.floating:
                q[3:7] *= 1.0 + 1e-12 * rng.normal()
            loop.q = q
            if isinstance(loop, CellController):  # its tick's kinematics converted q
                loop._kinematics()
            qdot = rng.normal(size=robot.nv)
            got = Loop._integrate(loop, qdot)  # a cell's own adds its chains' correction
            np.testing.assert_array_equal(got, robot.integrate(q, qdot, loop.dt))
            np.testing.assert_array_equal(loop._pinocchio_q(q), robot.to_pinocchio(q))


def test_rates_not_finite_are_refused_before_the_configuration_moves(tripod):
    """A floating base's loop names the rates, as ``Robot.integrate`` does."""
    loop = CellController(tripod, 0.01)
    qdot = np.zeros(tripod.nv)
    qdot[3] = np.nan
    with pytest.raises(InvalidInput, match="qdot"):
        Loop._integrate(loop, qdot)
