"""JerkLimiter: bounded acceleration and jerk after the resolver, the box kept (issue 41)."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
import ruckig

import rrc_pin
from rrc_pin.control.random_operator import random_commands
from rrc_pin.control.smoothing import STILL, JerkLimiter
from rrc_pin.kinematics import Kinematics, Layout
from rrc_pin.solvers.tick.problem import Box

SEEDS = [20261206, int(np.random.SeedSequence().entropy % 2**63)]
DT, A, J = 0.01, 20.0, 500.0
TOL = 1e-9
"""[rad/s^2, rad/s^3] Rounding allowance on the bounds (rates of about 1 rad/s)."""


def session(seed: int, smooth: bool):
    """10 s of random hand twists on panda, the hand's target advanced by each twist (so the
    two runs follow the same reference); the rates integrated, the stage's or the resolver's.
    Returns the hand positions, the integrated rates, the boxes and the clipped ticks."""
    arm = rrc_pin.load("panda")
    tool = arm.tool_frame
    commands = random_commands(np.random.default_rng(seed), 10.0, DT, speed=0.08, turn=0.3)
    resolver = rrc_pin.Resolver(arm, dt=DT)
    stage = JerkLimiter(arm.nv, DT, A, J, lower=arm.dof_lower, upper=arm.dof_upper)
    q, reference = arm.ready(), pin.SE3(arm.fk(arm.ready()))
    hands, rates, boxes, clipped = [], [], [], 0
    for twist in commands:
        task = rrc_pin.FrameTask(tool, twist, target=reference.homogeneous, gain=5.0)
        r = resolver.solve(q, [task], qdot_prev=stage.rates if smooth else None)
        qdot = r.qdot
        if smooth:
            out = stage.step(r.qdot, r.problem.box, arm.dof_positions(q))
            qdot, clipped = out.qdot, clipped + int(out.clipped.any())
        rates.append(qdot)
        boxes.append(r.problem.box)
        q = arm.integrate(q, qdot, DT)
        hands.append(arm.fk(q)[:3, 3])
        moved = twist * DT * r.scale
        reference = pin.SE3(pin.exp3(moved[3:]) @ reference.rotation,
                            reference.translation + moved[:3])  # fmt: skip
    return np.array(hands), np.array(rates), boxes, clipped


@pytest.mark.parametrize("seed", SEEDS, ids=["fixed", "fresh"])
def test_bounded_rates_inside_the_box_near_the_unsmoothed_path(seed):
    """Every tick's rate change within a_max dt and its change within j_max dt^2, the rates in
    the resolver's box exactly (the box never had to win), and the hand near the unsmoothed
    run's at the same instant: at most 2.5 cm for the fixed seed. Each run advances its own
    reference by its own scale, so where the raw rates jump (by up to 4.4 rad/s in a tick:
    joints stopped at their limits, or turned fast near a singularity) the two runs can part
    ways for a while: over 31 seeds the worst tick was 0.6-26.5 cm apart, the median tick at
    most 2.9 cm. A fresh seed is held to its median tick, 5 cm."""
    raw_hands, raw_rates, _, _ = session(seed, smooth=False)
    hands, rates, boxes, clipped = session(seed, smooth=True)
    acc = np.diff(np.vstack([np.zeros(7), rates]), axis=0) / DT
    jerk = np.diff(np.vstack([np.zeros(7), acc]), axis=0) / DT
    assert clipped == 0, seed  # no tick where the box had to win
    assert np.abs(acc).max() <= A + TOL and np.abs(jerk).max() <= J + TOL, seed
    for v, box in zip(rates, boxes, strict=True):
        assert (box.lb <= v).all() and (v <= box.ub).all()
    assert np.abs(np.diff(raw_rates, axis=0)).max() / DT > 2 * A  # the smoothing had work
    apart = np.linalg.norm(hands - raw_hands, axis=1)
    if seed == SEEDS[0]:
        assert apart.max() < 0.025, (seed, apart.max())
    assert np.median(apart) < 0.05, (seed, np.median(apart))


def test_a_joint_driven_into_its_limit_brakes_and_stays_inside():
    """Panda's joint 1 commanded at its full speed toward its upper limit: the stage slows it
    before the limit (its distance from the positions), the box never has to win, the
    position stays inside to the last tick and the bounds hold; without the limits given,
    the box wins as the joint arrives (reported)."""
    arm = rrc_pin.load("panda")
    limits = rrc_pin.JointLimits()
    stage = JerkLimiter(arm.nv, DT, A, J, lower=arm.dof_lower, upper=arm.dof_upper)
    q = arm.ready()
    q[0] = arm.upper[0] - 0.5
    layout = Layout.of(arm)
    rates = []
    for _ in range(200):
        _, dof, q_pin = arm.positions(q)
        box = limits.constraints(Kinematics(arm.model, arm.model.createData(), layout, dof,
                                            q_pin), DT, stage.rates).box  # fmt: skip
        command = np.zeros(7)
        command[0] = box.ub[0]  # the resolver's fastest answer toward the limit
        out = stage.step(command, box, arm.dof_positions(q))
        assert not out.clipped.any()
        q = arm.integrate(q, out.qdot, DT)
        assert q[0] <= arm.upper[0]
        rates.append(out.qdot)
    acc = np.diff(np.vstack([np.zeros(7), rates]), axis=0) / DT
    assert np.abs(acc).max() <= A + TOL
    assert arm.upper[0] - q[0] < 0.01  # it got there
    blind = JerkLimiter(arm.nv, DT, A, J)
    q = arm.ready()
    q[0] = arm.upper[0] - 0.5
    wins = 0
    for _ in range(200):
        _, dof, q_pin = arm.positions(q)
        box = limits.constraints(Kinematics(arm.model, arm.model.createData(), layout, dof,
                                            q_pin), DT, blind.rates).box  # fmt: skip
        out = blind.step(np.r_[box.ub[0], np.zeros(6)], box)
        wins += int(out.clipped.any())
        q = arm.integrate(q, out.qdot, DT)
        assert q[0] <= arm.upper[0]  # the box still won: inside
    assert wins > 0


def test_the_box_wins_and_says_so():
    stage = JerkLimiter(2, DT, A, J)
    stage.reset([1.0, -1.0])
    box = Box(np.array([-0.5, -2.0]), np.array([0.5, 2.0]), np.zeros((2, 2), np.int8), True,
              False, np.array([2.0, 2.0]))  # fmt: skip
    out = stage.step([1.0, -1.0], box)
    np.testing.assert_array_equal(out.qdot, [0.5, -1.0])
    np.testing.assert_array_equal(out.clipped, [True, False])


@pytest.mark.parametrize("seed", SEEDS, ids=["fixed", "fresh"])
def test_stop_stands_still_within_its_stated_time(seed):
    rng = np.random.default_rng(seed)
    free = Box(np.full(7, -3.0), np.full(7, 3.0), np.zeros((2, 7), np.int8), True, False,
               np.full(7, 3.0))  # fmt: skip
    for _ in range(20):
        stage = JerkLimiter(7, DT, A, J)
        command = rng.uniform(-2.5, 2.5, size=7)
        for _ in range(int(rng.integers(1, 40))):  # mid-ramp: accelerations not zero
            stage.step(command, free)
        stage.stop()
        bound, previous = stage.stop_time(), stage.rates
        ticks = 0
        while np.abs(stage.rates).max() >= STILL:
            out = stage.step(command, free)  # the command is ignored
            assert np.abs(out.qdot - previous).max() <= A * DT + TOL
            previous = out.qdot
            ticks += 1
            assert ticks * DT <= bound, (seed, ticks * DT, bound)


def test_a_step_reaches_its_target_as_soon_as_ruckig_does():
    """One step of 1.5 rad/s from rest: the stage and Ruckig's velocity interface (same
    bounds) are within 1e-3 of it at the same tick, and never overshoot it by more than
    one jerk step."""
    stage = JerkLimiter(1, DT, A, J)
    free = Box(np.array([-3.0]), np.array([3.0]), np.zeros((2, 1), np.int8), True, False,
               np.array([3.0]))  # fmt: skip
    otg, inp, out = ruckig.Ruckig(1, DT), ruckig.InputParameter(1), ruckig.OutputParameter(1)
    inp.control_interface = ruckig.ControlInterface.Velocity
    inp.current_position, inp.current_velocity, inp.current_acceleration = [0.0], [0.0], [0.0]
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = [10.0], [A], [J]
    inp.target_velocity, inp.target_acceleration = [1.5], [0.0]
    mine, theirs = [], []
    for _ in range(40):
        mine.append(stage.step([1.5], free).qdot[0])
        otg.update(inp, out)
        theirs.append(out.new_velocity[0])
        out.pass_to_input(inp)
    first = [int(np.flatnonzero(np.abs(np.array(v) - 1.5) < 1e-3)[0]) for v in (mine, theirs)]
    assert abs(first[0] - first[1]) <= 1, first
    assert max(mine) <= 1.5 + J * DT * DT


def test_bad_arguments_are_refused_by_name():
    for args, argument in [((0, DT, A, J), "n"), ((2, 0.0, A, J), "dt"),
                           ((2, DT, -1.0, J), "acceleration"), ((2, DT, A, [1.0, 2.0, 3.0]),
                           "jerk")]:  # fmt: skip
        with pytest.raises(rrc_pin.InvalidInput) as info:
            JerkLimiter(*args)
        assert info.value.argument == argument
    stage = JerkLimiter(2, DT, A, J)
    with pytest.raises(rrc_pin.InvalidInput):
        stage.step([0.0, np.nan], Box(np.zeros(2), np.zeros(2), np.zeros((2, 2), np.int8),
                                      True, False, np.ones(2)))  # fmt: skip
    with pytest.raises(rrc_pin.InvalidInput) as info:
        stage.step([0.0, 0.0], "box")  # type: ignore[arg-type]
    assert info.value.argument == "box"
