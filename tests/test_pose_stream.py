"""PoseStream: a 90 Hz tracker with noise, dropouts and jumps into a 100 Hz loop (issue 41)."""

from __future__ import annotations

import numpy as np
import pytest

import rrc_pin
from rrc_pin.control.pose_stream import PoseStream, StreamOptions
from rrc_pin.control.synthetic_stream import Jump, device_pose, synthetic_stream

DT = 0.01
SECONDS = 14.0
DROPOUTS = [(3.0, 3.15), (6.0, 6.4)]
GLITCH = Jump(4.5, (0.25, 0.0, 0.0), 3)  # three samples 0.25 m off, then back
MOVED = Jump(8.5, (0.0, 0.2, 0.05))  # the tracker's frame moved for good
CLUTCH = (10.5, 11.5)
SETTLED = 0.5
"""[s] After each event's end (a dropout, a jump, a re-anchoring) the hand catches up: the
lag and error are measured outside these windows."""


def clean(t: float, phase: float = 0.0) -> np.ndarray:
    """What the tracker would report at ``t`` without noise: the truth, moved by MOVED."""
    pose = device_pose(t, phase=phase)
    if t >= MOVED.start:
        pose[:3, 3] += MOVED.offset
    return pose


class Replay:
    """A recording replayed into a stream at the control rate, one hand's record."""

    def __init__(self, hand: np.ndarray, seed: int, phase: float = 0.0) -> None:
        self.recording = synthetic_stream(SECONDS, 90.0, seed=seed, dropouts=DROPOUTS,
                                          jumps=[GLITCH, MOVED], phase=phase)  # fmt: skip
        self.stream = PoseStream(hand)
        self.phase, self.next = phase, 0
        self.hands: list[np.ndarray] = []
        self.expected: list[np.ndarray] = []
        self.targets: list[np.ndarray] = []
        self.states: list[str] = []

    def twist(self, t: float, hand: np.ndarray) -> np.ndarray:
        rec, stream = self.recording, self.stream
        while self.next < len(rec.times) and rec.times[self.next] <= t:
            stream.push(rec.times[self.next], rec.poses[self.next])
            self.next += 1
        stream.clutch(CLUTCH[0] <= t < CLUTCH[1], t)
        twist = stream.twist(t, hand)
        self.hands.append(hand[:3, 3])
        self.expected.append(stream.target_for(clean(t, self.phase))[:3, 3])
        self.targets.append(stream.target[:3, 3])
        self.states.append(stream.state)
        return twist

    def lag_and_error(self) -> tuple[float, float, float]:
        """The delay [s] that best aligns the hand with the clean target, and the largest
        and RMS distances [m] at it, over steady tracking."""
        t = np.arange(len(self.hands)) * DT
        steady = np.array([s == "tracking" for s in self.states])
        ends = [0.0, *(b for _, b in DROPOUTS), GLITCH.start + 0.05, MOVED.start,
                *self.stream.anchors]  # fmt: skip
        for end in ends:
            steady &= ~((t >= end) & (t < end + SETTLED))
        hands, expected = np.array(self.hands), np.array(self.expected)
        best = (0.0, np.inf, np.inf)
        for lag in range(30):
            idx = np.flatnonzero(steady)
            idx = idx[idx >= lag]
            err = np.linalg.norm(hands[idx] - expected[idx - lag], axis=1)
            rms = float(np.sqrt((err**2).mean()))
            if rms < best[2]:
                best = (lag * DT, float(err.max()), rms)
        return best


def test_panda_follows_a_recorded_stream_through_its_faults():
    """Controller.step with the stream's twists (world_aligned) at 100 Hz: the hand follows
    the device 0.10 s behind within 3 mm (tracker noise 0.5 mm); the two jumps are rejected
    (the glitch's first sample, the moved frame's first, re-anchored after 5 samples); the
    clutch holds the hand and its release re-anchors without a step."""
    arm = rrc_pin.load("panda")
    ctl = rrc_pin.Controller(arm, dt=DT)
    replay = Replay(arm.fk(ctl.q), seed=1)
    for k in range(round(SECONDS / DT)):
        ctl.step(replay.twist(k * DT, arm.fk(ctl.q)), ref="world_aligned")
    stream = replay.stream
    lag, worst, rms = replay.lag_and_error()
    assert 0.05 <= lag <= 0.12 and worst < 3e-3 and rms < 1.5e-3, (lag, worst, rms)
    assert stream.rejected == 2
    assert len(stream.anchors) == 2 and MOVED.start < stream.anchors[0] < MOVED.start + 0.1
    assert stream.anchors[1] == CLUTCH[1]
    states = replay.states
    assert "dropout" in states and "lost" in states and "clutched" in states
    release = round(CLUTCH[1] / DT)
    targets, hands = np.array(replay.targets), np.array(replay.hands)
    assert np.abs(targets[release] - targets[release - 1]).max() < 1e-12  # no step
    held = hands[round(CLUTCH[0] / DT) + 50 : release]  # once the lag is made up
    assert np.ptp(held, axis=0).max() < 1e-4  # the hand held while the device moved
    dv = np.linalg.norm(np.diff(hands, 2, axis=0), axis=1) / DT  # velocity change per tick
    tracking = np.array([s == "tracking" for s in states])[1:-1]
    assert dv[release - 3 : release + 10].max() <= dv[tracking].max()


def test_two_hands_of_baxter_each_on_its_own_stream():
    """Both hands through one Resolver with two FrameTasks (world_aligned), a posture below:
    each follows its own recording (other seeds, the figure's phase apart) as panda's did."""
    baxter = rrc_pin.load("baxter")
    left, right = baxter.tool_frames
    resolver = rrc_pin.Resolver(baxter, dt=DT)
    q = baxter.ready()
    posture = rrc_pin.PostureTask(baxter.ready(), gain=0.5, weight=1e-3)
    replays = {left: Replay(baxter.fk(q, left), seed=2),
               right: Replay(baxter.fk(q, right), seed=3, phase=1.0)}  # fmt: skip
    for k in range(round(SECONDS / DT)):
        tasks = [rrc_pin.FrameTask(f, r.twist(k * DT, baxter.fk(q, f))) for f, r in replays.items()]
        result = resolver.solve(q, [tasks, [posture]], priority="strict")
        q = baxter.integrate(q, result.qdot, DT)
    for frame, replay in replays.items():
        lag, worst, rms = replay.lag_and_error()
        assert 0.05 <= lag <= 0.12 and worst < 3e-3 and rms < 1.5e-3, (frame, lag, worst, rms)
        assert replay.stream.rejected == 2


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
