"""A task of your own: keep the hand at its height.

Shows: a ``rrc_pin.Task`` subclass (two methods: the frames it reads, and its rows
``A qdot ~= b`` at a tick, built from the tick's kinematics) used beside the library's
tasks. On panda, the height task sits at the top priority level and a hand command below it:
the command's downward part is not followed, its sideways part is. Needs only
``pip install -e .``.

Run: ``python examples/custom_task.py``
"""

import os

import numpy as np

import rrc_pin
from rrc_pin import TaskRows
from rrc_pin.kinematics import Kinematics

QUICK = os.environ.get("RRC_PIN_EXAMPLES_QUICK") == "1"
ticks = 20 if QUICK else 200


class HeightTask(rrc_pin.Task):
    """The origin of ``frame`` at height ``z`` [m] (base frame): ``vz = gain (z - z_now)``."""

    def __init__(self, frame: str, z: float, gain: float = 5.0, weight: float = 1.0) -> None:
        self.frame, self.z, self.gain = frame, z, gain
        self.weight = weight
        self.name = f"height:{frame}"

    def frames(self) -> tuple[str, ...]:
        """The frames the task reads (checked against the robot before a tick)."""
        return (self.frame,)

    def rows(self, kin: Kinematics) -> TaskRows:
        """One row at this tick: the height rate of the frame's origin, and its target."""
        J = kin.jacobian(self.frame, "world_aligned")  # (6, nv), rows [v; w], base axes
        z_now = kin.pose(self.frame)[2, 3]
        return TaskRows(J[2:3], np.array([self.gain * (self.z - z_now)]), None, self.name)


arm = rrc_pin.load("panda")
tool = arm.tool_frame
resolver = rrc_pin.Resolver(arm, dt=0.01)
q = arm.ready()
start = arm.fk(q)[:3, 3]
height = HeightTask(tool, z=start[2])
command = rrc_pin.FrameTask(tool, [0.0, 0.05, -0.05, 0.0, 0.0, 0.0])  # sideways and down
for _ in range(ticks):
    r = resolver.solve(q, [height, command], priority="strict")
    q = q + r.qdot * resolver.dt
moved = arm.fk(q)[:3, 3] - start
print(f"after {ticks} ticks of 'sideways and down' under the height task:")
print(f"  sideways {1e3 * moved[1]:.2f} mm (commanded {1e3 * 0.05 * ticks * 0.01:.2f})")
print(f"  down     {1e3 * -moved[2]:.4f} mm (the height task keeps it)")
print(f"  tasks: {[(t.name, t.level, t.served, round(t.scale, 3)) for t in r.tasks]}")
