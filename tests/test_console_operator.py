"""The operator's controls: the deadman gates every twist; jogs, sliders and the target."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from rrc_pin.console import commands as cmd
from rrc_pin.console.operator import Operator, OperatorSettings
from rrc_pin.errors import InvalidInput


def test_nothing_is_commanded_while_the_deadman_is_released():
    op = Operator()
    op.apply(cmd.Velocity(np.array([0.05, 0, 0, 0, 0, 0])), 0.0)
    assert op.twist(0.0) is None
    op.apply(cmd.Latch(True), 0.0)
    twist, frame = op.twist(0.0)
    np.testing.assert_array_equal(twist, [0.05, 0, 0, 0, 0, 0])
    assert frame == "local"


def test_the_hold_button_keeps_the_deadman_for_its_timeout():
    op = Operator(OperatorSettings(hold_timeout=0.25))
    op.apply(cmd.Hold(), 10.0)
    assert op.enabled(10.2)
    assert not op.enabled(10.3)


def test_a_jog_adds_half_the_range_on_its_axis_until_its_timeout():
    op = Operator(OperatorSettings(max_linear=0.1, max_angular=0.5, jog_timeout=0.25))
    op.apply(cmd.Latch(True), 0.0)
    op.apply(cmd.Velocity(np.array([0, 0.01, 0, 0, 0, 0]), "world_aligned"), 0.0)
    op.apply(cmd.Jog(2, -1), 0.0)
    op.apply(cmd.Jog(5, 1), 0.1)
    twist, frame = op.twist(0.2)
    np.testing.assert_allclose(twist, [0, 0.01, -0.05, 0, 0, 0.25])
    assert frame == "world_aligned"
    np.testing.assert_allclose(op.twist(0.4)[0], [0, 0.01, 0, 0, 0, 0])  # both expired
    op.apply(cmd.Jog(0, 1), 1.0)  # a new jog after expiry starts from zero
    np.testing.assert_allclose(op.twist(1.0)[0], [0.05, 0.01, 0, 0, 0, 0])


def test_the_target_servo_points_at_the_target_and_is_clipped():
    op = Operator(OperatorSettings(max_linear=0.1, max_angular=0.5, target_gain=2.0))
    op.apply(cmd.Latch(True), 0.0)
    hand = pin.SE3(pin.rpy.rpyToMatrix(0.3, -0.2, 0.5), np.array([0.4, 0.1, 0.5]))
    near = hand * pin.SE3(np.eye(3), np.array([0.01, 0.0, 0.0]))  # 1 cm along hand x
    op.apply(cmd.Target(near.homogeneous), 0.0)
    assert op.needs_pose()
    twist, frame = op.twist(0.0, hand.homogeneous)
    assert frame == "local"
    np.testing.assert_allclose(twist, [0.02, 0, 0, 0, 0, 0], atol=1e-12)  # gain * error
    far = hand * pin.SE3(pin.rpy.rpyToMatrix(1.0, 0, 0), np.array([0.0, 1.0, 0.0]))
    op.apply(cmd.Target(far.homogeneous), 0.0)
    twist, _ = op.twist(0.0, hand.homogeneous)
    assert np.linalg.norm(twist[:3]) == pytest.approx(0.1)
    assert np.linalg.norm(twist[3:]) == pytest.approx(0.5)


def test_stop_drops_everything_and_counts():
    op = Operator()
    op.apply(cmd.Latch(True), 0.0)
    op.apply(cmd.Velocity(np.ones(6) * 0.01), 0.0)
    op.apply(cmd.Target(np.eye(4)), 0.0)
    op.stop()
    assert op.twist(0.0) is None
    assert op.target is None and not op.latched and op.stops == 1
    np.testing.assert_array_equal(op.velocity, np.zeros(6))


@pytest.mark.parametrize(
    "field",
    ["max_linear", "max_angular", "jog_timeout", "hold_timeout", "target_gain", "jog_fraction"],
)
def test_settings_are_checked(field):
    with pytest.raises(InvalidInput, match=field):
        OperatorSettings(**{field: 0.0})
    with pytest.raises(InvalidInput, match="jog_fraction"):
        OperatorSettings(jog_fraction=1.5)
