"""The generic slowdown: approaching a singularity slows the hand, leaving is never slowed
(ur5 near its elbow and wrist singularities; panda, whose elbow cannot stretch within its
limits, near its wrist centre crossing the shoulder axis)."""

from __future__ import annotations

import numpy as np
import pytest

import rrc_pin
from rrc_pin.control import Controller, Slowdown

PANDA = np.array([0.0, -0.5, 0.0, -2.0, 0.0, 1.8, 0.7])
UR5 = np.array([0.3, -1.2, 1.2, -1.5, 1.2, 0.4])
# (arm, start, joint driven to the singular value, singular value, what is singular there)
CASES = [
    ("ur5", UR5, 2, 0.0, "elbow: elbow_joint = 0, the arm stretched"),
    ("ur5", UR5, 4, 0.0, "wrist: wrist_2_joint = 0, wrist axes 1 and 3 parallel"),
    ("panda", PANDA, 3, -0.46, "the wrist centre over the shoulder axis (sigma_min 1e-3)"),
]


def approach_twist(arm, q, joint, value, speed):
    """The tool twist (world_aligned) of moving ``joint`` toward ``value``, at ``speed`` m/s."""
    dq = np.zeros(arm.nq)
    dq[joint] = np.sign(value - q[joint])
    twist = arm.jacobian(q) @ dq
    return twist * speed / np.linalg.norm(twist[:3])


@pytest.mark.parametrize(("name", "q0", "joint", "value", "what"), CASES)
def test_approaching_slows_and_leaving_is_never_slowed(name, q0, joint, value, what):
    arm = rrc_pin.load(name)
    strategy = Slowdown(start=0.1, stop=0.01, rate=4.0)
    slowed = Controller(arm, q0=q0, strategy=strategy, drift=None)
    q_near = q0.copy()
    q_near[joint] = value + 0.25 * np.sign(q0[joint] - value)  # inside the slowdown zone
    twist = approach_twist(arm, q_near, joint, value, 0.05)
    slowed.q = q_near.copy()
    for _ in range(150):
        slowed.step(twist, "world_aligned")
    sigma = slowed.log.column("sigma_min")
    factor = slowed.log.column("factor")
    assert sigma[0] < 0.1 and factor.min() < 0.2, (sigma[0], factor.min())
    assert sigma.min() > 0.9 * strategy.stop  # never past the stop
    assert np.all(np.diff(sigma) < 1e-9)  # it approached all along
    # Back out: the first tick away gets the full command, as without the strategy.
    plain = Controller(arm, q0=slowed.q, drift=None)
    back = slowed.step(-twist, "world_aligned").resolution
    assert slowed.log.column("factor")[-1] == 1.0
    assert np.allclose(back.qdot, plain.step(-twist, "world_aligned").resolution.qdot, atol=1e-12)
    for _ in range(50):
        slowed.step(-twist, "world_aligned")
    assert np.all(slowed.log.column("factor")[-51:] == 1.0)
    assert slowed.log.column("sigma_min")[-1] > sigma[-1]


def test_hysteresis_releases_above_the_band_only():
    strategy = Slowdown(start=0.05, stop=0.01, release=1.5)  # releases above 0.075
    arm = rrc_pin.load("ur5")
    ctl = Controller(arm, q0=UR5, strategy=strategy)
    q = UR5.copy()
    # sigma_min: 0.097 at elbow 0.6, 0.025 at 0.15, 0.058 at 0.35
    for elbow, engaged in [(0.6, False), (0.15, True), (0.35, True), (0.6, False), (0.35, False)]:
        q[2] = elbow
        ctl.q = q.copy()
        ctl.step([0.0, 0.0, 0.01, 0.0, 0.0, 0.0], ref="local")
        assert strategy.engaged is engaged, (elbow, ctl.log.column("sigma_min")[-1])


def test_manipulability_measure_and_bad_settings():
    strategy = Slowdown("manipulability", start=1e-3, stop=1e-5)
    assert strategy.value(np.array([2.0, 0.5, 0.1])) == pytest.approx(0.1)
    for kwargs, argument in [({"measure": "volume"}, "measure"), ({"start": 0.001}, "start"),
                             ({"rate": 0.0}, "rate"), ({"release": 0.5}, "release")]:
        with pytest.raises(rrc_pin.InvalidInput) as info:
            Slowdown(**kwargs)
        assert info.value.argument == argument
