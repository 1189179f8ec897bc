"""Barker's singularity strategies on barker6 (issue 8): through each singularity (eq. (32),
eq. (33), theta5 = 0) under every strategy, and what each strategy does by the paper."""

from __future__ import annotations

import numpy as np
import pytest

import rrc_pin
from rrc_pin.control import (
    STRATEGIES,
    AuxiliaryHand,
    Controller,
    Freezing,
    Uncoupled,
    WristChoice,
)
from rrc_pin.control.strategies.barker_arm import elbow_singular_angle, nearness

ARM = rrc_pin.load("barker6")
CF = ARM.closed_form
THETA3_S = elbow_singular_angle(CF)
Q0 = np.deg2rad([20.0, 30.0, 60.0, 10.0, 40.0, 0.0])


def through(joint: int, singular: float, side: float) -> tuple[np.ndarray, np.ndarray]:
    """A start ``side`` rad from ``singular`` on ``joint`` and the constant twist (base axes)
    that drives that joint through it in about 0.5 s."""
    q = Q0.copy()
    q[joint] = singular + side
    dq = np.zeros(6)
    dq[joint] = -side / 0.5
    return q, ARM.jacobian(q) @ dq


SINGULARITIES = {
    "shoulder (eq. 32)": through(1, np.deg2rad(-31.37), np.deg2rad(8.0)),
    "elbow (eq. 33)": through(2, THETA3_S, np.deg2rad(8.0)),
    "wrist (S5 = 0)": through(4, 0.0, np.deg2rad(8.0)),
}


@pytest.mark.parametrize("singularity", list(SINGULARITIES))
@pytest.mark.parametrize("strategy", list(STRATEGIES))
def test_through_each_singularity_rates_are_finite_and_within_the_limits(strategy, singularity):
    q0, twist = SINGULARITIES[singularity]
    ctl = Controller(ARM, q0=q0, strategy=strategy)
    for _ in range(70):  # through the singular value at 50
        ctl.step(twist, "world_aligned")
    q, qdot = ctl.log.column("q"), ctl.log.column("qdot")
    assert np.isfinite(q).all() and np.isfinite(qdot).all()
    assert np.all(np.abs(qdot) <= ARM.velocity_limit * (1 + 1e-9))
    assert np.all(q >= ARM.lower) and np.all(q <= ARM.upper)
    assert singularity in "".join(ctl.log.column("singularity"))  # it went near


def from_shoulder(q: np.ndarray) -> np.ndarray:
    """Wrist centre from the shoulder (joint 2) axis, perpendicular to it [m], base axes.

    The URDF's ``joint2`` frame has its origin and z axis on joint 2's axis.
    """
    T1 = ARM.fk(q, "joint2")
    d = ARM.fk(q)[:3, 3] - T1[:3, 3]
    z = T1[:3, 2]
    return d - (d @ z) * z


def shoulder_distance(q: np.ndarray) -> float:
    return float(np.linalg.norm(from_shoulder(q)))


def radial(q: np.ndarray) -> np.ndarray:
    """Unit vector from the shoulder axis out to the wrist centre, in the arm's plane."""
    d = from_shoulder(q)
    return d / np.linalg.norm(d)


def test_auxiliary_control_retracts_toward_the_shoulder_and_refuses_an_outward_command():
    q = Q0.copy()
    q[2] = THETA3_S  # the stretched elbow, eq. (33) = 0
    strategy = AuxiliaryHand()
    ctl = Controller(ARM, q0=q, strategy=strategy, drift=None)
    out = np.concatenate([0.05 * radial(q), np.zeros(3)])
    step = ctl.step(out, "world_aligned")
    assert np.max(np.abs(step.resolution.qdot[:3])) < 1e-9  # eq. (45): theta3 does not move
    assert abs(shoulder_distance(step.q) - shoulder_distance(q)) < 1e-9
    start = shoulder_distance(ctl.q)
    before = ARM.fk(ctl.q)[:3, 3]
    for _ in range(20):
        ctl.step(-out, "world_aligned")
    moved = ARM.fk(ctl.q)[:3, 3] - before
    assert shoulder_distance(ctl.q) < start - 0.005  # retracted
    cos = float(moved @ -radial(q)) / np.linalg.norm(moved)
    assert cos > 0.95  # nearly a straight line toward the shoulder
    assert strategy.entries == 1


def test_k3_flips_on_each_entry_so_the_elbow_bends_the_other_way():
    strategy = AuxiliaryHand(region=0.05)
    q = Q0.copy()
    q[2] = THETA3_S + np.deg2rad(8.0)  # bent to the + side, outside the region
    ctl = Controller(ARM, q0=q, strategy=strategy, drift=None)
    sides, signs = [], []
    for entry in (1, 2):
        for _ in range(300):  # extend until the elbow is straight
            ctl.step(np.concatenate([0.05 * radial(ctl.q), np.zeros(3)]), "world_aligned")
            if abs(ctl.q[2] - THETA3_S) < 1e-12:
                break
        assert abs(ctl.q[2] - THETA3_S) < 1e-12 and strategy.entries == entry
        signs.append(np.sign(strategy.k3))
        for _ in range(300):  # back up, out of the region
            ctl.step(np.concatenate([-0.05 * radial(ctl.q), np.zeros(3)]), "world_aligned")
            if nearness(CF, ctl.q).elbow > 1.2 * strategy.region:
                break
        assert not strategy.inside
        sides.append(np.sign(ctl.q[2] - THETA3_S))
    assert signs[0] == -signs[1] and sides[0] == -sides[1]
    qdot = ctl.log.column("qdot")
    assert np.isfinite(qdot).all() and np.all(np.abs(qdot) <= ARM.velocity_limit * (1 + 1e-9))


def test_wrist_choice_keeps_theta4_still_and_hands_the_roll_to_theta4_at_theta6_limit():
    q = Q0.copy()
    q[4] = np.deg2rad(1.0)  # |sin theta5| < 0.05
    q[5] = ARM.upper[5] - 0.05
    ctl = Controller(ARM, q0=q, strategy=WristChoice(), drift=None)
    roll = [0.0, 0.0, 0.0, 0.0, 0.0, 1.0]  # about the hand's z axis
    for _ in range(20):
        ctl.step(roll, "local")
    qdot, notes = ctl.log.column("qdot"), ctl.log.column("note")
    on6 = notes == "roll on theta6"
    on4 = notes == "roll on theta4 (theta6 at its limit)"
    assert on6[:5].all() and on4[-5:].all()
    assert np.all(qdot[on6, 3] == 0.0) and np.all(qdot[on6, 5] > 0.5)
    assert np.all(qdot[on4, 5] == 0.0) and np.all(qdot[on4, 3] > 0.5)
    assert ctl.q[5] <= ARM.upper[5]


def test_freezing_holds_the_frozen_joints_and_releases_them_outside_the_region():
    q0, twist = SINGULARITIES["wrist (S5 = 0)"]
    strategy = Freezing(region=0.05)
    ctl = Controller(ARM, q0=q0, strategy=strategy, drift=None)
    for _ in range(100):
        ctl.step(twist, "world_aligned")
    q, qdot, notes = ctl.log.column("q"), ctl.log.column("qdot"), ctl.log.column("note")
    frozen = np.array(["theta4" in n for n in notes])
    assert frozen.any() and not frozen[0] and not frozen[-1]
    assert np.all(qdot[frozen][:, [3, 5]] == 0.0)
    assert np.all(np.abs(np.sin(q[frozen][:, 4]) + np.sin(qdot[frozen][:, 4]) * 0.0) < 0.1)
    released = np.flatnonzero(~frozen[1:] & frozen[:-1]) + 1
    assert released.size and np.all(np.abs(np.sin(q[released, 4] + qdot[released, 4] * 0.01))
                                    >= strategy.region)


def test_uncoupled_commands_the_wrist_joints_one_by_one():
    ctl = Controller(ARM, q0=Q0, strategy=Uncoupled(), drift=None)
    step = ctl.step([0.02, 0.0, 0.01, 0.3, -0.2, 0.1], "world_aligned")
    assert np.allclose(step.resolution.qdot[3:], [0.3, -0.2, 0.1], atol=1e-12)
    achieved = ctl.log.column("achieved")[0]
    J = ARM.jacobian(Q0)
    assert np.allclose(J[:3, :3] @ step.resolution.qdot[:3], [0.02, 0.0, 0.01], atol=1e-12)
    assert np.isfinite(achieved).all()


def test_barker_strategies_refuse_other_arms():
    for name in ("generalized_inverse", "freezing", "auxiliary_hand", "wrist_choice", "uncoupled"):
        with pytest.raises(rrc_pin.InvalidInput, match="Barker's closed form") as info:
            Controller("panda", strategy=name)
        assert info.value.argument == "strategy"
