"""Nadkarni's guidance: the hand's origin on a straight line while it turns.

Shows: ``rrc_pin.guidance``. The screw of a finite displacement between two hand poses
(axis, translation along it, angle, pitch), then guidance Type III on panda from its ready
pose to a goal 10 cm away turned -150 deg about the hand's z: the hand's origin keeps to the
straight line and the turn is shared evenly by the steps. With a ``Resolver`` as the solver,
the joint limits hold at every step. Needs only ``pip install -e .``.

Run: ``python examples/guidance.py``
"""

import os

import numpy as np
import pinocchio as pin

import rrc_pin
from rrc_pin import guidance

QUICK = os.environ.get("RRC_PIN_EXAMPLES_QUICK") == "1"
steps = 10 if QUICK else 40

arm = rrc_pin.load("panda")
q0 = arm.ready()
start = arm.fk(q0)
goal = start.copy()
goal[:3, 3] += [0.0, 0.1, 0.0]
goal[:3, :3] = start[:3, :3] @ pin.exp3(np.radians(-150.0) * np.array([0.0, 0.0, 1.0]))

s = guidance.screw_from_poses(start, goal)
print(f"screw: axis {np.round(s.u, 3)}, through {np.round(s.rho, 3)} m, "
      f"d {1e3 * float(s.d):.1f} mm, theta {np.degrees(float(s.theta)):.1f} deg")  # fmt: skip

# Each step first order (the thesis's eq. (4-11)), then refined on the step's exact pose
# (correction="newton"; "none" leaves the first-order error of each step).
path = guidance.straight_line(arm, q0, goal, steps, solver=rrc_pin.Resolver(arm, dt=1.0),
                              correction="newton")  # fmt: skip
line = goal[:3, 3] - start[:3, 3]
line /= np.linalg.norm(line)
off = [np.linalg.norm((h[:3, 3] - start[:3, 3]) - ((h[:3, 3] - start[:3, 3]) @ line) * line)
       for h in path.hand]  # fmt: skip
turns = [np.degrees(np.linalg.norm(pin.log3(path.hand[i][:3, :3].T @ path.hand[i + 1][:3, :3])))
         for i in range(steps)]  # fmt: skip
end = pin.log6(pin.SE3(goal) * pin.SE3(path.hand[-1]).inverse()).vector
print(f"Type III in {steps} steps: off the line at most {1e3 * max(off):.2f} mm, "
      f"turn per step {min(turns):.2f} to {max(turns):.2f} deg (even: {150 / steps:.2f})")
print(f"  end off the goal by {1e3 * np.linalg.norm(end[:3]):.2f} mm and "
      f"{np.degrees(np.linalg.norm(end[3:])):.3f} deg; every step within the joint limits: "
      f"{bool(np.all((path.q >= arm.lower) & (path.q <= arm.upper)))}")
