"""PoseStream: a 90 Hz tracker with noise, dropouts and jumps into a 100 Hz loop (issue 41)."""

from __future__ import annotations

import numpy as np
import pytest

import rrc_pin
from rrc_pin.control.pose_stream import PoseStream, StreamOptions


def test_reset_holds_the_hand_where_it_is_and_the_next_samples_move_it_from_there():
    """A controller that moved the hand otherwise (reverse) resets its stream there: the
    target is the pose given, and the device's next motion moves it from that pose."""
    hand = np.eye(4)
    stream = PoseStream(hand)
    device = np.eye(4)
    stream.push(0.0, device)
    device[:3, 3] = [0.01, 0.0, 0.0]
    stream.push(0.01, device)
    assert np.allclose(stream.target[:3, 3], [0.01, 0.0, 0.0], atol=1e-12)
    moved = np.eye(4)
    moved[:3, 3] = [0.3, 0.2, 0.1]
    stream.reset(moved)
    assert np.allclose(stream.target, moved, atol=1e-12)
    device[:3, 3] = [0.02, 0.0, 0.01]
    stream.push(0.02, device)
    assert np.allclose(stream.target[:3, 3], [0.31, 0.2, 0.11], atol=1e-12)
    with pytest.raises(rrc_pin.InvalidInput, match="hand"):
        stream.reset(np.zeros((4, 4)))


def test_the_twist_is_bounded_and_fades_in_a_dropout():
    hand = np.eye(4)
    options = StreamOptions(gain=10.0, linear_speed=0.3, angular_speed=1.0, timeout=0.05,
                            decay=0.05)  # fmt: skip
    stream = PoseStream(hand, options)
    stream.push(0.0, np.eye(4))
    far = np.eye(4)
    far[:3, 3] = [0.04, 0.0, 0.0]  # within the jump bound at 90 Hz
    far[:3, :3] = rotation_z(0.2)
    assert stream.push(1 / 90, far)
    twist = stream.twist(1 / 90, hand)
    assert np.linalg.norm(twist[:3]) == pytest.approx(0.3)  # clamped along itself
    np.testing.assert_allclose(twist[:3] / 0.3, [1.0, 0.0, 0.0], atol=1e-12)
    assert np.linalg.norm(twist[3:]) == pytest.approx(1.0)
    faded = stream.twist(1 / 90 + 0.05 + 0.1, hand)  # 0.1 s past the timeout: e^-2
    assert stream.state == "dropout"
    np.testing.assert_allclose(faded, twist * np.exp(-2.0), rtol=1e-12)
    stream.push(0.2, far)
    assert stream.state == "tracking"
    np.testing.assert_allclose(stream.twist(0.2, hand), twist, rtol=1e-12)


def test_the_workspace_box_clamps_the_target():
    options = StreamOptions(lower=[-0.1, -0.1, 0.0], upper=[0.1, 0.1, 0.2], jump=1.0)
    stream = PoseStream(np.eye(4), options)
    stream.push(0.0, np.eye(4))
    moved = np.eye(4)
    moved[:3, 3] = [0.5, -0.05, -0.3]
    stream.push(0.1, moved)
    np.testing.assert_allclose(stream.target[:3, 3], [0.1, -0.05, 0.0], atol=1e-15)


def test_the_mapping_turns_scales_and_rotates_in_place():
    """Device axes turned 90 deg about z into the base, translation halved; the hand turns
    about the base axes where it is."""
    turn = rotation_z(np.pi / 2)
    stream = PoseStream(np.eye(4), StreamOptions(device_axes=turn, scale=0.5, jump=1.0,
                                                 jump_angle=4.0))  # fmt: skip
    hand = np.eye(4)
    hand[:3, 3] = [0.3, 0.0, 0.5]
    stream = PoseStream(hand, stream.options)
    stream.push(0.0, np.eye(4))
    moved = np.eye(4)
    moved[:3, 3] = [0.2, 0.0, 0.0]
    moved[:3, :3] = rotation_x(0.3)
    stream.push(0.1, moved)
    target = stream.target
    np.testing.assert_allclose(target[:3, 3], [0.3, 0.1, 0.5], atol=1e-15)
    np.testing.assert_allclose(target[:3, :3], rotation_y(0.3), atol=1e-15)


def test_bad_arguments_are_refused_by_name():
    for kwargs, argument in [({"gain": 0.0}, "gain"), ({"settle": 0}, "settle"),
                             ({"lower": [0, 0, 0]}, "lower"),
                             ({"lower": [0, 0, 0], "upper": [1, -1, 1]}, "upper"),
                             ({"device_axes": np.ones((3, 3))}, "device_axes")]:  # fmt: skip
        with pytest.raises(rrc_pin.InvalidInput) as info:
            StreamOptions(**kwargs)
        assert info.value.argument == argument
    stream = PoseStream(np.eye(4))
    stream.push(1.0, np.eye(4))
    with pytest.raises(rrc_pin.InvalidInput) as info:
        stream.push(0.5, np.eye(4))
    assert info.value.argument == "t"
    with pytest.raises(rrc_pin.InvalidInput):
        stream.push(2.0, np.ones((4, 4)))
    with pytest.raises(rrc_pin.InvalidInput):
        stream.clutch("yes")  # type: ignore[arg-type]
    assert stream.state == "tracking" and stream.rejected == 0


def rotation_z(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rotation_x(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rotation_y(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])
