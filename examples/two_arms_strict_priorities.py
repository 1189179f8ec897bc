"""Two arms on one torso with strict priorities.

Shows: baxter (15 joints: head pan and two 7-joint arms) from its ready pose, one resolver
for both hands. The top level holds both grippers' commands (the left one up, the right one
forward), the level below a posture, which gets only what the hands leave. A command too fast
for the joints is scaled down, both hands by the one common scale, so the pair keeps its
relative motion; then the left hand moves up while the right one holds still. Needs only
``pip install -e .``.

Run: ``python examples/two_arms_strict_priorities.py``
"""

import os

import numpy as np

import rrc_pin

QUICK = os.environ.get("RRC_PIN_EXAMPLES_QUICK") == "1"
ticks = 20 if QUICK else 100

baxter = rrc_pin.load("baxter")
left, right = baxter.tool_frames
resolver = rrc_pin.Resolver(baxter, dt=0.01)
q = baxter.ready()
start = {frame: baxter.fk(q, frame)[:3, 3] for frame in (left, right)}

for speed in (0.05, 2.0):  # [m/s], base axes
    tasks = [
        [rrc_pin.FrameTask(left, [0.0, 0.0, speed, 0.0, 0.0, 0.0]),  # top level: both hands
         rrc_pin.FrameTask(right, [speed, 0.0, 0.0, 0.0, 0.0, 0.0])],
        rrc_pin.PostureTask(baxter.ready(), gain=1.0),  # then the posture
    ]  # fmt: skip
    r = resolver.solve(q, tasks, priority="strict")
    print(f"left hand up, right hand forward, {speed} m/s: status {r.status}, levels {r.levels}")
    for t in r.tasks:
        print(f"  level {t.level} {t.name:28s} {t.served:7s} scale {t.scale:.3f}")

for _ in range(ticks):  # integrate the slow command
    r = resolver.solve(q, [[rrc_pin.FrameTask(left, [0, 0, 0.05, 0, 0, 0]),
                            rrc_pin.FrameTask(right, [0, 0, 0, 0, 0, 0])],
                           rrc_pin.PostureTask(baxter.ready(), gain=1.0)],
                       priority="strict")  # fmt: skip
    q = q + r.qdot * resolver.dt
moved = {frame: baxter.fk(q, frame)[:3, 3] - start[frame] for frame in (left, right)}
print(f"after {ticks} ticks: left hand moved {np.round(1e3 * moved[left], 2)} mm, "
      f"right hand {np.round(1e3 * moved[right], 3)} mm")  # fmt: skip
