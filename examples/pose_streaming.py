"""Streamed pose targets: a 90 Hz tracker with its faults driving hands at 100 Hz.

Shows: a recorded device stream (synthesised, seeded: 0.5 mm noise, two dropouts, a
three-sample glitch and a tracker whose frame moved) replayed into ``rrc_pin.Controller``
through its own stream (``ctl.stream()``: push the device's poses, press the clutch, and
``ctl.step()`` follows), with the clutch pressed for half a second; the same with the jerk
stage on (``smoothing=SmoothingOptions(...)``); baxter's two hands in one ``Controller``
(the left the tool frame, the right a second streamed frame); gsfc_dual's two free hands in
one ``CellController``. Prints how far behind the device each hand is, the jumps rejected,
the re-anchorings, and how far the smoothed hand is from the raw one.
Needs only ``pip install -e .``.

Run: ``python examples/pose_streaming.py``
"""

from __future__ import annotations

import os

import numpy as np

import rrc_pin
from rrc_pin.cells import CellController
from rrc_pin.control.pose_stream import PoseStream
from rrc_pin.control.smoothing import SmoothingOptions
from rrc_pin.control.synthetic_stream import Jump, device_pose, synthetic_stream

QUICK = os.environ.get("RRC_PIN_EXAMPLES_QUICK") == "1"
DT = 0.01
SECONDS = 6.0 if QUICK else 14.0
MOVED = Jump(4.2 if QUICK else 8.5, (0.0, 0.2, 0.05))  # the tracker's frame moves for good
FAULTS = {"dropouts": [(1.5, 1.65), (3.0, 3.4) if QUICK else (6.0, 6.4)],
          "jumps": [Jump(2.2 if QUICK else 4.5, (0.25, 0.0, 0.0), 3), MOVED]}  # fmt: skip
CLUTCH = (5.0, 5.5) if QUICK else (10.5, 11.5)


class Device:
    """One tracker's recording, pushed into a controller's stream as the loop's clock passes.

    In a real loop the device's thread calls ``stream.push`` as its samples come.
    """

    def __init__(self, stream: PoseStream, seed: int, phase: float = 0.0) -> None:
        self.recording = synthetic_stream(SECONDS, 90.0, seed=seed, phase=phase, **FAULTS)
        self.stream, self.phase, self.next, self.errors = stream, phase, 0, []

    def feed(self, t: float, hand: np.ndarray) -> None:
        """Push the samples due by ``t`` [s], set the clutch, note the hand's distance.

        The distance to the clean device's pose 0.1 s before (the stream's lag, 1 / gain).
        """
        rec = self.recording
        while self.next < len(rec.times) and rec.times[self.next] <= t + 1e-9:
            self.stream.push(rec.times[self.next], rec.poses[self.next])
            self.next += 1
        self.stream.clutch(CLUTCH[0] <= t < CLUTCH[1], t)
        clean = device_pose(max(t - 0.1, 0.0), phase=self.phase)
        if t - 0.1 >= MOVED.start:
            clean[:3, 3] += MOVED.offset
        if self.stream.state == "tracking":
            self.errors.append(np.linalg.norm(self.stream.target_for(clean)[:3, 3] - hand[:3, 3]))

    def summary(self) -> str:
        """How the hand followed, in words."""
        s = self.stream
        return (f"median distance to the device's pose 0.1 s before "
                f"{1e3 * np.median(self.errors):.1f} mm; jumps rejected {s.rejected}; "
                f"re-anchored at {', '.join(f'{a:.2f} s' for a in s.anchors)}")


def replay(ctl: rrc_pin.control.Loop, devices: dict[str, Device]) -> np.ndarray:
    """Step ``ctl`` for SECONDS with its devices fed; the first frame's positions."""
    frames = {n: ctl.frame_of(n) if isinstance(ctl, CellController) else n for n in devices}
    path = []
    for k in range(round(SECONDS / DT)):
        for name, device in devices.items():
            device.feed(k * DT, ctl.robot.fk(ctl.q, frames[name]))
        ctl.step()
        path.append(ctl.robot.fk(ctl.q, frames[next(iter(devices))])[:3, 3])
    return np.array(path)


def main() -> None:
    """Panda raw and jerk-limited, baxter's two hands, gsfc_dual's two free hands."""
    panda = rrc_pin.load("panda")
    paths = {}
    for label, smoothing in (("raw", None), ("jerk-limited", SmoothingOptions(20.0, 500.0))):
        ctl = rrc_pin.Controller(panda, dt=DT, smoothing=smoothing)
        device = Device(ctl.stream(), seed=1)
        paths[label] = replay(ctl, {panda.tool_frame: device})
        print(f"panda {label}, {SECONDS:.0f} s of a 90 Hz stream at 100 Hz: {device.summary()}")
    apart = np.linalg.norm(paths["raw"] - paths["jerk-limited"], axis=1)
    print(f"panda jerk-limited hand from the raw one: largest {1e3 * apart.max():.1f} mm, "
          f"median {1e3 * np.median(apart):.2f} mm")

    baxter = rrc_pin.load("baxter", tool_frame="left_gripper")
    ctl = rrc_pin.Controller(baxter, dt=DT)
    devices = {"left_gripper": Device(ctl.stream(), seed=2),
               "right_gripper": Device(ctl.stream("right_gripper"), seed=3, phase=1.0)}  # fmt: skip
    replay(ctl, devices)
    for frame, device in devices.items():
        print(f"baxter {frame}: {device.summary()}")

    dual = rrc_pin.load("gsfc_dual")
    free = rrc_pin.cells.make_cell({k: (a.robot, a.base) for k, a in dual.arms.items()},
                                   name="free", ready={k: dual.ready()[a.q]
                                                       for k, a in dual.arms.items()})  # fmt: skip
    cell = CellController(free, DT)
    devices = {"left": Device(cell.stream("left"), seed=4),
               "right": Device(cell.stream("right"), seed=5, phase=1.0)}  # fmt: skip
    replay(cell, devices)
    for name, device in devices.items():
        print(f"gsfc_dual {name} hand: {device.summary()}")


if __name__ == "__main__":
    main()
