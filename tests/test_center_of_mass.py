"""rrc_pin.center_of_mass: the centre of mass's Jacobian against finite differences."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import rrc_pin
from rrc_pin.center_of_mass import center_of_mass, check_mass
from rrc_pin.kinematics import Kinematics, Layout

SEEDS = [20261206, int(np.random.SeedSequence().entropy % 2**63)]


def kinematics(robot, q):
    q, dof, q_pin = robot.positions(q)
    return Kinematics(robot.model, robot.model.createData(), Layout.of(robot), dof, q_pin)


@pytest.mark.parametrize("seed", SEEDS, ids=["fixed", "fresh"])
@pytest.mark.parametrize("name", ["yeh_tripod", "talos_upper", "g1_upper", "romeo_upper", "panda"])
def test_the_jacobian_is_the_finite_difference(name, seed):
    robot = rrc_pin.load(name)
    q = robot.random_q(np.random.default_rng(seed))
    com = center_of_mass(kinematics(robot, q))
    h = 1e-6
    fd = np.empty((3, robot.nv))
    for j in range(robot.nv):
        e = np.zeros(robot.nv)
        e[j] = h
        up = center_of_mass(kinematics(robot, robot.integrate(q, e, 1.0))).position
        down = center_of_mass(kinematics(robot, robot.integrate(q, -e, 1.0))).position
        fd[:, j] = (up - down) / (2 * h)
    assert np.abs(com.jacobian - fd).max() < 1e-8, seed
    data = robot.model.createData()
    expected = pin.centerOfMass(robot.model, data, robot.to_pinocchio(q))
    np.testing.assert_allclose(com.position, expected, atol=1e-14)


def test_a_model_without_mass_is_refused():
    model = rrc_pin.load("panda").model.copy()
    for i in range(model.njoints):
        model.inertias[i] = pin.Inertia.Zero()
    with pytest.raises(rrc_pin.InvalidInput) as info:
        check_mass(model)
    assert info.value.argument == "robot"
    check_mass(rrc_pin.load("panda").model)
