"""Pointing: a tool axis kept along a direction, a camera axis kept on a point.

Shows: ``rrc_pin.AxisAlignTask`` turning panda's tool axis onto a tilted direction while its
hand holds its place and a command below spins it about that axis (the task leaves that
rotation free); then ``rrc_pin.LookAtTask`` keeping the tool's axis on a point of the table
while the hand is carried 0.2 m sideways. Prints the angles. Needs only ``pip install -e .``.

Run: ``python examples/pointing.py``
"""

from __future__ import annotations

import numpy as np

import rrc_pin
from rrc_pin.kinematics import Kinematics, Layout

DT = 0.01


def kinematics(arm: rrc_pin.Robot, q: np.ndarray) -> Kinematics:
    """The kinematics of ``arm`` at ``q`` (what a resolver builds each tick)."""
    _, dof, q_pin = arm.positions(q)
    return Kinematics(arm.model, arm.model.createData(), Layout.of(arm), dof, q_pin)


def main() -> None:
    """Align, then look at."""
    arm = rrc_pin.load("panda")
    tool, q = arm.tool_frame, arm.ready()
    align = rrc_pin.AxisAlignTask(tool, axis=[0, 0, 1], direction=[0.3, -0.2, -1.0])
    hold = rrc_pin.FrameTask(tool, rows="position", target=arm.fk(q))
    spin = rrc_pin.FrameTask(tool, [0.0, 0.0, 0.3], rows="orientation", ref="local")
    resolver = rrc_pin.Resolver(arm, dt=DT)
    before = align.angle(kinematics(arm, q))
    for _ in range(150):
        q = arm.integrate(q, resolver.solve(q, [[hold, align], [spin]], priority="strict").qdot, DT)
    x0, x = arm.fk(arm.ready())[:3, 0], arm.fk(q)[:3, 0]
    print(f"tool axis to the direction: {np.degrees(before):.1f} deg -> "
          f"{np.degrees(align.angle(kinematics(arm, q))):.4f} deg in 1.5 s; spun about it "
          f"{np.degrees(np.arccos(np.clip(x0 @ x, -1.0, 1.0))):.0f} deg; hand moved "
          f"{1e3 * np.linalg.norm(arm.fk(q)[:3, 3] - hold.target[:3, 3]):.3f} mm")

    q = arm.ready()
    point = arm.fk(q)[:3, 3] + np.array([0.1, 0.05, -0.4])
    look = rrc_pin.LookAtTask(tool, point, gain=10.0)
    start = arm.fk(q)
    worst = 0.0
    for k in range(300):
        target = start.copy()
        target[1, 3] += 0.1 * DT * min(k, 200)
        carry = rrc_pin.FrameTask(tool, [0.0, 0.1 if k < 200 else 0.0, 0.0], rows="position",
                                  target=target)  # fmt: skip
        q = arm.integrate(q, resolver.solve(q, [[carry, look]], priority="strict").qdot, DT)
        if k >= 100:
            worst = max(worst, look.angle(kinematics(arm, q)))
    print(f"look-at: the axis on the point within {1e3 * worst:.3f} mrad while the hand moved "
          f"{1e3 * (arm.fk(q)[1, 3] - start[1, 3]):.1f} mm sideways")
    print(f"the point {np.round(point, 3).tolist()} m, the tool at "
          f"{np.round(arm.fk(q)[:3, 3], 3).tolist()} m")


if __name__ == "__main__":
    main()
