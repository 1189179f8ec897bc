"""rrc_pin.dexterity: the Jacobian's derivative and the singular values' gradients, exact."""

from __future__ import annotations

import numpy as np
import pytest

import rrc_pin
from rrc_pin.dexterity import dexterity, jacobian_derivative, metric
from rrc_pin.kinematics import Kinematics, Layout

SEEDS = [20261206, int(np.random.SeedSequence().entropy % 2**63)]
ROBOTS = ["panda", "rrc_k1607", "barker6", "baxter", "yeh_tripod", "talos_upper"]
STEP = 1e-6
"""[rad] Central differences: truncation ~1e-12 relative, rounding ~1e-10."""


def kinematics(robot: rrc_pin.Robot, q: np.ndarray) -> Kinematics:
    q, dof, q_pin = robot.positions(q)
    return Kinematics(robot.model, robot.model.createData(), Layout.of(robot), dof, q_pin)


def central(robot: rrc_pin.Robot, q: np.ndarray, f) -> np.ndarray:
    """d f / d qdot_j (j along the rates, on the configuration manifold), stacked on axis 0."""
    out = []
    for j in range(robot.nv):
        e = np.zeros(robot.nv)
        e[j] = STEP
        plus = f(kinematics(robot, robot.integrate(q, e, 1.0)))
        minus = f(kinematics(robot, robot.integrate(q, -e, 1.0)))
        out.append((plus - minus) / (2 * STEP))
    return np.array(out)


@pytest.mark.parametrize("seed", SEEDS, ids=["fixed", "fresh"])
@pytest.mark.parametrize("name", ROBOTS)
def test_the_jacobian_derivative_is_the_finite_difference(name, seed):
    robot = rrc_pin.load(name)
    q = robot.random_q(np.random.default_rng(seed))
    for frame in robot.tool_frames:
        D = jacobian_derivative(kinematics(robot, q), frame)
        fd = central(robot, q, lambda k, f=frame: k.jacobian(f))
        assert D.shape == (robot.nv, 6, robot.nv)
        assert np.abs(D - fd).max() < 1e-8, (name, seed, frame, np.abs(D - fd).max())


@pytest.mark.parametrize("seed", SEEDS, ids=["fixed", "fresh"])
@pytest.mark.parametrize("name", ROBOTS)
def test_the_gradients_are_the_finite_differences(name, seed):
    robot = rrc_pin.load(name)
    q = robot.random_q(np.random.default_rng(seed))
    frame = robot.tool_frames[0]
    for rows in [(0, 1, 2, 3, 4, 5), (0, 1, 2), (3, 4, 5)]:
        d = dexterity(kinematics(robot, q), frame, rows)
        fd_w = central(robot, q, lambda k, r=rows: np.array(dexterity(k, frame, r).manipulability))
        fd_s = central(robot, q, lambda k, r=rows: dexterity(k, frame, r).sigma)
        scale = max(1.0, float(np.abs(fd_w).max()))
        assert np.abs(d.manipulability_gradient() - fd_w).max() < 1e-7 * scale, (name, seed, rows)
        gap = np.min(np.abs(np.diff(d.sigma))) if d.sigma.size > 1 else 1.0
        if gap > 1e-4:  # a simple singular value: differentiable
            assert np.abs(d.gradients - fd_s.T).max() < 1e-6, (name, seed, rows)


def test_the_measure_is_yoshikawas_in_the_resolvers_metric():
    arm = rrc_pin.load("panda")
    q = arm.ready()
    kin = kinematics(arm, q)
    J = arm.jacobian(q)
    reach = kin.layout.reach[arm.tool_frame]
    Jm = np.diag(metric(kin, arm.tool_frame, (0, 1, 2, 3, 4, 5))) @ J
    assert metric(kin, arm.tool_frame, (0, 3))[0] == pytest.approx(1.0 / reach)
    d = dexterity(kin, arm.tool_frame)
    assert d.manipulability == pytest.approx(np.sqrt(np.linalg.det(Jm @ Jm.T)), rel=1e-12)
    assert d.manipulability == pytest.approx(np.sqrt(np.linalg.det(J @ J.T)) / reach**3, rel=1e-12)


def test_a_floating_base_is_not_counted():
    """The tripod's body twist is not a joint of a leg: the measure reads the legs' columns,
    and moving the body as a whole changes neither it nor its gradient's legs part."""
    tripod = rrc_pin.load("yeh_tripod")
    q = tripod.ready()
    kin = kinematics(tripod, q)
    d = dexterity(kin, tripod.tool_frames[0])
    assert d.sigma.size == 6
    assert np.abs(d.manipulability_gradient()[:6]).max() < 1e-12
    moved = tripod.integrate(q, np.r_[0.1, -0.2, 0.05, 0.3, -0.1, 0.2, np.zeros(18)], 1.0)
    other = dexterity(kinematics(tripod, moved), tripod.tool_frames[0])
    assert other.manipulability == pytest.approx(d.manipulability, rel=1e-12)
