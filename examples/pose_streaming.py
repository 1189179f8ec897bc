"""Streamed pose targets: a 90 Hz tracker with its faults driving hands at 100 Hz.

Shows: a recorded device stream (synthesised, seeded: 0.5 mm noise, two dropouts, a
three-sample glitch and a tracker whose frame moved) replayed into
``rrc_pin.Controller.step`` on panda through a ``rrc_pin.PoseStream`` (its twists in base
axes), with the hand's clutch pressed for a second; then baxter's two hands, each on its own
stream, through one ``Resolver`` with two ``FrameTask``. Prints how far behind the device the
hand is, the jumps rejected and the re-anchorings. Needs only ``pip install -e .``.

Run: ``python examples/pose_streaming.py``
"""

from __future__ import annotations

import os

import numpy as np

import rrc_pin
from rrc_pin.control.synthetic_stream import Jump, device_pose, synthetic_stream

QUICK = os.environ.get("RRC_PIN_EXAMPLES_QUICK") == "1"
DT = 0.01
SECONDS = 6.0 if QUICK else 14.0
MOVED = Jump(4.2 if QUICK else 8.5, (0.0, 0.2, 0.05))  # the tracker's frame moves for good
FAULTS = {"dropouts": [(1.5, 1.65), (3.0, 3.4) if QUICK else (6.0, 6.4)],
          "jumps": [Jump(2.2 if QUICK else 4.5, (0.25, 0.0, 0.0), 3), MOVED]}  # fmt: skip
CLUTCH = (5.0, 5.5) if QUICK else (10.5, 11.5)


class Hand:
    """One hand's stream fed from its recording as the loop's clock passes the samples."""

    def __init__(self, pose: np.ndarray, seed: int, phase: float = 0.0) -> None:
        self.recording = synthetic_stream(SECONDS, 90.0, seed=seed, phase=phase, **FAULTS)
        self.stream = rrc_pin.PoseStream(pose)
        self.phase, self.next, self.errors = phase, 0, []

    def twist(self, t: float, pose: np.ndarray) -> np.ndarray:
        """Push the samples due by ``t`` [s]; the hand's twist for its ``pose``."""
        rec = self.recording
        while self.next < len(rec.times) and rec.times[self.next] <= t:
            self.stream.push(rec.times[self.next], rec.poses[self.next])
            self.next += 1
        self.stream.clutch(CLUTCH[0] <= t < CLUTCH[1], t)
        clean = device_pose(max(t - 0.1, 0.0), phase=self.phase)  # 0.1 s ago, no noise
        if t - 0.1 >= MOVED.start:
            clean[:3, 3] += MOVED.offset
        if self.stream.state == "tracking":
            self.errors.append(np.linalg.norm(self.stream.target_for(clean)[:3, 3] - pose[:3, 3]))
        return self.stream.twist(t, pose)

    def summary(self) -> str:
        """How the hand followed, in words."""
        s = self.stream
        return (f"median distance to the device's pose 0.1 s before "
                f"{1e3 * np.median(self.errors):.1f} mm; jumps rejected {s.rejected}; "
                f"re-anchored at {', '.join(f'{a:.2f} s' for a in s.anchors)}")


def main() -> None:
    """Panda through Controller.step, then baxter's two hands through one Resolver."""
    panda = rrc_pin.load("panda")
    ctl = rrc_pin.Controller(panda, dt=DT)
    hand = Hand(panda.fk(ctl.q), seed=1)
    for k in range(round(SECONDS / DT)):
        ctl.step(hand.twist(k * DT, panda.fk(ctl.q)), ref="world_aligned")
    print(f"panda, {SECONDS:.0f} s of a 90 Hz stream at 100 Hz: {hand.summary()}")

    baxter = rrc_pin.load("baxter")
    resolver = rrc_pin.Resolver(baxter, dt=DT)
    q = baxter.ready()
    posture = rrc_pin.PostureTask(baxter.ready(), gain=0.5, weight=1e-3)
    hands = {f: Hand(baxter.fk(q, f), seed=2 + i, phase=float(i))
             for i, f in enumerate(baxter.tool_frames)}  # fmt: skip
    for k in range(round(SECONDS / DT)):
        tasks = [rrc_pin.FrameTask(f, h.twist(k * DT, baxter.fk(q, f))) for f, h in hands.items()]
        q = baxter.integrate(q, resolver.solve(q, [tasks, [posture]], priority="strict").qdot, DT)
    for frame, h in hands.items():
        print(f"baxter {frame}: {h.summary()}")


if __name__ == "__main__":
    main()
