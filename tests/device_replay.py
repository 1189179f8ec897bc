"""A recorded device stream replayed into a PoseStream at the control rate, and how well the
hand followed it (shared by the stream's and the controllers' tests; issue 41)."""

from __future__ import annotations

import numpy as np

from rrc_pin.control.pose_stream import PoseStream
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
    """A 90 Hz recording (noise, two dropouts, a glitch, a moved frame) fed into ``stream``
    as the loop's clock passes its samples, the clutch pressed over CLUTCH; one hand's record."""

    def __init__(self, stream: PoseStream, seed: int, phase: float = 0.0,
                 seconds: float = SECONDS) -> None:  # fmt: skip
        self.recording = synthetic_stream(seconds, 90.0, seed=seed, dropouts=DROPOUTS,
                                          jumps=[GLITCH, MOVED], phase=phase)  # fmt: skip
        self.stream, self.seed = stream, seed
        self.phase, self.next = phase, 0
        self.hands: list[np.ndarray] = []
        self.expected: list[np.ndarray] = []
        self.targets: list[np.ndarray] = []
        self.states: list[str] = []

    def feed(self, t: float, hand: np.ndarray) -> None:
        """The samples due by ``t`` [s] pushed, the clutch set; the hand's pose recorded."""
        rec, stream = self.recording, self.stream
        while self.next < len(rec.times) and rec.times[self.next] <= t + 1e-9:
            stream.push(rec.times[self.next], rec.poses[self.next])
            self.next += 1
        stream.clutch(CLUTCH[0] <= t < CLUTCH[1], t)
        self.hands.append(hand[:3, 3])
        self.expected.append(stream.target_for(clean(t, self.phase))[:3, 3])
        self.targets.append(stream.target[:3, 3])
        self.states.append(stream.state)

    def twist(self, t: float, hand: np.ndarray) -> np.ndarray:
        """:meth:`feed`, then the stream's twist for ``hand`` (a loop without streams)."""
        self.feed(t, hand)
        return self.stream.twist(t, hand)

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

    def check_faults(self) -> None:
        """Both jumps rejected, the moved frame re-anchored within 0.1 s, the clutch held the
        hand and its release re-anchored with no step in the target or the hand's motion."""
        stream, states = self.stream, self.states
        assert stream.rejected == 2, self.seed
        first = stream.anchors[0] if stream.anchors else -1.0
        assert len(stream.anchors) == 2 and MOVED.start < first < MOVED.start + 0.1, self.seed
        assert abs(stream.anchors[1] - CLUTCH[1]) < 1e-9, self.seed
        assert "dropout" in states and "lost" in states and "clutched" in states, self.seed
        release = round(CLUTCH[1] / DT)
        targets, hands = np.array(self.targets), np.array(self.hands)
        step = np.abs(targets[release] - targets[release - 1]).max()
        assert step < 1e-12, self.seed  # no step
        held = hands[round(CLUTCH[0] / DT) + 50 : release]  # once the lag is made up
        assert np.ptp(held, axis=0).max() < 1e-4, self.seed  # held while the device moved
        dv = np.linalg.norm(np.diff(hands, 2, axis=0), axis=1) / DT  # velocity change per tick
        tracking = np.array([s == "tracking" for s in states])[1:-1]
        assert dv[release - 3 : release + 10].max() <= dv[tracking].max(), self.seed
